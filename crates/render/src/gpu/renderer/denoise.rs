//! The denoised preview (`gpu::denoise`): while the scene's display asks
//! for it and the trace pipeline accumulates the guides, the display pass
//! shows the latest image filtered, filtered again only when a new image is
//! shown.

use super::{MeteredFrom, Renderer};
use crate::gpu::context::GpuContext;
use crate::gpu::denoise::{DenoiseSettings, DenoiseSources, Denoiser};
use crate::gpu::features::Feature;
use crate::gpu::readback::read_texture;
use anyhow::{Result, bail};

impl Renderer {
    /// Whether the display shows the denoised image: the scene asks for it
    /// and the installed pipeline accumulates the guides (while its build
    /// is pending, the raw image shows).
    pub fn denoises(&self) -> bool {
        self.scene.render.display.denoise
            && self.trace.key.features.contains(Feature::DenoiseGuides)
    }

    /// Records the filter of the latest image if it has not been filtered
    /// yet, and returns the view of the filtered image; `None` when not
    /// denoising.
    pub(super) fn record_denoise(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<Option<wgpu::TextureView>> {
        if !self.denoises() {
            return Ok(None);
        }
        let Some((albedo, normal)) = self.accumulation.latest_guides() else {
            // No band traced with the guides yet.
            return Ok(None);
        };
        let from = MeteredFrom {
            shown: self.accumulation.shown_count(),
            size: self.size,
            render_size: self.shown_size(),
        };
        let settings = DenoiseSettings::default();
        let denoiser = match &mut self.display.denoiser {
            Some(d) => d,
            slot => slot.insert(Denoiser::new(&ctx.device)?),
        };
        if self.display.denoised_from != Some(from) {
            let (mean, spread) = self.accumulation.latest_views();
            let sources = DenoiseSources {
                mean,
                spread,
                albedo,
                normal,
                frames: self.accumulation.frames(),
                size: from.render_size,
            };
            denoiser.record(ctx, encoder, &sources, &settings);
            self.display.denoised_from = Some(from);
        }
        Ok(denoiser.output(&settings).map(|(_, view)| view.clone()))
    }

    /// The guides the trace pass accumulated over the shown region: the
    /// first hit's albedo plus emission, and its shading normal as
    /// 0.5 + 0.5·n; `None` unless the pipeline accumulates them.
    pub fn read_guides(&self, ctx: &GpuContext) -> Result<Option<[Vec<[f32; 4]>; 2]>> {
        let Some([albedo, normal]) = self.accumulation.latest_guide_textures() else {
            return Ok(None);
        };
        Ok(Some([
            self.read_accumulated(ctx, albedo)?.2,
            self.read_accumulated(ctx, normal)?.2,
        ]))
    }

    /// The denoised linear image of the shown region (alpha 1), waiting for
    /// the GPU: for `render --denoise-exr`, the bench and tests. An error
    /// unless the scene's display has `denoise` on.
    pub fn read_denoised(&mut self, ctx: &GpuContext) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let recorded = self.record_denoise(ctx, &mut encoder)?.is_some();
        let settings = DenoiseSettings::default();
        let output = self
            .display
            .denoiser
            .as_ref()
            .and_then(|d| d.output(&settings));
        let (true, Some((texture, _))) = (recorded, output) else {
            bail!("no denoised image: the scene's display does not have denoise on");
        };
        ctx.queue.submit([encoder.finish()]);
        let bytes = read_texture(&ctx.device, &ctx.queue, texture, 16)?;
        let mut pixels: Vec<[f32; 4]> = bytemuck::cast_slice(&bytes).to_vec();
        for p in &mut pixels {
            p[3] = 1.0;
        }
        Ok((texture.width(), texture.height(), pixels))
    }
}
