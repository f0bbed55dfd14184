//! The viewer as a web page (issue 34): the same window code, panel,
//! renderer and kernels as the desktop, compiled to wasm32 with WebGPU;
//! winit's web backend draws into the page's canvas.
//!
//! What differs is only what a page must do differently:
//! - **Files.** The page fetches the files it ships (`assets.json` lists
//!   the presets, env maps, meshes and images served beside it) into its
//!   own files (`marbre_core::page_files`) before the viewer starts, so
//!   that every load reads from memory as the desktop reads from disk.
//! - **The device.** The adapter and device are awaited
//!   (`GpuContext::for_web_window`): a page cannot block on them.
//! - **The scene.** A link's fragment (`#scene=…`, `app::share_link`)
//!   opens its scene; else `?preset=` names a shipped preset; else the
//!   last preset opened (the settings are in local storage), else the
//!   default preset.
//!
//! The platform seams beside this module: `file_dialogs.rs` (the browser's
//! chooser, dropped files, downloads), `file_watch.rs` (nothing to watch),
//! `local_storage.rs` (the settings).

pub mod local_storage;

use super::file_dialogs;
use super::share_link;
use super::viewer::Viewer;
use super::{ViewerOptions, settings};
use anyhow::{Context as _, Result, anyhow};
use marbre_core::page_files;
use marbre_render::gpu::{GpuContext, KernelChoice};
use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::Arc;
use wasm_bindgen::JsCast as _;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::platform::web::{EventLoopExtWebSys, WindowAttributesExtWebSys};
use winit::window::{Window, WindowId};

/// The canvas the viewer draws into, and the element that shows the
/// page's progress and errors (`web/index.html`).
const CANVAS_ID: &str = "marbre";
const STATUS_ID: &str = "marbre-status";

/// The list of shipped files the page fetches, written by `web/build.sh`.
const MANIFEST: &str = "assets.json";

/// Starts the page: fetches its files, then opens the viewer on the
/// canvas. Called once by the page's wasm entry (`web/src/lib.rs`).
pub fn start() {
    std::panic::set_hook(Box::new(|info| {
        let message = format!("marbre stopped: {info}");
        // The JavaScript stack names the wasm functions: std has no
        // backtrace on wasm32.
        let stack =
            js_sys::Reflect::get(&js_sys::Error::new(""), &"stack".into()).unwrap_or_default();
        web_sys::console::error_2(&message.clone().into(), &stack);
        show_status(&message, true);
    }));
    let _ = log::set_logger(&ConsoleLog).map(|()| log::set_max_level(log::LevelFilter::Info));
    wasm_bindgen_futures::spawn_local(async {
        if let Err(e) = open_page().await {
            log::error!("{e:#}");
            show_status(&format!("{e:#}"), true);
        }
    });
}

async fn open_page() -> Result<()> {
    show_status("fetching the presets, env maps and images…", false);
    let count = fetch_shipped_files().await?;
    log::info!("the page holds {count} shipped files");
    let preset = startup_preset()?;
    if let Err(e) = file_dialogs::accept_drops() {
        log::warn!("dropping files on the page is off: {e:?}");
    }
    show_status("starting WebGPU…", false);
    let event_loop = EventLoop::new().map_err(|e| anyhow!("cannot start the page's loop: {e}"))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    event_loop.spawn_app(PageApp {
        options: ViewerOptions {
            preset,
            kernel: query_kernel()?,
            max_spp: query_value(&search()?, "spp")
                .map(|n| {
                    n.parse::<u32>().ok().filter(|&n| n >= 1).ok_or_else(|| {
                        anyhow!("?spp={n}: give a whole number of samples, 1 or more")
                    })
                })
                .transpose()?,
            // Whole rounds: the browser paces the frames, and a page cannot
            // wait for the GPU to time bands on the wall clock. Bands sized
            // by SwiftShader's timestamps made the first image take 42 s
            // instead of 1.3 (docs/PERFORMANCE.md, "The web page").
            frame_budget_ms: 0.0,
            ..Default::default()
        },
        viewer: Rc::default(),
        started: false,
    });
    Ok(())
}

