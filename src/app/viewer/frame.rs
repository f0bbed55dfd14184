//! One frame on the GPU: the edits carried to the renderer, the trace,
//! metering and display passes, egui on top, present; and the figures the
//! panel shows about it.

use super::Viewer;
use crate::app::screenshots;
use crate::app::ui_layer::{self, Compositor, Mode, Redraw, UiLayer};
use crate::panel::{QualityStats, Stats};
use anyhow::{Context as _, Result};
use marbre_core::scene::Change;
use marbre_render::gpu::pass_timer::Pass;
use marbre_render::gpu::readback::read_texture;
use marbre_render::gpu::{DisplayTarget, FeatureSet, NonFiniteCounts, TraceBudget, Viewport};
use std::path::Path;
use web_time::Instant;

/// The window's colour around the image and under the panels.
const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.02,
    g: 0.02,
    b: 0.02,
    a: 1.0,
};

impl Viewer {
    fn quality_stats(&self) -> QualityStats {
        let scene_features: Vec<_> = FeatureSet::for_scene(&self.scene).0.into_iter().collect();
        QualityStats {
            points: self.meters.convergence.points().to_vec(),
            latest: self.meters.convergence.latest(),
            paused_at_target: self.paused_at_target(),
            // The trace on the CPU clock where it is timed so (CPU adapters).
            passes: self.meters.timer.as_ref().map_or_else(Vec::new, |t| {
                Pass::ALL
                    .iter()
                    .map(|&p| match p {
                        Pass::Trace if self.trace_on_wall_clock() => {
                            (p.label(), self.meters.trace_ms)
                        }
                        _ => (p.label(), t.ms(p)),
                    })
                    .collect()
            }),
            without_ms: scene_features
                .iter()
                .map(|&f| self.meters.feature_costs.without(f))
                .collect(),
            scene_features,
            disabled: self.meters.feature_costs.disabled().clone(),
            with_all_ms: self.meters.feature_costs.with_all(),
        }
    }

    /// Why the kernel drawing runs; where the CPU kernel was asked for (or
    /// picked by auto) and the fragment kernel stands in for a scene it
    /// does not trace, why it does not (looked up only then: Stats is read
    /// every frame).
    fn kernel_reason(&self) -> String {
        use marbre_render::gpu::Kernel;
        let standing_in = self.renderer.requested_kernel() == Kernel::Cpu
            && self.renderer.kernel() != Kernel::Cpu;
        let why = standing_in
            .then(|| marbre_render::cpu_kernel::support(&self.scene).err())
            .flatten();
        match why {
            Some(why) => format!("{}; {why}", self.kernels.reason()),
            None => self.kernels.reason().to_owned(),
        }
    }

    /// Whether tracing rests: the user asked to stop at the target error,
    /// and the estimate of the current image is there.
    fn paused_at_target(&self) -> bool {
        let controls = &self.panel.quality;
        let enough = self
            .options
            .stop_at_spp()
            .is_some_and(|n| self.renderer.accumulated_samples() >= n);
        enough || controls.stop_at_target && self.meters.convergence.reached(controls.target_error)
    }

    /// Whether this frame ends a run that ends by itself: its count of
    /// frames, or the event it waits for (the image's samples, the
    /// denoiser's images) has come. Such a frame is shown, and captured
    /// for `--window-screenshot`.
    fn is_last_frame(&self) -> bool {
        let options = &self.options;
        options
            .exit_after_frames
            .is_some_and(|n| self.clock.frames + 1 >= n)
            || options
                .exit_after_spp
                .is_some_and(|n| self.renderer.accumulated_samples() >= n)
            || options.exit_after_denoised.is_some_and(|n| {
                self.renderer
                    .denoise_report()
                    .is_some_and(|report| report.images >= n)
            })
    }

