//! Runs one of the shaders' compute harnesses: `cs_evaluate` reads a
//! uniform of the harness's own layout and a list of points, and writes one
//! vec4 per point. The noise and texture harnesses share this plumbing; each
//! only defines its uniform and what it evaluates.

use super::dispatch;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::pipelines::{
    compute_pipeline, entry, float_texture, permutation_table, storage, uniform, upload_atlas,
};
use crate::gpu::shader_source::Program;
use anyhow::Result;
use glam::Vec3;
use marbre_core::texture::ImageAtlas;

/// Evaluates `program` (a harness) built with `features` at every point.
/// `harness_uniform` is the raw bytes of the program's binding-0 uniform;
/// binding 6 holds Perlin's permutation and binding 8 the image atlas (one
/// black texel without one), as in the trace pass.
pub fn run(
    ctx: &GpuContext,
    program: Program,
    features: &FeatureSet,
    harness_uniform: &[u8],
    atlas: Option<&ImageAtlas>,
    points: &[Vec3],
) -> Result<Vec<[f32; 4]>> {
    if points.is_empty() {
        return Ok(Vec::new());
    }
    let device = &ctx.device;
    let (pipeline, layout) = compute_pipeline(
        device,
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
    let init = |label: &str, contents: &[u8], usage| dispatch::upload(ctx, label, contents, usage);
    let inputs: Vec<[f32; 4]> = points.iter().map(|p| [p.x, p.y, p.z, 0.0]).collect();
    let uniform_buffer = init("harness", harness_uniform, wgpu::BufferUsages::UNIFORM);
    let input_buffer = init(
        "points",
        bytemuck::cast_slice(&inputs),
        wgpu::BufferUsages::STORAGE,
    );
    let perm_buffer = init(
        "permutation",
        bytemuck::cast_slice(&permutation_table()),
        wgpu::BufferUsages::UNIFORM,
    );
    let output_buffer = dispatch::output(ctx, "results", (inputs.len() * 16) as u64);
    let empty = ImageAtlas::pack(&[], 1)?;
    let atlas_view = upload_atlas(ctx, atlas.unwrap_or(&empty));
    let mut entries: Vec<wgpu::BindGroupEntry> = [
        (0, &uniform_buffer),
        (1, &input_buffer),
        (2, &output_buffer),
        (6, &perm_buffer),
    ]
    .map(|(binding, buffer)| wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    })
    .into();
    entries.push(wgpu::BindGroupEntry {
        binding: 8,
        resource: wgpu::BindingResource::TextureView(&atlas_view),
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("compute harness"),
        layout: &layout,
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    let groups = ((points.len() as u32).div_ceil(64), 1);
    dispatch::record(&mut encoder, &pipeline, &bind_group, groups);
    dispatch::read_back(ctx, encoder, &output_buffer)
}
