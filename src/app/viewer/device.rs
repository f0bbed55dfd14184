//! Recovering from a lost GPU device: a new device on the adapter the
//! window can present with, and every GPU resource made again from the
//! scene model (the CPU side is the source of truth, so nothing the user
//! made is lost; the accumulated samples start over).

use super::{Viewer, surface_config};
use crate::app::swatches::Swatches;
use anyhow::{Context as _, Result};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::pass_timer::PassTimer;
use marbre_render::session::{LoadedScene, load_environment, max_texture_side, renderer_with};

impl Viewer {
    /// Replaces the lost device and everything made on it.
    pub(super) fn recover_device(&mut self, reason: &str) -> Result<()> {
        log::warn!("recreating the GPU device after it was lost: {reason}");
        let ctx = GpuContext::for_surface(self.ctx.instance.clone(), &self.surface)
            .context("recreating the GPU device after it was lost")?;
        self.device_watch.attach(&ctx.device);
        self.config = surface_config(&self.surface, &ctx, self.window.inner_size());
        self.surface.configure(&ctx.device, &self.config);
        // The environment's pixels live only on the GPU: read the file
        // again (a source that no longer loads falls back to none).
        let mut notes = Vec::new();
        let env = match load_environment(
            &self.scene.environment.source,
            self.scene.environment.ldr_images,
            max_texture_side(&ctx),
        ) {
            Ok(loaded) => loaded.map(|l| l.image),
            Err(e) => {
                notes.push(format!("{e:#}"));
                None
            }
        };
        let loaded = LoadedScene {
            scene: self.renderer.scene().clone(),
            env,
            images: self.renderer.images().clone(),
            notes: Vec::new(),
            substitutes: Vec::new(),
        };
        let size = self.renderer.size();
        self.renderer = renderer_with(&ctx, &loaded, size, self.renderer.kernel())?;
        self.meters.timer = PassTimer::new(&ctx);
        self.ui_layer = None;
        self.ui_compositor = None;
        self.egui_renderer =
            egui_wgpu::Renderer::new(&ctx.device, self.config.format, Default::default());
        // The new egui renderer has no textures, and egui only sends what
        // changed: a new context (with the old one's memory: open
        // sections, scroll, focus) sends the whole font atlas again.
        let memory = self.egui_ctx.memory(|m| m.clone());
        let egui_ctx = egui::Context::default();
        egui_ctx.memory_mut(|m| *m = memory);
        self.egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &self.window,
            Some(self.window.scale_factor() as f32),
            None,
            Some(max_texture_side(&ctx) as usize),
        );
        // The swatches' worker and images belong to the old device and
        // context: a new book and worker render them again.
        self.swatches = Swatches::new(&ctx, &egui_ctx);
        self.egui_ctx = egui_ctx;
        self.ctx = ctx;
        self.panel.error(format!(
            "the GPU device was lost ({reason}); recreated it and every GPU resource from the scene"
        ));
        for note in notes {
            self.panel.error(note);
        }
        Ok(())
    }
}
