//! Runs one of the shaders' compute harnesses: `cs_evaluate` reads a
//! uniform of the harness's own layout and a list of points, and writes one
//! vec4 per point. The noise, texture and geometry harnesses share this
//! plumbing; each only defines its uniform and what it evaluates.
//!
//! Points come in any number (`marbre noise` reads them from stdin), and a
//! device binds, allocates and dispatches only so many at once: they are
//! evaluated in batches that fit the device's limits ([`batch_points`]).

use super::dispatch;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::pipelines::{
    compute_pipeline, entry, float_texture, permutation_table, storage, uniform, upload_atlas,
};
use crate::gpu::shader_source::Program;
use anyhow::{Result, ensure};
use glam::Vec3;
use marbre_core::texture::ImageAtlas;

/// The `@workgroup_size` of every harness's `cs_evaluate`, which reads
/// its point at `global_invocation_id.x`: one dispatch row only.
const WORKGROUP_SIZE: u64 = 64;

/// The bytes of a point, and of its result: one vec4 each.
const POINT_BYTES: u64 = 16;

/// A harness's pipeline and the bindings every batch shares, built once
/// for any number of batches.
pub struct PointsHarness {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    permutation: wgpu::Buffer,
    atlas: wgpu::TextureView,
}

impl PointsHarness {
    /// `program` (a harness) built with `features`. Binding 6 holds
    /// Perlin's permutation and binding 8 the image atlas (one black texel
    /// without one), as in the trace pass.
    pub fn new(
        ctx: &GpuContext,
        program: Program,
        features: &FeatureSet,
        atlas: Option<&ImageAtlas>,
    ) -> Result<Self> {
        let (pipeline, layout) = compute_pipeline(
            &ctx.device,
            program,
            features,
            &[
                entry(0, uniform()),
                entry(1, storage(true)),
                entry(2, storage(false)),
                entry(6, uniform()),
                entry(8, float_texture(false)),
            ],
            "cs_evaluate",
        )?;
        let permutation = dispatch::upload(
            ctx,
            "permutation",
            bytemuck::cast_slice(&permutation_table()),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let empty = ImageAtlas::pack(&[], 1)?;
        let atlas = upload_atlas(ctx, atlas.unwrap_or(&empty));
        Ok(Self {
            pipeline,
            layout,
            permutation,
            atlas,
        })
    }

    /// The results at every point, evaluated in batches of whole items of
    /// `per_item` points each, that fit the device's limits.
    /// `harness_uniform` gives the raw bytes of the program's binding-0
    /// uniform for a batch of so many points.
    pub fn run(
        &self,
        ctx: &GpuContext,
        points: &[Vec3],
        per_item: usize,
        harness_uniform: impl Fn(usize) -> Result<Vec<u8>>,
    ) -> Result<Vec<[f32; 4]>> {
        let batch = batch_points(&ctx.device.limits(), per_item)?;
        let mut results = Vec::with_capacity(points.len());
        for points in points.chunks(batch) {
            results.extend(self.dispatch(ctx, points, &harness_uniform(points.len())?)?);
        }
        Ok(results)
    }

    /// One dispatch over `points`, within the device's limits.
    fn dispatch(
        &self,
        ctx: &GpuContext,
        points: &[Vec3],
        harness_uniform: &[u8],
    ) -> Result<Vec<[f32; 4]>> {
        let init =
            |label: &str, contents: &[u8], usage| dispatch::upload(ctx, label, contents, usage);
        let inputs: Vec<[f32; 4]> = points.iter().map(|p| [p.x, p.y, p.z, 0.0]).collect();
        let uniform_buffer = init("harness", harness_uniform, wgpu::BufferUsages::UNIFORM)?;
        let input_buffer = init(
            "points",
            bytemuck::cast_slice(&inputs),
            wgpu::BufferUsages::STORAGE,
        )?;
        let output_buffer = dispatch::output(ctx, "results", inputs.len() as u64 * POINT_BYTES)?;
        let mut entries: Vec<wgpu::BindGroupEntry> = [
            (0, &uniform_buffer),
            (1, &input_buffer),
            (2, &output_buffer),
            (6, &self.permutation),
        ]
        .map(|(binding, buffer)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .into();
        entries.push(wgpu::BindGroupEntry {
            binding: 8,
            resource: wgpu::BindingResource::TextureView(&self.atlas),
        });
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("compute harness"),
            layout: &self.layout,
            entries: &entries,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let groups = (points.len() as u64).div_ceil(WORKGROUP_SIZE) as u32;
        dispatch::record(ctx, &mut encoder, &self.pipeline, &bind_group, (groups, 1))?;
        dispatch::read_back(ctx, encoder, &output_buffer)
    }
}

/// The most points one dispatch of a harness takes under `limits`, in
/// whole items of `per_item` points: as many as a storage binding and a
/// buffer hold (the points in, their results out, the read-back), and one
/// row of workgroups covers. An error, naming the limits, where not even
/// one item fits.
pub fn batch_points(limits: &wgpu::Limits, per_item: usize) -> Result<usize> {
    let bytes = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    let dispatched = u64::from(limits.max_compute_workgroups_per_dimension) * WORKGROUP_SIZE;
    let points = (bytes / POINT_BYTES)
        .min(dispatched)
        .min(u64::from(u32::MAX));
    let items = points / per_item as u64;
    ensure!(
        items > 0,
        "this GPU cannot evaluate {per_item} point(s) in one dispatch: its \
         max_storage_buffer_binding_size is {}, max_buffer_size {} and \
         max_compute_workgroups_per_dimension {}",
        limits.max_storage_buffer_binding_size,
        limits.max_buffer_size,
        limits.max_compute_workgroups_per_dimension
    );
    Ok((items * per_item as u64) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(binding: u64, buffer: u64, workgroups: u32) -> wgpu::Limits {
        wgpu::Limits {
            max_storage_buffer_binding_size: binding,
            max_buffer_size: buffer,
            max_compute_workgroups_per_dimension: workgroups,
            ..wgpu::Limits::default()
        }
    }

    /// A batch is as large as the tightest limit allows, in whole items.
    #[test]
    fn a_batch_fits_the_tightest_limit_in_whole_items() {
        // WebGPU's defaults: 128 MiB bindings hold 8 Mi points, and 65535
        // workgroups of 64 cover fewer.
        assert_eq!(
            batch_points(&wgpu::Limits::default(), 1).unwrap(),
            65535 * 64
        );
        // The binding is the tightest: 1600 bytes hold 100 points.
        assert_eq!(batch_points(&limits(1600, 1 << 20, 1000), 1).unwrap(), 100);
        // The buffer size is.
        assert_eq!(batch_points(&limits(1 << 20, 160, 1000), 1).unwrap(), 10);
        // The workgroups are: 2 rows of 64.
        assert_eq!(batch_points(&limits(1 << 20, 1 << 20, 2), 1).unwrap(), 128);
        // Items of 3 points: 100 points hold 33 whole items.
        assert_eq!(batch_points(&limits(1600, 1 << 20, 1000), 3).unwrap(), 99);
        // A 32-bit count bounds the largest devices.
        let huge = limits(u64::MAX, u64::MAX, u32::MAX);
        assert_eq!(batch_points(&huge, 1).unwrap(), u32::MAX as usize);
    }

    /// On a device held to small limits (64 points a binding, then 128
    /// points a dispatch row), 1000 points are evaluated in batches and
    /// give exactly the values one dispatch gives on the whole device.
    #[test]
    fn work_over_a_devices_limits_is_split_to_them() {
        use crate::gpu::harness::noise::{Evaluate, evaluate_scalar};
        use marbre_core::noise::{NoiseKind, NoiseSettings};
        let Some(ctx) =
            crate::gpu::testing::gpu_or_skip("work_over_a_devices_limits_is_split_to_them")
        else {
            return;
        };
        let noise = NoiseSettings {
            kind: NoiseKind::Perlin,
            ..Default::default()
        };
        let points: Vec<Vec3> = (0..1000)
            .map(|i| Vec3::new(i as f32 * 0.37, (i % 7) as f32 * 1.3, -0.5 * i as f32))
            .collect();
        let whole = evaluate_scalar(&ctx, &noise, Evaluate::Fbm, &points).unwrap();
        for (binding, workgroups, batch) in [(64 * POINT_BYTES, 1000, 64), (1 << 20, 2, 128)] {
            let small = ctx
                .limited(wgpu::Limits {
                    max_storage_buffer_binding_size: binding,
                    max_compute_workgroups_per_dimension: workgroups,
                    ..ctx.device.limits()
                })
                .unwrap();
            assert_eq!(batch_points(&small.device.limits(), 1).unwrap(), batch);
            let split = evaluate_scalar(&small, &noise, Evaluate::Fbm, &points).unwrap();
            assert_eq!(split, whole, "in batches of {batch}");
            small.uncaptured.check().unwrap();
        }
    }

    #[test]
    fn limits_too_small_for_one_item_are_an_error_naming_them() {
        let e = batch_points(&limits(32, 1 << 20, 1000), 3).unwrap_err();
        let e = e.to_string();
        assert!(e.contains("3 point(s)"), "{e}");
        assert!(e.contains("max_storage_buffer_binding_size is 32"), "{e}");
    }
}