/// Fetches every file `assets.json` lists into the page's files; returns
/// how many. The requests run together; each is awaited in turn.
async fn fetch_shipped_files() -> Result<usize> {
    let window = web_sys::window().context("no browser window")?;
    let text = fetch_bytes(&window, MANIFEST).await?;
    let list: js_sys::Array = js_sys::JSON::parse(&String::from_utf8_lossy(&text))
        .map_err(|e| anyhow!("{MANIFEST} is not JSON: {e:?}"))?
        .dyn_into()
        .map_err(|_| anyhow!("{MANIFEST} is not a list of paths"))?;
    let paths: Vec<String> = list.iter().filter_map(|v| v.as_string()).collect();
    let pending: Vec<_> = paths
        .iter()
        .map(|path| JsFuture::from(window.fetch_with_str(path)))
        .collect();
    for (path, response) in paths.iter().zip(pending) {
        let bytes = response_bytes(path, response.await).await?;
        page_files::insert(std::path::Path::new(path), bytes);
    }
    Ok(paths.len())
}

async fn fetch_bytes(window: &web_sys::Window, path: &str) -> Result<Vec<u8>> {
    response_bytes(path, JsFuture::from(window.fetch_with_str(path)).await).await
}

async fn response_bytes(path: &str, response: Result<JsValue, JsValue>) -> Result<Vec<u8>> {
    let response: web_sys::Response = response
        .map_err(|e| anyhow!("cannot fetch {path}: {e:?}"))?
        .dyn_into()
        .map_err(|_| anyhow!("cannot fetch {path}: not a response"))?;
    if !response.ok() {
        return Err(anyhow!(
            "cannot fetch {path}: the server answered {}",
            response.status()
        ));
    }
    let buffer = JsFuture::from(
        response
            .array_buffer()
            .map_err(|e| anyhow!("cannot read {path}: {e:?}"))?,
    )
    .await
    .map_err(|e| anyhow!("cannot read {path}: {e:?}"))?;
    Ok(js_sys::Uint8Array::new(&buffer).to_vec())
}

/// The scene to open: a shared link's (put among the page's files at
/// `share_link::SHARED_PRESET_PATH`), or `?preset=`'s; None opens the
/// last preset, as the desktop does, else the default.
fn startup_preset() -> Result<Option<PathBuf>> {
    let location = web_sys::window().context("no browser window")?.location();
    let hash = location.hash().unwrap_or_default();
    if let Some(shared) = share_link::decode(&hash) {
        // A damaged link opens what the page would open without it, and
        // says why in the panel.
        let text = match shared {
            Ok(text) => text,
            Err(e) => {
                file_dialogs::note(e.to_string());
                return Ok(query_value(&search()?, "preset").map(PathBuf::from));
            }
        };
        let path = PathBuf::from(share_link::SHARED_PRESET_PATH);
        page_files::insert(&path, text.into_bytes());
        return Ok(Some(path));
    }
    Ok(query_value(&search()?, "preset").map(PathBuf::from))
}

/// `?kernel=compute` (or fragment, cpu): the trace kernel, as the
/// desktop's `--kernel`; the fragment kernel by default, as `auto` would
/// need a second device to time the kernels on, which a page cannot wait
/// for.
fn query_kernel() -> Result<KernelChoice> {
    match query_value(&search()?, "kernel") {
        Some(name) => name.parse().map_err(|_| {
            anyhow!(
                "?kernel={name}: give one of {}",
                KernelChoice::NAMES.join(", ")
            )
        }),
        None => Ok(KernelChoice::Fragment),
    }
}

