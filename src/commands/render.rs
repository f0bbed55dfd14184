//! `marbre render`: the viewer's renderer, offscreen.

use super::session::{accumulate, load_scene, renderer_for};
use crate::gpu::GpuContext;
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
    let loaded = load_scene(&args.preset, args.env.as_deref())?;
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
