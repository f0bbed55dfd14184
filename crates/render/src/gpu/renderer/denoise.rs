//! The denoised display: while the scene's display asks for it and the
//! trace pipeline accumulates the guides, the display pass shows the
//! latest image filtered, by OIDN (`oidn_stage.rs`) or by the à-trous
//! filter (`gpu::denoise`), which runs where OIDN's library is not found
//! and is filtered again only when a new image is shown.

use super::{MeteredFrom, Renderer};
use crate::denoiser::{DenoiseReport, Running};
use crate::gpu::context::GpuContext;
use crate::gpu::denoise::{DenoiseSettings, DenoiseSources, Denoiser};
use crate::gpu::features::Feature;
use crate::gpu::readback::read_texture;
use anyhow::{Result, bail};
use marbre_core::scene::Denoiser as Choice;

impl Renderer {
    /// Whether the display shows the denoised image: the scene asks for it
    /// and the installed pipeline accumulates the guides (while its build
    /// is pending, the raw image shows).
    pub fn denoises(&self) -> bool {
        self.scene.render.display.denoise
            && self.trace.key.features.contains(Feature::DenoiseGuides)
    }

    /// Records this frame's step of the denoiser and returns the view of
    /// the denoised image to show; `None` when not denoising, or before
    /// OIDN's first image of this accumulation.
    pub(super) fn record_denoise(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<Option<wgpu::TextureView>> {
        if !self.denoises() || self.accumulation.latest_guides().is_none() {
            // Not denoising, or no band traced with the guides yet.
            return Ok(None);
        }
        let instead_of_oidn = match self.scene.render.display.denoiser {
            Choice::Atrous => None,
            Choice::Oidn => match self.oidn_library() {
                Ok(library) => return self.record_oidn(ctx, encoder, library),
                Err(why) => Some(why),
            },
        };
        self.display.oidn.report = Some(DenoiseReport {
            running: Running::Atrous { instead_of_oidn },
            ..DenoiseReport::default()
        });
        self.record_atrous(ctx, encoder).map(Some)
    }

    /// The à-trous filter of the latest image, recorded if it has not
    /// been filtered yet; the view of its output.
    fn record_atrous(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<wgpu::TextureView> {
        let (albedo, normal) = self
            .accumulation
            .latest_guides()
            .expect("checked by record_denoise");
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
        Ok(denoiser
            .output(&settings)
            .map(|(_, view)| view.clone())
            .expect("recorded above"))
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
    /// the GPU and for OIDN: for `render --denoise-exr`, the bench and
    /// tests. An error unless the scene's display has `denoise` on.
    pub fn read_denoised(&mut self, ctx: &GpuContext) -> Result<(u32, u32, Vec<[f32; 4]>)> {
        if !self.denoises() {
            bail!("no denoised image: the scene's display does not have denoise on");
        }
        if let Some(Running::Oidn { .. }) = self.finish_denoise(ctx)? {
            let texture = self.oidn_texture_now().expect("denoised above");
            let bytes = read_texture(&ctx.device, &ctx.queue, texture, 16)?;
            let (w, h) = (texture.width(), texture.height());
            return Ok((w, h, bytemuck::cast_slice(&bytes).to_vec()));
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let Some(view) = self.record_denoise(ctx, &mut encoder)? else {
            bail!("no denoised image: no band was traced with the guides");
        };
        drop(view);
        ctx.queue.submit([encoder.finish()]);
        let settings = DenoiseSettings::default();
        let (texture, _) = self
            .display
            .denoiser
            .as_ref()
            .and_then(|d| d.output(&settings))
            .expect("recorded above");
        let bytes = read_texture(&ctx.device, &ctx.queue, texture, 16)?;
        let mut pixels: Vec<[f32; 4]> = bytemuck::cast_slice(&bytes).to_vec();
        for p in &mut pixels {
            p[3] = 1.0;
        }
        Ok((texture.width(), texture.height(), pixels))
    }
}
