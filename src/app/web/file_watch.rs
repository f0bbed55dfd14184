//! Hot reload in a web page: there is nothing to watch. A page's files
//! change only when the user opens or drops one, and the viewer loads
//! that file then; the desktop's watcher is `app/file_watch.rs`.

use marbre_core::lexical_path::normalize;
use std::path::{Path, PathBuf};

/// The desktop watcher's stand-in: it watches nothing and reports nothing.
pub struct FileWatch;

impl FileWatch {
    pub fn new() -> anyhow::Result<Self> {
        Ok(Self)
    }

    pub fn watch_folder_of(&mut self, _file: &Path) -> anyhow::Result<()> {
        Ok(())
    }

    pub fn watch_tree(&mut self, dir: &Path) -> anyhow::Result<()> {
        anyhow::bail!(
            "a web page cannot watch {} (the source tree is not in the page)",
            dir.display()
        )
    }

    pub fn changed(&self) -> Vec<PathBuf> {
        Vec::new()
    }
}

/// Whether two of the page's paths name the same file.
pub fn is_same_file(changed: &Path, file: &Path) -> bool {
    normalize(changed) == normalize(file)
}
