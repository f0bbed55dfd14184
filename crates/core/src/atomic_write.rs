//! Saves that never leave a half-written file behind, nor replace what
//! they should not.
//!
//! A file is written to a temporary sibling, flushed, renamed over its
//! name, and the folder is synced so the rename itself survives a power
//! cut. A link is written through (its target is replaced, the link
//! stays); a read-only file is refused rather than replaced by the rename
//! (which Unix allows whenever the folder is writable). The temporaries
//! being written are listed, so that a command interrupted by SIGINT or
//! SIGTERM removes them ([`remove_pending_temporaries`]).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporaries being written now, by any thread.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Writes `bytes` to a temporary file beside `path` (beside the file a link
/// at `path` points to), flushes it to disk, renames it over that file and
/// syncs the folder. A crash or a full disk at any point leaves either the
/// old file or the new one, never a truncated mix.
///
/// In a web page (wasm32) the bytes replace the page's own file
/// ([`crate::page_files`]) at once, which is atomic there.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if cfg!(target_arch = "wasm32") {
        crate::page_files::insert(path, bytes);
        return Ok(());
    }
    let path = &write_target(path)?;
    let dir = folder_of(path);
    std::fs::create_dir_all(dir)?;
    if let Ok(meta) = std::fs::metadata(path)
        && meta.permissions().readonly()
    {
        return Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "the file is read-only; marbre does not replace it",
        ));
    }
    let tmp = temporary_for(path)?;
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(tmp.clone());
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)?;
        // The rename is an entry of the folder: without this, a power cut
        // may lose it although the file's bytes are on disk.
        std::fs::File::open(dir)?.sync_all()
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .retain(|p| *p != tmp);
    result
}

/// Writes two files as one: `first` and `second` (each `(path, bytes)`)
/// both get their new bytes, or, if anything fails, both keep what they
/// had (a baked image and its sidecar must never disagree). Both
/// temporaries are written and flushed before either is renamed; the old
/// `first` is kept as a hard link until `second` is in place, and put back
/// if it cannot be.
pub fn write_atomic_pair(first: (&Path, &[u8]), second: (&Path, &[u8])) -> std::io::Result<()> {
    if cfg!(target_arch = "wasm32") {
        write_atomic(first.0, first.1)?;
        return write_atomic(second.0, second.1);
    }
    let (a, b) = (write_target(first.0)?, write_target(second.0)?);
    for path in [&a, &b] {
        check_writable(path)?;
    }
    let (tmp_a, tmp_b) = (temporary_for(&a)?, temporary_for(&b)?);
    let backup = folder_of(&a).join(format!(
        ".{}.{}.old",
        a.file_name().unwrap_or_default().to_string_lossy(),
        std::process::id()
    ));
    PENDING.lock().unwrap_or_else(|e| e.into_inner()).extend([
        tmp_a.clone(),
        tmp_b.clone(),
        backup.clone(),
    ]);
    let had_a = a.exists();
    let result = (|| {
        for (tmp, bytes) in [(&tmp_a, first.1), (&tmp_b, second.1)] {
            let mut f = std::fs::File::create(tmp)?;
            f.write_all(bytes)?;
            f.sync_all()?;
        }
        if had_a {
            std::fs::hard_link(&a, &backup)?;
        }
        std::fs::rename(&tmp_a, &a)?;
        if let Err(e) = std::fs::rename(&tmp_b, &b) {
            let _ = if had_a {
                std::fs::rename(&backup, &a)
            } else {
                std::fs::remove_file(&a)
            };
            return Err(e);
        }
        for dir in [folder_of(&a), folder_of(&b)] {
            std::fs::File::open(dir)?.sync_all()?;
        }
        Ok(())
    })();
    for leftover in [&tmp_a, &tmp_b, &backup] {
        let _ = std::fs::remove_file(leftover);
    }
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .retain(|p| ![&tmp_a, &tmp_b, &backup].contains(&p));
    result
}

/// The file a write to `path` replaces: `path`, or where the link at `path`
/// leads (followed to its end, relative links from their own folder).
pub fn write_target(path: &Path) -> std::io::Result<PathBuf> {
    let mut target = path.to_owned();
    // Links to links are followed; a loop ends in the kernel's own limit
    // when the file is opened, so a bound here only keeps this loop finite.
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = std::fs::read_link(&target)?;
                target = folder_of(&target).join(link);
            }
            _ => return Ok(target),
        }
    }
    Err(std::io::Error::other("too many levels of links"))
}

