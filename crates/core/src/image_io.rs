//! Writing rendered images, atomically.

use crate::atomic_write::write_atomic;
use anyhow::{Result, bail};
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
