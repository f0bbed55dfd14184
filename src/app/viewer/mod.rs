//! One window's state: surface, renderer, egui, the scene being edited, and
//! what keeps the user's work safe (the document, autosave, prompts).
//!
//! The viewer's code is split by concern: `files` (presets, environment
//! maps, dialogs, recent files, hot reload, the unsaved-changes prompts),
//! `frame` (one frame on the GPU, stats), `device` (recreating everything
//! after a lost device).

mod device;
mod files;
mod frame;

use super::convergence::Convergence;
use super::device_watch::DeviceWatch;
use super::document::Document;
use super::feature_costs::FeatureCosts;
use super::file_dialogs::OpenDialog;
use super::file_watch::{FileWatch, is_same_file};
use super::frame_budget::FrameBudget;
use super::frame_script::{FrameScript, Presented, ScriptAction};
use super::history::History;
use super::kernel_choice::KernelChooser;
use super::present_schedule::{FrameState, PresentSchedule};
use super::prompts::{self, Prompt};
use super::recovery::{self, Autosave};
use super::render_job::{RenderJob, Update};
use super::scene_loader::{FileKind, SceneKind, SceneLoad, load_reporting};
use super::settings::Settings;
use super::shortcuts::{Keys, Shortcut};
use super::shown_frames::ShownFramesFile;
use super::soak::SoakDriver;
use super::swatches::Swatches;
use super::ui_layer::{Compositor, STATS_REFRESH, UiLayer};
use super::{ViewerOptions, camera_input};
use crate::panel::timeline::Timeline;
use crate::panel::{self, PanelAction, PanelState};
use anyhow::Result;
use marbre_core::scene::{EnvSource, OrbitCamera, Scene};
use marbre_render::gpu::pass_timer::PassTimer;
use marbre_render::gpu::{GpuContext, NonFiniteCounts, Renderer};
use marbre_render::session::{
    DEFAULT_PRESET, LoadedScene, load_scene, max_texture_side, renderer_with,
};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use web_time::Instant;
use winit::event::WindowEvent;
use winit::window::{Fullscreen, Window};

/// Width of the side panel, in points, when the window opens: room for a
/// nested constant colour's row with its key button (a wider row would
/// widen the panel by itself).
const PANEL_WIDTH: f32 = 396.0;
/// Height of the Quality strip under the image, in points, when the window
/// opens: a fifth of a 720-pt window (it was a quarter); it can be dragged
/// taller, or folded to its header line.
const QUALITY_HEIGHT: f32 = 150.0;
/// The smallest window, in points, that shows the panels; a smaller one
/// (shrunk by hand, or by a window manager ignoring the minimum size)
/// shows the image alone.
const MIN_UI_SIZE: egui::Vec2 = egui::vec2(PANEL_WIDTH + 240.0, QUALITY_HEIGHT + 160.0);
/// How often the heap's free pages go back to the system: edits, loads and
/// shader builds leave holes in glibc's heaps that otherwise stay resident
/// (a 10,000-frame soak grew 348 -> 598 MiB), and a trim takes a few
/// milliseconds.
const HEAP_TRIM_INTERVAL: std::time::Duration = std::time::Duration::from_secs(5);

/// The fields are declared in the order they must be dropped in (Rust
/// drops a struct's fields in declaration order), which is the shutdown
/// order (issue 26): first the workers that hold a device (each joined by
/// its own drop: the Render dialog's render, bakes, `auto`'s kernel
/// timing, the swatches) and the file watchers, then the GPU objects made
/// on the window's device, then the surface, the device and instance,
/// and last the window the surface draws on. `App` drops the viewer in
/// `exiting`, while the event loop and its display connection still live.
pub struct Viewer {
    /// The Render dialog's render, running in the background.
    render_job: Option<RenderJob>,
    /// The Bake… buttons' bakes, running off the render thread.
    bakes: super::bake::Bakes,
    /// Which trace kernel runs, and `auto`'s timing of both.
    kernels: KernelChooser,
    /// The texture nodes' preview swatches, rendered on a worker thread.
    swatches: Swatches,
    /// Files on their way in: dialogs, loads, hot reload.
    incoming: Incoming,
    renderer: Renderer,
    /// What the Quality strip and the Stats panel report.
    meters: Meters,
    /// The panel's pixels kept between frames (`app/ui_layer.rs`), and
    /// what blends them over the image when they reach into it.
    ui_layer: Option<UiLayer>,
    ui_compositor: Option<Compositor>,
    egui_renderer: egui_wgpu::Renderer,
    egui_state: egui_winit::State,
    egui_ctx: egui::Context,
    /// Lost devices and uncaptured GPU errors.
    device_watch: DeviceWatch,
    /// How much tracing a frame asks for, learnt from the trace's times.
    budget: FrameBudget,
    scene: Scene,
    /// The preset being edited, its undo history and what guards it.
    edits: Editing,
    panel: PanelState,
    options: ViewerOptions,
    /// Window size, last preset, recent files; saved on exit.
    settings: Settings,
    /// Where settings and the recovery file live (none: not persisted, as
    /// in a scripted run).
    config_dir: Option<PathBuf>,
    /// A script driving the frames (`marbre soak`), through its one hook.
    script: Option<Box<dyn FrameScript>>,
    show_help: bool,
    ui_hidden: bool,
    /// The user chose to quit: the loop exits after this frame.
    quitting: bool,
    clock: FrameClock,
    /// The play head: the moment of the scene's time that is traced.
    timeline: Timeline,
    screenshot_requested: bool,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: GpuContext,
    window: Arc<Window>,
}

