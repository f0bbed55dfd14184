//! The files the viewer keeps between runs: `settings.ron` and the info
//! file beside each autosaved scene. Their types and readers are here, in
//! core, so that the fuzz targets read them as the viewer does; where the
//! folder is and when the files are written stay with the viewer
//! (`app::settings`, `app::recovery`).

use crate::atomic_write::write_atomic;
use crate::capped_read::{self, read_capped_to_string};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How many recent files the menu lists.
pub const MAX_RECENT_FILES: usize = 10;

/// Settings that persist between runs: the window size, the last preset,
/// the recent files and the trace kernel found faster per adapter.
///
/// A missing or unreadable settings file never stops the app: it starts
/// with the defaults and says why in the panel, and the next save replaces
/// the file (atomically, so a crash mid-save keeps the old one).
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
    pub fn file(dir: &Path) -> PathBuf {
        dir.join("settings.ron")
    }

    /// The settings a `settings.ron` holds, the recent files cut to
    /// [`MAX_RECENT_FILES`].
    pub fn parse(text: &str) -> Result<Settings, ron::error::SpannedError> {
        let mut settings: Settings = ron::from_str(text)?;
        settings.recent_files.truncate(MAX_RECENT_FILES);
        Ok(settings)
    }

    /// The text [`Settings::save`] writes, which [`Settings::parse`] reads
    /// back to equal settings.
    pub fn to_text(&self) -> Result<String, ron::Error> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
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
        match Settings::parse(&text) {
            Ok(settings) => (settings, None),
            Err(e) => {
                let note = format!("{}: {e}; using default settings", path.display());
                (Settings::default(), Some(note))
            }
        }
    }

    /// Writes the settings into `dir` atomically.
    pub fn save(&self, dir: &Path) -> anyhow::Result<()> {
        let text = self.to_text()?;
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

/// The info file beside an autosaved scene (`app::recovery`): which preset
/// it was edited from, when, and by which process.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecoveryInfo {
    /// The preset the scene was loaded from (Save writes there).
    pub source: PathBuf,
    /// Local time of the autosave, for the offer's text; as
    /// "YYYY-MM-DD HH:MM:SS" it also sorts in time order.
    pub saved_at: String,
    /// The marbre process that wrote it.
    pub pid: u32,
}

impl RecoveryInfo {
    /// The info an info file holds.
    pub fn parse(text: &str) -> Result<RecoveryInfo, ron::error::SpannedError> {
        ron::from_str(text)
    }

    /// The text of its file, which [`RecoveryInfo::parse`] reads back to
    /// an equal info.
    pub fn to_text(&self) -> Result<String, ron::Error> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_round_trip_through_the_file() {
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
    fn a_missing_settings_file_gives_defaults_silently() {
        let dir = tempfile::Builder::new()
            .prefix("settings-missing")
            .tempdir()
            .unwrap();
        assert_eq!(Settings::load(dir.path()), (Settings::default(), None));
    }

    #[test]
    fn a_broken_settings_file_gives_defaults_and_says_why() {
        let dir = tempfile::Builder::new()
            .prefix("settings-broken")
            .tempdir()
            .unwrap();
        std::fs::write(dir.path().join("settings.ron"), "(window_size: Some((1, ").unwrap();
        let (settings, note) = Settings::load(dir.path());
        assert_eq!(settings, Settings::default());
        let note = note.expect("a note");
        assert!(note.contains("settings.ron"), "{note}");
        assert!(note.ends_with("; using default settings"), "{note}");
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

    /// A hand-edited file listing more recent files than the menu shows
    /// is read with the newest [`MAX_RECENT_FILES`].
    #[test]
    fn parsed_recent_files_are_capped() {
        let files: Vec<String> = (0..12).map(|i| format!("\"/p/{i}.ron\"")).collect();
        let settings = Settings::parse(&format!("(recent_files: [{}])", files.join(", "))).unwrap();
        assert_eq!(settings.recent_files.len(), MAX_RECENT_FILES);
        assert_eq!(settings.recent_files[9], Path::new("/p/9.ron"));
    }

    #[test]
    fn recovery_info_round_trips_through_its_text() {
        let info = RecoveryInfo {
            source: PathBuf::from("/presets/a \"b\".ron"),
            saved_at: "2026-11-22 19:00:00".into(),
            pid: 4242,
        };
        assert_eq!(RecoveryInfo::parse(&info.to_text().unwrap()).unwrap(), info);
        let e = RecoveryInfo::parse("(source: \"/a.ron\", pid: 1)").unwrap_err();
        assert!(e.to_string().contains("saved_at"), "{e}");
    }
}
