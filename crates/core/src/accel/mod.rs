//! Acceleration structures for triangle meshes, built on the CPU and walked
//! by the GPU (`crates/core/src/accel/traverse.wgsl`): the watertight ray–triangle test, the
//! binned-SAH BVH and its flattened nodes, a CPU traversal that mirrors the
//! shader's, and procedural meshes for tests and benchmarks.

pub mod aabb;
pub mod bvh;
pub mod shapes;
pub mod traverse;
pub mod triangle;
pub mod wide;

pub use bvh::{Bvh, BvhNode, BvhStats};
pub use traverse::MeshHit;
pub use triangle::{TriangleHit, intersect};
pub use wide::WideBvh;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// One triangle as `struct TriangleVerts` in `crates/core/src/accel/traverse.wgsl`: three
/// `vec4f` whose w is unused (48 bytes, no padding rules to get wrong).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct TriangleVerts {
    pub v0: [f32; 4],
    pub v1: [f32; 4],
    pub v2: [f32; 4],
}

impl TriangleVerts {
    pub fn new(tri: &[Vec3; 3]) -> Self {
        let [v0, v1, v2] = tri.map(|v| v.extend(0.0).to_array());
        TriangleVerts { v0, v1, v2 }
    }
}
