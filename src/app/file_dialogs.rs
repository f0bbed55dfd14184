//! Native file dialogs (rfd: the desktop portal, or zenity), run on a
//! worker thread so the window keeps drawing while one is open.
//!
//! Where no dialog can open (no desktop portal and no zenity, as under a
//! bare X server or over SSH), the viewer falls back to the typed path in
//! the panel and to dropping a file on the window; [`dialogs_available`]
//! says which route to take before anything hangs.

use marbre_core::image_decode::SUPPORTED_EXTENSIONS;
use std::path::PathBuf;
use std::sync::mpsc;

/// What a dialog is for: the viewer acts on the chosen path accordingly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DialogPurpose {
    OpenPreset,
    SavePresetAs,
    OpenEnvironment,
}

/// A dialog open on a worker thread.
pub struct OpenDialog {
    purpose: DialogPurpose,
    receiver: mpsc::Receiver<Option<PathBuf>>,
}

/// Whether a native dialog can be shown here: on Linux and the BSDs rfd
/// talks to the desktop portal over the session bus, or runs zenity.
pub fn dialogs_available() -> bool {
    if cfg!(any(target_os = "windows", target_os = "macos")) {
        return true;
    }
    std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some() || on_path("zenity")
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

impl OpenDialog {
    /// Opens the dialog for `purpose`, starting in `start`'s folder.
    pub fn open(purpose: DialogPurpose, start: Option<PathBuf>) -> Self {
        let (sender, receiver) = mpsc::channel();
        std::thread::spawn(move || {
            let mut dialog = rfd::FileDialog::new();
            if let Some(dir) = start.as_ref().and_then(|p| p.parent()) {
                dialog = dialog.set_directory(dir);
            }
            let chosen = match purpose {
                // An OBJ file opens as a new scene around the mesh.
                DialogPurpose::OpenPreset => dialog
                    .set_title("Open preset or OBJ file")
                    .add_filter("marbre preset or OBJ mesh", &["ron", "obj"])
                    .add_filter("marbre preset", &["ron"])
                    .add_filter("OBJ mesh", &["obj"])
                    .pick_file(),
                DialogPurpose::SavePresetAs => {
                    let name = start
                        .as_ref()
                        .and_then(|p| p.file_name())
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_else(|| "scene.ron".into());
                    dialog
                        .set_title("Save preset as")
                        .add_filter("marbre preset", &["ron"])
                        .set_file_name(name)
                        .save_file()
                }
                DialogPurpose::OpenEnvironment => dialog
                    .set_title("Open environment map")
                    .add_filter("environment map", &SUPPORTED_EXTENSIONS)
                    .pick_file(),
            };
            // The viewer may have closed: then nobody listens.
            let _ = sender.send(chosen);
        });
        Self { purpose, receiver }
    }

    /// The outcome once the dialog has closed: `Some(None)` if cancelled.
    pub fn poll(&self) -> Option<(DialogPurpose, Option<PathBuf>)> {
        match self.receiver.try_recv() {
            Ok(chosen) => Some((self.purpose, chosen)),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => Some((self.purpose, None)),
        }
    }
}

/// Files dropped on the window arrive as winit's `DroppedFile`; only a web
/// page collects its own (`app/web/file_dialogs.rs`).
pub fn take_dropped() -> Vec<PathBuf> {
    Vec::new()
}

/// The desktop's dialogs report through the viewer itself: nothing
/// waits here (a web page's own work does, `app/web/file_dialogs.rs`).
pub fn take_notes() -> Vec<String> {
    Vec::new()
}

/// A save on the desktop is on disk already; a web page offers it as a
/// download.
pub fn deliver_saved(_path: &std::path::Path) {}

/// A link carries a scene to the web page: the desktop has no page
/// address to put it in (Share is offered in a page only).
pub fn publish_link(_fragment: &str) -> Result<String, String> {
    Err(
        "links open marbre's web page: share from the page (README, \"The viewer in a browser\")"
            .into(),
    )
}

/// On the desktop a file is saved where the user says (Save as).
pub fn offer_download(_name: &std::path::Path, _bytes: &[u8]) {}