/// What the Quality strip and the Stats panel report, gathered frame by
/// frame.
struct Meters {
    /// GPU time of each pass, where the adapter has timestamp queries.
    timer: Option<PassTimer>,
    /// The error estimates since the last change, for the Quality panel.
    convergence: Convergence,
    /// Trace times with shader features compiled out, for the Quality panel.
    feature_costs: FeatureCosts,
    /// The trace's time per frame, smoothed, where it is timed on the CPU
    /// clock (the Quality strip's trace row).
    trace_ms: Option<f32>,
    /// The figures the panel shows, and when they were taken: refreshed
    /// every [`STATS_REFRESH`], so that the panel stays the same (and its
    /// layer is reused) between refreshes.
    shown_stats: Option<(Instant, panel::Stats)>,
    /// The pixels traced in the last frame the pass timer timed (its time
    /// arrives a frame or two later), or in the last frame without one.
    timed_trace_pixels: u64,
    /// Samples the current accumulation dropped for being NaN or infinite,
    /// and the accumulation they count.
    non_finite: (u32, NonFiniteCounts),
}

/// The preset being edited and what keeps its edits safe.
struct Editing {
    /// The preset file being edited and what it holds.
    document: Document,
    /// The camera the preset was loaded with, for the panel's Reset.
    preset_camera: OrbitCamera,
    /// Undo and redo of scene edits (Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y).
    history: History,
    /// Copies unsaved edits to the recovery file now and then.
    autosave: Option<Autosave>,
    /// A question waiting for the user's answer (unsaved changes, recovery).
    prompt: Option<Prompt>,
}

/// Files on their way in: each arrives on a worker thread or from a
/// watcher, and lands in the scene between frames.
#[derive(Default)]
struct Incoming {
    /// A native file dialog open on its thread.
    dialog: Option<OpenDialog>,
    /// A preset loading on its thread, and the view to keep when it lands.
    loading: Option<(SceneLoad, Option<files::KeepView>)>,
    /// The preset the window opens on is still loading.
    startup: Option<StartupLoad>,
    /// The preset's folder, for hot reload.
    watch: Option<FileWatch>,
    /// The WGSL sources, in `--dev` mode.
    shader_watch: Option<FileWatch>,
}

/// Frames counted and timed.
struct FrameClock {
    /// Frames run, shown or not: each traces within the budget.
    frames: u64,
    /// Frames shown, and which ones to show.
    shown: u64,
    schedule: PresentSchedule,
    /// When the last frame was shown (`fps` counts frames shown).
    last_frame: Instant,
    /// How long a shown frame takes, smoothed: what a frame that is not
    /// shown may trace.
    shown_frame_ms: f32,
    /// When free heap memory was last handed back ([`HEAP_TRIM_INTERVAL`]).
    last_heap_trim: Instant,
    /// When the window opened: the closing line's time open, which bounds
    /// the frames shown for the panel's refreshes.
    opened: Instant,
    /// Where the count of frames shown goes for the window tests.
    shown_file: ShownFramesFile,
    /// Frames in a row whose window image could not be had (a timeout, an
    /// occluded window): logged when such a run begins and when it ends,
    /// as a window that shows nothing for minutes must say why.
    unacquired: u32,
    fps: f32,
    ms_per_frame: f32,
}

/// The preset the window opens on, loading on a worker thread while the
/// window already shows the panel and a progress bar (a big OBJ and its BVH
/// take seconds) over an empty placeholder scene.
#[derive(Default)]
struct StartupLoad {
    /// A failure opens the default preset instead: the preset was the last
    /// session's, not one named on the command line.
    may_fall_back: bool,
    /// Input that arrived meanwhile, handled in order once the scene is
    /// drawn ([`Viewer::release_held_input`]): keys pressed and clicks made
    /// while it loads are meant for it, not for the placeholder.
    held_events: Vec<WindowEvent>,
}

/// Whether `event` is input to hold while the start-up scene loads; the
/// window's own events (drawing, resizing, closing) are handled at once.
fn held_until_loaded(event: &WindowEvent) -> bool {
    !matches!(
        event,
        WindowEvent::RedrawRequested
            | WindowEvent::Resized(_)
            | WindowEvent::CloseRequested
            | WindowEvent::Destroyed
            | WindowEvent::ScaleFactorChanged { .. }
            | WindowEvent::Moved(_)
            | WindowEvent::Occluded(_)
            | WindowEvent::ThemeChanged(_)
    )
}

/// A scripted run's scene, loaded before the first frame: the preset (or
/// OBJ file, framed for `aspect`) at `path`, or if it fails and
/// `may_fall_back`, the default preset (`path` then names it, and `notes`
/// says why).
fn load_before_first_frame(
    path: &mut PathBuf,
    aspect: f32,
    env: Option<&Path>,
    may_fall_back: bool,
    notes: &mut Vec<String>,
) -> Result<LoadedScene> {
    let kind = match FileKind::of(path) {
        FileKind::Obj => SceneKind::Obj { aspect },
        FileKind::Preset | FileKind::Environment => SceneKind::Preset,
    };
    match load_reporting(path, kind, env, &mut |_| {}) {
        Ok(loaded) => Ok(loaded),
        Err(e) if may_fall_back => {
            notes.push(format!("{e:#}; opening the default preset instead"));
            *path = default_preset();
            load_scene(path, env)
        }
        Err(e) => Err(e),
    }
}

