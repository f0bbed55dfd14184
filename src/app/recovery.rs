//! Autosave: while the scene has unsaved edits, a copy goes to a recovery
//! file every [`AUTOSAVE_INTERVAL`]; a clean exit, a save or a discard
//! removes it. A recovery file found later means the run that wrote it
//! ended without that (a crash, a kill, a power cut), and the viewer
//! offers it when the preset it was edited from is opened ([`offer_for`]).
//! Edits recovered from it are unsaved edits like any others: written at
//! once to this process's own file, before the crashed run's is removed
//! ([`Autosave::write_now`]), then autosaved on the same schedule, so that
//! a second crash offers them again.
//!
//! The copy is a preset (written by `preset::save`, so its paths are made
//! relative to the recovery folder and it loads like any other), beside a
//! small info file naming the preset it was edited from, when, and the
//! process that wrote it (`viewer_files::RecoveryInfo`, in core, where the
//! fuzz target reaches its reader). Each process writes its own pair of
//! files, named by its pid, so two marbres open at once never overwrite
//! each other's edits, and a file whose writer is still running is not
//! offered.

use marbre_core::atomic_write::write_atomic;
use marbre_core::capped_read::{self, read_capped_to_string};
use marbre_core::preset::{self, Preset};
use marbre_core::scene::Scene;
use marbre_core::viewer_files::RecoveryInfo;
use std::path::{Path, PathBuf};
use std::time::Duration;
use web_time::Instant;

/// How often unsaved edits are copied to the recovery file.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(20);

/// A recovery file left by a run that did not end cleanly.
#[derive(Debug, Clone, PartialEq)]
pub struct RecoveryOffer {
    /// The recovered scene, a preset file.
    pub preset: PathBuf,
    /// The preset it was edited from.
    pub source: PathBuf,
    pub saved_at: String,
    /// The folder and the writer's pid, which name the files.
    dir: PathBuf,
    pid: u32,
}

pub struct Autosave {
    dir: PathBuf,
    /// Names this process's files.
    pid: u32,
    /// The scene last written, so that an unchanged scene is not written
    /// again.
    written: Option<Scene>,
    last_write: Instant,
}

fn preset_file(dir: &Path, pid: u32) -> PathBuf {
    dir.join(format!("recovery-{pid}.ron"))
}

fn info_file(dir: &Path, pid: u32) -> PathBuf {
    dir.join(format!("recovery-{pid}-info.ron"))
}

/// The writer's pid in an info file's name, None for any other file.
fn info_file_pid(name: &str) -> Option<u32> {
    name.strip_prefix("recovery-")?
        .strip_suffix("-info.ron")?
        .parse()
        .ok()
}

/// Whether process `pid` is a marbre still running: on Linux, its /proc
/// entry has the same command name as this process (after a reboot the pid
/// may belong to another program, which does not count) and it has not
/// ended. A marbre killed a moment ago is a zombie until its parent (a
/// shell) reaps it: its entry and name are still there, so its state
/// decides. Elsewhere every other writer counts as gone, so its file is
/// offered.
fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let command = |process: &str| std::fs::read_to_string(format!("/proc/{process}/comm")).ok();
    let same_program =
        matches!((command(&pid.to_string()), command("self")), (Some(a), Some(b)) if a == b);
    same_program && !has_ended(pid)
}

/// Whether `/proc/<pid>/stat` says the process has ended: state `Z`
/// (zombie, not yet reaped) or `X` (dead), or no entry at all.
fn has_ended(pid: u32) -> bool {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return true;
    };
    // "pid (comm) state ...": the name may hold spaces and parentheses, so
    // the state is the first field after the last ')'.
    let state = stat
        .rfind(')')
        .and_then(|end| stat[end + 1..].split_whitespace().next());
    matches!(state, Some("Z" | "X") | None)
}

