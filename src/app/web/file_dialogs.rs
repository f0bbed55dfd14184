//! Files from and to the user in a web page: the browser's file chooser
//! (an `<input type="file">`) opens presets, OBJ files with their MTL and
//! images, and env maps; files dropped on the page open as a drop on the
//! desktop window does; a save is offered as a download. What the user
//! gives is put among the page's files (`marbre_core::page_files`) under
//! `uploads/`, so that an OBJ finds its MTL and a preset its images by
//! their relative names. The desktop's dialogs are `app/file_dialogs.rs`.

use marbre_core::image_decode::SUPPORTED_EXTENSIONS;
use marbre_core::page_files;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use wasm_bindgen::JsCast as _;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;

/// Where the files the user gives the page are put.
pub const UPLOADS: &str = "uploads";

/// What a dialog is for: the viewer acts on the chosen path accordingly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DialogPurpose {
    OpenPreset,
    SavePresetAs,
    OpenEnvironment,
}

/// A chooser the browser shows: `None` while open, then the chosen file
/// (`Some(None)` if cancelled).
type Outcome = Rc<RefCell<Option<Option<PathBuf>>>>;

/// A file chooser open in the page.
pub struct OpenDialog {
    purpose: DialogPurpose,
    outcome: Outcome,
}

/// A page always has the browser's chooser.
pub fn dialogs_available() -> bool {
    true
}

thread_local! {
    /// Files dropped on the page and read, waiting for the next frame.
    static DROPPED: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
    /// What went wrong in the page's own work (a file refused, a download
    /// or a screenshot that failed), for the panel at the next frame.
    static NOTES: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

/// The largest file the page takes from the user: the page's memory is at
/// most 4 GiB (wasm32), and a file is held whole, then decoded. (On the
/// desktop an OBJ or an image may be 2 GiB: `capped_read`.)
const MAX_GIVEN_BYTES: f64 = 1024.0 * 1024.0 * 1024.0;

/// Says `note` in the panel at the next frame.
pub fn note(note: String) {
    log::warn!("{note}");
    NOTES.with(|n| n.borrow_mut().push(note));
}

/// What the page's own work has to say since the last call.
pub fn take_notes() -> Vec<String> {
    NOTES.with(|n| std::mem::take(&mut *n.borrow_mut()))
}

impl OpenDialog {
    /// Opens the chooser for `purpose`. Save as needs none in a page: the
    /// file is saved under its name and offered as a download
    /// ([`deliver_saved`]), where the browser asks where to keep it.
    pub fn open(purpose: DialogPurpose, start: Option<PathBuf>) -> Self {
        let outcome: Outcome = Rc::default();
        if purpose == DialogPurpose::SavePresetAs {
            let name = start
                .as_ref()
                .and_then(|p| p.file_name())
                .map_or_else(|| PathBuf::from("scene.ron"), PathBuf::from);
            *outcome.borrow_mut() = Some(Some(name));
            return Self { purpose, outcome };
        }
        let accept = match purpose {
            DialogPurpose::OpenPreset => ".ron,.obj,.mtl,".to_owned() + &image_accept(),
            _ => image_accept(),
        };
        if let Err(e) = show_chooser(&accept, purpose, outcome.clone()) {
            log::warn!("cannot open the browser's file chooser: {e:?}");
            *outcome.borrow_mut() = Some(None);
        }
        Self { purpose, outcome }
    }

    /// The outcome once the chooser has closed: `Some(None)` if cancelled.
    pub fn poll(&self) -> Option<(DialogPurpose, Option<PathBuf>)> {
        let chosen = self.outcome.borrow_mut().take()?;
        Some((self.purpose, chosen))
    }
}

/// `.exr,.hdr,…`: the image kinds marbre reads.
fn image_accept() -> String {
    SUPPORTED_EXTENSIONS
        .iter()
        .map(|e| format!(".{e}"))
        .collect::<Vec<_>>()
        .join(",")
}

fn show_chooser(accept: &str, purpose: DialogPurpose, outcome: Outcome) -> Result<(), JsValue> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let input: web_sys::HtmlInputElement = document.create_element("input")?.dyn_into()?;
    input.set_type("file");
    input.set_accept(accept);
    // An OBJ comes with its MTL and images: all are chosen at once.
    input.set_multiple(purpose == DialogPurpose::OpenPreset);
    let chosen = input.clone();
    let outcome_on_cancel = outcome.clone();
    let on_change = Closure::once(move || {
        let files = chosen.files();
        wasm_bindgen_futures::spawn_local(async move {
            let paths = match files {
                Some(files) => read_into_page(&files).await,
                None => Vec::new(),
            };
            *outcome.borrow_mut() = Some(main_file(&paths, purpose));
        });
    });
    input.add_event_listener_with_callback("change", on_change.as_ref().unchecked_ref())?;
    on_change.forget();
    // A chooser closed without a file fires `cancel`, not `change`.
    let cancelled = Closure::once(move || {
        outcome_on_cancel.borrow_mut().get_or_insert(None);
    });
    input.add_event_listener_with_callback("cancel", cancelled.as_ref().unchecked_ref())?;
    cancelled.forget();
    input.click();
    Ok(())
}

