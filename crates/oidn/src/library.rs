//! Finding and opening OIDN's library, in this order:
//!
//! 1. `MARBRE_OIDN_DIR`, when set, and only there: an OIDN release folder
//!    (its `lib/`) or the folder of the library itself. Pointing it at an
//!    empty folder is how a user (and the tests) turn OIDN off.
//! 2. The system's library path (`ld.so`: `LD_LIBRARY_PATH`, the
//!    distribution's package, Homebrew's).
//! 3. The `pyoidn` wheel of `pip install pyoidn`, which carries OIDN's
//!    libraries in `pyoidn/oidn/lib/`, in the site folders `python3`
//!    reports (asked without importing pyoidn, which needs NumPy).

use crate::api::Api;
use std::ffi::OsStr;
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, OnceLock};

/// The variable naming OIDN's folder.
pub const DIR_VARIABLE: &str = "MARBRE_OIDN_DIR";

/// The library's file name, as the platform's loader spells OIDN 2's.
#[cfg(not(any(target_os = "macos", target_os = "windows")))]
pub const FILE_NAME: &str = "libOpenImageDenoise.so.2";
#[cfg(target_os = "macos")]
pub const FILE_NAME: &str = "libOpenImageDenoise.2.dylib";
#[cfg(target_os = "windows")]
pub const FILE_NAME: &str = "OpenImageDenoise.dll";

/// OIDN's library, opened, with its functions.
pub struct Library {
    pub(crate) api: Api,
    /// Where it was opened from (a file, or the bare name the system's
    /// loader resolved).
    pub origin: PathBuf,
    /// Kept open for as long as `api`'s pointers are used.
    #[cfg(not(target_arch = "wasm32"))]
    _library: libloading::Library,
}

impl fmt::Debug for Library {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Library")
            .field("origin", &self.origin)
            .finish()
    }
}

/// Why OIDN was not opened: each place looked at, and what was there.
#[derive(Debug, Clone, PartialEq)]
pub struct NotFound {
    pub tried: Vec<String>,
}

impl fmt::Display for NotFound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "OIDN's library ({FILE_NAME}) was not found: ")?;
        write!(f, "{}", self.tried.join("; "))?;
        write!(
            f,
            " (install it with `python3 -m pip install pyoidn`, or set {DIR_VARIABLE} to \
             an OIDN 2 release folder)"
        )
    }
}

impl std::error::Error for NotFound {}

impl Library {
    /// The process's OIDN, looked for once (from the environment of that
    /// moment) and kept: every denoise after the first costs no search.
    pub fn shared() -> Result<Arc<Library>, NotFound> {
        static SHARED: OnceLock<Result<Arc<Library>, NotFound>> = OnceLock::new();
        SHARED
            .get_or_init(|| Self::find(std::env::var_os(DIR_VARIABLE).as_deref()).map(Arc::new))
            .clone()
    }

    /// Looks for OIDN: only in `dir` when given (the variable's value),
    /// else on the system's library path, then in pyoidn's wheel.
    pub fn find(dir: Option<&OsStr>) -> Result<Self, NotFound> {
        let mut tried = Vec::new();
        if let Some(dir) = dir {
            let dir = Path::new(dir);
            for candidate in [dir.join("lib").join(FILE_NAME), dir.join(FILE_NAME)] {
                match Self::open(&candidate) {
                    Ok(lib) => return Ok(lib),
                    Err(why) => tried.push(why),
                }
            }
            tried.insert(0, format!("{DIR_VARIABLE} is {}", dir.display()));
            return Err(NotFound { tried });
        }
        match Self::open(Path::new(FILE_NAME)) {
            Ok(lib) => return Ok(lib),
            Err(why) => tried.push(format!("the system's library path: {why}")),
        }
        let sites = python_site_folders();
        if sites.is_empty() {
            tried.push("pyoidn: python3 reported no site folders".to_owned());
        }
        for site in sites {
            let candidate = site.join("pyoidn").join("oidn").join("lib").join(FILE_NAME);
            if !candidate.exists() {
                tried.push(format!("pyoidn: no {}", candidate.display()));
                continue;
            }
            match Self::open(&candidate) {
                Ok(lib) => return Ok(lib),
                Err(why) => tried.push(why),
            }
        }
        Err(NotFound { tried })
    }

    /// In a web page (wasm32) nothing opens: there is no native loader.
    #[cfg(target_arch = "wasm32")]
    fn open(path: &Path) -> Result<Self, String> {
        Err(format!(
            "{}: a web page cannot open native libraries",
            path.display()
        ))
    }

    /// Opens the library at `path` (or, for a bare name, wherever the
    /// system's loader finds it) and reads its functions.
    #[cfg(not(target_arch = "wasm32"))]
    fn open(path: &Path) -> Result<Self, String> {
        // SAFETY: opening runs the library's initialisers; OIDN's only set
        // up its C++ runtime. A file of that name that is not OIDN 2 fails
        // `Api::read` below.
        // The loader's message names the file.
        let library = unsafe { libloading::Library::new(path) }.map_err(|e| e.to_string())?;
        // SAFETY: a library named libOpenImageDenoise.so.2 exporting these
        // symbols is OIDN 2, whose signatures `Api` declares.
        let api = unsafe { Api::read(&library) }.map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(Self {
            api,
            origin: path.to_owned(),
            _library: library,
        })
    }
}

/// The site-packages folders of `python3` (system, user), where
/// `pip install pyoidn` puts the wheel; none when there is no `python3`.
fn python_site_folders() -> Vec<PathBuf> {
    let script = "import site, sysconfig\n\
                  p = sysconfig.get_paths()\n\
                  print(p['purelib']); print(p['platlib']); print(site.getusersitepackages())";
    let Ok(out) = Command::new("python3").args(["-c", script]).output() else {
        return Vec::new();
    };
    let mut folders: Vec<PathBuf> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(PathBuf::from)
        .collect();
    folders.dedup();
    folders
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An empty folder named by the variable is the only place looked at:
    /// the reason names it and both file names tried there.
    #[test]
    fn an_empty_folder_finds_nothing_and_says_where_it_looked() {
        let empty = tempfile::tempdir().unwrap();
        let why = Library::find(Some(empty.path().as_os_str())).unwrap_err();
        let text = why.to_string();
        assert!(text.contains(DIR_VARIABLE), "{text}");
        assert!(text.contains(&empty.path().display().to_string()), "{text}");
        assert_eq!(why.tried.len(), 3, "{why:?}");
        assert!(text.contains("pip install pyoidn"), "{text}");
    }

    /// A file of the right name that is not OIDN is refused, not called.
    #[test]
    fn a_file_that_is_not_oidn_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join(FILE_NAME), b"not a library").unwrap();
        let why = Library::find(Some(dir.path().as_os_str())).unwrap_err();
        assert!(why.tried.iter().any(|t| t.contains(FILE_NAME)), "{why:?}");
    }
}
