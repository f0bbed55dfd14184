//! Settings that persist between runs: the window size, the last preset,
//! the recent files and the trace kernel found faster per adapter, in `settings.ron` in marbre's configuration folder.
//!
//! A missing or unreadable settings file never stops the app: it starts
//! with the defaults and says why in the panel, and the next save replaces
//! the file (atomically, so a crash mid-save keeps the old one).

use marbre_core::atomic_write::write_atomic;
use marbre_core::capped_read::{self, read_capped_to_string};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Overrides the configuration folder (tests, portable installs).
pub const CONFIG_DIR_VARIABLE: &str = "MARBRE_CONFIG_DIR";

/// How many recent files the menu lists.
pub const MAX_RECENT_FILES: usize = 10;

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

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// The window's inner size in physical pixels when it last closed.
    pub window_size: Option<(u32, u32)>,
    /// The preset open when the app last closed; opened again when no
    /// `--preset` is given.
    pub last_preset: Option<PathBuf>,
    /// Presets and environment maps opened or saved, newest first.
    pub recent_files: Vec<PathBuf>,
    /// The trace kernel `auto` found faster, by adapter ("name (backend)"):
    /// a name, checked when read (`app::kernel_choice`), so a bad value
    /// is ignored with a note instead of discarding every setting.
    pub kernels: std::collections::BTreeMap<String, String>,
}

impl Settings {
    fn file(dir: &Path) -> PathBuf {
        dir.join("settings.ron")
    }

    /// Reads the settings in `dir`; defaults (and the reason, when the file
    /// exists but cannot be used) otherwise.
    pub fn load(dir: &Path) -> (Settings, Option<String>) {
        let path = Self::file(dir);
        let text = match read_capped_to_string(&path, capped_read::SMALL_TEXT) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return (Settings::default(), None);
            }
            Err(e) => {
                let note = format!("{}: {e}; using default settings", path.display());
                return (Settings::default(), Some(note));
            }
        };
        match ron::from_str::<Settings>(&text) {
            Ok(mut settings) => {
                settings.recent_files.truncate(MAX_RECENT_FILES);
                (settings, None)
            }
            Err(e) => {
                let note = format!("{}: {e}; using default settings", path.display());
                (Settings::default(), Some(note))
            }
        }
    }

    /// Writes the settings into `dir` atomically.
    pub fn save(&self, dir: &Path) -> anyhow::Result<()> {
        let text = ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())?;
        let path = Self::file(dir);
        write_atomic(&path, text.as_bytes()).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
    }

    /// Puts `path` first in the recent files (once), forgetting the oldest
    /// beyond [`MAX_RECENT_FILES`].
    pub fn remember(&mut self, path: &Path) {
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
        self.recent_files.retain(|p| *p != path);
        self.recent_files.insert(0, path);
        self.recent_files.truncate(MAX_RECENT_FILES);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_through_the_file() {
        let dir = tempfile::Builder::new()
            .prefix("settings-round-trip")
            .tempdir()
            .unwrap();
        let mut settings = Settings {
            window_size: Some((1400, 900)),
            last_preset: Some(PathBuf::from("/presets/a.ron")),
            ..Settings::default()
        };
        settings.remember(Path::new("/presets/a.ron"));
        settings.save(dir.path()).unwrap();
        assert_eq!(Settings::load(dir.path()), (settings, None));
    }

    #[test]
    fn a_missing_file_gives_defaults_silently() {
        let dir = tempfile::Builder::new()
            .prefix("settings-missing")
            .tempdir()
            .unwrap();
        assert_eq!(Settings::load(dir.path()), (Settings::default(), None));
    }

    #[test]
    fn a_broken_file_gives_defaults_and_says_why() {
        let dir = tempfile::Builder::new()
            .prefix("settings-broken")
            .tempdir()
            .unwrap();
        std::fs::write(dir.path().join("settings.ron"), "(window_size: Some((1, ").unwrap();
        let (settings, note) = Settings::load(dir.path());
        assert_eq!(settings, Settings::default());
        let note = note.expect("a note");
        assert!(note.contains("settings.ron"), "{note}");
    }

    #[test]
    fn recent_files_keep_each_path_once_newest_first_and_capped() {
        let mut settings = Settings::default();
        for i in 0..15 {
            settings.remember(Path::new(&format!("/p/{i}.ron")));
        }
        settings.remember(Path::new("/p/12.ron"));
        assert_eq!(settings.recent_files.len(), MAX_RECENT_FILES);
        assert_eq!(settings.recent_files[0], Path::new("/p/12.ron"));
        assert_eq!(settings.recent_files[1], Path::new("/p/14.ron"));
        let twelves = settings
            .recent_files
            .iter()
            .filter(|p| p.ends_with("12.ron"))
            .count();
        assert_eq!(twelves, 1);
    }
}
