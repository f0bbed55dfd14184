//! Preview swatches of texture nodes (the panel's, issue 21): each texture
//! of a batch evaluated on the GPU over the front half of a unit sphere,
//! through the same generated WGSL the renderer runs
//! ([`texture_codegen::generate_swatches`]). The CPU twin is
//! [`Texture::eval_at`] at [`sample_points`]: the GPU test holds one to the
//! other.
//!
//! Rendering a batch waits for the GPU; the viewer calls it from a worker
//! thread (`src/app/swatches.rs`), never from the UI thread. Pipelines are
//! kept by their generated code, so a parameter edit (a slider drag)
//! rewrites buffers only; a new structure compiles a pipeline (the costly
//! part on lavapipe, see docs/PERFORMANCE.md).

use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::harness::dispatch;
use crate::gpu::pipelines::{
    compute_pipeline_with, entry, float_texture, permutation_table, storage, uniform, upload_atlas,
};
use crate::gpu::scene_gpu::{self, Material};
use crate::gpu::shader_source::Program;
use crate::gpu::texture_codegen::{self, swatch_material};
use anyhow::{Result, ensure};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use marbre_core::scene::color_encoding::srgb_encode;
use marbre_core::scene::{MAX_MATERIALS, SurfacePoint, Texture};
use marbre_core::texture::{ImageAtlas, ImageSet, mapping::sphere_uv};
use std::collections::HashMap;

/// Side of a swatch, in pixels.
pub const SWATCH_SIZE: usize = 48;

/// The most textures one batch renders (one material slot each).
pub const MAX_BATCH: usize = 32;

/// Pipelines kept: one per distinct generated code, oldest dropped first.
const MAX_PIPELINES: usize = 16;

/// One swatch: `SWATCH_SIZE²` linear RGBA values, row 0 at the top; alpha
/// is 1 on the sphere, 0 around it.
pub type SwatchPixels = Vec<[f32; 4]>;