/// The recovery files in `dir` whose writers have ended, newest first:
/// each is offered when the preset it was edited from is opened.
pub fn pending_offers(dir: &Path) -> Vec<RecoveryOffer> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut offers: Vec<RecoveryOffer> = entries
        .filter_map(|entry| info_file_pid(entry.ok()?.file_name().to_str()?))
        .filter(|&pid| !process_alive(pid))
        .filter_map(|pid| {
            let text = read_capped_to_string(&info_file(dir, pid), capped_read::SMALL_TEXT).ok()?;
            let info = RecoveryInfo::parse(&text).ok()?;
            let preset = preset_file(dir, pid);
            preset.exists().then(|| RecoveryOffer {
                preset,
                source: info.source,
                saved_at: info.saved_at,
                dir: dir.to_owned(),
                pid,
            })
        })
        .collect();
    offers.sort_by(|a, b| b.saved_at.cmp(&a.saved_at));
    offers
}

/// The newest recovery file in `dir` of the preset (or OBJ file) at
/// `document`, however the path is written (relative, through a link):
/// what opening `document` offers. Another preset's autosave is not
/// offered over the one the user asked for (issue 28).
pub fn offer_for(dir: &Path, document: &Path) -> Option<RecoveryOffer> {
    pending_offers(dir)
        .into_iter()
        .find(|offer| crate::app::file_watch::is_same_file(&offer.source, document))
}

/// Removes a recovery file once it was recovered or declined.
pub fn discard(offer: &RecoveryOffer) {
    remove_files(&offer.dir, offer.pid);
}

fn remove_files(dir: &Path, pid: u32) {
    let _ = std::fs::remove_file(info_file(dir, pid));
    let _ = std::fs::remove_file(preset_file(dir, pid));
}