/// The folder `path` is in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// The temporary sibling `path` is written to first: hidden, and named by
/// the process, so two processes saving the same file never share one.
fn temporary_for(path: &Path) -> std::io::Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::other("path has no file name"))?;
    Ok(folder_of(path).join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Removes the temporaries being written now: what a command does when
/// SIGINT or SIGTERM stops it, so that no `.<name>.<pid>.tmp` is left.
/// Returns how many it removed.
pub fn remove_pending_temporaries() -> usize {
    let pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    pending
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

/// Whether a file could be written at `path` now, checked by creating and
/// removing a temporary beside it: the folder exists and is writable (not
/// on a read-only filesystem), `path` is not a folder, and a file there is
/// not read-only. What a render checks before it traces.
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    let target = write_target(path)?;
    if target.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "it is a folder",
        ));
    }
    if let Ok(meta) = std::fs::metadata(&target)
        && meta.permissions().readonly()
    {
        return Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "the file is read-only; marbre does not replace it",
        ));
    }
    let probe = temporary_for(&target)?;
    std::fs::File::create(&probe)?;
    std::fs::remove_file(&probe)
}

#[cfg(test)]
pub(crate) mod test_support {
    /// A file at `path` holding `bytes`, marked read-only (which root,
    /// running the tests in CI, could still write: the saves check the
    /// mark itself).
    pub fn read_only_file(path: &std::path::Path, bytes: &[u8]) {
        std::fs::write(path, bytes).unwrap();
        let mut permissions = std::fs::metadata(path).unwrap().permissions();
        permissions.set_readonly(true);
        std::fs::set_permissions(path, permissions).unwrap();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The list of pending temporaries is the process's: other tests'
    /// writes may be in it, so only this test's folder is looked for
    /// (removing them all, as SIGTERM does, would delete another test's
    /// temporary in the middle of its write).
    #[test]
    fn replaces_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(leftovers.len(), 1);
        let pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        assert!(
            !pending.iter().any(|p| p.starts_with(dir.path())),
            "still listed after: {pending:?}"
        );
    }

    /// A link (relative, through a second link) is written through: its
    /// target gets the bytes, the links stay links.
    #[test]
    fn a_link_is_written_through() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("real")).unwrap();
        let target = dir.path().join("real/out.png");
        std::fs::write(&target, b"old").unwrap();
        let first = dir.path().join("first.png");
        std::os::unix::fs::symlink("real/out.png", &first).unwrap();
        let second = dir.path().join("second.png");
        std::os::unix::fs::symlink("first.png", &second).unwrap();
        write_atomic(&second, b"new").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert!(second.symlink_metadata().unwrap().file_type().is_symlink());
        assert!(first.symlink_metadata().unwrap().file_type().is_symlink());
    }

    /// A pair is written whole, or not at all: with the second file
    /// read-only, neither changes (a bake's image never goes beside a
    /// sidecar that describes another).
    #[test]
    fn a_pair_is_written_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let (image, sidecar) = (
            dir.path().join("a.png"),
            dir.path().join("a.png.mapping.ron"),
        );
        write_atomic_pair((&image, b"image 1"), (&sidecar, b"size: 32")).unwrap();
        write_atomic_pair((&image, b"image 2"), (&sidecar, b"size: 64")).unwrap();
        assert_eq!(std::fs::read(&image).unwrap(), b"image 2");
        assert_eq!(std::fs::read(&sidecar).unwrap(), b"size: 64");
        test_support::read_only_file(&sidecar, b"size: 64");
        assert!(write_atomic_pair((&image, b"image 3"), (&sidecar, b"size: 16")).is_err());
        assert_eq!(std::fs::read(&image).unwrap(), b"image 2");
        assert_eq!(std::fs::read(&sidecar).unwrap(), b"size: 64");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            2,
            "no leftovers"
        );
    }

    /// A read-only file is refused, and a folder as the output, before
    /// anything is written; a writable place passes the check.
    #[test]
    fn a_read_only_file_and_a_folder_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("kept.exr");
        test_support::read_only_file(&path, b"old");
        assert!(
            check_writable(&path)
                .unwrap_err()
                .to_string()
                .contains("read-only")
        );
        assert!(write_atomic(&path, b"new").is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(
            check_writable(dir.path()).unwrap_err().to_string(),
            "it is a folder"
        );
        check_writable(&dir.path().join("new.png")).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