/// The preset (or OBJ file) to open: the command line's, else the last
/// one (if it still exists), else the default.
fn startup_preset(options: &ViewerOptions, settings: &Settings) -> PathBuf {
    if let Some(path) = options.preset.as_ref().or(options.obj.as_ref()) {
        return path.clone();
    }
    settings
        .last_preset
        .clone()
        .filter(|p| marbre_core::capped_read::is_file(p))
        .unwrap_or_else(default_preset)
}

/// The image's width / height in a window that shows the panel and the
/// Quality strip at their opening sizes: what an OBJ file opened at start
/// is framed for, before the first frame has laid the image out.
fn startup_aspect(window: &Window) -> f32 {
    let size = window.inner_size();
    let scale = window.scale_factor() as f32;
    let (w, h) = (size.width as f32, size.height as f32);
    let (image_w, image_h) = (w - PANEL_WIDTH * scale, h - QUALITY_HEIGHT * scale);
    if image_w >= 1.0 && image_h >= 1.0 {
        image_w / image_h
    } else {
        w / h.max(1.0)
    }
}

/// The default preset: in the working folder (a checkout, as the README
/// runs it), else in the source tree this binary was built from.
/// A web page serves it beside itself, under the same relative path.
fn default_preset() -> PathBuf {
    let local = PathBuf::from(DEFAULT_PRESET);
    if cfg!(target_arch = "wasm32") || local.is_file() {
        return local;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join(DEFAULT_PRESET)
}

impl Viewer {
    /// The viewer in `window`, on a device made for it here.
    pub fn new(
        window: Arc<Window>,
        options: ViewerOptions,
        settings: Settings,
        config_dir: Option<PathBuf>,
    ) -> Result<Self> {
        let gpu = GpuContext::for_window(window.clone())?;
        Self::with_gpu(window, gpu, options, settings, config_dir)
    }

    /// The viewer in `window`, on `gpu`'s device and surface (a web page
    /// awaits them: `GpuContext::for_web_window`).
    pub fn with_gpu(
        window: Arc<Window>,
        (ctx, surface): (GpuContext, wgpu::Surface<'static>),
        options: ViewerOptions,
        settings: Settings,
        config_dir: Option<PathBuf>,
    ) -> Result<Self> {
        let mut preset_path = startup_preset(&options, &settings);
        let may_fall_back =
            options.preset.is_none() && options.obj.is_none() && preset_path != default_preset();
        // A scripted run counts its frames from the first, so its scene must
        // be there; a person gets the window at once and the scene when it
        // has loaded.
        let scripted = options.ends_by_itself() || options.soak.is_some();
        let mut startup_notes = Vec::new();
        let (loaded, header) = if scripted {
            let loaded = load_before_first_frame(
                &mut preset_path,
                startup_aspect(&window),
                options.env.as_deref(),
                may_fall_back,
                &mut startup_notes,
            )?;
            (loaded, files::scene_header(&preset_path))
        } else {
            (LoadedScene::placeholder(), Default::default())
        };
        let device_watch = DeviceWatch::default();
        device_watch.attach(&ctx.device);
        let size = window.inner_size();
        let config = surface_config(&surface, &ctx, size);
        surface.configure(&ctx.device, &config);
        let loaded = loaded.fit_environment(max_texture_side(&ctx));
        let (mut kernels, kernel, kernel_notes) =
            KernelChooser::new(options.kernel, &ctx, &settings)?;
        let renderer = renderer_with(&ctx, &loaded, (config.width, config.height), kernel)?;
        if scripted {
            kernels.time_if_needed(&ctx, &loaded, (config.width, config.height));
        }
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&ctx.device, config.format, Default::default());
        let swatches = Swatches::new(&ctx, &egui_ctx);
        let env_path = match &loaded.scene.environment.source {
            EnvSource::LatLong { path } => path.display().to_string(),
            _ => String::new(),
        };
        let mut panel = PanelState::new(preset_path.display().to_string(), env_path);
        for note in startup_notes.into_iter().chain(kernel_notes) {
            panel.error(note);
        }
        if scripted {
            panel.info(format!("loaded {}", preset_path.display()));
        }
        for note in &loaded.notes {
            panel.info(note.clone());
        }
        let timer = PassTimer::new(&ctx);
        let preset_camera = loaded.scene.camera;
        let history = History::new(&loaded.scene);
        let document = Document::new(&preset_path, header, &loaded.scene);
        if !document.has_preset_file() {
            panel.preset_path = document.save_as_suggestion().display().to_string();
        }
        // A scripted run (--exit-after-*, --window-screenshot, a soak)
        // is not the user's work: nothing of it is autosaved or remembered,
        // so the user's next start (window size, last preset, recent files)
        // is the one their own last session left.
        let persists = !scripted && options.window_screenshot.is_none();
        let config_dir = config_dir.filter(|_| persists);
        // A run that crashed left unsaved edits: those of the preset opening
        // now are offered once it is in (`Viewer::offer_recovery`); those
        // of any other are named, and offered when it is opened.
        for offer in config_dir
            .as_deref()
            .map(recovery::pending_offers)
            .unwrap_or_default()
        {
            if !is_same_file(&offer.source, &preset_path) {
                panel.info(files::recovery_note(&offer));
            }
        }
        // A web page's memory goes with its tab: an autosave there would
        // be lost with what it saves (its settings persist in local storage).
        let autosave = config_dir
            .clone()
            .filter(|_| !cfg!(target_arch = "wasm32"))
            .map(Autosave::new);
        let script = options
            .soak
            .as_ref()
            .map(|soak| Box::new(SoakDriver::new(soak)) as Box<dyn FrameScript>);
        let mut viewer = Self {
            device_watch,
            kernels,
            bakes: Default::default(),
            budget: FrameBudget::new(options.frame_budget_ms),
            meters: Meters {
                timer,
                convergence: Convergence::default(),
                feature_costs: FeatureCosts::default(),
                trace_ms: None,
                shown_stats: None,
                timed_trace_pixels: 0,
                non_finite: (0, NonFiniteCounts::default()),
            },
            ui_layer: None,
            ui_compositor: None,
            window,
            surface,
            config,
            ctx,
            renderer,
            egui_ctx,
            egui_state,
            egui_renderer,
            swatches,
            scene: loaded.scene,
            edits: Editing {
                document,
                preset_camera,
                history,
                autosave,
                prompt: None,
            },
            panel,
            options,
            settings,
            config_dir,
            incoming: Incoming::default(),
            script,
            show_help: false,
            ui_hidden: false,
            quitting: false,
            timeline: Timeline::default(),
            clock: FrameClock {
                frames: 0,
                shown: 0,
                schedule: PresentSchedule::new(Instant::now()),
                last_frame: Instant::now(),
                shown_frame_ms: 0.0,
                last_heap_trim: Instant::now(),
                opened: Instant::now(),
                shown_file: ShownFramesFile::from_env(),
                unacquired: 0,
                fps: 0.0,
                ms_per_frame: 0.0,
            },
            screenshot_requested: false,
            render_job: None,
        };
        if scripted {
            viewer.opened(&preset_path);
            viewer.start_watching();
        } else {
            viewer.start_startup_load(&preset_path, may_fall_back);
        }
        Ok(viewer)
    }

    /// Samples per pixel accumulated in the image on screen (the web
    /// page's title says them).
    #[cfg(target_arch = "wasm32")]
    pub fn samples_accumulated(&self) -> u32 {
        self.renderer.accumulated_samples()
    }

    pub fn request_redraw(&self) {
        self.window.request_redraw();
    }

    /// Handles one window event; `Ok(false)` asks the loop to exit.
    pub fn handle_event(&mut self, event: &WindowEvent) -> Result<bool> {
        if let Some(startup) = &mut self.incoming.startup
            && held_until_loaded(event)
        {
            startup.held_events.push(event.clone());
            return Ok(true);
        }
        // Keys reach the viewer through egui's input only, read where the
        // frame knows which widget has the keyboard (`app/shortcuts.rs`).
        let _ = self.egui_state.on_window_event(&self.window, event);
        if !matches!(event, WindowEvent::RedrawRequested) {
            self.clock.schedule.note_input();
        }
        match event {
            WindowEvent::CloseRequested => self.request_quit(),
            // A minimised window has zero size: keep the last valid
            // configuration, and draw nothing until it comes back.
            WindowEvent::Resized(size) if size.width > 0 && size.height > 0 => {
                self.config.width = size.width;
                self.config.height = size.height;
                self.surface.configure(&self.ctx.device, &self.config);
            }
            WindowEvent::DroppedFile(path) => self.load_dropped(path),
            WindowEvent::RedrawRequested => return self.redraw(),
            _ => {}
        }
        Ok(!self.quitting)
    }

    /// The window's close button or the system asks to quit: with unsaved
    /// edits the user chooses first (a scripted run just ends).
    fn request_quit(&mut self) {
        if !self.options.ends_by_itself() && self.edits.document.is_dirty(&self.scene) {
            self.edits.prompt = Some(Prompt::Quit);
        } else {
            self.quit();
        }
    }

    /// Ends the session cleanly: no recovery file is left, and the
    /// settings remember the window and the preset.
    fn quit(&mut self) {
        if let Some(autosave) = &mut self.edits.autosave {
            autosave.finish();
        }
        if let Some(job) = &self.render_job {
            job.cancel();
        }
        if self.window.fullscreen().is_none() {
            let size = self.window.inner_size();
            self.settings.window_size = Some((size.width, size.height));
        }
        self.settings.last_preset = Some(
            std::path::absolute(&self.edits.document.path)
                .unwrap_or_else(|_| self.edits.document.path.clone()),
        );
        self.save_settings();
        self.report_quality();
        self.quitting = true;
    }

    /// The Render panel's Kernel switch: the new kernel is built off the
    /// render thread while the current one draws; `auto` uses the kernel
    /// stored for this adapter, or times both again on the current scene.
    fn set_kernel(&mut self, choice: marbre_render::gpu::KernelChoice) {
        match self.kernels.choose(choice, &self.ctx, &self.settings) {
            Ok((kernel, notes)) => {
                for note in notes {
                    self.panel.error(note);
                }
                if let Err(e) = self.renderer.request_kernel(&self.ctx, kernel) {
                    self.panel.error(format!("{e:#}"));
                }
                let loaded = LoadedScene {
                    scene: self.renderer.scene().clone(),
                    env: None,
                    images: self.renderer.images().clone(),
                    notes: Vec::new(),
                    substitutes: Vec::new(),
                };
                self.kernels
                    .time_if_needed(&self.ctx, &loaded, self.renderer.size());
            }
            Err(e) => self.panel.error(format!("{e:#}")),
        }
    }

    /// Reports the bakes that finished.
    fn poll_bakes(&mut self) {
        for result in self.bakes.finished() {
            match result {
                Ok(message) => self.panel.info(message),
                Err(message) => self.panel.error(message),
            }
        }
    }

    /// The Render dialog's Render: the scene as it is now, rendered on a
    /// thread of its own (`app/render_job.rs`) with the kernel the window
    /// traces with.
    fn start_render(&mut self, mut job: marbre_render::final_render::FinalRender) {
        if self.render_job.is_some() {
            return;
        }
        job.kernel = match self.renderer.kernel() {
            marbre_render::gpu::Kernel::Fragment => marbre_render::gpu::KernelChoice::Fragment,
            marbre_render::gpu::Kernel::Compute => marbre_render::gpu::KernelChoice::Compute,
            marbre_render::gpu::Kernel::Cpu => marbre_render::gpu::KernelChoice::Cpu,
        };
        let output = job.output.display().to_string();
        let images = self.renderer.images().clone();
        match RenderJob::start(&self.ctx, self.scene.clone(), images, job) {
            Ok(started) => {
                eprintln!("render: started {output}");
                self.render_job = Some(started);
                self.panel.render_dialog.last_result = None;
                self.show_render_progress();
            }
            Err(e) => self.render_ended(format!("cannot render {output}: {e:#}"), true),
        }
    }

    /// Shows the render's progress and lands what it reported.
    fn poll_render(&mut self) {
        let Some(job) = &mut self.render_job else {
            return;
        };
        let output = job.job.output.display().to_string();
        for update in job.poll() {
            match update {
                Update::Note(line) => {
                    eprintln!("render: {line}");
                    self.panel.info(line);
                }
                Update::Finished(result) => {
                    self.render_job = None;
                    self.panel.render_dialog.running = None;
                    match result {
                        Ok(marbre_render::final_render::Outcome::Written) => {
                            self.render_ended(format!("rendered {output}"), false)
                        }
                        Ok(marbre_render::final_render::Outcome::Cancelled) => self.render_ended(
                            format!("render of {output} cancelled: nothing written"),
                            false,
                        ),
                        Err(e) => self.render_ended(format!("render failed: {e}"), true),
                    }
                    return;
                }
            }
        }
        self.show_render_progress();
    }

    /// The dialog's progress bar from the job's latest report.
    fn show_render_progress(&mut self) {
        let Some(job) = &self.render_job else {
            return;
        };
        let progress = job.progress();
        let line = match progress {
            None => format!("{}…", job.stage()),
            Some(p) => match p.relative_error {
                Some(e) => format!(
                    "{} / {} spp, error {:.2} %",
                    p.samples,
                    p.max_samples,
                    100.0 * e
                ),
                None => format!("{} / {} spp", p.samples, p.max_samples),
            },
        };
        self.panel.render_dialog.running = Some(crate::panel::render_dialog::RunningView {
            output: job.job.output.display().to_string(),
            fraction: progress.map_or(0.0, |p| p.fraction()),
            line,
        });
    }

    /// How a render ended, in the dialog, the messages and the log.
    fn render_ended(&mut self, text: String, is_error: bool) {
        eprintln!("render: {text}");
        if is_error {
            self.panel.error(text.clone());
        } else {
            self.panel.info(text.clone());
        }
        self.panel.render_dialog.last_result = Some((text, is_error));
    }

    /// Installs the kernel `auto` found faster, once its timing is done.
    fn poll_kernel_timing(&mut self) {
        match self.kernels.poll(&mut self.settings) {
            Some(Ok(kernel)) => {
                self.panel
                    .info(format!("trace kernel: {}", self.kernels.reason()));
                self.save_settings();
                if kernel != self.renderer.kernel()
                    && let Err(e) = self.renderer.request_kernel(&self.ctx, kernel)
                {
                    self.panel.error(format!("{e:#}"));
                }
            }
            Some(Err(e)) => self.panel.error(format!("timing the trace kernels: {e:#}")),
            None => {}
        }
    }

    fn save_settings(&mut self) {
        if let Some(dir) = &self.config_dir {
            match self.settings.save(dir) {
                Ok(()) => super::settings::persist(dir),
                Err(e) => self.panel.error(format!("cannot save settings: {e:#}")),
            }
        }
    }

    /// What the Render dialog renders in time: the play head's moment, or
    /// every frame of the animation.
    fn render_timing(&self) -> marbre_render::frame_sequence::Timing {
        use marbre_render::frame_sequence::Timing;
        let animation = self.scene.animation.clone().unwrap_or_default();
        if self.panel.render_dialog.all_frames {
            Timing::Sequence {
                frames: 0..=animation.frame_count() - 1,
                fps: animation.fps,
                overwrite: true,
                animation: self.panel.render_dialog.animation_file(),
            }
        } else {
            Timing::Still {
                time: self.timeline.time,
                frame: self.timeline.frame(animation.fps),
            }
        }
    }

    /// What is traced of `scene` at the play head: the scene itself unless
    /// its time moves anything ([`Scene::at_time`]).
    fn traced<'a>(&self, scene: &'a Scene) -> std::borrow::Cow<'a, Scene> {
        if scene.moves() {
            std::borrow::Cow::Owned(scene.at_time(self.timeline.time))
        } else {
            std::borrow::Cow::Borrowed(scene)
        }
    }

    /// Undoes or redoes one step of scene edits, keeping the view.
    fn step_history(&mut self, undo: bool) {
        let restored = if undo {
            self.edits.history.undo(&self.scene)
        } else {
            self.edits.history.redo(&self.scene)
        };
        match restored {
            Some(scene) => {
                // A restored scene is handed on at once, so that the next
                // frame's change is the edits made after it, not the undo.
                let traced = self.traced(&scene);
                let change = traced.changes_from(self.renderer.requested_scene());
                match self.renderer.request_scene(&self.ctx, &traced, change) {
                    Ok(()) => {
                        self.scene = scene;
                        self.swatches.note(change);
                    }
                    Err(e) => self.panel.error(format!("{e:#}")),
                }
            }
            None => self.panel.info(if undo {
                "nothing to undo"
            } else {
                "nothing to redo"
            }),
        }
    }

    fn handle_actions(&mut self, actions: Vec<PanelAction>) {
        for action in actions {
            match action {
                PanelAction::LoadPreset(p) => self.request_load_preset(&p),
                PanelAction::SavePreset => {
                    self.save_document();
                }
                PanelAction::SavePresetAs(p) => self.request_save_as(&p),
                PanelAction::ShareLink => self.share_link(),
                PanelAction::BrowsePreset => {
                    self.open_dialog(super::file_dialogs::DialogPurpose::OpenPreset)
                }
                PanelAction::BrowseSavePresetAs => {
                    self.open_dialog(super::file_dialogs::DialogPurpose::SavePresetAs)
                }
                PanelAction::BrowseEnvironment => {
                    self.open_dialog(super::file_dialogs::DialogPurpose::OpenEnvironment)
                }
                PanelAction::OpenRecent(p) => self.load_dropped(&p),
                PanelAction::LoadEnvironment(p) => self.load_environment(&p),
                PanelAction::Screenshot => self.screenshot_requested = true,
                PanelAction::ResetCamera => self.scene.camera = self.edits.preset_camera,
                PanelAction::ToggleFeature(feature) => self.toggle_feature(feature),
                PanelAction::SetKernel(choice) => self.set_kernel(choice),
                PanelAction::Undo => self.step_history(true),
                PanelAction::Redo => self.step_history(false),
                PanelAction::Bake { object, property } => {
                    if let Err(e) = self.bakes.start(
                        &self.scene,
                        self.renderer.images(),
                        &self.edits.document.path,
                        object,
                        property,
                    ) {
                        self.panel.error(e);
                    }
                }
                PanelAction::StartRender(mut job) => {
                    job.timing = self.render_timing();
                    self.start_render(job)
                }
                PanelAction::CancelRender => {
                    if let Some(job) = &self.render_job {
                        job.cancel();
                    }
                }
            }
        }
    }

    fn handle_shortcuts(&mut self, pressed: Vec<Shortcut>) {
        use super::file_dialogs::DialogPurpose;
        for shortcut in pressed {
            // A prompt waits for its answer: Esc is Cancel (which keeps an
            // offered recovery for later). While it, or Save as, waits, the
            // shortcuts that would change the scene or write or open files
            // behind it wait too: Ctrl+S in Save as's field would otherwise
            // save over the preset that Save as is keeping.
            if self.edits.prompt.is_some() && shortcut == Shortcut::Close && !self.show_help {
                self.answer_prompt(prompts::Answer::Cancel);
                continue;
            }
            let waiting = self.edits.prompt.is_some() || self.panel.save_as.is_some();
            if waiting
                && matches!(
                    shortcut,
                    Shortcut::Undo
                        | Shortcut::Redo
                        | Shortcut::Save
                        | Shortcut::SaveAs
                        | Shortcut::Open
                        | Shortcut::HideUi
                        | Shortcut::RecallView(_)
                )
            {
                continue;
            }
            match shortcut {
                Shortcut::Undo => self.step_history(true),
                Shortcut::Redo => self.step_history(false),
                Shortcut::Save => {
                    self.save_document();
                }
                Shortcut::SaveAs => self.open_dialog(DialogPurpose::SavePresetAs),
                Shortcut::Open => self.open_dialog(DialogPurpose::OpenPreset),
                Shortcut::Help => self.show_help = !self.show_help,
                // The help first: it is drawn over Save as, and Save as
                // over the node editor's Add menu.
                Shortcut::Close if self.show_help => self.show_help = false,
                Shortcut::Close if self.panel.save_as.is_some() => self.panel.save_as = None,
                Shortcut::Close => {
                    panel::node_graph::close_menu(&self.egui_ctx, self.panel.node_graph);
                }
                Shortcut::HideUi => self.ui_hidden = !self.ui_hidden,
                Shortcut::PlayPause => self.timeline.toggle(Instant::now()),
                Shortcut::RecallView(index) => {
                    self.scene.recall_view(index);
                }
                Shortcut::Screenshot => self.screenshot_requested = true,
                Shortcut::RenderDialog => self.panel.render_dialog.toggle(),
                Shortcut::Fullscreen => {
                    let fullscreen = match self.window.fullscreen() {
                        Some(_) => None,
                        None => Some(Fullscreen::Borderless(None)),
                    };
                    self.window.set_fullscreen(fullscreen);
                }
            }
        }
    }

    /// Compiles `feature` out of the shader (or back in) to time the scene
    /// without it; a set that cannot be built is refused with the reason.
    fn toggle_feature(&mut self, feature: marbre_render::gpu::Feature) {
        self.meters.feature_costs.toggle(feature);
        let request = self
            .renderer
            .request_feature_override(&self.ctx, self.meters.feature_costs.override_set());
        if let Err(e) = request {
            self.meters.feature_costs.toggle(feature);
            self.panel
                .error(format!("cannot compile {feature:?} out: {e:#}"));
        }
    }

    /// Runs the UI for one frame; returns the image rectangle in points and
    /// whether the camera is being dragged.
    fn run_ui(&mut self) -> (egui::FullOutput, egui::Rect, bool) {
        let raw_input = self.egui_state.take_egui_input(&self.window);
        let stats = match &self.meters.shown_stats {
            Some((taken, stats)) if taken.elapsed() < STATS_REFRESH => stats.clone(),
            _ => {
                let stats = self.stats();
                self.meters.shown_stats = Some((Instant::now(), stats.clone()));
                stats
            }
        };
        let mut actions = Vec::new();
        let mut image_rect = egui::Rect::NOTHING;
        let mut dragging = false;
        self.panel.can_undo = self.edits.history.can_undo();
        self.panel.can_redo = self.edits.history.can_redo();
        self.panel.unsaved = self.edits.document.unsaved();
        self.panel
            .recent_files
            .clone_from(&self.settings.recent_files);
        let preset_name = self.document_name();
        if self
            .timeline
            .tick(Instant::now(), self.scene.animation.as_ref())
        {
            self.window.request_redraw();
        }
        let time = self.timeline.time;
        panel::keying::begin_frame(&self.egui_ctx, time, &self.scene);
        let (scene, panel_state, timeline) = (&mut self.scene, &mut self.panel, &mut self.timeline);
        let (prompt, ui_hidden) = (&self.edits.prompt, self.ui_hidden);
        let mut show_help = self.show_help;
        let mut pressed = Vec::new();
        let mut answer = None;
        let output = self.egui_ctx.run_ui(raw_input, |ui| {
            let keys = Keys::before_widgets(ui.ctx());
            // Too small a window for the panels (egui's layouts need room):
            // show the image alone until it grows again.
            let room = ui.max_rect().size();
            let roomy = room.x >= MIN_UI_SIZE.x && room.y >= MIN_UI_SIZE.y;
            if !ui_hidden && roomy {
                egui::Panel::right("marbre-panel")
                    .default_size(PANEL_WIDTH)
                    .show(ui, |ui| {
                        // Not shrunk to the content, and scrolled both
                        // ways: a row wider than the panel (a colour
                        // ramp's stop, an opened section) scrolls instead
                        // of widening the panel, which would resize the
                        // image and throw its samples away.
                        egui::ScrollArea::both()
                            .auto_shrink([false; 2])
                            .show(ui, |ui| {
                                actions = panel::draw(ui, scene, panel_state, &stats, timeline);
                            });
                    });
                // Folded, the strip is its header line: a panel of its
                // own, so that the unfolded one keeps the height it was
                // given.
                let quality = if panel_state.quality.folded {
                    egui::Panel::bottom("marbre-quality-folded").resizable(false)
                } else {
                    egui::Panel::bottom("marbre-quality")
                        .resizable(true)
                        .default_size(QUALITY_HEIGHT)
                };
                let folded = panel_state.quality.folded;
                quality.show(ui, |ui| {
                    if folded {
                        actions.extend(panel::draw_quality(ui, panel_state, &stats));
                    } else {
                        // As the side panel's: content that grows (the
                        // first estimates) scrolls instead of heightening
                        // the strip, which would shrink the image and
                        // throw its samples away.
                        egui::ScrollArea::both()
                            .auto_shrink([false; 2])
                            .show(ui, |ui| {
                                actions.extend(panel::draw_quality(ui, panel_state, &stats));
                            });
                    }
                });
            }
            image_rect = ui.available_rect_before_wrap();
            let response = ui.allocate_rect(image_rect, egui::Sense::click_and_drag());
            dragging = camera_input::apply(ui, &response, &mut scene.camera);
            panel::help::draw_help_overlay(ui.ctx(), &mut show_help);
            if !ui_hidden {
                panel::render_dialog::show(ui.ctx(), &mut panel_state.render_dialog, &mut actions);
            }
            // Save as under a question it asked (a file to replace): the
            // question has the keyboard.
            panel::save_as::show(
                ui.ctx(),
                &mut panel_state.save_as,
                prompt.is_none(),
                &mut actions,
            );
            if let Some(prompt) = prompt {
                answer = prompts::show(ui.ctx(), prompt, &preset_name);
            }
            // A window over the image (help, a prompt, the Render dialog)
            // is not the image.
            let pointer_on_image = ui.ctx().pointer_hover_pos().is_none_or(|p| {
                image_rect.contains(p)
                    && ui
                        .ctx()
                        .layer_id_at(p)
                        .is_none_or(|layer| layer.order == egui::Order::Background)
            });
            pressed = keys.after_widgets(ui.ctx(), pointer_on_image);
        });
        self.show_help = show_help;
        self.handle_actions(actions);
        self.handle_shortcuts(pressed);
        let keys = panel::keying::take_requests(&self.egui_ctx);
        for (path, value) in keys {
            if let Err(why) = self.scene.insert_key(&path, time, &value) {
                self.panel.error(format!("No key on {path}: {why}"));
            }
        }
        if let Some(answer) = answer {
            self.answer_prompt(answer);
        }
        (output, image_rect, dragging)
    }

    fn redraw(&mut self) -> Result<bool> {
        if let Some(reason) = self.device_watch.take_lost() {
            self.recover_device(&reason)?;
        }
        for message in self.device_watch.take_messages() {
            self.panel.error(format!("GPU error: {message}"));
        }
        let state = FrameState {
            now: Instant::now(),
            images: self.renderer.images_made(),
            may_skip: self.may_leave_unshown(),
        };
        if !self.clock.schedule.shows(&state) {
            self.trace_unshown();
            return Ok(!self.quitting);
        }
        self.poll_dialog();
        for dropped in super::file_dialogs::take_dropped() {
            self.load_dropped(&dropped);
        }
        for note in super::file_dialogs::take_notes() {
            self.panel.error(note);
        }
        self.poll_render();
        self.poll_file_watch();
        self.poll_loading()?;
        self.release_held_input()?;
        self.script_before_frame()?;
        let now = Instant::now();
        let dt = now.duration_since(self.clock.last_frame).as_secs_f32();
        self.clock.last_frame = now;
        self.clock.ms_per_frame = 0.9 * self.clock.ms_per_frame + 0.1 * dt * 1000.0;
        self.clock.fps = 1000.0 / self.clock.ms_per_frame.max(1e-3);

        let (mut output, image_rect, dragging) = self.run_ui();
        self.egui_state
            .handle_platform_output(&self.window, std::mem::take(&mut output.platform_output));
        // Texture uploads are applied now, whatever happens to this frame;
        // frees wait until the frame that may still use them is submitted.
        // A texture the kept panel layer was drawn with may change.
        if !output.textures_delta.set.is_empty() {
            self.ui_layer = None;
        }
        for (id, deltas) in output.textures_delta.set.drain() {
            for delta in &deltas {
                self.egui_renderer
                    .update_texture(&self.ctx.device, &self.ctx.queue, id, delta);
            }
        }
        let to_free: Vec<egui::TextureId> = output.textures_delta.free.drain().collect();
        let repaint_delay = output
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .map_or(std::time::Duration::ZERO, |v| v.repaint_delay);
        let result = self.draw_frame(output, image_rect, dragging);
        let took = now.elapsed().as_secs_f32() * 1000.0;
        self.clock.shown_frame_ms += 0.2 * (took - self.clock.shown_frame_ms);
        self.clock
            .schedule
            .shown(now, self.renderer.images_made(), repaint_delay);
        for id in &to_free {
            self.egui_renderer.free_texture(id);
        }
        self.autosave();
        if self.clock.last_heap_trim.elapsed() >= HEAP_TRIM_INTERVAL {
            self.clock.last_heap_trim = Instant::now();
            crate::heap::release_free_memory();
        }
        let go_on = result? && !self.quitting;
        if !go_on && !self.quitting {
            // A scripted run's last frame: end as a quit would.
            self.quit();
        }
        Ok(go_on)
    }

    /// Applies this frame's scripted edit or action, if a script runs.
    fn script_before_frame(&mut self) -> Result<()> {
        let Some(script) = &mut self.script else {
            return Ok(());
        };
        match script.before_frame(self.clock.frames, &mut self.scene) {
            ScriptAction::Nothing => {}
            ScriptAction::LoadPreset(path) => self.load_preset(&path),
            ScriptAction::LoseDevice => {
                // As a driver reset would: the device goes, its loss is
                // reported on the next poll, and the viewer recovers.
                self.ctx.device.destroy();
                let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
                let reason = self
                    .device_watch
                    .take_lost()
                    .unwrap_or_else(|| "destroyed by the soak".to_owned());
                self.recover_device(&reason)?;
            }
            ScriptAction::StartRender { size, spp, output } => {
                self.start_render(marbre_render::final_render::FinalRender {
                    size,
                    stop: marbre_render::final_render::Stop::Samples(spp),
                    auto_exposure: None,
                    kernel: marbre_render::gpu::KernelChoice::Auto,
                    output,
                    denoise: None,
                    denoise_quality: marbre_core::scene::DenoiseQuality::High,
                    denoise_exr: false,
                    allow_placeholders: true,
                    timing: Default::default(),
                    sample_offset: 0,
                    tile: None,
                    max_tile_pixels: marbre_render::final_render::DEFAULT_MAX_TILE_PIXELS,
                    moments: false,
                    guides: false,
                })
            }
        }
        Ok(())
    }

    /// After a presented frame, the script's turn (none: go on). Whether
    /// to go on; an error fails the run.
    fn script_after_present(&mut self) -> Result<bool> {
        let Some(script) = &mut self.script else {
            return Ok(true);
        };
        script.after_present(Presented {
            frame: self.clock.frames,
            ctx: &self.ctx,
            validation_errors: self.device_watch.validation_errors(),
        })
    }

    /// Copies unsaved edits to the recovery file when it is time.
    fn autosave(&mut self) {
        let dirty = self.edits.document.unsaved();
        let Some(autosave) = &mut self.edits.autosave else {
            return;
        };
        let (document, scene) = (&self.edits.document, &self.scene);
        if let Err(e) = autosave.tick(dirty, &document.path, || document.preset(scene)) {
            self.panel.error(format!("autosave failed: {e:#}"));
        }
    }

    /// The preset's file name, for prompts.
    fn document_name(&self) -> String {
        self.edits.document.path.file_name().map_or_else(
            || "The scene".to_owned(),
            |n| n.to_string_lossy().into_owned(),
        )
    }
}

/// The swapchain configuration for `size` (at least 1×1).
fn surface_config(
    surface: &wgpu::Surface<'_>,
    ctx: &GpuContext,
    size: winit::dpi::PhysicalSize<u32>,
) -> wgpu::SurfaceConfiguration {
    let caps = surface.get_capabilities(&ctx.adapter);
    let format = caps
        .formats
        .iter()
        .copied()
        // egui blends in gamma space, so it wants a non-sRGB target; the
        // display pass then encodes sRGB itself.
        .find(|f| !f.is_srgb())
        .unwrap_or(caps.formats[0]);
    // The kept panel layer is copied onto the window's image, where the
    // surface allows copies (app/ui_layer.rs); else it is blended over it.
    let copy = caps.usages & wgpu::TextureUsages::COPY_DST;
    wgpu::SurfaceConfiguration {
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | copy,
        format,
        width: size.width.max(1),
        height: size.height.max(1),
        present_mode: wgpu::PresentMode::AutoVsync,
        desired_maximum_frame_latency: 2,
        alpha_mode: caps.alpha_modes[0],
        view_formats: vec![],
        color_space: wgpu::SurfaceColorSpace::Auto,
    }
}
