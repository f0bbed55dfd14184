//! The uniform buffers holding a scene's primitives and their materials.
//! They are fixed-size arrays (see `shaders/scene.wgsl`), so an edit only
//! rewrites them; they never grow.

use crate::gpu::scene_gpu;
use marbre_core::scene::Scene;
use wgpu::util::DeviceExt;

pub struct GeometryBuffers {
    spheres: wgpu::Buffer,
    cylinders: wgpu::Buffer,
    polygons: wgpu::Buffer,
    materials: wgpu::Buffer,
}

impl GeometryBuffers {
    pub fn new(device: &wgpu::Device, scene: &Scene) -> Self {
        let buffer = |label: &str, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
        };
        Self {
            spheres: buffer("spheres", bytemuck::cast_slice(&scene_gpu::spheres(scene))),
            cylinders: buffer(
                "cylinders",
                bytemuck::cast_slice(&scene_gpu::cylinders(scene)),
            ),
            polygons: buffer(
                "polygons",
                bytemuck::cast_slice(&scene_gpu::polygons(scene)),
            ),
            materials: buffer(
                "materials",
                bytemuck::cast_slice(&scene_gpu::materials(scene)),
            ),
        }
    }

    pub fn write(&self, queue: &wgpu::Queue, scene: &Scene) {
        let write = |buffer: &wgpu::Buffer, bytes: &[u8]| queue.write_buffer(buffer, 0, bytes);
        write(
            &self.spheres,
            bytemuck::cast_slice(&scene_gpu::spheres(scene)),
        );
        write(
            &self.cylinders,
            bytemuck::cast_slice(&scene_gpu::cylinders(scene)),
        );
        write(
            &self.polygons,
            bytemuck::cast_slice(&scene_gpu::polygons(scene)),
        );
        write(
            &self.materials,
            bytemuck::cast_slice(&scene_gpu::materials(scene)),
        );
    }

    /// The trace bind group's entries for these buffers (bindings 1, 2, 9
    /// and 10 of `shaders/scene.wgsl`).
    pub fn entries(&self) -> [wgpu::BindGroupEntry<'_>; 4] {
        use crate::gpu::pipelines::buffer_entry as entry;
        [
            entry(1, &self.spheres),
            entry(2, &self.materials),
            entry(9, &self.cylinders),
            entry(10, &self.polygons),
        ]
    }

    /// The bindings [`GeometryBuffers::entries`] fills.
    pub const BINDINGS: [u32; 4] = [1, 2, 9, 10];
}
