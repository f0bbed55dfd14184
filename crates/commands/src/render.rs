//! `marbre render`: the viewer's renderer, offscreen.

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use marbre_core::image_io;
use marbre_core::scene::{LightPoints, Metering, Strategy, View};
use marbre_render::gpu::auto_exposure;
use marbre_render::gpu::error_meter::ErrorEstimate;
use marbre_render::gpu::{GpuContext, KernelChoice, Renderer};
use marbre_render::session::{
    accumulate, describe_pick, load_scene, max_texture_side, pick_kernel, renderer_with,
    trace_frame,
};
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The preset to render.
    #[arg(long)]
    pub preset: PathBuf,
    /// Environment map to use instead of the preset's.
    #[arg(long)]
    pub env: Option<PathBuf>,
    /// Samples per pixel (default 64); with --target-error, the most it
    /// may take (default 16384).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Stop as soon as the estimated relative error (√relMSE, from the
    /// spread of each pixel's frames, as the viewer's Quality panel shows
    /// it) is at or below this, e.g. 0.01 for 1 %.
    #[arg(long)]
    pub target_error: Option<f64>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Output: .png (tone-mapped, sRGB) or .exr (linear radiance, float).
    #[arg(short = 'o', long)]
    pub output: PathBuf,
    /// Expose the PNG automatically, the preset's exposure becoming a
    /// compensation; as the viewer's "auto exposure": by Reinhard's key
    /// (`key`, the default: log-average luminance to middle grey) or
    /// Massal's RMS luminance (`massal`). EXR output stays unscaled
    /// radiance.
    #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "key", value_name = "METERING")]
    pub auto_exposure: Option<MeteringArg>,
    /// The trace kernel: fragment, compute, or auto (the faster of the
    /// two on this scene, timed first).
    #[arg(long, value_enum, default_value_t = KernelChoice::Auto)]
    pub kernel: KernelChoice,
    /// What each sample records instead of the preset's view: lit (the
    /// radiance), hit-mask, primitive, normal, albedo or depth. A view's
    /// EXR holds its values as they are; its PNG shows them clamped to
    /// [0, 1], unexposed, sRGB-encoded.
    #[arg(long, value_parser = parse_view)]
    pub view: Option<View>,
    /// Where light samples lie on their light instead of the preset's
    /// rule: random, centroid (one fixed point per light) or fixed-set (the
    /// same light-samples points for every pixel).
    #[arg(long, value_parser = parse_light_points)]
    pub light_points: Option<LightPoints>,
    /// The direct-light strategy instead of the preset's: light, bsdf,
    /// mis-balance, mis-power or hemisphere (BSDF sampling with the
    /// diffuse lobe uniform over the hemisphere).
    #[arg(long, value_parser = parse_strategy)]
    pub strategy: Option<Strategy>,
}

/// The value of `all` called `s` by `name`, or the list of names.
fn parse_named<T: Copy>(s: &str, all: &[T], name: fn(T) -> &'static str) -> Result<T, String> {
    all.iter().copied().find(|&v| name(v) == s).ok_or_else(|| {
        let names: Vec<&str> = all.iter().map(|&v| name(v)).collect();
        format!("`{s}` is not one of {}", names.join(", "))
    })
}

fn parse_view(s: &str) -> Result<View, String> {
    parse_named(s, &View::ALL, View::name)
}

fn parse_light_points(s: &str) -> Result<LightPoints, String> {
    parse_named(s, &LightPoints::ALL, LightPoints::name)
}

fn parse_strategy(s: &str) -> Result<Strategy, String> {
    parse_named(s, &Strategy::ALL, Strategy::name)
}

/// `--auto-exposure`'s metering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MeteringArg {
    Key,
    Massal,
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

/// Samples per pixel without --target-error, and the cap with it.
const DEFAULT_SPP: u32 = 64;
const DEFAULT_MAX_SPP: u32 = 16384;