    /// With `max_spp`, the last round traces only the samples left, so that
    /// the image stops at exactly that many (as a render's `--spp` does).
    /// Decided between rounds: a round under way keeps its samples.
    fn limit_rounds_to_max_spp(&mut self) {
        let Some(max) = self.options.stop_at_spp() else {
            return;
        };
        let left = max.saturating_sub(self.renderer.accumulated_samples());
        if left > 0 && self.renderer.round_progress() == 0.0 {
            self.renderer.limit_round_samples(left);
        }
    }

    /// Follows the non-finite counters: they restart with the
    /// accumulation, and a readback arrives a frame or two late.
    fn observe_non_finite(&mut self) {
        let generation = self.renderer.accumulation_generation();
        if self.meters.non_finite.0 != generation {
            self.meters.non_finite = (generation, NonFiniteCounts::default());
        }
        if let Some(counts) = self.renderer.poll_non_finite() {
            self.meters.non_finite.1 = counts;
        }
    }

    pub(super) fn stats(&self) -> Stats {
        let (w, h) = self.renderer.render_size();
        let round_ms = self
            .budget
            .round_ms(u64::from(w) * u64::from(h))
            .or_else(|| self.meters.timer.as_ref().and_then(|t| t.ms(Pass::Trace)));
        let info = self.ctx.adapter.get_info();
        let mesh = self.renderer.mesh_stats();
        Stats {
            fps: self.clock.fps,
            ms_per_frame: round_ms.unwrap_or(self.clock.ms_per_frame),
            ms_is_gpu: !self.trace_on_wall_clock(),
            kernel: self.renderer.kernel(),
            kernel_choice: self.kernels.choice(),
            kernel_reason: self.kernel_reason(),
            round_progress: self.renderer.round_progress(),
            denoise: self.renderer.denoise_report().cloned(),
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
            non_finite: self.meters.non_finite.1,
            quality: self.quality_stats(),
        }
    }

