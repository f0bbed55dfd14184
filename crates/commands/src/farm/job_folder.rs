//! Writing a job's folder: its subfolders, its plan and its scheduler's
//! files, each written atomically. When a write fails (a full disk, a
//! read-only file), what this write created is removed again, so that a
//! failed `farm slurm|k8s` leaves no empty job skeleton behind; files
//! that were there before keep what they held or their new bytes, whole.

use super::shown_path;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The subfolders every job has: the tasks' parts, the finished frames,
/// the failed tasks' notes and the scheduler's logs.
const SUBFOLDERS: [&str; 4] = ["parts", "frames", "status", "logs"];

/// Writes `files` (name in `dir`, text) into `dir` and creates its
/// subfolders; scripts (`.sh`, `.sbatch`) are made executable. An error
/// names the file or folder that could not be written.
pub fn write(dir: &Path, files: &[(&str, String)]) -> Result<()> {
    let mut created = Created::default();
    let result = write_all(dir, files, &mut created);
    if result.is_err() {
        created.remove();
    }
    result
}

fn write_all(dir: &Path, files: &[(&str, String)], created: &mut Created) -> Result<()> {
    created.folder(dir)?;
    for sub in SUBFOLDERS {
        created.folder(&dir.join(sub))?;
    }
    for (name, text) in files {
        let path = dir.join(name);
        let new = std::fs::symlink_metadata(&path).is_err();
        marbre_core::atomic_write::write_atomic(&path, text.as_bytes())
            .with_context(|| format!("writing {}", shown_path(&path)))?;
        if new {
            created.files.push(path.clone());
        }
        if name.ends_with(".sh") || name.ends_with(".sbatch") {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755))
                .with_context(|| format!("making {} executable", shown_path(&path)))?;
        }
    }
    Ok(())
}

/// What a write created, newest last.
#[derive(Default)]
struct Created {
    folders: Vec<PathBuf>,
    files: Vec<PathBuf>,
}

impl Created {
    /// Creates `folder` and the folders above it that are missing.
    fn folder(&mut self, folder: &Path) -> Result<()> {
        let missing: Vec<&Path> = folder
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && std::fs::symlink_metadata(d).is_err())
            .collect();
        for d in missing.into_iter().rev() {
            std::fs::create_dir(d).with_context(|| format!("creating {}", shown_path(d)))?;
            self.folders.push(d.to_owned());
        }
        Ok(())
    }

    /// Removes what was created, files first, then the folders from the
    /// deepest (each only if empty: a file another process put there
    /// stays).
    fn remove(&self) {
        for file in &self.files {
            let _ = std::fs::remove_file(file);
        }
        for folder in self.folders.iter().rev() {
            let _ = std::fs::remove_dir(folder);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A read-only file among those written: the error names it, and the
    /// folders and files the write created are gone; what was there
    /// stays.
    #[test]
    fn a_failed_write_names_the_file_and_leaves_what_was_there() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("new/job");
        let files = [("a.txt", "a".to_owned()), ("run.sh", "true".to_owned())];
        write(&dir, &files).unwrap();
        assert!(dir.join("status").is_dir() && dir.join("a.txt").is_file());
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(dir.join("run.sh"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, 0o755);

        let dir = root.path().join("kept");
        std::fs::create_dir(&dir).unwrap();
        let kept = dir.join("run.sh");
        std::fs::write(&kept, "old").unwrap();
        let mut permissions = std::fs::metadata(&kept).unwrap().permissions();
        permissions.set_readonly(true);
        std::fs::set_permissions(&kept, permissions).unwrap();
        let e = format!("{:#}", write(&dir, &files).unwrap_err());
        assert!(
            e.starts_with(&format!("writing {}: ", kept.display())),
            "{e}"
        );
        assert!(e.contains("read-only"), "{e}");
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, ["run.sh"]);
        assert_eq!(std::fs::read(&kept).unwrap(), b"old");
    }
}