impl Autosave {
    pub fn new(dir: PathBuf) -> Self {
        Self {
            dir,
            pid: std::process::id(),
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
                remove_files(&self.dir, self.pid);
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
        self.write_now(source, preset)
    }

    /// Writes `preset` (unsaved edits of `source`) at once, whatever the
    /// interval: a scene just recovered from a crashed run's file is
    /// copied to this process's own before that one is removed, so that a
    /// second crash at any moment still leaves it on disk. From then on
    /// [`Autosave::tick`] keeps it as any unsaved edits.
    pub fn write_now(&mut self, source: &Path, preset: Preset) -> anyhow::Result<()> {
        self.last_write = Instant::now();
        self.write(&preset, source)?;
        self.written = Some(preset.scene);
        Ok(())
    }

    /// The preset first, then the info that makes it an offer: a crash
    /// between the two leaves the previous autosave's pair, or none.
    fn write(&self, preset: &Preset, source: &Path) -> anyhow::Result<()> {
        preset::save(preset, &preset_file(&self.dir, self.pid))?;
        let info = RecoveryInfo {
            source: std::path::absolute(source).unwrap_or_else(|_| source.to_owned()),
            saved_at: chrono::Local::now().format("%Y-%m-%d %H:%M:%S").to_string(),
            pid: self.pid,
        };
        let text = info.to_text()?;
        let path = info_file(&self.dir, self.pid);
        write_atomic(&path, text.as_bytes()).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
    }

    /// A clean exit: the edits were saved or knowingly discarded.
    pub fn finish(&mut self) {
        self.written = None;
        remove_files(&self.dir, self.pid);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A recovery file as process `pid` would leave it.
    fn left_by(dir: &Path, pid: u32, saved_at: &str, exposure: f32) {
        let mut preset = Preset::default();
        preset.scene.render.display.exposure = exposure;
        preset::save(&preset, &preset_file(dir, pid)).unwrap();
        let info = RecoveryInfo {
            source: PathBuf::from(format!("/presets/{pid}.ron")),
            saved_at: saved_at.into(),
            pid,
        };
        std::fs::write(info_file(dir, pid), info.to_text().unwrap()).unwrap();
    }

    /// Pids beyond Linux's pid_max (2^22): no such process.
    const GONE: u32 = 1 << 23;

    fn newest(dir: &Path) -> Option<RecoveryOffer> {
        pending_offers(dir).into_iter().next()
    }

    /// A marbre killed a moment ago whose parent has not reaped it yet: a
    /// real zombie with this program's name (this test binary run again,
    /// listing its tests and exiting), left unreaped while it is judged.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_zombie_writer_counts_as_gone() {
        let mut child = std::process::Command::new(std::env::current_exe().unwrap())
            .args(["--list", "--exact", "no such test"])
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let pid = child.id();
        let state = || {
            let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
            let end = stat.rfind(')').unwrap();
            stat[end + 1..]
                .split_whitespace()
                .next()
                .unwrap()
                .to_owned()
        };
        // Not reaped, the child stays a zombie once it exits.
        let deadline = web_time::Instant::now() + std::time::Duration::from_secs(60);
        while state() != "Z" {
            assert!(
                web_time::Instant::now() < deadline,
                "the child never exited"
            );
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        let name = |p: &str| std::fs::read_to_string(format!("/proc/{p}/comm")).unwrap();
        assert_eq!(
            name(&pid.to_string()),
            name("self"),
            "the zombie is named as a marbre"
        );
        assert!(!process_alive(pid), "a zombie is dead");
        let dir = tempfile::Builder::new()
            .prefix("recovery-zombie")
            .tempdir()
            .unwrap();
        left_by(dir.path(), pid, "2026-11-22 19:00:00", 2.0);
        assert_eq!(newest(dir.path()).map(|o| o.pid), Some(pid));
        child.wait().unwrap();
    }

    #[test]
    fn a_dead_writers_file_is_offered_and_a_live_ones_is_not() {
        let dir = tempfile::Builder::new()
            .prefix("recovery-offer")
            .tempdir()
            .unwrap();
        left_by(dir.path(), std::process::id(), "2026-11-22 19:00:00", 2.0);
        assert_eq!(newest(dir.path()), None, "this process is alive");
        left_by(dir.path(), GONE, "2026-11-22 18:00:00", 3.0);
        let offer = newest(dir.path()).expect("an offer");
        assert_eq!(offer.source, Path::new(&format!("/presets/{GONE}.ron")));
        let recovered = preset::load(&offer.preset).unwrap().preset;
        assert_eq!(recovered.scene.render.display.exposure, 3.0);
        discard(&offer);
        assert_eq!(newest(dir.path()), None);
        assert!(
            preset_file(dir.path(), std::process::id()).exists(),
            "the live writer's file is left alone"
        );
    }

    #[test]
    fn several_are_listed_newest_first() {
        let dir = tempfile::Builder::new()
            .prefix("recovery-several")
            .tempdir()
            .unwrap();
        left_by(dir.path(), GONE, "2026-11-22 18:00:00", 3.0);
        left_by(dir.path(), GONE + 2, "2026-11-22 17:00:00", 5.0);
        left_by(dir.path(), GONE + 1, "2026-11-22 18:30:00", 4.0);
        let times: Vec<String> = pending_offers(dir.path())
            .into_iter()
            .map(|o| o.saved_at)
            .collect();
        assert_eq!(
            times,
            [
                "2026-11-22 18:30:00",
                "2026-11-22 18:00:00",
                "2026-11-22 17:00:00"
            ]
        );
    }

    /// Opening a preset offers its own autosave, however its path is
    /// written, and never another preset's; of two of its own, the newer.
    #[test]
    fn opening_a_preset_offers_its_own_autosave_only() {
        let dir = tempfile::Builder::new()
            .prefix("recovery-for")
            .tempdir()
            .unwrap();
        let presets = dir.path().join("presets");
        std::fs::create_dir(&presets).unwrap();
        let (mine, cornell) = (presets.join("mine.ron"), presets.join("cornell.ron"));
        for path in [&mine, &cornell] {
            preset::save(&Preset::default(), path).unwrap();
        }
        let config = dir.path().join("config");
        std::fs::create_dir(&config).unwrap();
        for (pid, saved_at) in [
            (GONE, "2026-11-22 18:00:00"),
            (GONE + 1, "2026-11-22 19:00:00"),
        ] {
            left_by(&config, pid, saved_at, 3.0);
            let info = RecoveryInfo {
                source: mine.clone(),
                saved_at: saved_at.into(),
                pid,
            };
            std::fs::write(info_file(&config, pid), ron::to_string(&info).unwrap()).unwrap();
        }
        assert_eq!(offer_for(&config, &cornell), None);
        let offer = offer_for(&config, &presets.join("../presets/./mine.ron"));
        assert_eq!(offer.map(|o| o.pid), Some(GONE + 1));
    }

    /// After a reboot a dead marbre's pid may be another program's.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_pid_now_held_by_another_program_counts_as_ended() {
        let dir = tempfile::Builder::new()
            .prefix("recovery-reused-pid")
            .tempdir()
            .unwrap();
        let mut other = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .expect("spawn sleep");
        left_by(dir.path(), other.id(), "2026-11-22 18:00:00", 3.0);
        let offer = newest(dir.path());
        other.kill().unwrap();
        other.wait().unwrap();
        assert!(offer.is_some(), "sleep is not marbre: the file is offered");
    }

    #[test]
    fn autosave_writes_unsaved_edits_after_the_interval_and_removes_them_when_clean() {
        let dir = tempfile::Builder::new()
            .prefix("recovery-autosave")
            .tempdir()
            .unwrap();
        let mut autosave = Autosave::new(dir.path().to_owned());
        let mine = preset_file(dir.path(), std::process::id());
        let mut edited = Preset::default();
        edited.scene.render.display.exposure = 3.0;
        autosave
            .tick(true, Path::new("a.ron"), || edited.clone())
            .unwrap();
        assert!(!mine.exists(), "not before the interval");
        autosave.last_write -= AUTOSAVE_INTERVAL;
        autosave
            .tick(true, Path::new("a.ron"), || edited.clone())
            .unwrap();
        let saved = preset::load(&mine).unwrap().preset;
        assert_eq!(saved.scene.render.display.exposure, 3.0);
        autosave
            .tick(false, Path::new("a.ron"), || unreachable!())
            .unwrap();
        assert!(!mine.exists(), "clean again: removed");
    }

    /// Recovered edits are written at once, then kept on the usual
    /// schedule while unsaved, and removed once clean.
    #[test]
    fn a_recovered_scene_is_written_at_once_and_kept_while_unsaved() {
        let dir = tempfile::Builder::new()
            .prefix("recovery-recovered")
            .tempdir()
            .unwrap();
        let mut autosave = Autosave::new(dir.path().to_owned());
        let mine = preset_file(dir.path(), std::process::id());
        let mut recovered = Preset::default();
        recovered.scene.render.display.exposure = 3.0;
        autosave
            .write_now(Path::new("a.ron"), recovered.clone())
            .unwrap();
        let info = std::fs::read_to_string(info_file(dir.path(), std::process::id())).unwrap();
        let source = RecoveryInfo::parse(&info).unwrap().source;
        assert_eq!(source, std::path::absolute("a.ron").unwrap());
        let saved = preset::load(&mine).unwrap().preset;
        assert_eq!(saved.scene.render.display.exposure, 3.0, "written at once");
        autosave
            .tick(true, Path::new("a.ron"), || recovered.clone())
            .unwrap();
        assert!(mine.exists(), "still unsaved: kept");
        recovered.scene.render.display.exposure = 4.0;
        autosave.last_write -= AUTOSAVE_INTERVAL;
        autosave
            .tick(true, Path::new("a.ron"), || recovered.clone())
            .unwrap();
        let saved = preset::load(&mine).unwrap().preset;
        assert_eq!(saved.scene.render.display.exposure, 4.0, "rewritten");
        autosave
            .tick(false, Path::new("a.ron"), || unreachable!())
            .unwrap();
        assert!(!mine.exists(), "saved: removed");
    }

    #[test]
    fn two_processes_autosave_to_their_own_files() {
        let dir = tempfile::Builder::new()
            .prefix("recovery-two")
            .tempdir()
            .unwrap();
        let mut first = Autosave::new(dir.path().to_owned());
        let mut second = Autosave::new(dir.path().to_owned());
        second.pid = GONE;
        for (autosave, exposure) in [(&mut first, 1.5), (&mut second, 2.5)] {
            let mut edited = Preset::default();
            edited.scene.render.display.exposure = exposure;
            autosave.last_write -= AUTOSAVE_INTERVAL;
            autosave.tick(true, Path::new("a.ron"), || edited).unwrap();
        }
        let exposure = |pid| {
            preset::load(&preset_file(dir.path(), pid))
                .unwrap()
                .preset
                .scene
                .render
                .display
                .exposure
        };
        assert_eq!(exposure(std::process::id()), 1.5);
        assert_eq!(exposure(GONE), 2.5);
        first.finish();
        assert!(!preset_file(dir.path(), std::process::id()).exists());
        assert!(
            preset_file(dir.path(), GONE).exists(),
            "the other's edits stay"
        );
    }
}
