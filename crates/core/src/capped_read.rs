//! Reading an input file whole, with a size cap suited to its kind, and
//! only if it is a regular file.
//!
//! `std::fs::read` reads until the file ends: `/dev/zero` as a preset grew
//! marbre to 24 GB before the kernel killed it, and a FIFO blocks forever
//! waiting for a writer. Every file marbre reads whole goes through
//! [`read_capped`]: anything but a regular file (after following links) is
//! refused before it is opened, and a file larger than its kind's cap is
//! refused by its size before a byte is read (and, should it grow while
//! read, after `cap + 1` bytes). The error is an `io::Error`, so each
//! format's own "cannot read the file" message names the path and says why.

use std::io::{self, Read};
use std::path::Path;

/// What a file is read as, and the most bytes that kind may have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileKind {
    /// What the file is, in messages ("a preset").
    pub name: &'static str,
    pub max_bytes: u64,
}

const MIB: u64 = 1 << 20;

/// A preset's RON text: the largest shipped is under 100 KB, and a TX
/// text inside one is capped on its own.
pub const PRESET: FileKind = FileKind {
    name: "a preset",
    max_bytes: 64 * MIB,
};
/// An OBJ mesh: a 10-million-triangle scan is about 700 MB of text.
pub const OBJ: FileKind = FileKind {
    name: "an OBJ file",
    max_bytes: 2048 * MIB,
};
/// An MTL material library.
pub const MTL: FileKind = FileKind {
    name: "an MTL file",
    max_bytes: 64 * MIB,
};
/// An image or environment map: a 16k × 8k float EXR without compression
/// is 1.5 GiB (RGB, f32).
pub const IMAGE: FileKind = FileKind {
    name: "an image",
    max_bytes: 2048 * MIB,
};
/// A TX texture text (the report's grammar) or a gallery index.
pub const TX: FileKind = FileKind {
    name: "a TX text",
    max_bytes: 16 * MIB,
};
/// The viewer's settings, a recovery note: a few hundred bytes.
pub const SMALL_TEXT: FileKind = FileKind {
    name: "a settings file",
    max_bytes: MIB,
};

/// The bytes of the file at `path`, if it is a regular file of at most
/// `kind.max_bytes`.
///
/// In a web page (wasm32) the file comes from the page's own files
/// ([`crate::page_files`]), under the same cap.
pub fn read_capped(path: &Path, kind: FileKind) -> io::Result<Vec<u8>> {
    if cfg!(target_arch = "wasm32") {
        let bytes = crate::page_files::read(path)?;
        if bytes.len() as u64 > kind.max_bytes {
            return Err(too_large(kind));
        }
        return Ok(bytes.to_vec());
    }
    check_regular(&std::fs::metadata(path)?, kind)?;
    let file = std::fs::File::open(path)?;
    // The file behind the path may have been swapped since: check again
    // what was opened.
    let size = check_regular(&file.metadata()?, kind)?;
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(kind.max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > kind.max_bytes {
        return Err(too_large(kind));
    }
    Ok(bytes)
}

/// Whether `path` names a file marbre can read: a regular file on disk,
/// or in a web page one of the page's files (where `std::fs` knows none).
pub fn is_file(path: &Path) -> bool {
    if cfg!(target_arch = "wasm32") {
        return crate::page_files::contains(path);
    }
    path.is_file()
}

/// [`read_capped`] as UTF-8 text.
pub fn read_capped_to_string(path: &Path, kind: FileKind) -> io::Result<String> {
    String::from_utf8(read_capped(path, kind)?).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

/// The file's size, if `meta` is a regular file within the cap.
fn check_regular(meta: &std::fs::Metadata, kind: FileKind) -> io::Result<u64> {
    let file_type = meta.file_type();
    if !file_type.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "not a regular file (it is {}); {} must be a file",
                describe(&file_type),
                kind.name
            ),
        ));
    }
    if meta.len() > kind.max_bytes {
        return Err(too_large(kind));
    }
    Ok(meta.len())
}