/// Pixel `(x, y)`'s sample: the point of the unit sphere seen at the
/// pixel's centre from +z (orthographic), and its (u, v) by the renderer's
/// sphere mapping; `None` outside the sphere's disc.
pub fn sample_points() -> Vec<Option<SurfacePoint>> {
    let n = SWATCH_SIZE as f32;
    (0..SWATCH_SIZE * SWATCH_SIZE)
        .map(|i| {
            let x = 2.0 * ((i % SWATCH_SIZE) as f32 + 0.5) / n - 1.0;
            let y = 1.0 - 2.0 * ((i / SWATCH_SIZE) as f32 + 0.5) / n;
            let r2 = x * x + y * y;
            (r2 < 1.0).then(|| {
                let p = Vec3::new(x, y, (1.0 - r2).sqrt());
                SurfacePoint::new(p, sphere_uv(p))
            })
        })
        .collect()
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SwatchPoint {
    p: [f32; 4],
    uv: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SwatchBatch {
    points: u32,
    swatches: u32,
    _pad: [u32; 2],
}

struct Pipeline {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

/// Renders batches of swatches on one device, keeping what does not change
/// between batches (sample points, Perlin's table, pipelines).
pub struct SwatchRenderer {
    ctx: GpuContext,
    points: wgpu::Buffer,
    permutation: wgpu::Buffer,
    atlas: wgpu::TextureView,
    pipelines: HashMap<String, Pipeline>,
    /// Generated code in the order its pipeline was made.
    built: Vec<String>,
}

impl SwatchRenderer {
    pub fn new(ctx: GpuContext) -> Result<Self> {
        let points: Vec<SwatchPoint> = sample_points()
            .into_iter()
            .map(|s| match s {
                Some(s) => SwatchPoint {
                    p: [s.object.x, s.object.y, s.object.z, 1.0],
                    uv: [s.uv.x, s.uv.y, 0.0, 0.0],
                },
                None => SwatchPoint::zeroed(),
            })
            .collect();
        let points = dispatch::upload(
            &ctx,
            "swatch points",
            bytemuck::cast_slice(&points),
            wgpu::BufferUsages::STORAGE,
        )?;
        let permutation = dispatch::upload(
            &ctx,
            "swatch permutation",
            bytemuck::cast_slice(&permutation_table()),
            wgpu::BufferUsages::UNIFORM,
        )?;
        // Image nodes show the CPU reference's stand-in colour: swatches do
        // not load the scene's images.
        let atlas = upload_atlas(&ctx, &ImageAtlas::pack(&[], 1)?);
        Ok(Self {
            ctx,
            points,
            permutation,
            atlas,
            pipelines: HashMap::new(),
            built: Vec::new(),
        })
    }

    /// Each texture's swatch, in order. Waits for the GPU.
    pub fn render(&mut self, textures: &[Texture]) -> Result<Vec<SwatchPixels>> {
        if textures.is_empty() {
            return Ok(Vec::new());
        }
        ensure!(
            textures.len() <= MAX_BATCH.min(MAX_MATERIALS),
            "a swatch batch holds at most {MAX_BATCH} textures, not {}",
            textures.len()
        );
        let generated = texture_codegen::generate_swatches(textures, &ImageSet::default())?;
        let mut materials: Vec<Material> = textures
            .iter()
            .map(|t| scene_gpu::material(&swatch_material(t)))
            .collect();
        materials.resize(MAX_MATERIALS, Material::default());
        let features = FeatureSet::for_textures(textures);
        let key = format!("{:?}\n{}", features.defines(), generated.wgsl);
        if !self.pipelines.contains_key(&key) {
            let (pipeline, layout) = compute_pipeline_with(
                &self.ctx.device,
                Program::Swatch,
                &features,
                &generated.wgsl,
                &[
                    entry(2, uniform()),
                    entry(6, uniform()),
                    entry(7, uniform()),
                    entry(8, float_texture(false)),
                    entry(16, uniform()),
                    entry(17, storage(true)),
                    entry(18, storage(false)),
                ],
                "cs_swatch",
            )?;
            if self.built.len() == MAX_PIPELINES {
                let oldest = self.built.remove(0);
                self.pipelines.remove(&oldest);
            }
            self.built.push(key.clone());
            self.pipelines
                .insert(key.clone(), Pipeline { pipeline, layout });
        }
        let pipeline = &self.pipelines[&key];
        let count = SWATCH_SIZE * SWATCH_SIZE;
        let batch = SwatchBatch {
            points: count as u32,
            swatches: textures.len() as u32,
            _pad: [0; 2],
        };
        let init = |label: &str, contents: &[u8]| {
            dispatch::upload(&self.ctx, label, contents, wgpu::BufferUsages::UNIFORM)
        };
        let batch_buffer = init("swatch batch", bytemuck::bytes_of(&batch))?;
        let materials_buffer = init("swatch materials", bytemuck::cast_slice(&materials))?;
        let params_buffer = init("swatch params", bytemuck::cast_slice(&generated.params))?;
        let output = dispatch::output(
            &self.ctx,
            "swatch results",
            (count * textures.len() * 16) as u64,
        )?;
        let buffers = [
            (2, &materials_buffer),
            (6, &self.permutation),
            (7, &params_buffer),
            (16, &batch_buffer),
            (17, &self.points),
            (18, &output),
        ];
        let mut entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        entries.push(wgpu::BindGroupEntry {
            binding: 8,
            resource: wgpu::BindingResource::TextureView(&self.atlas),
        });
        let bind_group = self
            .ctx
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("swatches"),
                layout: &pipeline.layout,
                entries: &entries,
            });
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        let groups = ((count as u32).div_ceil(64), textures.len() as u32);
        dispatch::record(
            &self.ctx,
            &mut encoder,
            &pipeline.pipeline,
            &bind_group,
            groups,
        )?;
        let values: Vec<[f32; 4]> = dispatch::read_back(&self.ctx, encoder, &output)?;
        Ok(values.chunks(count).map(<[_]>::to_vec).collect())
    }
}

/// A swatch's pixel as 8-bit sRGB with alpha (what egui shows): the
/// linear value clamped to [0, 1] and encoded; NaN reads as 0.
pub fn to_srgba8(pixel: [f32; 4]) -> [u8; 4] {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    let clean = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    [
        byte(srgb_encode(clean(pixel[0]))),
        byte(srgb_encode(clean(pixel[1]))),
        byte(srgb_encode(clean(pixel[2]))),
        byte(clean(pixel[3])),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A swatch batch and its points have its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_batch_has_its_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(
            Program::Swatch,
            &FeatureSet::default(),
            &crate::gpu::texture_codegen::generate_swatches(
                &[],
                &marbre_core::texture::ImageSet::empty(),
            )
            .unwrap()
            .wgsl,
        );
        twin_layout!(module, SwatchPoint, [p, uv]);
        twin_layout!(module, SwatchBatch, [points, swatches]);
    }
}
