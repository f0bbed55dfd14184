//! One window's state: surface, renderer, egui, the scene being edited.

use super::convergence::Convergence;
use super::feature_costs::FeatureCosts;
use super::history::History;
use super::{ViewerOptions, camera_input, screenshots};
use crate::commands::session::{load_images, load_scene, preset_or_default, renderer_for};
use crate::cubemap;
use crate::envmap;
use crate::gpu::pass_timer::{Pass, PassTimer};
use crate::gpu::readback::read_texture;
use crate::gpu::{DisplayTarget, FeatureSet, GpuContext, NonFiniteCounts, Renderer, Viewport};
use crate::panel::{self, PanelAction, PanelState, QualityStats, Stats};
use crate::preset::{self, Preset};
use crate::scene::{EnvSource, OrbitCamera, Scene};
use crate::texture::ImageSet;
use anyhow::{Context as _, Result};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use winit::event::{ElementState, KeyEvent, WindowEvent};
use winit::keyboard::{Key, NamedKey};
use winit::window::Window;

/// Width of the side panel, in points, when the window opens.
const PANEL_WIDTH: f32 = 380.0;
/// Height of the Quality strip under the image, in points, when the window
/// opens.
const QUALITY_HEIGHT: f32 = 190.0;

pub struct Viewer {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: GpuContext,
    renderer: Renderer,
    /// GPU time of each pass, where the adapter has timestamp queries.
    timer: Option<PassTimer>,
    /// The error estimates since the last change, for the Quality panel.
    convergence: Convergence,
    /// Trace times with shader features compiled out, for the Quality panel.
    feature_costs: FeatureCosts,
    /// Undo and redo of scene edits (Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y).
    history: History,
    /// Samples the current accumulation dropped for being NaN or infinite,
    /// and the accumulation they count.
    non_finite: (u32, NonFiniteCounts),
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    scene: Scene,
    /// The preset's description, kept so that saving does not lose it.
    description: String,
    /// The camera the preset was loaded with, for the panel's Reset.
    preset_camera: OrbitCamera,
    panel: PanelState,
    options: ViewerOptions,
    frames: u64,
    last_frame: Instant,
    fps: f32,
    ms_per_frame: f32,
    screenshot_requested: bool,
}

