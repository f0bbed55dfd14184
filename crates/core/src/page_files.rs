//! The files a web page holds: in a browser (wasm32) there is no file
//! system, so every file marbre reads there (the shipped presets, env maps
//! and images the page fetched beside itself, a file the user dropped or
//! picked) is put here first, under the path a preset names it by, and
//! [`crate::capped_read`] reads from here instead of `std::fs`. A save
//! ([`crate::atomic_write`]) lands here too; the page then offers the bytes
//! as a download (issue 34).
//!
//! Paths are compared lexically normalised (`presets/../envmaps/sky.exr`
//! is `envmaps/sky.exr`), as a relative path resolves against the page's
//! address. The store exists on every target so that its rules are tested
//! natively; only wasm32 builds route reads and writes through it.

use crate::lexical_path::normalize;
use std::collections::BTreeMap;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Every file the page holds, by normalised path. A page has one thread;
/// the lock only keeps the native tests honest.
static FILES: Mutex<BTreeMap<PathBuf, Arc<[u8]>>> = Mutex::new(BTreeMap::new());

fn key(path: &Path) -> PathBuf {
    normalize(path)
}

/// Puts `bytes` at `path`, replacing what was there.
pub fn insert(path: &Path, bytes: impl Into<Arc<[u8]>>) {
    FILES
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key(path), bytes.into());
}

/// The bytes at `path`, or NotFound naming what the page holds nearby.
pub fn read(path: &Path) -> io::Result<Arc<[u8]>> {
    let files = FILES.lock().unwrap_or_else(|e| e.into_inner());
    files.get(&key(path)).cloned().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::NotFound,
            "the page holds no such file (open it with the file button or drop it on the page)",
        )
    })
}

/// Forgets the file at `path` (a download delivered: the page's memory
/// is all it has).
pub fn remove(path: &Path) {
    FILES
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .remove(&key(path));
}

/// Whether the page holds a file at `path`.
pub fn contains(path: &Path) -> bool {
    FILES
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .contains_key(&key(path))
}

/// The paths the page holds under `folder` (every path for `.`), sorted.
pub fn list(folder: &Path) -> Vec<PathBuf> {
    let folder = key(folder);
    let everything = folder == Path::new(".");
    FILES
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .keys()
        .filter(|p| everything || p.starts_with(&folder))
        .cloned()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file put under one spelling of its path is read under another
    /// that names the same place, and a missing file says how to add it.
    #[test]
    fn paths_that_name_the_same_file_read_the_same_bytes() {
        insert(
            Path::new("page-test/presets/../envmaps/sky.exr"),
            &b"sky"[..],
        );
        assert_eq!(
            &*read(Path::new("./page-test/envmaps/sky.exr")).unwrap(),
            b"sky"
        );
        assert!(contains(Path::new("page-test/envmaps/./sky.exr")));
        let missing = read(Path::new("page-test/envmaps/none.exr")).unwrap_err();
        assert_eq!(missing.kind(), io::ErrorKind::NotFound);
        assert!(missing.to_string().contains("drop it on the page"));
        assert_eq!(
            list(Path::new("page-test/envmaps")),
            vec![PathBuf::from("page-test/envmaps/sky.exr")]
        );
        insert(Path::new("page-test/envmaps/sky.exr"), &b"new sky"[..]);
        assert_eq!(
            &*read(Path::new("page-test/envmaps/sky.exr")).unwrap(),
            b"new sky"
        );
        remove(Path::new("page-test/presets/../envmaps/sky.exr"));
        assert!(!contains(Path::new("page-test/envmaps/sky.exr")));
    }
}
