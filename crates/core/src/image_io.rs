//! Writing rendered images, atomically.
//!
//! A render's output folder must exist (`check_output_folder`): a typo in
//! a path is named before any rendering rather than made into folders,
//! and a path through a file names the file.

use crate::atomic_write::write_atomic;
use anyhow::{Result, bail};
use std::io::ErrorKind;
use std::path::Path;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Tone-mapped 8-bit sRGB.
    Png,
    /// Linear radiance, 32-bit float RGBA.
    Exr,
}

impl ImageFormat {
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ => bail!("{}: the output must end in .png or .exr", path.display()),
        }
    }
}

/// Fails unless the folder `path` goes in exists, naming the cause: the
/// path component that is a file, or the topmost folder missing.
pub fn check_output_folder(path: &Path) -> Result<()> {
    let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return Ok(());
    };
    let mut missing = None;
    for folder in dir.ancestors().take_while(|d| !d.as_os_str().is_empty()) {
        match std::fs::metadata(folder) {
            Ok(m) if m.is_dir() => break,
            Ok(_) => bail!(
                "cannot write {}: {} is a file, not a folder",
                path.display(),
                folder.display()
            ),
            // Not a directory: a component above is a file, found further up.
            Err(e) if matches!(e.kind(), ErrorKind::NotFound | ErrorKind::NotADirectory) => {
                missing = Some(folder);
            }
            Err(e) => bail!("cannot write {}: {}: {e}", path.display(), folder.display()),
        }
    }
    match missing {
        Some(folder) => bail!(
            "cannot write {}: the folder {} does not exist",
            path.display(),
            folder.display()
        ),
        None => Ok(()),
    }
}

pub fn save_png(image: &image::RgbaImage, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    image.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )?;
    write_atomic(path, &bytes)?;
    Ok(())
}

pub fn save_exr(width: u32, height: u32, pixels: &[[f32; 4]], path: &Path) -> Result<()> {
    use exr::prelude::*;
    let (w, h) = (width as usize, height as usize);
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let p = pixels[y * w + x];
        (p[0], p[1], p[2], p[3])
    });
    let image = Image::from_channels((w, h), channels);
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut bytes)?;
    write_atomic(path, bytes.get_ref())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_folder_is_named_and_not_made() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("renders/today/x.png");
        assert_eq!(
            check_output_folder(&out).unwrap_err().to_string(),
            format!(
                "cannot write {}: the folder {} does not exist",
                out.display(),
                dir.path().join("renders").display()
            )
        );
        assert!(!dir.path().join("renders").exists());
        std::fs::create_dir_all(dir.path().join("renders/today")).unwrap();
        check_output_folder(&out).unwrap();
    }

    #[test]
    fn a_file_in_the_path_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("notes.txt");
        std::fs::write(&file, "not a folder").unwrap();
        for out in [file.join("x.png"), file.join("a/b/x.exr")] {
            assert_eq!(
                check_output_folder(&out).unwrap_err().to_string(),
                format!(
                    "cannot write {}: {} is a file, not a folder",
                    out.display(),
                    file.display()
                )
            );
        }
    }

    #[test]
    fn a_bare_file_name_goes_in_the_current_folder() {
        check_output_folder(Path::new("x.png")).unwrap();
    }
}
