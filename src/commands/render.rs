//! `marbre render`: the viewer's renderer, offscreen.

use super::session::{accumulate, load_scene, renderer_for};
use crate::gpu::auto_exposure;
use crate::gpu::{GpuContext, Renderer};
use crate::image_io;
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The preset to render.
    #[arg(long)]
    pub preset: PathBuf,
    /// Environment map to use instead of the preset's.
    #[arg(long)]
    pub env: Option<PathBuf>,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Output: .png (tone-mapped, sRGB) or .exr (linear radiance, float).
    #[arg(short = 'o', long)]
    pub output: PathBuf,
    /// Expose the PNG automatically (log-average luminance to middle grey),
    /// the preset's exposure becoming a compensation; as the viewer's
    /// "auto exposure". EXR output stays unscaled radiance.
    #[arg(long)]
    pub auto_exposure: bool,
}

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=16384).contains(&n))
            .ok_or_else(|| format!("`{v}` is not a size between 1 and 16384"))
    };
    Ok((parse(w)?, parse(h)?))
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let format = image_io::ImageFormat::from_path(&args.output)?;
    if args.spp == 0 {
        bail!("--spp must be at least 1");
    }
    let mut loaded = load_scene(&args.preset, args.env.as_deref())?;
    if args.auto_exposure {
        loaded.scene.render.auto_exposure = true;
    }
    for note in &loaded.notes {
        eprintln!("note: {note}");
    }
    let ctx = GpuContext::headless()?;
    let mut renderer = renderer_for(&ctx, &loaded, args.size)?;
    let bar = indicatif::ProgressBar::new(u64::from(args.spp));
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} [{bar:40}] {pos}/{len} spp, {elapsed} (eta {eta})",
        )
        .expect("a valid template"),
    );
    bar.set_message(ctx.describe());
    accumulate(&ctx, &mut renderer, args.spp, |n| {
        bar.set_position(u64::from(n))
    })?;
    bar.finish();
    // EXR output is the radiance, unscaled: only a PNG is exposed.
    if loaded.scene.render.auto_exposure && matches!(format, image_io::ImageFormat::Png) {
        report_auto_exposure(&ctx, &mut renderer)?;
    }
    match format {
        image_io::ImageFormat::Png => {
            let image = renderer.read_display(&ctx)?;
            image_io::save_png(&image, &args.output)
        }
        image_io::ImageFormat::Exr => {
            let (w, h, pixels) = renderer.read_radiance(&ctx)?;
            image_io::save_exr(w, h, &pixels, &args.output)
        }
    }
    .with_context(|| format!("saving {}", args.output.display()))?;
    eprintln!("wrote {}", args.output.display());
    Ok(())
}

/// Prints the exposure the PNG gets: the GPU's metering (what the display
/// pass applies) and the CPU twin's log-average over the whole image.
fn report_auto_exposure(ctx: &GpuContext, renderer: &mut Renderer) -> Result<()> {
    let metered = renderer.metering(ctx)?;
    let (_, _, pixels) = renderer.read_radiance(ctx)?;
    let compensation = renderer.scene().render.exposure;
    eprintln!(
        "auto exposure: {:+.2} stops{} (log-average luminance {:.4} over {} metered texels; \
         {:.4} over the whole image)",
        metered.stops,
        if compensation == 0.0 {
            String::new()
        } else {
            format!(", {compensation:+.2} stops of compensation on top")
        },
        metered.log_average,
        metered.count,
        auto_exposure::log_average_luminance(&pixels),
    );
    Ok(())
}
