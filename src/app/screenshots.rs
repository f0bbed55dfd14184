//! F12 screenshots: the rendered image as PNG (tone-mapped) and EXR (linear
//! radiance), with timestamped names, without the UI.

use anyhow::Result;
use marbre_core::image_io;
use marbre_render::gpu::{GpuContext, Renderer};
use std::path::{Path, PathBuf};

pub const FOLDER: &str = "screenshots";

/// Writes both files and returns their paths.
#[cfg(not(target_arch = "wasm32"))]
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

/// In a web page: draws and copies the image now, then reads both back
/// awaited (a page cannot wait for the GPU), writes them among the page's
/// files and offers them as downloads; returns their paths at once.
#[cfg(target_arch = "wasm32")]
pub fn save(ctx: &GpuContext, renderer: &mut Renderer, folder: &Path) -> Result<[PathBuf; 2]> {
    use crate::app::file_dialogs;
    use marbre_render::gpu::readback::read_texture_async;
    let stamp = chrono::Local::now().format("%Y%m%d-%H%M%S%.3f");
    let png = folder.join(format!("marbre-{stamp}.png"));
    let exr = folder.join(format!("marbre-{stamp}.exr"));
    let (display, mean) = renderer.snapshot(ctx)?;
    let (device, queue) = (ctx.device.clone(), ctx.queue.clone());
    let paths = [png.clone(), exr.clone()];
    wasm_bindgen_futures::spawn_local(async move {
        let (w, h) = (display.width(), display.height());
        let written = async {
            let srgb = read_texture_async(&device, &queue, &display, 4).await?;
            let image = image::RgbaImage::from_raw(w, h, srgb)
                .ok_or_else(|| anyhow::anyhow!("readback returned the wrong number of bytes"))?;
            image_io::save_png(&image, &png)?;
            let linear = read_texture_async(&device, &queue, &mean, 16).await?;
            let pixels: &[[f32; 4]] = bytemuck::cast_slice(&linear);
            image_io::save_exr(w, h, pixels, None, &exr)?;
            anyhow::Ok(())
        };
        match written.await {
            // Delivered, they need no place in the page's memory.
            Ok(()) => {
                for file in [&png, &exr] {
                    file_dialogs::deliver_saved(file);
                    marbre_core::page_files::remove(file);
                }
            }
            Err(e) => file_dialogs::note(format!("screenshot failed: {e:#}")),
        }
    });
    Ok(paths)
}
