//! F12 screenshots: the rendered image as PNG (tone-mapped) and EXR (linear
//! radiance), with timestamped names, without the UI.

use anyhow::Result;
use marbre_core::image_io;
use marbre_render::gpu::{GpuContext, Renderer};
use std::path::{Path, PathBuf};

pub const FOLDER: &str = "screenshots";

/// Writes both files and returns their paths.
pub fn save(ctx: &GpuContext, renderer: &mut Renderer, folder: &Path) -> Result<[PathBuf; 2]> {
    let stamp = chrono::Local::now().format("%Y%m%d-%H%M%S%.3f");
    let png = folder.join(format!("marbre-{stamp}.png"));
    let exr = folder.join(format!("marbre-{stamp}.exr"));
    // A preview or a round under way would give a smaller or older image
    // than the window will show in a moment: the first round is finished
    // here, so a screenshot is always at the full resolution.
    renderer.complete_first_round(ctx)?;
    image_io::save_png(&renderer.read_display(ctx)?, &png)?;
    let (w, h, pixels) = renderer.read_radiance(ctx)?;
    image_io::save_exr(w, h, &pixels, None, &exr)?;
    Ok([png, exr])
}
