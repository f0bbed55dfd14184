//! The viewer's settings in a web page: the browser's local storage holds
//! what a desktop keeps in `~/.config/marbre` (`settings.ron`: recent
//! files, window size, the kernel per adapter). The viewer reads and
//! writes them as files among the page's files, under [`FOLDER`]; this
//! copies them in at start and out after each save.

use marbre_core::page_files;
use marbre_core::viewer_files::Settings;
use std::path::{Path, PathBuf};

/// The settings folder among the page's files.
pub const FOLDER: &str = "local-storage";

/// The key a file's text is stored under: `marbre/<name>`.
fn key(name: &str) -> String {
    format!("marbre/{name}")
}

fn storage() -> Option<web_sys::Storage> {
    web_sys::window()?.local_storage().ok()?
}

/// Puts the stored settings among the page's files; returns their folder.
pub fn restore() -> PathBuf {
    let folder = PathBuf::from(FOLDER);
    let file = Settings::file(&folder);
    let name = file.file_name().map(|n| n.to_string_lossy().into_owned());
    if let (Some(storage), Some(name)) = (storage(), name)
        && let Ok(Some(text)) = storage.get_item(&key(&name))
    {
        page_files::insert(&file, text.into_bytes());
    }
    folder
}

/// Copies the settings file of `dir` to local storage. A browser that
/// refuses (private mode, quota) only loses them for the next visit.
pub fn store(dir: &Path) {
    let file = Settings::file(dir);
    let (Some(storage), Some(name), Ok(bytes)) = (
        storage(),
        file.file_name().map(|n| n.to_string_lossy().into_owned()),
        page_files::read(&file),
    ) else {
        return;
    };
    if let Err(e) = storage.set_item(&key(&name), &String::from_utf8_lossy(&bytes)) {
        log::warn!("cannot keep the settings in local storage: {e:?}");
    }
}
