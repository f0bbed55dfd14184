//! The desktop viewer: a winit window, the progressive renderer every frame,
//! and the egui panel on top.
//!
//! Data flow per frame: winit events → egui input → panel edits the `Scene`
//! → the renderer re-derives buffers (or the pipeline, when the feature set
//! changes) → trace pass → display pass → egui pass → present.

mod bake;
mod camera_input;
mod convergence;
mod device_watch;
mod document;
mod feature_costs;
// The platform's seams (issue 34): the desktop's and the web page's
// implementations side by side, with the same items.
#[cfg_attr(target_arch = "wasm32", path = "web/file_dialogs.rs")]
mod file_dialogs;
#[cfg_attr(target_arch = "wasm32", path = "web/file_watch.rs")]
mod file_watch;
mod frame_budget;
pub mod frame_script;
mod history;
mod kernel_choice;
mod present_schedule;
mod prompts;
mod recovery;
mod render_job;
mod scene_loader;
mod screenshots;
mod settings;
pub mod share_link;
mod shortcuts;
mod shown_frames;
pub mod soak;
pub mod swatches;
mod ui_layer;
mod viewer;
#[cfg(target_arch = "wasm32")]
pub mod web;

pub use frame_budget::{DEFAULT_BUDGET_MS as DEFAULT_FRAME_BUDGET_MS, parse_budget_ms};

use anyhow::Result;
use std::path::PathBuf;
use std::sync::Arc;
use viewer::Viewer;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// What the command line asks of the viewer.
#[derive(Debug, Clone, Default)]
pub struct ViewerOptions {
    pub preset: Option<PathBuf>,
    /// An OBJ file to open as a new scene instead of a preset
    /// (`marbre_core::obj_scene`).
    pub obj: Option<PathBuf>,
    pub env: Option<PathBuf>,
    pub exit_after_frames: Option<u64>,
    /// Exit once the image holds this many samples per pixel (tracing
    /// stops there, as with `max_spp`): a run that ends on an event of the
    /// trace, however slow the machine (issue 47).
    pub exit_after_spp: Option<u32>,
    /// Exit once the denoiser has made this many images.
    pub exit_after_denoised: Option<u32>,
    pub window_screenshot: Option<PathBuf>,
    /// Read the WGSL files from the source tree and rebuild the trace
    /// pipeline when one changes.
    pub dev: bool,
    /// Run as `marbre soak`: random edits driven frame by frame, memory
    /// judged at the end.
    pub soak: Option<soak::SoakOptions>,
    /// The trace kernel: fragment, compute, cpu, or auto (the fastest,
    /// timed on the first scene and remembered per adapter).
    pub kernel: marbre_render::gpu::KernelChoice,
    /// The trace time a frame may take, in ms (`app::frame_budget`); 0
    /// traces a whole round every frame.
    pub frame_budget_ms: f32,
    /// Stop tracing once this many samples per pixel are accumulated, as
    /// a render's sample count does (the web page's `?spp=`); None traces
    /// on (or to the Quality strip's target error).
    pub max_spp: Option<u32>,
}

impl ViewerOptions {
    /// Whether the run ends by itself (a frame count or an event): a
    /// script's or a test's run rather than a person's, whose scene must
    /// be there from the first frame and which leaves no trace in the
    /// settings.
    pub fn ends_by_itself(&self) -> bool {
        self.exit_after_frames.is_some()
            || self.exit_after_spp.is_some()
            || self.exit_after_denoised.is_some()
    }

    /// The samples per pixel tracing stops at: `max_spp` or the run's
    /// last image, whichever comes first.
    pub fn stop_at_spp(&self) -> Option<u32> {
        match (self.max_spp, self.exit_after_spp) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

struct App {
    options: ViewerOptions,
    viewer: Option<Viewer>,
    /// A start-up failure, reported after the loop exits.
    error: Option<anyhow::Error>,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.is_some() {
            return;
        }
        let (config_dir, settings) = settings::load();
        // A soak is about what frames leave behind, not what they show: a
        // smaller window keeps its many frames quick on a software
        // rasteriser.
        let (width, height) = if self.options.soak.is_some() {
            (800, 500)
        } else {
            settings.window_size.unwrap_or((1280, 720))
        };
        let attributes = Window::default_attributes()
            .with_title("marbre")
            .with_inner_size(winit::dpi::PhysicalSize::new(
                width.max(320),
                height.max(240),
            ))
            // Room for the side panel, the Quality strip and some image.
            .with_min_inner_size(winit::dpi::LogicalSize::new(640, 400));
        let options = self.options.clone();
        let result = event_loop
            .create_window(attributes)
            .map_err(anyhow::Error::from)
            .and_then(|w| Viewer::new(Arc::new(w), options, settings, config_dir));
        match result {
            Ok(v) => self.viewer = Some(v),
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(viewer) = &mut self.viewer else {
            return;
        };
        match viewer.handle_event(&event) {
            Ok(true) => {}
            Ok(false) => event_loop.exit(),
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(v) = &self.viewer {
            v.request_redraw();
        }
    }

    /// The viewer goes here, while the event loop (and its connection to
    /// the display, which the surface presents through) still lives: its
    /// workers are joined and its GPU objects dropped in order (`Viewer`'s
    /// doc), so nothing that touches a driver outlives the loop.
    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        self.viewer = None;
    }
}

/// Whether the environment names no display server winit could reach.
fn no_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"]
        .iter()
        .all(|name| std::env::var_os(name).is_none_or(|v| v.is_empty()))
}

/// Opens the window and runs until it is closed (or the frame limit is hit).
pub fn run(options: ViewerOptions) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| match e {
        // winit's message carries its own source path; say what to do.
        winit::error::EventLoopError::Os(_) if no_display() => anyhow::anyhow!(
            "no display to open a window on (neither DISPLAY nor WAYLAND_DISPLAY is set): run \
             marbre in a desktop session, or under Xvfb (`xvfb-run marbre …`); the commands \
             render, tx, bake and noise need no display"
        ),
        e => anyhow::anyhow!("cannot open a window: {e}"),
    })?;
    // Progressive rendering: draw continuously while there is work to do.
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        options,
        viewer: None,
        error: None,
    };
    event_loop.run_app(&mut app)?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