    pub(super) fn draw_frame(
        &mut self,
        output: egui::FullOutput,
        image_rect: egui::Rect,
        dragging: bool,
    ) -> Result<bool> {
        // A map (lat-long or cube) chosen in the panel, or read another
        // way, needs its image loaded first; until it is in, the scene keeps
        // the one drawn (a failed load leaves it so).
        let (env, drawn) = (&self.scene.environment, &self.renderer.scene().environment);
        if env.source.is_map() && (env.source != drawn.source || env.ldr_images != drawn.ldr_images)
        {
            let (drawn_source, drawn_ldr) = (drawn.source.clone(), drawn.ldr_images);
            let env = &mut self.scene.environment;
            let source = std::mem::replace(&mut env.source, drawn_source);
            let ldr = std::mem::replace(&mut env.ldr_images, drawn_ldr);
            self.load_environment_source(source, ldr);
        }
        // What this frame's edits changed, worked out once against the
        // scene the renderer was last asked to draw, and handed on.
        // The scene as traced at the play head; for a scene whose time
        // moves nothing, the scene itself, and its one comparison serves
        // the renderer and the document alike.
        let traced = self.traced(&self.scene).into_owned();
        let moves = self.scene.moves();
        let mut change = traced.changes_from(self.renderer.requested_scene());
        // A structural edit that changes the scene's features ends any
        // feature-cost experiment: the new shader is specialised again.
        if self
            .meters
            .feature_costs
            .follow_scene(&FeatureSet::for_scene(&self.scene))
        {
            self.renderer.forget_feature_override();
        }
        self.poll_kernel_timing();
        self.poll_bakes();
        // Structural edits build their shader off this thread: the old one
        // keeps rendering until the new one is ready.
        if let Err(e) = self.renderer.request_scene(&self.ctx, &traced, change) {
            // Keep what is on screen; show why the edit was refused.
            self.panel.error(format!("{e:#}"));
            self.scene = self.renderer.requested_scene().clone();
            change = Change::empty();
        }
        if let Some(Err(e)) = self.renderer.poll_build(&self.ctx) {
            // The shader failed to build: the old one stays, and so does
            // the scene it renders (for the history, an edit back to it).
            self.panel.error(format!("{e:#}"));
            let failed = std::mem::replace(&mut self.scene, self.renderer.scene().clone());
            change |= self.scene.changes_from(&failed);
        }
        // What the scene now is, after any refused edit was put back: one
        // step of the undo history unless a drag or typing goes on.
        let gesture = self.egui_ctx.input(|i| i.pointer.any_down())
            || self.egui_ctx.egui_wants_keyboard_input();
        // With time in the scene the traced scene moves on its own: the
        // document's edits are its change from the last one recorded.
        if moves {
            change = self.scene.changes_from(self.edits.history.last());
        }
        self.edits.history.observe(&self.scene, change, gesture);
        self.edits.document.observe(&self.scene, change);
        if let Some(error) = self
            .swatches
            .after_frame(&self.egui_ctx, &self.scene, change)
        {
            self.panel.error(error);
        }
        // Only an edit can add an image or change a path.
        if change.edits_document() {
            self.reload_images_if_needed();
        }
        // Minimised: nothing to draw into (the surface keeps its last
        // valid size until the window comes back).
        let size = self.window.inner_size();
        if size.width == 0 || size.height == 0 {
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
            other => {
                if self.clock.unacquired == 0 {
                    log::warn!(
                        "the window's image: {other:?}; frames are not shown until it comes"
                    );
                }
                self.clock.unacquired += 1;
                return Ok(true);
            }
        };
        if self.clock.unacquired > 0 {
            log::warn!(
                "the window's image came after {} frames without one",
                self.clock.unacquired
            );
            self.clock.unacquired = 0;
        }
        let target = frame.texture.create_view(&Default::default());
        let is_last = self.is_last_frame();
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
        self.meters.convergence.observe(
            self.renderer.accumulation_generation(),
            self.renderer.poll_error(),
        );
        self.observe_non_finite();
        if let Some(t) = &mut self.meters.timer {
            t.begin_frame();
            if !self.scene.render.display.auto_exposure {
                t.forget(Pass::AutoExposure);
            }
        }
        if let Some((ms, pixels)) = self.meters.timer.as_mut().and_then(|t| {
            let ms = t.take_fresh(Pass::Trace)?;
            Some((ms, std::mem::take(&mut self.meters.timed_trace_pixels)))
        }) {
            self.observe_trace_time(ms, pixels);
        }
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        if !self.paused_at_target() {
            self.limit_rounds_to_max_spp();
            if self.trace_on_wall_clock() {
                self.trace_and_wait(self.budget.budget());
            } else {
                let trace_writes = self
                    .meters
                    .timer
                    .as_ref()
                    .and_then(|t| t.timestamps(Pass::Trace));
                let work = self.renderer.trace_within(
                    &self.ctx,
                    &mut encoder,
                    self.budget.budget(),
                    trace_writes,
                );
                if self.meters.timer.as_ref().is_some_and(|t| t.is_timing()) {
                    self.meters.timed_trace_pixels = work.pixels;
                }
            }
            self.renderer
                .meter_error(&self.ctx, &mut encoder, self.meters.timer.as_ref());
        }
        let mut paint_jobs = self.egui_ctx.tessellate(output.shapes, ppp);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: ppp,
        };
        let targets: Vec<(&wgpu::Texture, &wgpu::TextureView)> =
            std::iter::once((&frame.texture, &target))
                .chain(capture.as_ref().map(|(t, v)| (t, v)))
                .collect();
        let image = egui::Rect::from_min_size(
            egui::pos2(viewport.x, viewport.y),
            egui::vec2(viewport.width, viewport.height),
        );
        let inside = ui_layer::drawn_inside(&paint_jobs, ppp, image);
        let extra = self.draw_layered(
            &mut encoder,
            &targets,
            viewport,
            &mut paint_jobs,
            &screen,
            inside,
        )?;
        if let Some(t) = &mut self.meters.timer {
            t.resolve(&mut encoder);
        }
        self.ctx
            .queue
            .submit(extra.into_iter().chain(std::iter::once(encoder.finish())));
        if let Some(t) = &mut self.meters.timer {
            t.after_submit();
        }
        self.renderer.after_submit();
        self.ctx.queue.present(frame);
        let script_goes_on = self.script_after_present()?;
        self.clock.frames += 1;
        self.clock.shown += 1;
        self.clock.shown_file.publish(self.clock.shown);
        let controls = &self.panel.quality;
        if controls.screenshot_at_target
            && self
                .meters
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
        Ok(!is_last && script_goes_on)
    }

    /// Uploads egui's meshes for a pass that draws them.
    fn update_egui_buffers(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        paint_jobs: &[egui::ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) -> Vec<wgpu::CommandBuffer> {
        self.egui_renderer.update_buffers(
            &self.ctx.device,
            &self.ctx.queue,
            encoder,
            paint_jobs,
            screen,
        )
    }

    /// Records the display pass of the image into `viewport` of `view`.
    fn display_on(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        viewport: Viewport,
        load: wgpu::LoadOp<wgpu::Color>,
    ) -> Result<()> {
        let target = DisplayTarget {
            view,
            format: self.config.format,
            viewport,
            load,
        };
        self.renderer
            .display(&self.ctx, encoder, &target, self.meters.timer.as_ref())
    }

    /// The kept panel layer (egui drawn into it again only if its output
    /// changed, `app/ui_layer.rs`) on each target with the image: copied
    /// under the image (where the window's image allows copies), and
    /// blended over it within `inside`, the pixels where egui draws inside
    /// the image (a prompt), if any; without copies, the image is drawn
    /// first and the whole layer blended over it.
    fn draw_layered(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &[(&wgpu::Texture, &wgpu::TextureView)],
        viewport: Viewport,
        paint_jobs: &mut [egui::ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
        inside: Option<egui::Rect>,
    ) -> Result<Vec<wgpu::CommandBuffer>> {
        let copies = self.config.usage.contains(wgpu::TextureUsages::COPY_DST);
        let mode = if copies && inside.is_none() {
            Mode::Copied
        } else {
            Mode::Blended
        };
        let format = self.config.format;
        let compositor = match self.ui_compositor.take() {
            Some(c) if c.format() == format => c,
            _ => {
                self.ui_layer = None;
                Compositor::new(&self.ctx.device, format)
            }
        };
        if !self.ui_layer.as_ref().is_some_and(|l| l.fits(&self.config)) {
            self.ui_layer = Some(UiLayer::new(&self.ctx.device, &self.config, &compositor));
        }
        let key = ui_layer::output_key(paint_jobs, screen);
        let mut layer = self.ui_layer.take().expect("made above");
        let mut extra = Vec::new();
        match layer.redraw(key, mode, || {
            ui_layer::band_fingerprints(paint_jobs, screen)
        }) {
            Redraw::Nothing => {}
            Redraw::Whole(view) => {
                extra = self.update_egui_buffers(encoder, paint_jobs, screen);
                let clear = match mode {
                    Mode::Copied => BACKGROUND,
                    Mode::Blended => wgpu::Color::TRANSPARENT,
                };
                let mut pass = self.egui_pass(encoder, view, wgpu::LoadOp::Clear(clear));
                self.egui_renderer.render(&mut pass, paint_jobs, screen);
            }
            Redraw::Rows(_, rows) if rows.is_empty() => {}
            Redraw::Rows(view, rows) => {
                extra = self.update_egui_buffers(encoder, paint_jobs, screen);
                let mut pass = self.egui_pass(encoder, view, wgpu::LoadOp::Load);
                let clear = match mode {
                    Mode::Copied => BACKGROUND,
                    Mode::Blended => wgpu::Color::TRANSPARENT,
                };
                ui_layer::draw_rows(
                    &self.egui_renderer,
                    &compositor,
                    &mut pass,
                    paint_jobs,
                    screen,
                    &rows,
                    clear,
                );
            }
        }
        let mut drawn = Ok(());
        for &(texture, view) in targets {
            drawn = if copies {
                layer.copy_to(encoder, texture);
                self.display_on(encoder, view, viewport, wgpu::LoadOp::Load)
            } else {
                self.display_on(encoder, view, viewport, wgpu::LoadOp::Clear(BACKGROUND))
            };
            if drawn.is_err() {
                break;
            }
            if mode == Mode::Blended {
                compositor.blend(encoder, view, &layer, inside.filter(|_| copies));
            }
        }
        self.ui_layer = Some(layer);
        self.ui_compositor = Some(compositor);
        drawn.map(|()| extra)
    }

    /// Begins egui's pass onto `view`, timed as the panel's.
    fn egui_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        load: wgpu::LoadOp<wgpu::Color>,
    ) -> wgpu::RenderPass<'static> {
        let timestamps = self
            .meters
            .timer
            .as_ref()
            .and_then(|t| t.render_pass(Pass::Ui));
        ui_layer::begin_pass(encoder, view, load, timestamps)
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

    /// One line on stderr when the viewer ends cleanly (closed, or a
    /// scripted run's last frame): what the Quality strip showed, and the
    /// frames drawn since the start, for scripts and tests.
    pub(super) fn report_quality(&self) {
        let spp = self.renderer.accumulated_samples();
        let error = self
            .meters
            .convergence
            .latest()
            .map_or("none yet".to_owned(), |e| {
                format!(
                    "{:.4} relative (RMSE {:.5}) at {} spp",
                    e.relative, e.rmse, e.samples
                )
            });
        let (w, h) = self.renderer.render_size();
        let clock = if self.trace_on_wall_clock() {
            "CPU clock"
        } else {
            "GPU timestamps"
        };
        let trace = match self.budget.round_ms(u64::from(w) * u64::from(h)) {
            Some(ms) => format!("{ms:.1} ms per round ({clock})"),
            None => "not timed yet".to_owned(),
        };
        // The other passes' GPU times: what a frame costs besides the trace.
        let passes: Vec<String> = self.meters.timer.as_ref().map_or_else(Vec::new, |t| {
            Pass::ALL[1..]
                .iter()
                .filter_map(|&p| t.ms(p).map(|ms| format!("{} {ms:.1} ms", p.label())))
                .collect()
        });
        // Samples per second of the image's accumulation, what the
        // window's throughput is measured by (docs/PERFORMANCE.md).
        let seconds = self.renderer.accumulation_time().as_secs_f64();
        let rate = if seconds > 0.0 {
            format!("{:.2} spp/s", f64::from(spp) / seconds)
        } else {
            "no time yet".to_owned()
        };
        eprintln!(
            "quality: {spp} spp accumulated in {} frames of which {} shown; {seconds:.1} s, {rate} ({} kernel); {} restarts; window at {:.1} fps, open {:.1} s; estimated error {error}; trace pass {trace}; other passes: {}",
            self.clock.frames,
            self.clock.shown,
            self.renderer.kernel(),
            // Images thrown away since the start (an edit, a resize…),
            // for the tests that an action keeps the image.
            self.renderer.accumulation_generation(),
            self.clock.fps,
            self.clock.opened.elapsed().as_secs_f64(),
            if passes.is_empty() {
                "not timed".to_owned()
            } else {
                passes.join(", ")
            }
        );
        if let Some(report) = self.renderer.denoise_report() {
            let meanwhile = report.fewest_frames_meanwhile.map_or(String::new(), |n| {
                format!("; each while {n} frames or more were drawn")
            });
            eprintln!(
                "denoise: {}; {} images{meanwhile}",
                report.running.describe(),
                report.images
            );
        }
    }

    /// Whether the trace is timed on the CPU clock, submitted alone and
    /// waited for: without timestamp queries, and on CPU adapters, whose
    /// queue runs on this machine's cores anyway and whose compute-pass
    /// timestamps are not usable (lavapipe's read about 0.02 ms for a pass
    /// of any size, where the frame took 300 ms: the budget then grew
    /// without bound), and for the CPU kernel, whose trace is CPU work
    /// the timestamps do not see.
    /// A web page never does: it cannot wait for the GPU (the browser
    /// answers on its own event loop), so the frame budget follows the
    /// timestamps where the browser gives them and traces whole rounds
    /// where it does not.
    fn trace_on_wall_clock(&self) -> bool {
        !cfg!(target_arch = "wasm32")
            && (self.meters.timer.is_none() || self.traces_on_these_cores())
    }

    /// Whether the trace runs on this machine's cores: a CPU adapter, or
    /// the CPU kernel.
    fn traces_on_these_cores(&self) -> bool {
        self.ctx.is_cpu() || self.renderer.kernel() == marbre_render::gpu::Kernel::Cpu
    }

    /// Whether this frame may trace without being shown
    /// (`app/present_schedule.rs`): only where the trace runs on this
    /// machine's cores (a CPU adapter, or the CPU kernel), and while nothing but
    /// the image moves (no animation playing, no script, no scene loading,
    /// tracing not paused at the target, not a scripted run's last frame)
    /// and there is an image to trace for (a minimised window traces
    /// nothing, as before). Never in a web page: such a frame traces on
    /// the wall clock, which a page cannot wait on.
    pub(super) fn may_leave_unshown(&self) -> bool {
        let last = self.is_last_frame();
        // The window's size last: it asks the display server.
        self.trace_on_wall_clock()
            && self.traces_on_these_cores()
            && self.script.is_none()
            && !self.timeline.playing()
            && self.incoming.startup.is_none()
            && self.incoming.loading.is_none()
            && !self.paused_at_target()
            && !last
            && {
                let size = self.window.inner_size();
                size.width > 0 && size.height > 0
            }
    }

    /// A frame that is not shown: the trace alone, as long as a shown
    /// frame lasts ([`crate::app::frame_budget::FrameBudget::unshown_budget`]).
    pub(super) fn trace_unshown(&mut self) {
        self.limit_rounds_to_max_spp();
        self.trace_and_wait(self.budget.unshown_budget(self.clock.shown_frame_ms));
        self.renderer.after_submit();
        self.clock.frames += 1;
    }

    /// Traces this frame's budget in a submit of its own and waits for it,
    /// timing it on the CPU clock.
    fn trace_and_wait(&mut self, budget: TraceBudget) {
        // The last frame's display and panel first: the time measured is
        // the trace's alone.
        if let Err(e) = self.ctx.device.poll(wgpu::PollType::wait_indefinitely()) {
            log::warn!("waiting for the last frame: {e}");
        }
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        let start = Instant::now();
        let work = self
            .renderer
            .trace_within(&self.ctx, &mut encoder, budget, None);
        self.ctx.queue.submit([encoder.finish()]);
        if let Err(e) = self.ctx.device.poll(wgpu::PollType::wait_indefinitely()) {
            log::warn!("waiting for the trace: {e}");
            return;
        }
        self.observe_trace_time(start.elapsed().as_secs_f32() * 1000.0, work.pixels);
    }

    /// Takes in a measured trace time and the pixels it traced: it sets
    /// the next frames' budget, and, scaled to a whole round, feeds the
    /// feature-cost measurement.
    fn observe_trace_time(&mut self, ms: f32, pixels: u64) {
        if pixels == 0 || self.paused_at_target() {
            return;
        }
        self.budget.observe(ms, pixels);
        self.meters.trace_ms = Some(self.meters.trace_ms.map_or(ms, |s| s + 0.2 * (ms - s)));
        let (w, h) = self.renderer.render_size();
        let round_ms = ms * (f64::from(w) * f64::from(h) / pixels as f64) as f32;
        self.meters
            .feature_costs
            .record(self.renderer.features(), round_ms);
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
            // COPY_DST: the kept panel layer is copied onto it as onto the window.
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
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
        marbre_core::image_io::save_png(&image, path)
            .with_context(|| format!("saving the window screenshot {}", path.display()))
    }
}