fn too_large(kind: FileKind) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!(
            "larger than the {} MiB {} may have",
            kind.max_bytes / MIB,
            kind.name
        ),
    )
}

/// What a non-regular file is, in words.
fn describe(file_type: &std::fs::FileType) -> &'static str {
    if file_type.is_dir() {
        "a folder"
    } else {
        special_file(file_type).unwrap_or("not a file")
    }
}

/// The kinds of special file Unix has.
#[cfg(unix)]
fn special_file(file_type: &std::fs::FileType) -> Option<&'static str> {
    use std::os::unix::fs::FileTypeExt;
    if file_type.is_fifo() {
        Some("a FIFO")
    } else if file_type.is_char_device() || file_type.is_block_device() {
        Some("a device")
    } else if file_type.is_socket() {
        Some("a socket")
    } else {
        None
    }
}

/// Elsewhere (Windows, the browser's wasm32) std names none.
#[cfg(not(unix))]
fn special_file(_: &std::fs::FileType) -> Option<&'static str> {
    None
}

#[cfg(test)]
pub(crate) mod test_support {
    use std::path::Path;
    use std::sync::mpsc;
    use std::time::Duration;

    /// A FIFO at `path` (made by `mkfifo`, which std lacks).
    pub fn make_fifo(path: &Path) {
        let status = std::process::Command::new("mkfifo")
            .arg(path)
            .status()
            .expect("mkfifo runs");
        assert!(status.success(), "mkfifo {}", path.display());
    }

    /// `f`'s result, or a failure if it has not returned in 10 s (a read
    /// that blocks on a FIFO would hang the test run otherwise).
    pub fn within_10_s<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
        let (send, receive) = mpsc::channel();
        std::thread::spawn(move || {
            let _ = send.send(f());
        });
        receive
            .recv_timeout(Duration::from_secs(10))
            .expect("still blocked after 10 s")
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::{make_fifo, within_10_s};
    use super::*;

    #[test]
    fn a_device_a_fifo_and_a_folder_are_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.ron");
        make_fifo(&fifo);
        let refused = |path: std::path::PathBuf| {
            within_10_s(move || read_capped(&path, PRESET).unwrap_err().to_string())
        };
        assert_eq!(
            refused("/dev/zero".into()),
            "not a regular file (it is a device); a preset must be a file"
        );
        assert_eq!(
            refused(fifo),
            "not a regular file (it is a FIFO); a preset must be a file"
        );
        assert_eq!(
            refused(dir.path().to_owned()),
            "not a regular file (it is a folder); a preset must be a file"
        );
    }

    /// A file over the cap is refused by its size: a sparse file of
    /// cap + 1 bytes (no disk used) is not read.
    #[test]
    fn a_file_over_its_cap_is_refused_and_one_at_the_cap_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.ron");
        let file = std::fs::File::create(&path).unwrap();
        file.set_len(SMALL_TEXT.max_bytes + 1).unwrap();
        assert_eq!(
            read_capped(&path, SMALL_TEXT).unwrap_err().to_string(),
            "larger than the 1 MiB a settings file may have"
        );
        file.set_len(SMALL_TEXT.max_bytes).unwrap();
        assert_eq!(
            read_capped(&path, SMALL_TEXT).unwrap().len() as u64,
            SMALL_TEXT.max_bytes
        );
    }

    #[test]
    fn a_link_to_a_file_is_read_and_text_must_be_utf8() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.tx");
        std::fs::write(&path, "UNI FTX").unwrap();
        let link = dir.path().join("b.tx");
        std::os::unix::fs::symlink(&path, &link).unwrap();
        assert_eq!(read_capped_to_string(&link, TX).unwrap(), "UNI FTX");
        std::fs::write(&path, b"UNI \xff").unwrap();
        assert_eq!(
            read_capped_to_string(&path, TX).unwrap_err().to_string(),
            "not UTF-8 text (byte 4)"
        );
    }
}