impl Viewer {
    pub fn new(window: Arc<Window>, options: ViewerOptions) -> Result<Self> {
        let preset_path = preset_or_default(options.preset.as_deref());
        let loaded = load_scene(&preset_path, options.env.as_deref())?;
        let description = preset::load(&preset_path)
            .map(|l| l.preset.description)
            .unwrap_or_default();
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle().with_env());
        let surface = instance
            .create_surface(window.clone())
            .context("creating the window surface")?;
        let ctx = GpuContext::for_surface(instance, &surface)?;
        let size = window.inner_size();
        let caps = surface.get_capabilities(&ctx.adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            // egui blends in gamma space, so it wants a non-sRGB target; the
            // display pass then encodes sRGB itself.
            .find(|f| !f.is_srgb())
            .unwrap_or(caps.formats[0]);
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&ctx.device, &config);
        let renderer = renderer_for(&ctx, &loaded, (config.width, config.height))?;
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(&ctx.device, format, Default::default());
        let env_path = match &loaded.scene.environment.source {
            EnvSource::LatLong { path } => path.display().to_string(),
            _ => String::new(),
        };
        let mut panel = PanelState::new(preset_path.display().to_string(), env_path);
        panel.info(format!("loaded {}", preset_path.display()));
        for note in &loaded.notes {
            panel.info(note.clone());
        }
        let timer = PassTimer::new(&ctx);
        let preset_camera = loaded.scene.camera;
        let history = History::new(&loaded.scene);
        Ok(Self {
            history,
            timer,
            convergence: Convergence::default(),
            feature_costs: FeatureCosts::default(),
            non_finite: (0, NonFiniteCounts::default()),
            window,
            surface,
            config,
            ctx,
            renderer,
            egui_ctx,
            egui_state,
            egui_renderer,
            scene: loaded.scene,
            description,
            preset_camera,
            panel,
            options,
            frames: 0,
            last_frame: Instant::now(),
            fps: 0.0,
            ms_per_frame: 0.0,
            screenshot_requested: false,
        })
    }

    pub fn request_redraw(&self) {
        self.window.request_redraw();
    }

    /// Handles one window event; `Ok(false)` asks the loop to exit.
    pub fn handle_event(&mut self, event: &WindowEvent) -> Result<bool> {
        let consumed = self
            .egui_state
            .on_window_event(&self.window, event)
            .consumed;
        match event {
            WindowEvent::CloseRequested => return Ok(false),
            WindowEvent::Resized(size) => {
                self.config.width = size.width.max(1);
                self.config.height = size.height.max(1);
                // A minimised window has zero size: keep the last valid one.
                if size.width > 0 && size.height > 0 {
                    self.surface.configure(&self.ctx.device, &self.config);
                }
            }
            WindowEvent::DroppedFile(path) => self.load_dropped(path),
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        logical_key: Key::Named(NamedKey::F12),
                        state: ElementState::Pressed,
                        ..
                    },
                ..
            } if !consumed => self.screenshot_requested = true,
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        logical_key: Key::Character(text),
                        state: ElementState::Pressed,
                        ..
                    },
                ..
            } if !consumed => {
                // Keys 1–9 recall the preset's saved views.
                if let Ok(digit @ 1..=9) = text.parse::<usize>() {
                    self.scene.recall_view(digit - 1);
                }
            }
            WindowEvent::RedrawRequested => return self.redraw(),
            _ => {}
        }
        Ok(true)
    }

    fn load_dropped(&mut self, path: &Path) {
        let is_preset = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ron"));
        if is_preset {
            self.load_preset(path);
        } else {
            self.load_environment(path);
        }
    }

    fn load_preset(&mut self, path: &Path) {
        match load_scene(path, None) {
            Ok(loaded) => {
                if let Err(e) = self.apply_scene(
                    loaded.scene.clone(),
                    loaded.env.as_ref(),
                    Some(loaded.images.clone()),
                ) {
                    self.panel.error(format!("{}: {e:#}", path.display()));
                    return;
                }
                self.preset_camera = self.scene.camera;
                self.description = preset::load(path)
                    .map(|l| l.preset.description)
                    .unwrap_or_default();
                self.panel.preset_path = path.display().to_string();
                if let EnvSource::LatLong { path } = &self.scene.environment.source {
                    self.panel.env_path = path.display().to_string();
                }
                self.panel.info(format!("loaded {}", path.display()));
                for note in loaded.notes {
                    self.panel.info(note);
                }
            }
            // The scene on screen stays as it was.
            Err(e) => self.panel.error(format!("{e:#}")),
        }
    }

    fn load_environment(&mut self, path: &Path) {
        self.load_environment_source(EnvSource::LatLong {
            path: path.to_owned(),
        });
    }

    /// Loads a lat-long or cube map (a cube resampled to lat-long) and
    /// installs it with `source`; on failure the scene stays as it was.
    fn load_environment_source(&mut self, source: EnvSource) {
        let what = source
            .paths()
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ");
        match cubemap::load_source(&source) {
            Ok(Some(l)) => {
                let mut scene = self.scene.clone();
                scene.environment.source = source;
                if let Err(e) = self.apply_scene(scene, Some(&l.image), None) {
                    self.panel.error(format!("{what}: {e:#}"));
                    return;
                }
                if let EnvSource::LatLong { path } = &self.scene.environment.source {
                    self.panel.env_path = path.display().to_string();
                }
                self.panel.info(format!("environment {what}"));
                for note in l.notes {
                    self.panel.info(note);
                }
            }
            Ok(None) => {}
            Err(e) => self.panel.error(format!("{e:#}")),
        }
    }

    /// Installs a whole new scene and environment, and its images if given;
    /// on failure nothing changes.
    fn apply_scene(
        &mut self,
        scene: Scene,
        env: Option<&envmap::EnvImage>,
        images: Option<ImageSet>,
    ) -> Result<()> {
        self.renderer.set_scene(&self.ctx, &scene)?;
        if let Some(images) = images {
            self.renderer.set_images(&self.ctx, images)?;
        }
        self.renderer.set_environment(&self.ctx, env);
        self.scene = scene;
        Ok(())
    }

    /// Loads the images an edit added or changed (a new image node, a typed
    /// path), reporting unreadable files; the renderer shows placeholders
    /// for those.
    fn reload_images_if_needed(&mut self) {
        if self.scene.image_sources() == self.renderer.images().sources() {
            return;
        }
        let mut notes = Vec::new();
        let result = load_images(&self.scene, &mut notes)
            .and_then(|images| self.renderer.set_images(&self.ctx, images));
        for note in notes {
            self.panel.error(note);
        }
        if let Err(e) = result {
            self.panel.error(format!("{e:#}"));
        }
    }

    fn save_preset(&mut self, path: &Path) {
        let preset = Preset {
            description: self.description.clone(),
            scene: self.scene.clone(),
            ..Preset::default()
        };
        match preset::save(&preset, path) {
            Ok(()) => {
                self.panel.preset_path = path.display().to_string();
                self.panel.info(format!("saved {}", path.display()));
            }
            Err(e) => self.panel.error(e.to_string()),
        }
    }

    fn take_screenshot(&mut self) {
        match screenshots::save(
            &self.ctx,
            &mut self.renderer,
            Path::new(screenshots::FOLDER),
        ) {
            Ok([png, exr]) => {
                self.panel
                    .info(format!("saved {} and {}", png.display(), exr.display()))
            }
            Err(e) => self.panel.error(format!("screenshot failed: {e:#}")),
        }
    }

    /// Undoes or redoes one step of scene edits, keeping the view.
    fn step_history(&mut self, request: HistoryRequest) {
        let restored = match request {
            HistoryRequest::Undo => self.history.undo(&self.scene),
            HistoryRequest::Redo => self.history.redo(&self.scene),
        };
        match restored {
            Some(scene) => self.scene = scene,
            None => self.panel.info(match request {
                HistoryRequest::Undo => "nothing to undo",
                HistoryRequest::Redo => "nothing to redo",
            }),
        }
    }

    fn handle_actions(&mut self, actions: Vec<PanelAction>) {
        for action in actions {
            match action {
                PanelAction::LoadPreset(p) => self.load_preset(&p),
                PanelAction::SavePreset => {
                    let path = PathBuf::from(&self.panel.preset_path);
                    self.save_preset(&path);
                }
                PanelAction::SavePresetAs(p) => self.save_preset(&p),
                PanelAction::LoadEnvironment(p) => self.load_environment(&p),
                PanelAction::Screenshot => self.screenshot_requested = true,
                PanelAction::ResetCamera => self.scene.camera = self.preset_camera,
                PanelAction::ToggleFeature(feature) => self.toggle_feature(feature),
                PanelAction::Undo => self.step_history(HistoryRequest::Undo),
                PanelAction::Redo => self.step_history(HistoryRequest::Redo),
            }
        }
    }

    /// Compiles `feature` out of the shader (or back in) to time the scene
    /// without it; a set that cannot be built is refused with the reason.
    fn toggle_feature(&mut self, feature: crate::gpu::Feature) {
        self.feature_costs.toggle(feature);
        let request = self
            .renderer
            .request_feature_override(&self.ctx, self.feature_costs.override_set());
        if let Err(e) = request {
            self.feature_costs.toggle(feature);
            self.panel
                .error(format!("cannot compile {feature:?} out: {e:#}"));
        }
    }

    fn quality_stats(&self) -> QualityStats {
        let scene_features: Vec<_> = FeatureSet::for_scene(&self.scene).0.into_iter().collect();
        QualityStats {
            points: self.convergence.points().to_vec(),
            latest: self.convergence.latest(),
            paused_at_target: self.paused_at_target(),
            passes: self.timer.as_ref().map_or_else(Vec::new, |t| {
                Pass::ALL.iter().map(|&p| (p.label(), t.ms(p))).collect()
            }),
            without_ms: scene_features
                .iter()
                .map(|&f| self.feature_costs.without(f))
                .collect(),
            scene_features,
            disabled: self.feature_costs.disabled().clone(),
            with_all_ms: self.feature_costs.with_all(),
        }
    }

    /// Whether tracing rests: the user asked to stop at the target error,
    /// and the estimate of the current image is there.
    fn paused_at_target(&self) -> bool {
        let controls = &self.panel.quality;
        controls.stop_at_target && self.convergence.reached(controls.target_error)
    }

    /// Follows the non-finite counters: they restart with the
    /// accumulation, and a readback arrives a frame or two late.
    fn observe_non_finite(&mut self) {
        let generation = self.renderer.accumulation_generation();
        if self.non_finite.0 != generation {
            self.non_finite = (generation, NonFiniteCounts::default());
        }
        if let Some(counts) = self.renderer.poll_non_finite() {
            self.non_finite.1 = counts;
        }
    }

    fn stats(&self) -> Stats {
        let gpu_ms = self.timer.as_ref().and_then(|t| t.ms(Pass::Trace));
        let info = self.ctx.adapter.get_info();
        let mesh = self.renderer.mesh_stats();
        Stats {
            fps: self.fps,
            ms_per_frame: gpu_ms.unwrap_or(self.ms_per_frame),
            ms_is_gpu: gpu_ms.is_some(),
            samples: self.renderer.accumulated_samples(),
            adapter: info.name,
            backend: format!("{:?}", info.backend),
            features: self
                .renderer
                .features()
                .0
                .iter()
                .map(|f| format!("{f:?}"))
                .collect(),
            shader_bytes: self.renderer.trace_shader_bytes(),
            building: self.renderer.is_building(),
            last_build_ms: self.renderer.last_build().map(|d| d.as_secs_f32() * 1000.0),
            resolution: self.renderer.render_size(),
            lights: mesh.lights,
            triangles: mesh.triangles,
            bvh_nodes: mesh.bvh_nodes,
            bvh_build_ms: mesh.bvh_build.as_secs_f32() * 1000.0,
            non_finite: self.non_finite.1,
            quality: self.quality_stats(),
        }
    }

    /// Runs the UI for one frame; returns the image rectangle in points and
    /// whether the camera is being dragged.
    fn run_ui(&mut self) -> (egui::FullOutput, egui::Rect, bool) {
        let raw_input = self.egui_state.take_egui_input(&self.window);
        let stats = self.stats();
        let mut actions = Vec::new();
        let mut image_rect = egui::Rect::NOTHING;
        let mut dragging = false;
        self.panel.can_undo = self.history.can_undo();
        self.panel.can_redo = self.history.can_redo();
        let (scene, panel_state) = (&mut self.scene, &mut self.panel);
        let mut history_request = None;
        let output = self.egui_ctx.run_ui(raw_input, |ui| {
            history_request = history_shortcut(ui.ctx());
            egui::Panel::right("marbre-panel")
                .default_size(PANEL_WIDTH)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        actions = panel::draw(ui, scene, panel_state, &stats);
                    });
                });
            egui::Panel::bottom("marbre-quality")
                .resizable(true)
                .default_size(QUALITY_HEIGHT)
                .show(ui, |ui| {
                    actions.extend(panel::draw_quality(ui, panel_state, &stats));
                });
            image_rect = ui.available_rect_before_wrap();
            let response = ui.allocate_rect(image_rect, egui::Sense::click_and_drag());
            dragging = camera_input::apply(ui, &response, &mut scene.camera);
        });
        self.handle_actions(actions);
        if let Some(request) = history_request {
            self.step_history(request);
        }
        (output, image_rect, dragging)
    }

    fn redraw(&mut self) -> Result<bool> {
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f32();
        self.last_frame = now;
        self.ms_per_frame = 0.9 * self.ms_per_frame + 0.1 * dt * 1000.0;
        self.fps = 1000.0 / self.ms_per_frame.max(1e-3);

        let (mut output, image_rect, dragging) = self.run_ui();
        self.egui_state
            .handle_platform_output(&self.window, std::mem::take(&mut output.platform_output));
        // Texture uploads are applied now, whatever happens to this frame;
        // frees wait until the frame that may still use them is submitted.
        for (id, deltas) in output.textures_delta.set.drain() {
            for delta in &deltas {
                self.egui_renderer
                    .update_texture(&self.ctx.device, &self.ctx.queue, id, delta);
            }
        }
        let to_free: Vec<egui::TextureId> = output.textures_delta.free.drain().collect();
        let result = self.draw_frame(output, image_rect, dragging);
        for id in &to_free {
            self.egui_renderer.free_texture(id);
        }
        result
    }

    fn draw_frame(
        &mut self,
        output: egui::FullOutput,
        image_rect: egui::Rect,
        dragging: bool,
    ) -> Result<bool> {
        // A map (lat-long or cube) chosen in the panel needs its image
        // loaded first.
        if self.scene.environment.source.is_map()
            && self.scene.environment.source != self.renderer.scene().environment.source
        {
            let source = std::mem::replace(
                &mut self.scene.environment.source,
                self.renderer.scene().environment.source.clone(),
            );
            self.load_environment_source(source);
        }
        // A structural edit that changes the scene's features ends any
        // feature-cost experiment: the new shader is specialised again.
        if self
            .feature_costs
            .follow_scene(&FeatureSet::for_scene(&self.scene))
        {
            self.renderer.forget_feature_override();
        }
        // Structural edits build their shader off this thread: the old one
        // keeps rendering until the new one is ready.
        let edited = self.scene != *self.renderer.scene();
        if edited && let Err(e) = self.renderer.request_scene(&self.ctx, &self.scene) {
            // Keep what is on screen; show why the edit was refused.
            self.panel.error(format!("{e:#}"));
            self.scene = self.renderer.scene().clone();
        }
        if let Some(Err(e)) = self.renderer.poll_build(&self.ctx) {
            // The shader failed to build: the old one stays, and so does
            // the scene it renders.
            self.panel.error(format!("{e:#}"));
            self.scene = self.renderer.scene().clone();
        }
        // What the scene now is, after any refused edit was put back: one
        // step of the undo history unless a drag or typing goes on.
        let gesture = self.egui_ctx.input(|i| i.pointer.any_down())
            || self.egui_ctx.egui_wants_keyboard_input();
        self.history.observe(&self.scene, gesture);
        // Only an edit can add an image or change a path.
        if edited {
            self.reload_images_if_needed();
        }
        if self.config.width == 0 || self.config.height == 0 {
            return Ok(true);
        }
        let ppp = output.pixels_per_point;
        let viewport = Viewport {
            x: (image_rect.min.x * ppp).round().max(0.0),
            y: (image_rect.min.y * ppp).round().max(0.0),
            width: (image_rect.width() * ppp).round().max(1.0),
            height: (image_rect.height() * ppp).round().max(1.0),
        };
        self.renderer
            .resize(&self.ctx, (viewport.width as u32, viewport.height as u32));
        self.renderer.set_render_scale(if dragging {
            self.scene.render.interactive_scale
        } else {
            1.0
        });

        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.ctx.device, &self.config);
                return Ok(true);
            }
            _ => return Ok(true),
        };
        let target = frame.texture.create_view(&Default::default());
        let is_last = self
            .options
            .exit_after_frames
            .is_some_and(|n| self.frames + 1 >= n);
        let capture = if is_last && self.options.window_screenshot.is_some() {
            Some(self.capture_texture())
        } else {
            None
        };
        // Runs the callbacks of finished readbacks (they otherwise wait for
        // the next submit), so the timer and the error meter are free to
        // measure this frame, both of them.
        if let Err(e) = self.ctx.device.poll(wgpu::PollType::Poll) {
            log::warn!("polling the device: {e}");
        }
        self.convergence.observe(
            self.renderer.accumulation_generation(),
            self.renderer.poll_error(),
        );
        self.observe_non_finite();
        if let Some(t) = &mut self.timer {
            t.begin_frame();
            if !self.scene.render.auto_exposure {
                t.forget(Pass::AutoExposure);
            }
        }
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        if !self.paused_at_target() {
            let trace_writes = self.timer.as_ref().and_then(|t| t.render_pass(Pass::Trace));
            self.renderer.trace(&self.ctx, &mut encoder, trace_writes);
            self.renderer
                .meter_error(&self.ctx, &mut encoder, self.timer.as_ref());
        }
        let paint_jobs = self.egui_ctx.tessellate(output.shapes, ppp);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: ppp,
        };
        let extra = self.egui_renderer.update_buffers(
            &self.ctx.device,
            &self.ctx.queue,
            &mut encoder,
            &paint_jobs,
            &screen,
        );
        let background = wgpu::LoadOp::Clear(wgpu::Color {
            r: 0.02,
            g: 0.02,
            b: 0.02,
            a: 1.0,
        });
        let views: Vec<&wgpu::TextureView> = std::iter::once(&target)
            .chain(capture.as_ref().map(|(_, v)| v))
            .collect();
        for view in views {
            let target = DisplayTarget {
                view,
                format: self.config.format,
                viewport,
                load: background,
            };
            self.renderer
                .display(&self.ctx, &mut encoder, &target, self.timer.as_ref())?;
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    timestamp_writes: self.timer.as_ref().and_then(|t| t.render_pass(Pass::Ui)),
                    ..Default::default()
                })
                .forget_lifetime();
            self.egui_renderer.render(&mut pass, &paint_jobs, &screen);
        }
        if let Some(t) = &mut self.timer {
            t.resolve(&mut encoder);
        }
        self.ctx
            .queue
            .submit(extra.into_iter().chain(std::iter::once(encoder.finish())));
        if let Some(t) = &mut self.timer {
            t.after_submit();
        }
        self.renderer.after_submit();
        self.record_feature_cost();
        self.ctx.queue.present(frame);
        self.frames += 1;
        let controls = &self.panel.quality;
        if controls.screenshot_at_target
            && self
                .convergence
                .take_screenshot_moment(controls.target_error)
        {
            self.screenshot_requested = true;
        }
        if self.screenshot_requested {
            self.screenshot_requested = false;
            self.take_screenshot();
        }
        if let (Some((texture, _)), Some(path)) = (capture, self.options.window_screenshot.clone())
        {
            self.save_window_capture(&texture, &path)?;
        }
        if is_last {
            self.report_quality();
        }
        Ok(!is_last)
    }

    /// One line on stderr when a scripted run (`--exit-after-frames`) ends:
    /// what the Quality strip showed, for scripts and tests.
    fn report_quality(&self) {
        let spp = self.renderer.accumulated_samples();
        let error = self
            .convergence
            .latest()
            .map_or("none yet".to_owned(), |e| {
                format!(
                    "{:.4} relative (RMSE {:.5}) at {} spp",
                    e.relative, e.rmse, e.samples
                )
            });
        let trace = match self.timer.as_ref().and_then(|t| t.ms(Pass::Trace)) {
            Some(ms) => format!("{ms:.1} ms per frame (GPU timestamps)"),
            None => "not timed (no timestamp queries)".to_owned(),
        };
        eprintln!("quality: {spp} spp accumulated; estimated error {error}; trace pass {trace}");
    }

    /// Feeds the trace pass's time (GPU, or the whole frame's on the CPU
    /// clock without timestamps) to the feature-cost measurement.
    fn record_feature_cost(&mut self) {
        if self.paused_at_target() {
            return;
        }
        let trace_ms = match &mut self.timer {
            Some(t) => t.take_fresh(Pass::Trace),
            None => Some(self.last_frame.elapsed().as_secs_f32() * 1000.0),
        };
        if let Some(ms) = trace_ms {
            self.feature_costs.record(self.renderer.features(), ms);
        }
    }

    /// An offscreen twin of the swapchain image, so the final frame (UI
    /// included) can be read back: swapchain images may not be copyable.
    fn capture_texture(&self) -> (wgpu::Texture, wgpu::TextureView) {
        let texture = self.ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("window capture"),
            size: wgpu::Extent3d {
                width: self.config.width,
                height: self.config.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.config.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        (texture, view)
    }

    fn save_window_capture(&self, texture: &wgpu::Texture, path: &Path) -> Result<()> {
        let mut bytes = read_texture(&self.ctx.device, &self.ctx.queue, texture, 4)?;
        if matches!(
            self.config.format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        ) {
            for px in bytes.chunks_exact_mut(4) {
                px.swap(0, 2);
            }
        }
        let image = image::RgbaImage::from_raw(self.config.width, self.config.height, bytes)
            .context("window capture has the wrong size")?;
        crate::image_io::save_png(&image, path)
            .with_context(|| format!("saving the window screenshot {}", path.display()))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum HistoryRequest {
    Undo,
    Redo,
}

/// Ctrl+Z undoes, Ctrl+Shift+Z and Ctrl+Y redo (Cmd on macOS), unless a
/// text field has the keyboard: there the keys edit the text.
fn history_shortcut(ctx: &egui::Context) -> Option<HistoryRequest> {
    use egui::{Key, KeyboardShortcut, Modifiers};
    if ctx.egui_wants_keyboard_input() {
        return None;
    }
    ctx.input_mut(|i| {
        // The shifted shortcut first: Ctrl+Z would also match it.
        let redo = i.consume_shortcut(&KeyboardShortcut::new(
            Modifiers::COMMAND | Modifiers::SHIFT,
            Key::Z,
        )) || i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Y));
        if redo {
            Some(HistoryRequest::Redo)
        } else if i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Z)) {
            Some(HistoryRequest::Undo)
        } else {
            None
        }
    })
}
