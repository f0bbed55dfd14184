//! The storage buffers of the scene's triangles and lights: the BVH nodes,
//! the triangles' vertices and attributes in BVH order (bindings 12–14 of
//! `shaders/scene.wgsl`), and the light table (binding 15), which names
//! emissive triangles by their place in that order.
//!
//! The BVH is rebuilt only when the geometry or its placement changes; the
//! light table when the geometry, a material, a sphere's size or the point
//! light changes (an emission edit changes the powers).

use crate::gpu::harness::dispatch::check_size;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use marbre_core::accel::{Bvh, BvhNode, TriangleVerts, WideBvh};
use marbre_core::lights::{EmitterTriangle, Light, LightTable};
use marbre_core::scene::{Change, MeshPlacement, Scene};
use std::sync::Arc;
use std::time::Duration;
use wgpu::util::DeviceExt;

/// `TriangleAttributes` of `shaders/scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct TriangleAttributes {
    pub uv01: [f32; 4],
    pub uv2: [f32; 2],
    pub material: u32,
    pub _pad: u32,
}

/// The meshes as the CPU kernel walks them (`cpu_kernel`): the BVH, the
/// triangles' corners and attributes in its order, the very data the
/// storage buffers hold.
pub struct MeshGeometry {
    pub bvh: Bvh,
    /// The BVH four children a node, as the CPU kernel walks it.
    pub wide: WideBvh,
    pub positions: Vec<[Vec3; 3]>,
    pub attributes: Vec<TriangleAttributes>,
}

impl Default for MeshGeometry {
    /// No triangle: the hierarchy of one empty node.
    fn default() -> Self {
        Self {
            bvh: Bvh::build(&[]),
            wide: WideBvh::default(),
            positions: Vec::new(),
            attributes: Vec::new(),
        }
    }
}

/// What the BVH was built from: the same key, the same BVH.
#[derive(Debug, Clone, PartialEq, Default)]
struct GeometryKey {
    meshes: Vec<(usize, MeshPlacement, u32)>,
}

impl GeometryKey {
    fn of(scene: &Scene) -> Self {
        let bases = scene.mesh_material_bases();
        Self {
            meshes: scene
                .meshes
                .iter()
                .zip(bases)
                .map(|(m, base)| {
                    (
                        std::sync::Arc::as_ptr(&m.geometry.0) as usize,
                        m.placement,
                        base,
                    )
                })
                .collect(),
        }
    }
}

/// Counts for the Stats panel.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MeshStats {
    pub triangles: usize,
    pub bvh_nodes: usize,
    pub bvh_build: Duration,
    pub lights: usize,
}

pub struct MeshBuffers {
    key: GeometryKey,
    nodes: wgpu::Buffer,
    triangles: wgpu::Buffer,
    attributes: wgpu::Buffer,
    lights: wgpu::Buffer,
    /// The same geometry on the CPU, for the CPU kernel.
    geometry: Arc<MeshGeometry>,
    /// The triangles in BVH order, as the light table reads them.
    emitters: Vec<EmitterTriangle>,
    table: LightTable,
    stats: MeshStats,
    /// Geometry a loader thread prepared for the next scene.
    provided: Option<PreparedGeometry>,
}

fn storage_buffer(device: &wgpu::Device, label: &str, contents: &[u8]) -> wgpu::Buffer {
    // A binding may not be empty: an empty list is one zeroed element.
    let zeros = [0u8; 64];
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: if contents.is_empty() {
            &zeros
        } else {
            contents
        },
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    })
}

/// The CPU half of a geometry upload: the BVH over every mesh triangle in
/// world space, the triangles and their attributes in BVH order, and the
/// emissive ones. Building it is the slow part of loading a big mesh (the
/// BVH), so a loader thread can do it ([`MeshBuffers::provide`]) while the
/// window keeps drawing.
pub struct PreparedGeometry {
    key: GeometryKey,
    geometry: MeshGeometry,
    verts: Vec<TriangleVerts>,
    emitters: Vec<EmitterTriangle>,
}

impl PreparedGeometry {
    pub fn of(scene: &Scene) -> Self {
        let key = GeometryKey::of(scene);
        let bases = scene.mesh_material_bases();
        let mut positions: Vec<[Vec3; 3]> = Vec::with_capacity(scene.triangle_count());
        let mut attributes = Vec::with_capacity(scene.triangle_count());
        for (mesh, base) in scene.meshes.iter().zip(bases) {
            positions.extend(mesh.world_positions());
            let g = &mesh.geometry.0;
            for (uv, &m) in g.uvs.iter().zip(&g.materials) {
                attributes.push(TriangleAttributes {
                    uv01: [uv[0].x, uv[0].y, uv[1].x, uv[1].y],
                    uv2: [uv[2].x, uv[2].y],
                    material: base + m.min(mesh.materials.len().saturating_sub(1) as u32),
                    _pad: 0,
                });
            }
        }
        let bvh = Bvh::build(&positions);
        let positions = bvh.reorder(&positions);
        let attributes = bvh.reorder(&attributes);
        let verts: Vec<TriangleVerts> = positions.iter().map(TriangleVerts::new).collect();
        let emitters = positions
            .iter()
            .zip(&attributes)
            .map(|(&vertices, a)| EmitterTriangle {
                vertices,
                material: a.material,
            })
            .collect();
        Self {
            key,
            geometry: MeshGeometry {
                wide: WideBvh::build(&bvh),
                bvh,
                positions,
                attributes,
            },
            verts,
            emitters,
        }
    }
}

