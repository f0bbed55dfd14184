//! Settings that persist between runs, in `settings.ron` in marbre's
//! configuration folder: the type and its reader and writer are
//! `marbre_core::viewer_files::Settings` (in core, where the fuzz target
//! reaches them); where the folder is is the viewer's.

use std::path::PathBuf;

pub use marbre_core::viewer_files::Settings;

/// Overrides the configuration folder (tests, portable installs).
pub const CONFIG_DIR_VARIABLE: &str = "MARBRE_CONFIG_DIR";

/// The folder holding `settings.ron` and the recovery file:
/// `$MARBRE_CONFIG_DIR`, else the platform's configuration folder
/// (`~/.config/marbre` on Linux). `None` where neither exists: nothing is
/// persisted then.
pub fn config_dir() -> Option<PathBuf> {
    match std::env::var_os(CONFIG_DIR_VARIABLE) {
        Some(dir) if !dir.is_empty() => Some(PathBuf::from(dir)),
        _ => dirs::config_dir().map(|d| d.join("marbre")),
    }
}
