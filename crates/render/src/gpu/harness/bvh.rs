//! Sends rays through the real WGSL mesh traversal (`crates/core/src/accel/traverse.wgsl`) in
//! a compute pass, so the parity and watertightness tests can hold it to
//! the CPU ([`marbre_core::accel`]) and `marbre bench-bvh` can time it.
//!
//! Bindings of `shaders/harness/bvh.wgsl`: 0 its uniform (ray count, row
//! pitch), 1 the rays, 2 the results, 3 `bvh_nodes`, 4 `mesh_triangles`.

use super::dispatch;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::pipelines::{checked, entry, shader_module, storage, uniform};
use crate::gpu::shader_source::Program;
use anyhow::{Result, ensure};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use marbre_core::accel::{BvhNode, MeshHit, TriangleVerts};
use std::time::Duration;
use web_time::Instant;

/// `NO_TRIANGLE` in accel/traverse.wgsl: the triangle of a miss.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// One ray: `origin + t direction` for t in (0, `t_max`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
    pub t_max: f32,
}

/// `struct HarnessRay` in harness/bvh.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct HarnessRay {
    origin: [f32; 4],
    direction: [f32; 4],
}

/// `struct BvhHarnessUniform` in harness/bvh.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BvhHarnessUniform {
    count: u32,
    row_pitch: u32,
    _pad: [u32; 2],
}

/// Which query the rays make.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Query {
    /// `slab_ray_intersect`: the closest hit.
    Closest,
    /// `slab_ray_occluded`: any hit.
    Occluded,
}

/// A mesh uploaded once (its BVH nodes and reordered triangles) with the
/// harness's two pipelines, ready for any number of ray batches.
pub struct BvhHarness {
    layout: wgpu::BindGroupLayout,
    closest: wgpu::ComputePipeline,
    occluded: wgpu::ComputePipeline,
    nodes: wgpu::Buffer,
    triangles: wgpu::Buffer,
}

/// The rays' buffers and bind group, for one batch.
struct Batch {
    bind_group: wgpu::BindGroup,
    results: wgpu::Buffer,
    groups: (u32, u32),
}

