//! Writing rendered images, atomically.
//!
//! An output's missing folders are created, as Blender does for a render's
//! output path (`create_output_folder` says which, for the caller to
//! report); a path through a file is refused with the file named.

use crate::atomic_write::write_atomic;
use anyhow::{Context, Result, bail};
use std::io::ErrorKind;
use std::path::{Path, PathBuf};

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

/// Makes the folder `path` goes in. Returns the topmost folder created
/// (None when it was there already); an error names the path component
/// that is a file, or the folder that could not be made and why.
pub fn create_output_folder(path: &Path) -> Result<Option<PathBuf>> {
    let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return Ok(None);
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
    if missing.is_some() {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    }
    Ok(missing.map(Path::to_owned))
}

pub fn save_png(image: &image::RgbaImage, path: &Path) -> Result<()> {
    create_output_folder(path)?;
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
    create_output_folder(path)?;
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

    fn one_pixel() -> image::RgbaImage {
        image::RgbaImage::from_pixel(1, 1, image::Rgba([10, 20, 30, 255]))
    }

    #[test]
    fn missing_folders_are_created_and_the_topmost_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("renders/today/x.png");
        assert_eq!(
            create_output_folder(&out).unwrap(),
            Some(dir.path().join("renders"))
        );
        assert!(dir.path().join("renders/today").is_dir());
        assert_eq!(create_output_folder(&out).unwrap(), None, "there now");
        save_png(&one_pixel(), &dir.path().join("more/y.png")).unwrap();
        let saved = image::open(dir.path().join("more/y.png")).unwrap();
        assert_eq!(saved.to_rgba8(), one_pixel());
    }

    #[test]
    fn a_file_in_the_path_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("notes.txt");
        std::fs::write(&file, "not a folder").unwrap();
        for out in [file.join("x.png"), file.join("a/b/x.exr")] {
            let png = save_png(&one_pixel(), &out).unwrap_err().to_string();
            let exr = save_exr(1, 1, &[[1.0; 4]], &out).unwrap_err().to_string();
            for message in [png, exr] {
                assert_eq!(
                    message,
                    format!(
                        "cannot write {}: {} is a file, not a folder",
                        out.display(),
                        file.display()
                    )
                );
            }
        }
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "not a folder");
    }

    #[test]
    fn a_bare_file_name_needs_no_folder() {
        assert_eq!(create_output_folder(Path::new("x.png")).unwrap(), None);
    }
}
