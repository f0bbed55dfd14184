//! Autosave: while the scene has unsaved edits, a copy goes to a recovery
//! file every [`AUTOSAVE_INTERVAL`]; a clean exit, a save or a discard
//! removes it. A recovery file found at start-up means the last run ended
//! without that (a crash, a kill, a power cut), and the viewer offers it.
//!
//! The copy is a preset (written by `preset::save`, so its paths are made
//! relative to the recovery folder and it loads like any other), beside a
//! small info file naming the preset it was edited from, when, and the
//! process that wrote it: a recovery file of a marbre still running is
//! not offered to a second one.

use crate::atomic_write::write_atomic;
use crate::preset::{self, Preset};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How often unsaved edits are copied to the recovery file.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(20);

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct RecoveryInfo {
    /// The preset the scene was loaded from (Save writes there).
    source: PathBuf,
    /// Local time of the autosave, for the offer's text.
    saved_at: String,
    /// The marbre process that wrote it.
    pid: u32,
}

/// A recovery file left by a run that did not end cleanly.
#[derive(Debug, Clone, PartialEq)]
pub struct RecoveryOffer {
    /// The recovered scene, a preset file.
    pub preset: PathBuf,
    /// The preset it was edited from.
    pub source: PathBuf,
    pub saved_at: String,
}

pub struct Autosave {
    dir: PathBuf,
    /// The scene last written, so that an unchanged scene is not written
    /// again.
    written: Option<Scene>,
    last_write: Instant,
}

fn preset_file(dir: &Path) -> PathBuf {
    dir.join("recovery.ron")
}

fn info_file(dir: &Path) -> PathBuf {
    dir.join("recovery-info.ron")
}

/// Whether process `pid` is running (Linux: its /proc entry exists;
/// elsewhere every writer counts as gone, so the file is offered).
fn process_alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists()
}

/// The recovery file in `dir` if a run that has ended left one.
pub fn pending_offer(dir: &Path) -> Option<RecoveryOffer> {
    let preset = preset_file(dir);
    let info: RecoveryInfo = ron::from_str(&std::fs::read_to_string(info_file(dir)).ok()?).ok()?;
    if !preset.exists() || process_alive(info.pid) {
        return None;
    }
    Some(RecoveryOffer {
        preset,
        source: info.source,
        saved_at: info.saved_at,
    })
}

/// Removes the recovery file in `dir` (after it was recovered or declined).
pub fn discard(dir: &Path) {
    let _ = std::fs::remove_file(info_file(dir));
    let _ = std::fs::remove_file(preset_file(dir));
}

impl Autosave {
    pub fn new(dir: PathBuf) -> Self {
        Self {
            dir,
            written: None,
            last_write: Instant::now(),
        }
    }

    /// Called every frame: writes `preset` (the scene with unsaved edits,
    /// from `source`) when the interval has passed and it changed since
    /// the last write; removes the file when there is nothing unsaved.
    pub fn tick(
        &mut self,
        dirty: bool,
        source: &Path,
        preset: impl FnOnce() -> Preset,
    ) -> anyhow::Result<()> {
        if !dirty {
            if self.written.take().is_some() {
                discard(&self.dir);
            }
            self.last_write = Instant::now();
            return Ok(());
        }
        if self.last_write.elapsed() < AUTOSAVE_INTERVAL {
            return Ok(());
        }
        self.last_write = Instant::now();
        let preset = preset();
        if self.written.as_ref() == Some(&preset.scene) {
            return Ok(());
        }
        self.write(&preset, source)?;
        self.written = Some(preset.scene);
        Ok(())
    }

    fn write(&self, preset: &Preset, source: &Path) -> anyhow::Result<()> {
        preset::save(preset, &preset_file(&self.dir))?;
        let info = RecoveryInfo {
            source: std::path::absolute(source).unwrap_or_else(|_| source.to_owned()),
            saved_at: chrono::Local::now().format("%Y-%m-%d %H:%M:%S").to_string(),
            pid: std::process::id(),
        };
        let text = ron::ser::to_string_pretty(&info, ron::ser::PrettyConfig::default())?;
        let path = info_file(&self.dir);
        write_atomic(&path, text.as_bytes()).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
    }

    /// A clean exit: the edits were saved or knowingly discarded.
    pub fn finish(&mut self) {
        self.written = None;
        discard(&self.dir);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_dir::TempDir;

    fn info(dir: &Path, pid: u32) {
        let info = RecoveryInfo {
            source: PathBuf::from("/presets/a.ron"),
            saved_at: "2026-11-22 19:00:00".into(),
            pid,
        };
        std::fs::write(info_file(dir), ron::to_string(&info).unwrap()).unwrap();
    }

    #[test]
    fn a_dead_writers_file_is_offered_and_a_live_ones_is_not() {
        let dir = TempDir::new("recovery-offer");
        preset::save(&Preset::default(), &preset_file(dir.root())).unwrap();
        info(dir.root(), std::process::id());
        assert_eq!(pending_offer(dir.root()), None, "this process is alive");
        // Beyond Linux's pid_max (2^22): no such process.
        info(dir.root(), 1 << 23);
        let offer = pending_offer(dir.root()).expect("an offer");
        assert_eq!(offer.source, Path::new("/presets/a.ron"));
        assert!(preset::load(&offer.preset).is_ok());
        discard(dir.root());
        assert_eq!(pending_offer(dir.root()), None);
    }

    #[test]
    fn autosave_writes_unsaved_edits_after_the_interval_and_removes_them_when_clean() {
        let dir = TempDir::new("recovery-autosave");
        let mut autosave = Autosave::new(dir.root().to_owned());
        let mut edited = Preset::default();
        edited.scene.render.exposure = 3.0;
        autosave
            .tick(true, Path::new("a.ron"), || edited.clone())
            .unwrap();
        assert!(!preset_file(dir.root()).exists(), "not before the interval");
        autosave.last_write -= AUTOSAVE_INTERVAL;
        autosave
            .tick(true, Path::new("a.ron"), || edited.clone())
            .unwrap();
        let saved = preset::load(&preset_file(dir.root())).unwrap().preset;
        assert_eq!(saved.scene.render.exposure, 3.0);
        autosave
            .tick(false, Path::new("a.ron"), || unreachable!())
            .unwrap();
        assert!(!preset_file(dir.root()).exists(), "clean again: removed");
    }
}
