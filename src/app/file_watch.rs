//! Hot reload: watches the open preset's folder (and, in `--dev` mode, the
//! source tree's `crates/`, where the WGSL files live) and reports changed
//! files, debounced so that an
//! editor's save (often a write, a rename and a metadata change) is one
//! event.
//!
//! Folders rather than files are watched: editors that save by writing a
//! new file and renaming it over the old one would end a watch on the file
//! itself after its first save.

use notify_debouncer_mini::notify::{RecommendedWatcher, RecursiveMode};
use notify_debouncer_mini::{DebounceEventResult, Debouncer, new_debouncer};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

/// How long a file must stay quiet before its change is reported.
const DEBOUNCE: Duration = Duration::from_millis(250);

/// A folder being watched and the files in it that count.
pub struct FileWatch {
    debouncer: Debouncer<RecommendedWatcher>,
    receiver: mpsc::Receiver<DebounceEventResult>,
    watched_dir: Option<PathBuf>,
}

impl FileWatch {
    pub fn new() -> anyhow::Result<Self> {
        let (sender, receiver) = mpsc::channel();
        let debouncer = new_debouncer(DEBOUNCE, sender)?;
        Ok(Self {
            debouncer,
            receiver,
            watched_dir: None,
        })
    }

    /// Watches the folder of `file` instead of the one watched so far.
    pub fn watch_folder_of(&mut self, file: &Path) -> anyhow::Result<()> {
        let dir = absolute_folder(file);
        if self.watched_dir.as_ref() == Some(&dir) {
            return Ok(());
        }
        if let Some(old) = self.watched_dir.take() {
            let _ = self.debouncer.watcher().unwatch(&old);
        }
        self.debouncer
            .watcher()
            .watch(&dir, RecursiveMode::NonRecursive)
            .map_err(|e| anyhow::anyhow!("cannot watch {} for changes: {e}", dir.display()))?;
        self.watched_dir = Some(dir);
        Ok(())
    }

    /// Watches the folder `dir` and every folder below it, once.
    pub fn watch_tree(&mut self, dir: &Path) -> anyhow::Result<()> {
        let dir = std::path::absolute(dir).unwrap_or_else(|_| dir.to_owned());
        self.debouncer
            .watcher()
            .watch(&dir, RecursiveMode::Recursive)
            .map_err(|e| anyhow::anyhow!("cannot watch {} for changes: {e}", dir.display()))?;
        self.watched_dir = Some(dir);
        Ok(())
    }

    /// The files changed since the last call (each once), absolute.
    pub fn changed(&self) -> Vec<PathBuf> {
        let mut changed = Vec::new();
        while let Ok(result) = self.receiver.try_recv() {
            // A watcher error (a folder removed) only means no reload.
            for event in result.unwrap_or_default() {
                if !changed.contains(&event.path) {
                    changed.push(event.path);
                }
            }
        }
        changed
    }
}

/// The absolute folder holding `file` ("." for a bare file name).
fn absolute_folder(file: &Path) -> PathBuf {
    let absolute = std::path::absolute(file).unwrap_or_else(|_| file.to_owned());
    absolute
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_owned)
}

/// Whether `changed` (absolute, from the watcher) is `file`.
pub fn is_same_file(changed: &Path, file: &Path) -> bool {
    let file = std::path::absolute(file).unwrap_or_else(|_| file.to_owned());
    changed == file
        || (changed.file_name() == file.file_name()
            && std::fs::canonicalize(changed).ok() == std::fs::canonicalize(&file).ok()
            && changed.exists())
}

#[cfg(test)]
mod tests {
    use super::*;
    use web_time::Instant;

    /// A file written after the watch starts is reported, once, after the
    /// debounce; a file in another folder is not.
    #[test]
    fn reports_a_changed_file_in_the_watched_folder() {
        let dir = tempfile::Builder::new()
            .prefix("file-watch")
            .tempdir()
            .unwrap();
        let file = dir.path().join("scene.ron");
        std::fs::write(&file, "()").unwrap();
        let mut watch = FileWatch::new().unwrap();
        watch.watch_folder_of(&file).unwrap();
        // Written several times, as editors do: one report.
        for text in ["(a)", "(ab)", "(abc)"] {
            std::fs::write(&file, text).unwrap();
        }
        let start = Instant::now();
        let mut seen = Vec::new();
        while start.elapsed() < Duration::from_secs(10) && seen.is_empty() {
            std::thread::sleep(Duration::from_millis(50));
            seen = watch.changed();
        }
        assert!(
            seen.iter().any(|p| is_same_file(p, &file)),
            "no change reported for {}: {seen:?}",
            file.display()
        );
        assert_eq!(seen.iter().filter(|p| is_same_file(p, &file)).count(), 1);
    }
}