impl MeshBuffers {
    /// Refuses `scene` if a buffer of its meshes would exceed `limits`,
    /// naming the buffer and the limit, before any is built (issue 47): a
    /// storage binding over the device's limit is a validation error that
    /// would otherwise reach the frame. The triangles' buffers are sized
    /// exactly; the BVH's nodes and the lights by their bounds (a binary
    /// BVH over n triangles has at most 2n − 1 nodes; every emitter is a
    /// triangle, a sphere or the point light).
    pub fn check_fits(limits: &wgpu::Limits, scene: &Scene) -> Result<()> {
        let triangles = scene.triangle_count() as u64;
        let lights = triangles + scene.spheres.len() as u64 + 1;
        let usage = wgpu::BufferUsages::STORAGE;
        for (label, count, size) in [
            ("mesh triangles", triangles, size_of::<TriangleVerts>()),
            (
                "mesh attributes",
                triangles,
                size_of::<TriangleAttributes>(),
            ),
            ("bvh nodes", 2 * triangles, size_of::<BvhNode>()),
            ("lights", lights, size_of::<Light>()),
        ] {
            check_size(limits, label, count.saturating_mul(size as u64), usage)?;
        }
        Ok(())
    }

    pub fn new(device: &wgpu::Device, scene: &Scene) -> Self {
        let mut out = Self {
            key: GeometryKey::default(),
            nodes: storage_buffer(device, "bvh nodes", &[]),
            triangles: storage_buffer(device, "mesh triangles", &[]),
            attributes: storage_buffer(device, "mesh attributes", &[]),
            lights: storage_buffer(device, "lights", &[]),
            geometry: Arc::default(),
            emitters: Vec::new(),
            table: LightTable::default(),
            stats: MeshStats::default(),
            provided: None,
        };
        out.rebuild_geometry(device, scene);
        out.rebuild_lights(device, scene);
        out
    }

    /// Brings the buffers up to `scene` after `change`: the BVH if its
    /// geometry moved, the light table if anything it reads may have (the
    /// geometry, the materials' emission, the point light).
    pub fn update(&mut self, device: &wgpu::Device, scene: &Scene, change: Change) {
        if change.contains(Change::GEOMETRY) && GeometryKey::of(scene) != self.key {
            self.rebuild_geometry(device, scene);
        }
        if change.intersects(
            Change::GEOMETRY
                | Change::LIGHTS
                | Change::MATERIAL_PARAMETERS
                | Change::MATERIAL_STRUCTURE,
        ) {
            self.rebuild_lights(device, scene);
        }
    }

    fn rebuild_geometry(&mut self, device: &wgpu::Device, scene: &Scene) {
        let key = GeometryKey::of(scene);
        let prepared = match self.provided.take() {
            Some(p) if p.key == key => p,
            _ => PreparedGeometry::of(scene),
        };
        self.key = prepared.key;
        self.emitters = prepared.emitters;
        self.nodes = storage_buffer(
            device,
            "bvh nodes",
            bytemuck::cast_slice(&prepared.geometry.bvh.nodes),
        );
        self.triangles = storage_buffer(
            device,
            "mesh triangles",
            bytemuck::cast_slice(&prepared.verts),
        );
        self.attributes = storage_buffer(
            device,
            "mesh attributes",
            bytemuck::cast_slice(&prepared.geometry.attributes),
        );
        self.stats.triangles = prepared.verts.len();
        self.stats.bvh_nodes = prepared.geometry.bvh.nodes.len();
        self.stats.bvh_build = prepared.geometry.bvh.stats.build_time;
        self.geometry = Arc::new(prepared.geometry);
    }

    /// Hands over geometry prepared off the render thread (a loader
    /// thread): the next update whose scene has this geometry uploads it
    /// instead of building the BVH again.
    pub fn provide(&mut self, prepared: PreparedGeometry) {
        self.provided = Some(prepared);
    }

    fn rebuild_lights(&mut self, device: &wgpu::Device, scene: &Scene) {
        let table = LightTable::build(scene, &self.emitters);
        if table != self.table {
            let entries: Vec<Light> = table.lights.clone();
            self.lights = storage_buffer(device, "lights", bytemuck::cast_slice(&entries));
            self.stats.lights = table.lights.len();
            self.table = table;
        }
    }

    pub fn table(&self) -> &LightTable {
        &self.table
    }

    /// The geometry the buffers hold, for the CPU kernel.
    pub fn geometry(&self) -> &Arc<MeshGeometry> {
        &self.geometry
    }

    pub fn stats(&self) -> MeshStats {
        self.stats
    }

    /// The trace bind group's entries (bindings 12 to 15).
    pub fn entries(&self) -> [wgpu::BindGroupEntry<'_>; 4] {
        use crate::gpu::pipelines::buffer_entry as entry;
        [
            entry(12, &self.nodes),
            entry(13, &self.triangles),
            entry(14, &self.attributes),
            entry(15, &self.lights),
        ]
    }

    /// The bindings [`MeshBuffers::entries`] fills.
    pub const BINDINGS: [u32; 4] = [12, 13, 14, 15];
}