impl BvhHarness {
    /// Uploads a mesh: `nodes` from [`marbre_core::accel::Bvh::build`] and its
    /// triangles in the BVH's order.
    pub fn new(ctx: &GpuContext, nodes: &[BvhNode], triangles: &[TriangleVerts]) -> Result<Self> {
        ensure!(!nodes.is_empty(), "a BVH has at least its root");
        let device = &ctx.device;
        let module = shader_module(device, Program::BvhHarness, &FeatureSet::default(), "")?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bvh harness"),
            entries: &[
                entry(0, uniform()),
                entry(1, storage(true)),
                entry(2, storage(false)),
                entry(3, storage(true)),
                entry(4, storage(true)),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bvh harness"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry_point: &str| {
            checked(device, "bvh harness pipeline", || {
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry_point),
                    layout: Some(&pipeline_layout),
                    module: &module,
                    entry_point: Some(entry_point),
                    compilation_options: Default::default(),
                    cache: None,
                })
            })
        };
        let closest = pipeline("cs_closest")?;
        let occluded = pipeline("cs_occluded")?;
        // A binding may not be empty: the mesh of no triangles gets one
        // that is never read (its root's box rejects every ray).
        let placeholder = [TriangleVerts::zeroed()];
        let triangles = if triangles.is_empty() {
            &placeholder[..]
        } else {
            triangles
        };
        let storage_buffer = |label, contents: &[u8]| {
            dispatch::upload(ctx, label, contents, wgpu::BufferUsages::STORAGE)
        };
        Ok(Self {
            nodes: storage_buffer("bvh nodes", bytemuck::cast_slice(nodes))?,
            triangles: storage_buffer("mesh triangles", bytemuck::cast_slice(triangles))?,
            layout,
            closest,
            occluded,
        })
    }

    /// The closest hit of each ray, `None` for a miss; `triangle` indexes
    /// the reordered triangles.
    pub fn closest(&self, ctx: &GpuContext, rays: &[Ray]) -> Result<Vec<Option<MeshHit>>> {
        Ok(self
            .run(ctx, rays, Query::Closest)?
            .iter()
            .map(|r| {
                (r[1] != NO_TRIANGLE).then(|| MeshHit {
                    t: f32::from_bits(r[0]),
                    triangle: r[1],
                    b1: f32::from_bits(r[2]),
                    b2: f32::from_bits(r[3]),
                })
            })
            .collect())
    }

    /// Whether each ray hits anything before its `t_max`.
    pub fn occluded(&self, ctx: &GpuContext, rays: &[Ray]) -> Result<Vec<bool>> {
        Ok(self
            .run(ctx, rays, Query::Occluded)?
            .iter()
            .map(|r| r[0] != 0)
            .collect())
    }

    /// Wall-clock times of `repeats` dispatches of all `rays`, each waited
    /// for, sorted, after one untimed warm-up (which compiles the shader on
    /// drivers that do so at the first dispatch). Uploads and readback are
    /// outside the timing.
    pub fn time(
        &self,
        ctx: &GpuContext,
        rays: &[Ray],
        query: Query,
        repeats: u32,
    ) -> Result<Vec<Duration>> {
        ensure!(!rays.is_empty(), "no rays to time");
        let batch = self.batch(ctx, rays)?;
        let dispatch = || -> Result<()> {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(ctx, &mut encoder, &batch, query)?;
            ctx.queue.submit([encoder.finish()]);
            ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
            // Invalid work times nothing.
            ctx.uncaptured.check()
        };
        dispatch()?;
        let mut times = Vec::new();
        for _ in 0..repeats.max(1) {
            let start = Instant::now();
            dispatch()?;
            times.push(start.elapsed());
        }
        times.sort();
        Ok(times)
    }

    fn run(&self, ctx: &GpuContext, rays: &[Ray], query: Query) -> Result<Vec<[u32; 4]>> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let batch = self.batch(ctx, rays)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.encode(ctx, &mut encoder, &batch, query)?;
        dispatch::read_back(ctx, encoder, &batch.results)
    }

    fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        batch: &Batch,
        query: Query,
    ) -> Result<()> {
        let pipeline = match query {
            Query::Closest => &self.closest,
            Query::Occluded => &self.occluded,
        };
        dispatch::record(ctx, encoder, pipeline, &batch.bind_group, batch.groups)
    }

    fn batch(&self, ctx: &GpuContext, rays: &[Ray]) -> Result<Batch> {
        let device = &ctx.device;
        let groups = (rays.len() as u32).div_ceil(64);
        let per_row = groups.min(device.limits().max_compute_workgroups_per_dimension);
        let rows = groups.div_ceil(per_row);
        ensure!(
            rows <= device.limits().max_compute_workgroups_per_dimension,
            "too many rays for one dispatch: {}",
            rays.len()
        );
        let params = BvhHarnessUniform {
            count: rays.len() as u32,
            row_pitch: per_row * 64,
            _pad: [0; 2],
        };
        let gpu_rays: Vec<HarnessRay> = rays
            .iter()
            .map(|r| HarnessRay {
                origin: r.origin.extend(r.t_max).to_array(),
                direction: r.direction.extend(0.0).to_array(),
            })
            .collect();
        let init = |label, contents: &[u8], usage| dispatch::upload(ctx, label, contents, usage);
        let uniform_buffer = init(
            "bvh harness",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let ray_buffer = init(
            "rays",
            bytemuck::cast_slice(&gpu_rays),
            wgpu::BufferUsages::STORAGE,
        )?;
        let results = dispatch::output(ctx, "bvh results", (rays.len() * 16) as u64)?;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bvh harness"),
            layout: &self.layout,
            entries: &[
                (0, &uniform_buffer),
                (1, &ray_buffer),
                (2, &results),
                (3, &self.nodes),
                (4, &self.triangles),
            ]
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }),
        });
        Ok(Batch {
            bind_group,
            results,
            groups: (per_row, rows),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::pipelines::validate;
    use crate::gpu::shader_source::assemble;

    /// naga accepts the harness (no GPU needed), and the WGSL structs have
    /// the layouts of their Rust twins.
    #[test]
    fn the_harness_wgsl_validates() {
        use crate::gpu::twin_layout::twin_layout;
        let source = assemble(Program::BvhHarness, &FeatureSet::default(), "").unwrap();
        validate(&source).unwrap();
        let module = &naga::front::wgsl::parse_str(&source).unwrap();
        twin_layout!(module, BvhNode, [min, a, max, count]);
        twin_layout!(module, TriangleVerts, [v0, v1, v2]);
        twin_layout!(module, HarnessRay, [origin, direction]);
        twin_layout!(module, BvhHarnessUniform, [count, row_pitch]);
    }

    /// The shader's constants are the CPU traversal's.
    #[test]
    fn the_wgsl_constants_match_the_cpu() {
        use marbre_core::accel::bvh::MAX_DEPTH;
        use marbre_core::accel::traverse::{SLAB_INFLATE, SLAB_PARALLEL};
        use naga::{Expression, Literal};
        let source = assemble(Program::BvhHarness, &FeatureSet::default(), "").unwrap();
        let module = naga::front::wgsl::parse_str(&source).unwrap();
        let constant = |name: &str| {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap();
            match module.global_expressions[c.init] {
                Expression::Literal(l) => l,
                ref e => panic!("{name}: {e:?}"),
            }
        };
        assert_eq!(constant("SLAB_INFLATE"), Literal::F32(SLAB_INFLATE));
        assert_eq!(constant("SLAB_PARALLEL"), Literal::F32(SLAB_PARALLEL));
        assert_eq!(constant("BVH_STACK_SIZE"), Literal::U32(MAX_DEPTH as u32));
        assert_eq!(constant("NO_TRIANGLE"), Literal::U32(NO_TRIANGLE));
    }
}
