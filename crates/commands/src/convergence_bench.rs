//! `marbre bench-convergence`: what accuracy costs in time on one preset.
//! It renders a high-spp reference (cached on disk), then the preset at
//! increasing samples per pixel, and reports samples per second and the
//! time to reach each error, so renderers and settings can be compared at
//! equal error rather than equal samples.

use super::accuracy_bench::ErrorMetrics;
use super::references::ReferenceCache;
use super::render::parse_size;
use anyhow::{Context, Result};
use clap::Args;
use marbre_core::image_io;
use marbre_render::gpu::{GpuContext, Kernel, KernelChoice};
use marbre_render::session::{
    LoadedScene, accumulate, describe_pick, load_scene, pick_kernel, renderer_with,
};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct ConvergenceBenchArgs {
    /// The preset to measure.
    #[arg(long, default_value = "presets/cornell.ron")]
    pub preset: PathBuf,
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Samples per pixel of the reference.
    #[arg(long, default_value_t = 4096)]
    pub reference_spp: u32,
    /// Sample counts measured, each a fresh render.
    #[arg(long, value_delimiter = ',', default_value = "1,4,16,64,256")]
    pub spp: Vec<u32>,
    /// Where references are kept between runs.
    #[arg(long, default_value = "target/marbre-references")]
    pub cache: PathBuf,
    /// Also writes the measured rows to this CSV file
    /// (spp,seconds,samples_per_second,rmse).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Also writes the reference (cached or rendered) to this EXR file.
    #[arg(long)]
    pub reference_out: Option<PathBuf>,
    /// The trace kernel of the measured renders: fragment, compute, cpu,
    /// or auto (the fastest on this preset, timed first). The reference is
    /// rendered with the fragment kernel: all give the same image, so one
    /// cached reference serves them all.
    #[arg(long, default_value_t = KernelChoice::Auto, value_parser = crate::kernel_choice_parser())]
    pub kernel: KernelChoice,
}

fn render(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    size: (u32, u32),
    spp: u32,
    kernel: Kernel,
) -> Result<(Vec<[f32; 4]>, f64)> {
    let mut renderer = renderer_with(ctx, loaded, size, kernel)?;
    // One warm-up frame compiles the shader; it is not timed.
    accumulate(ctx, &mut renderer, 1, |_| {})?;
    renderer.reset_accumulation();
    let start = Instant::now();
    accumulate(ctx, &mut renderer, spp, |_| {})?;
    let seconds = start.elapsed().as_secs_f64();
    let (_, _, pixels) = renderer.read_radiance(ctx)?;
    Ok((pixels, seconds))
}

pub fn run(args: &ConvergenceBenchArgs) -> Result<()> {
    let ctx = GpuContext::headless()?;
    let info = ctx.adapter.get_info();
    let (w, h) = args.size;
    println!("adapter: {} ({:?})", info.name, info.backend);
    println!(
        "{}: {w}x{h}, reference {} spp",
        args.preset.display(),
        args.reference_spp
    );
    let loaded = load_scene(&args.preset, None)?;
    let (kernel, timings) = pick_kernel(&ctx, &loaded, args.size, args.kernel)?;
    // compare_mitsuba.py reads this line.
    println!(
        "{}",
        describe_pick(kernel, timings.as_ref(), args.kernel, &loaded.scene)
    );
    let reference = ReferenceCache::new(&args.cache).get_or_render(
        &ctx,
        &loaded,
        args.size,
        args.reference_spp,
        |_| {},
    )?;
    if reference.cached {
        println!("reference: {} (cached)", reference.path.display());
    } else {
        println!("reference: rendered, saved to {}", reference.path.display());
    }
    let reference = reference.pixels;
    if let Some(path) = &args.reference_out {
        image_io::save_exr(w, h, &reference, None, path)
            .with_context(|| format!("writing {}", path.display()))?;
        println!("reference written to {}", path.display());
    }
    let mut csv = String::from("spp,seconds,samples_per_second,rmse\n");
    println!("| spp | seconds | samples/s | RMSE | RMSE × √seconds |");
    println!("|---|---|---|---|---|");
    let mut points = Vec::new();
    for &spp in &args.spp {
        let (pixels, seconds) = render(&ctx, &loaded, args.size, spp, kernel)?;
        let error = ErrorMetrics::between(&pixels, &reference).rmse;
        let samples = f64::from(w * h) * f64::from(spp) / seconds;
        println!(
            "| {spp} | {seconds:.2} | {:.3} M | {error:.5} | {:.5} |",
            samples / 1e6,
            error * seconds.sqrt()
        );
        points.push((seconds, error));
        csv.push_str(&format!("{spp},{seconds},{samples},{error}\n"));
    }
    if let Some(path) = &args.csv {
        std::fs::write(path, csv).with_context(|| format!("writing {}", path.display()))?;
    }
    // Monte Carlo error falls as 1/√time: RMSE·√t is the constant that
    // predicts the time to any error, t(E) = (RMSE·√t / E)².
    if let Some(&(seconds, error)) = points.last() {
        let efficiency = error * seconds.sqrt();
        for target in [0.05, 0.02, 0.01] {
            println!(
                "time to RMSE {target}: {:.1} s (from the last row)",
                (efficiency / target).powi(2)
            );
        }
    }
    Ok(())
}