pub fn run(args: &RenderArgs) -> Result<()> {
    let format = image_io::ImageFormat::from_path(&args.output)?;
    let spp = args.spp.unwrap_or(if args.target_error.is_some() {
        DEFAULT_MAX_SPP
    } else {
        DEFAULT_SPP
    });
    if spp == 0 {
        bail!("--spp must be at least 1");
    }
    if let Some(target) = args.target_error
        && !(target.is_finite() && target > 0.0)
    {
        bail!("--target-error must be a positive number, like 0.01 for 1 %");
    }
    let mut loaded = load_scene(&args.preset, args.env.as_deref())?;
    if let Some(metering) = args.auto_exposure {
        let display = &mut loaded.scene.render.display;
        display.auto_exposure = true;
        display.metering = match metering {
            MeteringArg::Key => Metering::Key,
            MeteringArg::Massal => Metering::MassalRms,
        };
    }
    let render = &mut loaded.scene.render;
    render.view = args.view.unwrap_or(render.view);
    render.transport.light_points = args.light_points.unwrap_or(render.transport.light_points);
    render.transport.strategy = args.strategy.unwrap_or(render.transport.strategy);
    let ctx = GpuContext::headless()?;
    let loaded = loaded.fit_environment(max_texture_side(&ctx));
    for note in &loaded.notes {
        eprintln!("note: {note}");
    }
    let (kernel, timings) = pick_kernel(&ctx, &loaded, args.size, args.kernel)?;
    eprintln!("{}", describe_pick(kernel, timings.as_ref()));
    let mut renderer = renderer_with(&ctx, &loaded, args.size, kernel)?;
    let bar = indicatif::ProgressBar::new(u64::from(spp));
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} [{bar:40}] {pos}/{len} spp, {elapsed} (eta {eta})",
        )
        .expect("a valid template"),
    );
    bar.set_message(ctx.describe());
    match args.target_error {
        None => accumulate(&ctx, &mut renderer, spp, |n| bar.set_position(u64::from(n)))?,
        Some(target) => {
            let reached = accumulate_to_error(&ctx, &mut renderer, target, spp, &bar)?;
            bar.finish();
            report_error(&renderer, target, reached);
        }
    }
    bar.finish();
    // EXR output is the radiance, unscaled: only a PNG is exposed.
    if loaded.scene.render.shown_display().auto_exposure
        && matches!(format, image_io::ImageFormat::Png)
    {
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

/// How often the error is measured while rendering to a target: each
/// measurement waits for the GPU, so not after every frame of a fast one.
const ERROR_CHECK_INTERVAL: Duration = Duration::from_millis(250);

/// Traces until the estimated relative error is at most `target`, or
/// `max_spp` samples per pixel; returns the last estimate.
fn accumulate_to_error(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    target: f64,
    max_spp: u32,
    bar: &indicatif::ProgressBar,
) -> Result<Option<ErrorEstimate>> {
    let mut last_check: Option<Instant> = None;
    while renderer.accumulated_samples() < max_spp {
        // Waiting for each frame keeps the GPU no further ahead than the
        // check: a target reached is not overshot by a queue of frames.
        trace_frame(ctx, renderer)?;
        bar.set_position(u64::from(renderer.accumulated_samples()));
        if last_check.is_some_and(|t| t.elapsed() < ERROR_CHECK_INTERVAL) {
            continue;
        }
        last_check = Some(Instant::now());
        if let Some(e) = renderer.estimate_error(ctx)? {
            bar.set_message(format!("error {:.2} %", 100.0 * e.relative));
            if e.relative <= target {
                return Ok(Some(e));
            }
        }
    }
    // The cap: measure the final image.
    renderer.estimate_error(ctx)
}

/// Says where the error ended, against the target.
fn report_error(renderer: &Renderer, target: f64, estimate: Option<ErrorEstimate>) {
    let spp = renderer.accumulated_samples();
    let seconds = renderer.accumulation_time().as_secs_f64();
    match estimate {
        Some(e) if e.relative <= target => eprintln!(
            "target reached: estimated relative error {:.3} % (RMSE {:.5}) at {spp} spp in {seconds:.1} s",
            100.0 * e.relative,
            e.rmse
        ),
        Some(e) => eprintln!(
            "target not reached: estimated relative error {:.3} % (RMSE {:.5}) at the cap of {spp} spp \
             ({seconds:.1} s); raise --spp, about {:.0} s more would do",
            100.0 * e.relative,
            e.rmse,
            e.seconds_to(target)
        ),
        None => eprintln!("no error estimate: it needs two frames (--spp {spp} is too few)"),
    }
}

/// Prints the exposure the PNG gets: the GPU's metering (what the display
/// pass applies) and the CPU twin's average over the whole image.
fn report_auto_exposure(ctx: &GpuContext, renderer: &mut Renderer) -> Result<()> {
    let metered = renderer.metering(ctx)?;
    let (_, _, pixels) = renderer.read_radiance(ctx)?;
    let display = renderer.scene().render.display;
    let compensation = display.exposure;
    let (what, metered_value, whole) = match display.metering {
        Metering::Key => (
            "log-average",
            metered.log_average,
            auto_exposure::log_average_luminance(&pixels),
        ),
        Metering::MassalRms => (
            "Massal's RMS",
            metered.rms,
            auto_exposure::rms_luminance(&pixels),
        ),
    };
    eprintln!(
        "auto exposure: {:+.2} stops{} ({what} luminance {:.4} over {} metered texels; \
         {:.4} over the whole image)",
        metered.stops_for(display.metering),
        if compensation == 0.0 {
            String::new()
        } else {
            format!(", {compensation:+.2} stops of compensation on top")
        },
        metered_value,
        metered.count,
        whole,
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: RenderArgs,
    }

    fn auto_exposure(flags: &[&str]) -> Option<MeteringArg> {
        let base = ["render", "--preset", "p.ron", "-o", "x.png"];
        Cli::try_parse_from(base.iter().chain(flags))
            .unwrap()
            .args
            .auto_exposure
    }

    /// The bare flag meters by the key as it always did; a value picks
    /// Massal's RMS; without the flag the preset decides.
    #[test]
    fn auto_exposure_takes_an_optional_metering() {
        assert_eq!(auto_exposure(&[]), None);
        assert_eq!(auto_exposure(&["--auto-exposure"]), Some(MeteringArg::Key));
        assert_eq!(
            auto_exposure(&["--auto-exposure", "--size", "8x8"]),
            Some(MeteringArg::Key)
        );
        assert_eq!(
            auto_exposure(&["--auto-exposure", "massal"]),
            Some(MeteringArg::Massal)
        );
        assert_eq!(
            auto_exposure(&["--auto-exposure=key"]),
            Some(MeteringArg::Key)
        );
        let bad = Cli::try_parse_from([
            "render",
            "--preset",
            "p",
            "-o",
            "x.png",
            "--auto-exposure=rms",
        ]);
        assert!(bad.is_err());
    }
}