/// The page address's query string (`?preset=…&kernel=…&spp=…`).
fn search() -> Result<String> {
    Ok(web_sys::window()
        .context("no browser window")?
        .location()
        .search()
        .unwrap_or_default())
}

/// The value of `key` in a query string (`?a=1&b=2`), undecoded: the
/// values marbre reads are plain paths and names.
fn query_value(search: &str, key: &str) -> Option<String> {
    search
        .trim_start_matches('?')
        .split('&')
        .find_map(|pair| pair.strip_prefix(key)?.strip_prefix('='))
        .map(str::to_owned)
}

/// The tab's title says how far the image is, as a render's progress
/// does: "marbre · 12 spp" (the browser tests wait on it).
fn show_progress(viewer: &Viewer) {
    let title = format!("marbre · {} spp", viewer.samples_accumulated());
    if let Some(document) = web_sys::window().and_then(|w| w.document())
        && document.title() != title
    {
        document.set_title(&title);
    }
}

/// Shows `message` in the page's status line (an error stays shown).
fn show_status(message: &str, error: bool) {
    let Some(element) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id(STATUS_ID))
    else {
        return;
    };
    element.set_text_content(Some(message));
    let _ = element.set_attribute("class", if error { "error" } else { "" });
}

/// The page's half of the desktop's `App`: the window is made at once,
/// the viewer when the device has been awaited.
struct PageApp {
    options: ViewerOptions,
    viewer: Rc<RefCell<Option<Viewer>>>,
    started: bool,
}

impl ApplicationHandler for PageApp {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if std::mem::replace(&mut self.started, true) {
            return;
        }
        let canvas = web_sys::window()
            .and_then(|w| w.document())
            .and_then(|d| d.get_element_by_id(CANVAS_ID))
            .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok());
        let attributes = Window::default_attributes()
            .with_title("marbre")
            .with_canvas(canvas);
        let window = match event_loop.create_window(attributes) {
            Ok(window) => Arc::new(window),
            Err(e) => {
                show_status(&format!("cannot use the page's canvas: {e}"), true);
                return;
            }
        };
        let slot = self.viewer.clone();
        let options = self.options.clone();
        wasm_bindgen_futures::spawn_local(async move {
            let (config_dir, settings) = settings::load();
            let viewer = GpuContext::for_web_window(window.clone())
                .await
                .context(
                    "this browser gives no WebGPU device (Chrome and Edge 113+, Safari 26+, \
                     Firefox 141+ on Windows have one; the README lists how to enable it)",
                )
                .and_then(|gpu| {
                    Viewer::with_gpu(window.clone(), gpu, options, settings, config_dir)
                });
            match viewer {
                Ok(viewer) => {
                    show_status("", false);
                    *slot.borrow_mut() = Some(viewer);
                    window.request_redraw();
                }
                Err(e) => {
                    log::error!("{e:#}");
                    show_status(&format!("{e:#}"), true);
                }
            }
        });
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let mut slot = self.viewer.borrow_mut();
        let Some(viewer) = slot.as_mut() else {
            return;
        };
        let redraw = matches!(event, WindowEvent::RedrawRequested);
        match viewer.handle_event(&event) {
            Ok(true) if redraw => show_progress(viewer),
            Ok(true) => {}
            Ok(false) => event_loop.exit(),
            Err(e) => {
                show_status(&format!("{e:#}"), true);
                event_loop.exit();
            }
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(viewer) = self.viewer.borrow().as_ref() {
            viewer.request_redraw();
        }
    }
}

/// `log` to the browser's console.
struct ConsoleLog;

impl log::Log for ConsoleLog {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::Level::Info
    }

    fn log(&self, record: &log::Record) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let line: JsValue = format!("{}: {}", record.target(), record.args()).into();
        match record.level() {
            log::Level::Error => web_sys::console::error_1(&line),
            log::Level::Warn => web_sys::console::warn_1(&line),
            _ => web_sys::console::log_1(&line),
        }
    }

    fn flush(&self) {}
}
