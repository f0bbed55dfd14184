//! OIDN's own time at the viewer's and a final frame's sizes (the denoise
//! knob's RMSE curves are at the bench's small size): the default preset
//! at 640 × 360 and 1920 × 1080, each network, on the device the viewer
//! would use (CUDA on NVIDIA, else the CPU).

use anyhow::{Result, anyhow};
use marbre_core::scene::{DenoiseQuality, Denoiser};
use marbre_render::denoiser::{GuidedImage, device_for, oidn_for};
use marbre_render::gpu::GpuContext;
use marbre_render::session::{accumulate, load_scene, renderer_with};
use std::path::Path;
use std::time::Instant;

/// The sizes timed.
const SIZES: [(u32, u32); 2] = [(640, 360), (1920, 1080)];
/// Timed runs per network, after one that commits its filters.
const RUNS: usize = 3;

/// One line per size: each network's median wall time; or why OIDN was
/// not timed.
pub fn measure(ctx: &GpuContext, root: &Path) -> Result<Vec<String>> {
    let library = match oidn_for(Denoiser::Oidn) {
        Ok(library) => library.expect("asked for OIDN"),
        Err(why) => return Ok(vec![format!("OIDN not timed: {why}")]),
    };
    let device = device_for(ctx, &library);
    let mut oidn = marbre_oidn::Denoiser::new(library, device).map_err(|e| anyhow!("{e}"))?;
    let mut lines = Vec::new();
    for size in SIZES {
        let mut loaded = load_scene(&root.join("presets/default.ron"), None)?;
        let display = &mut loaded.scene.render.display;
        display.denoise = true;
        display.denoiser = Denoiser::Oidn;
        let mut renderer = renderer_with(ctx, &loaded, size, Default::default())?;
        accumulate(ctx, &mut renderer, 1, |_| {})?;
        let read = Instant::now();
        let [albedo, normal] = renderer
            .read_guides(ctx)?
            .ok_or_else(|| anyhow!("the trace did not accumulate the guides"))?;
        let (_, _, mean) = renderer.read_radiance(ctx)?;
        let read_ms = read.elapsed().as_secs_f64() * 1e3;
        let image = GuidedImage {
            size,
            mean,
            albedo,
            normal,
        };
        let mut times = Vec::new();
        for quality in DenoiseQuality::ALL {
            image.denoise(&mut oidn, quality)?;
            let mut ms: Vec<f64> = (0..RUNS)
                .map(|_| {
                    let start = Instant::now();
                    image
                        .denoise(&mut oidn, quality)
                        .map(|_| start.elapsed().as_secs_f64() * 1e3)
                })
                .collect::<Result<_>>()?;
            ms.sort_by(f64::total_cmp);
            times.push(format!("{} {:.0} ms", quality.label(), ms[RUNS / 2]));
        }
        lines.push(format!(
            "OIDN {} on the {} at {}×{}: {} (median of {RUNS}, filters committed; reading the \
             image and its guides back took {read_ms:.0} ms).",
            oidn.version(),
            device.name(),
            size.0,
            size.1,
            times.join(", "),
        ));
    }
    Ok(lines)
}
