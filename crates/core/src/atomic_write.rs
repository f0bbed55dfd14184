//! Saves that never leave a half-written file behind, nor replace what
//! they should not.
//!
//! A file is written to a temporary sibling, flushed, renamed over its
//! name, and the folder is synced so the rename itself survives a power
//! cut. A link is written through (its target is replaced, the link
//! stays); a read-only file is refused rather than replaced by the rename
//! (which Unix allows whenever the folder is writable), and so is anything
//! that is not a regular file: the rename would turn a device node
//! (`/dev/null`, `/dev/full`), a FIFO or a socket into a PNG.
//!
//! The temporaries being written are listed, so that a command interrupted
//! by SIGINT or SIGTERM removes them ([`remove_pending_temporaries`]); one
//! left by a process killed outright (SIGKILL, a power cut) is removed by
//! the next save into its folder ([`remove_stale_temporaries`]).

use std::collections::BTreeSet;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporaries being written now, by any thread.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The folders this process has cleaned of stale temporaries: each is read
/// once, so a sequence of 100 000 frames into one folder does not read it
/// 100 000 times.
static CLEANED: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());

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
    write_atomic_with(path, |temporary| {
        let mut f = std::fs::OpenOptions::new().write(true).open(temporary)?;
        f.write_all(bytes)
    })
}

