//! Settings that persist between runs, in `settings.ron` in marbre's
//! configuration folder: the type and its reader and writer are
//! `marbre_core::viewer_files::Settings` (in core, where the fuzz target
//! reaches them); where the folder is is the viewer's.

use std::path::PathBuf;

pub use marbre_core::viewer_files::Settings;

/// Overrides the configuration folder (tests, portable installs).
#[cfg(not(target_arch = "wasm32"))]
pub const CONFIG_DIR_VARIABLE: &str = "MARBRE_CONFIG_DIR";

/// The folder holding `settings.ron` and the recovery file:
/// `$MARBRE_CONFIG_DIR`, else the platform's configuration folder
/// (`~/.config/marbre` on Linux). `None` where neither exists: nothing is
/// persisted then.
#[cfg(not(target_arch = "wasm32"))]
pub fn config_dir() -> Option<PathBuf> {
    match std::env::var_os(CONFIG_DIR_VARIABLE) {
        Some(dir) if !dir.is_empty() => Some(PathBuf::from(dir)),
        _ => dirs::config_dir().map(|d| d.join("marbre")),
    }
}

/// In a web page the folder is a place among the page's files, filled
/// from the browser's local storage (`app::web::local_storage`).
#[cfg(target_arch = "wasm32")]
pub fn config_dir() -> Option<PathBuf> {
    Some(crate::app::web::local_storage::restore())
}

/// The configuration folder and the settings in it (the defaults where
/// there is none, or where they cannot be read: that is logged).
pub fn load() -> (Option<PathBuf>, Settings) {
    let dir = config_dir();
    let (settings, note) = dir
        .as_deref()
        .map_or_else(|| (Settings::default(), None), Settings::load);
    if let Some(note) = note {
        log::warn!("{note}");
    }
    (dir, settings)
}

/// Keeps what was just saved in `dir` for the next run: on the desktop it
/// is on disk already; a web page copies it to local storage.
pub fn persist(dir: &std::path::Path) {
    #[cfg(target_arch = "wasm32")]
    crate::app::web::local_storage::store(dir);
    #[cfg(not(target_arch = "wasm32"))]
    let _ = dir;
}