/// The file to open among those given at once: the preset or OBJ (not its
/// MTL or images), or the image for an environment.
fn main_file(paths: &[PathBuf], purpose: DialogPurpose) -> Option<PathBuf> {
    let has = |p: &PathBuf, exts: &[&str]| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| exts.contains(&e.to_ascii_lowercase().as_str()))
    };
    match purpose {
        DialogPurpose::OpenPreset => paths
            .iter()
            .find(|p| has(p, &["ron"]))
            .or_else(|| paths.iter().find(|p| has(p, &["obj"])))
            .or_else(|| paths.first())
            .cloned(),
        _ => paths.first().cloned(),
    }
}

/// Reads every file of `files` into the page's files under [`UPLOADS`];
/// returns their paths there. A file that cannot be read is logged and
/// skipped: the viewer then says the file is missing, naming it.
async fn read_into_page(files: &web_sys::FileList) -> Vec<PathBuf> {
    let mut paths = Vec::new();
    for i in 0..files.length() {
        let Some(file) = files.get(i) else { continue };
        if file.size() > MAX_GIVEN_BYTES {
            note(format!(
                "{}: {:.0} MiB is more than a web page can hold ({:.0} MiB at most); open it in \
                 the desktop viewer",
                file.name(),
                file.size() / 1048576.0,
                MAX_GIVEN_BYTES / 1048576.0
            ));
            continue;
        }
        let path = Path::new(UPLOADS).join(file.name());
        match JsFuture::from(file.array_buffer()).await {
            Ok(buffer) => {
                page_files::insert(&path, js_sys::Uint8Array::new(&buffer).to_vec());
                paths.push(path);
            }
            Err(e) => note(format!("cannot read {}: {e:?}", file.name())),
        }
    }
    paths
}

/// Lets files dropped anywhere on the page open as on the desktop window:
/// the browser would otherwise navigate to the file.
pub fn accept_drops() -> Result<(), JsValue> {
    let window = web_sys::window().ok_or("no window")?;
    let on_over = Closure::<dyn FnMut(web_sys::DragEvent)>::new(|e: web_sys::DragEvent| {
        e.prevent_default();
    });
    window.add_event_listener_with_callback("dragover", on_over.as_ref().unchecked_ref())?;
    on_over.forget();
    let on_drop = Closure::<dyn FnMut(web_sys::DragEvent)>::new(|e: web_sys::DragEvent| {
        e.prevent_default();
        let Some(files) = e.data_transfer().and_then(|d| d.files()) else {
            return;
        };
        wasm_bindgen_futures::spawn_local(async move {
            let paths = read_into_page(&files).await;
            if let Some(main) = main_file(&paths, DialogPurpose::OpenPreset) {
                DROPPED.with(|d| d.borrow_mut().push(main));
            }
        });
    });
    window.add_event_listener_with_callback("drop", on_drop.as_ref().unchecked_ref())?;
    on_drop.forget();
    Ok(())
}

/// The files dropped on the page since the last call (the desktop's come
/// as winit's `DroppedFile` instead).
pub fn take_dropped() -> Vec<PathBuf> {
    DROPPED.with(|d| std::mem::take(&mut *d.borrow_mut()))
}

/// Offers the file just saved at `path` (among the page's files) as a
/// download under its name.
pub fn deliver_saved(path: &Path) {
    let Ok(bytes) = page_files::read(path) else {
        return;
    };
    let name = path
        .file_name()
        .map_or_else(|| "scene.ron".into(), |n| n.to_string_lossy().into_owned());
    offer_download(Path::new(&name), &bytes);
}

/// Offers `bytes` as a download called `name`.
pub fn offer_download(name: &Path, bytes: &[u8]) {
    let name = name.to_string_lossy();
    if let Err(e) = download(&name, bytes) {
        note(format!("cannot offer {name} as a download: {e:?}"));
    }
}

/// Puts `fragment` in the page's address (replacing the history entry, so
/// Back leaves the page as before) and copies the whole link; returns it.
pub fn publish_link(fragment: &str) -> Result<String, String> {
    let window = web_sys::window().ok_or("no browser window")?;
    let location = window.location();
    let base = location.href().map_err(|e| format!("{e:?}"))?;
    let base = base.split('#').next().unwrap_or_default();
    let url = format!("{base}#{fragment}");
    window
        .history()
        .and_then(|h| h.replace_state_with_url(&JsValue::NULL, "", Some(&url)))
        .map_err(|e| format!("the browser refused the new address: {e:?}"))?;
    // The clipboard may be refused (no focus, no permission): the link is
    // in the address bar all the same, and the panel says which.
    let copied = JsFuture::from(window.navigator().clipboard().write_text(&url));
    let shown = url.clone();
    wasm_bindgen_futures::spawn_local(async move {
        if copied.await.is_err() {
            note(format!(
                "the browser did not let the page copy the link: copy it from the address bar ({} characters)",
                shown.len()
            ));
        }
    });
    Ok(url)
}

fn download(name: &str, bytes: &[u8]) -> Result<(), JsValue> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let blob = web_sys::Blob::new_with_u8_array_sequence(&parts)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob)?;
    let link: web_sys::HtmlAnchorElement = document.create_element("a")?.dyn_into()?;
    link.set_href(&url);
    link.set_download(name);
    link.click();
    // Not at once: some browsers start the download after `click` returns,
    // and cancel it if the address is gone by then.
    let revoke = Closure::once(move || {
        let _ = web_sys::Url::revoke_object_url(&url);
    });
    web_sys::window()
        .ok_or("no window")?
        .set_timeout_with_callback_and_timeout_and_arguments_0(
            revoke.as_ref().unchecked_ref(),
            60_000,
        )?;
    revoke.forget();
    Ok(())
}