/// [`write_atomic`] for bytes another program writes: `write` is given the
/// temporary's path (created empty, listed, and locked as every temporary
/// is) and fills it, as ffmpeg writes a video; the temporary is then
/// flushed and renamed over `path`. An error from `write` leaves `path` as
/// it was and no temporary.
pub fn write_atomic_with<E: From<std::io::Error>>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    if cfg!(target_arch = "wasm32") {
        return Err(std::io::Error::new(
            std::io::ErrorKind::Unsupported,
            "a web page's files are written whole, not by another program",
        )
        .into());
    }
    let path = &write_target(path)?;
    let dir = folder_of(path);
    std::fs::create_dir_all(dir)?;
    check_replaceable(path)?;
    remove_stale_temporaries(dir);
    let (tmp, file) = create_temporary(path)?;
    let result = write(&tmp).and_then(|()| {
        file.sync_all()?;
        std::fs::rename(&tmp, path)?;
        // The rename is an entry of the folder: without this, a power cut
        // may lose it although the file's bytes are on disk.
        File::open(dir)?.sync_all()?;
        Ok(())
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    unlist(&[&tmp]);
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
        remove_stale_temporaries(folder_of(path));
    }
    let backup = folder_of(&a).join(format!(
        ".{}.{}.old",
        a.file_name().unwrap_or_default().to_string_lossy(),
        std::process::id()
    ));
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(backup.clone());
    let had_a = a.exists();
    let mut temporaries = Vec::new();
    let result = (|| {
        for (path, bytes) in [(&a, first.1), (&b, second.1)] {
            let (tmp, mut f) = create_temporary(path)?;
            temporaries.push(tmp);
            f.write_all(bytes)?;
            f.sync_all()?;
        }
        if had_a {
            std::fs::hard_link(&a, &backup)?;
        }
        std::fs::rename(&temporaries[0], &a)?;
        if let Err(e) = std::fs::rename(&temporaries[1], &b) {
            let _ = if had_a {
                std::fs::rename(&backup, &a)
            } else {
                std::fs::remove_file(&a)
            };
            return Err(e);
        }
        for dir in [folder_of(&a), folder_of(&b)] {
            File::open(dir)?.sync_all()?;
        }
        Ok(())
    })();
    for leftover in temporaries.iter().chain([&backup]) {
        let _ = std::fs::remove_file(leftover);
    }
    let listed: Vec<&PathBuf> = temporaries.iter().chain([&backup]).collect();
    unlist(&listed);
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

/// The pid in a temporary's name (`.<name>.<pid>.tmp`), if it is one.
fn temporary_pid(name: &str) -> Option<u32> {
    let inner = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (file, pid) = inner.rsplit_once('.')?;
    if file.is_empty() || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// The temporary for `path`, created empty and listed (before it exists,
/// so that a signal in between still removes it), and locked until the
/// returned file is closed: the lock tells [`remove_stale_temporaries`] in
/// another process, perhaps on another machine sharing the folder (a farm's
/// nodes), whose pids it cannot see, that this one is being written.
fn create_temporary(path: &Path) -> std::io::Result<(PathBuf, File)> {
    let tmp = temporary_for(path)?;
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(tmp.clone());
    match File::create(&tmp).and_then(|f| f.lock().map(|()| f)) {
        Ok(f) => Ok((tmp, f)),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            unlist(&[&tmp]);
            Err(e)
        }
    }
}

/// Takes `done` off the list of pending temporaries.
fn unlist(done: &[&PathBuf]) {
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .retain(|p| !done.contains(&p));
}

/// Removes the temporaries in `dir` that a killed save left: named
/// `.<name>.<pid>.tmp`, a regular file, its pid not a live process here,
/// and not locked (a save on another machine sharing the folder holds
/// its lock). Read once a process for each folder; where this system has
/// no `/proc` to tell live processes by, nothing is removed. What cannot
/// be read or removed is left as it is: the save goes on regardless.
pub fn remove_stale_temporaries(dir: &Path) {
    if !Path::new("/proc/self").exists()
        || !CLEANED
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(dir.to_owned())
    {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let Some(pid) = entry.file_name().to_str().and_then(temporary_pid) else {
            continue;
        };
        let alive = pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists();
        // The entry's own type, links not followed: opening a FIFO would
        // wait for a writer.
        if alive || !entry.file_type().is_ok_and(|t| t.is_file()) {
            continue;
        }
        let path = entry.path();
        // Opened to write: an NFS lock (flock emulated by a byte-range
        // lock) is only taken on a file open for writing.
        let Ok(file) = std::fs::OpenOptions::new().write(true).open(&path) else {
            continue;
        };
        if file.try_lock().is_ok() {
            let _ = std::fs::remove_file(&path);
        }
    }
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

/// Fails unless a save may replace `path` (after links): it does not
/// exist yet, or it is a regular file that is not read-only. A folder, a
/// device node, a FIFO or a socket is named as what it is. Cheap (one
/// `stat`): what a sequence checks for each of its frames before tracing.
pub fn check_replaceable(path: &Path) -> std::io::Result<()> {
    let Ok(meta) = std::fs::metadata(write_target(path)?) else {
        return Ok(());
    };
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "it is a folder",
        ));
    }
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "it is {}, not a regular file; marbre replaces only regular files",
                kind_of(&meta.file_type())
            ),
        ));
    }
    if meta.permissions().readonly() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "the file is read-only; marbre does not replace it",
        ));
    }
    Ok(())
}

