//! CPU twins of the scene-free ray geometry in `sphere.wgsl` and
//! `ray_offset.wgsl`, each beside its Rust module:
//! the sphere's distance and the robust ray offset, line for line, so that
//! tests can hold the f32 shader and its twin to double precision
//! (`crates/render/tests/gpu/geometry_stability.rs`, through `gpu::harness::geometry`).

pub mod ray_offset;
pub mod sphere;

pub use ray_offset::offset_ray;
pub use sphere::{NO_HIT, sphere_distance};