/// What a file that is neither a regular file nor a folder is, in words.
fn kind_of(file_type: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_char_device() {
            return "a character device";
        }
        if file_type.is_block_device() {
            return "a block device";
        }
        if file_type.is_fifo() {
            return "a FIFO";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    let _ = file_type;
    "a special file"
}

/// Whether a file could be written at `path` now: it may be replaced
/// ([`check_replaceable`]: absent, or a regular file that is not
/// read-only), and the folder exists and is writable (not on a read-only
/// filesystem), checked by creating and removing a temporary beside it.
/// What every command checks of its outputs before it works.
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    check_replaceable(path)?;
    let probe = temporary_for(&write_target(path)?)?;
    File::create(&probe)?;
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

    /// A FIFO at `path`, made by mkfifo.
    fn fifo(path: &Path) {
        let made = std::process::Command::new("mkfifo")
            .arg(path)
            .status()
            .unwrap();
        assert!(made.success());
    }

    fn is_fifo(path: &Path) -> bool {
        use std::os::unix::fs::FileTypeExt;
        std::fs::metadata(path).unwrap().file_type().is_fifo()
    }

    /// A FIFO, or a link to one, is refused by the check and by every
    /// writer, named as what it is, and stays a FIFO (the rename used to
    /// replace it, as it replaced /dev/full, with the PNG). Tested on a
    /// FIFO, not on a device: CI runs as root, and a failure would
    /// destroy /dev/null.
    #[test]
    fn a_fifo_or_a_link_to_one_is_refused_and_stays() {
        let dir = tempfile::tempdir().unwrap();
        let pipe = dir.path().join("x.png");
        fifo(&pipe);
        let link = dir.path().join("link.png");
        std::os::unix::fs::symlink("x.png", &link).unwrap();
        let expected = "it is a FIFO, not a regular file; marbre replaces only regular files";
        for path in [&pipe, &link] {
            assert_eq!(check_writable(path).unwrap_err().to_string(), expected);
            assert_eq!(check_replaceable(path).unwrap_err().to_string(), expected);
            assert_eq!(
                write_atomic(path, b"png").unwrap_err().to_string(),
                expected
            );
            let with = write_atomic_with(path, |_| -> std::io::Result<()> {
                panic!("nothing is written to a FIFO's temporary")
            });
            assert_eq!(with.unwrap_err().to_string(), expected);
            let sidecar = dir.path().join("x.png.mapping.ron");
            assert!(write_atomic_pair((path, b"png"), (&sidecar, b"ron")).is_err());
            assert!(!sidecar.exists());
            assert!(is_fifo(&pipe));
        }
        assert!(link.symlink_metadata().unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    /// A pid that is not a live process: a child's, once it has been
    /// waited for.
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        pid
    }

    /// A temporary left by a killed save (its pid dead) goes at the next
    /// save into its folder; one of a live process, one locked by a save
    /// elsewhere, and files merely like one stay.
    #[test]
    fn a_dead_saves_temporary_is_removed_by_the_next_save() {
        let dir = tempfile::tempdir().unwrap();
        let stale = dir.path().join(format!(".frame.png.{}.tmp", dead_pid()));
        std::fs::write(&stale, b"half a PNG").unwrap();
        let mut live_child = std::process::Command::new("sleep")
            .arg("600")
            .spawn()
            .unwrap();
        let live = dir
            .path()
            .join(format!(".other.png.{}.tmp", live_child.id()));
        std::fs::write(&live, b"being written").unwrap();
        let own = dir
            .path()
            .join(format!(".mine.png.{}.tmp", std::process::id()));
        std::fs::write(&own, b"this process's").unwrap();
        // A save on another machine: a pid dead here, its lock held.
        let elsewhere = dir.path().join(format!(".far.png.{}.tmp", dead_pid()));
        let held = File::create(&elsewhere).unwrap();
        held.lock().unwrap();
        let alike = ["notes.1.tmp", ".x.tmp", ".x.12a.tmp", "..7.tmp"];
        for name in alike {
            std::fs::write(dir.path().join(name), b"a user's").unwrap();
        }
        write_atomic(&dir.path().join("frame.png"), b"png").unwrap();
        live_child.kill().unwrap();
        live_child.wait().unwrap();
        assert!(!stale.exists(), "the dead save's temporary is still there");
        for kept in [&live, &own, &elsewhere] {
            assert!(kept.exists(), "{} was removed", kept.display());
        }
        for name in alike {
            assert!(dir.path().join(name).exists(), "{name} was removed");
        }
        assert_eq!(std::fs::read(dir.path().join("frame.png")).unwrap(), b"png");
    }

    #[test]
    fn a_temporarys_pid_is_read_from_its_name() {
        assert_eq!(temporary_pid(".out.png.1234.tmp"), Some(1234));
        assert_eq!(temporary_pid(".a.5.tmp.77.tmp"), Some(77));
        for not in [
            "out.png.1.tmp",
            ".out.png.tmp",
            ".out.png.-1.tmp",
            "..1.tmp",
        ] {
            assert_eq!(temporary_pid(not), None, "{not}");
        }
    }
}
