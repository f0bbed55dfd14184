//! `marbre render`: the viewer's renderer, offscreen.
//!
//! The render itself is `marbre_render::final_render::render_to_file`,
//! which the viewer's Render dialog runs too; this file parses the flags
//! into its job and shows its progress on the terminal.

use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use marbre_core::scene::{DenoiseQuality, Denoiser, LightPoints, Metering, Strategy, View};
use marbre_core::tile::{Tile, TileGrid};
pub use marbre_render::final_render::parse_size;
use marbre_render::final_render::{
    DEFAULT_MAX_TILE_PIXELS, FinalRender, Progress, RenderObserver, Stop, render_to_file,
};
use marbre_render::frame_sequence::Timing;
use marbre_render::gpu::{GpuContext, KernelChoice};
use marbre_render::session::load_scene;
use std::ops::ControlFlow;
use std::path::PathBuf;

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
    #[arg(long, allow_negative_numbers = true, value_parser = crate::parse_spp)]
    pub spp: Option<u32>,
    /// Stop as soon as the estimated relative error (√relMSE, from the
    /// spread of each pixel's frames, as the viewer's Quality panel shows
    /// it) is at or below this, e.g. 0.01 for 1 %.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::parse_target_error)]
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
    /// The trace kernel: fragment, compute, cpu (for the scenes it
    /// traces; others go to the fragment kernel, and the output says why),
    /// or auto (the fastest on this scene, timed first).
    #[arg(long, default_value_t = KernelChoice::Auto, value_parser = crate::kernel_choice_parser())]
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
    /// Filter the PNG with a denoiser (the viewer's "denoise"), guided by
    /// the first hit's albedo and normal, accumulated beside the radiance:
    /// oidn (Intel Open Image Denoise, the default; where its library is
    /// not found, atrous runs instead and a note says why) or atrous
    /// (marbre's edge-avoiding filter, on the GPU). An EXR stays the raw
    /// accumulation unless --denoise-exr is given too.
    #[arg(
        long,
        num_args = 0..=1,
        default_missing_value = "oidn",
        value_name = "oidn|atrous",
        value_parser = parse_denoiser
    )]
    pub denoise: Option<Denoiser>,
    /// OIDN's network: high (for final frames, the default), balanced or
    /// fast.
    #[arg(long, default_value = "high", value_parser = parse_denoise_quality)]
    pub denoise_quality: DenoiseQuality,
    /// With --denoise, filter an EXR output as well (biased: it trades the
    /// noise for some blur).
    #[arg(long, requires = "denoise")]
    pub denoise_exr: bool,
    /// Render even if an image or material library the scene reads cannot
    /// be loaded (it shows as a magenta-and-black placeholder, or grey);
    /// without it such a render fails before tracing, naming the files.
    #[arg(long)]
    pub allow_placeholders: bool,
    /// Render the frames FIRST..LAST (both included, as Blender's range;
    /// `0..119` is 120 frames) of the preset's animation, each at its time
    /// frame/fps, to the output with its run of # replaced by the frame
    /// number (`-o out/frame_####.png`). Frames whose file exists are
    /// skipped (a stopped sequence resumes) unless --overwrite. Each
    /// frame's samples are its own, seeded by its number. At most 100 000
    /// frames a render (a longer sequence: several ranges).
    #[arg(long, value_parser = marbre_render::frame_sequence::parse_frame_range, conflicts_with = "time")]
    pub frames: Option<std::ops::RangeInclusive<u32>>,
    /// Frames a second for --frames and --time (default: the preset's
    /// animation's, else 24).
    #[arg(long, allow_negative_numbers = true)]
    pub fps: Option<f32>,
    /// Render one moment of the preset's time, in seconds (its samples
    /// those of the frame nearest it).
    #[arg(long, allow_negative_numbers = true)]
    pub time: Option<f32>,
    /// With --frames, trace again frames whose file exists.
    #[arg(long, requires = "frames")]
    pub overwrite: bool,
    /// With --frames, also assemble the frames (PNG) into one animated
    /// file: .gif or .apng (written by marbre), .webp or .mp4 (through
    /// ffmpeg, which must be installed).
    #[arg(long, requires = "frames", value_name = "FILE")]
    pub animation: Option<PathBuf>,
    /// Trace samples [K, K + spp) of the one long render instead of the
    /// first spp: renders at offsets 0, N, 2N… of --spp N are disjoint
    /// batches (for a farm) whose mean is the render of all their
    /// samples. A multiple of the preset's samples_per_frame.
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub sample_offset: u32,
    /// Trace only the pixels [X0, X1) × [Y0, Y1) of the image, with the
    /// whole image's camera and samples, to an .exr that records its
    /// place: `marbre merge` assembles the tiles into the whole render.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = Tile::parse, conflicts_with = "tiles")]
    pub tile: Option<Tile>,
    /// Cut the image into a grid of COLUMNSxROWS tiles, numbered row by
    /// row from the top left, and trace tile --tile-index of it (as
    /// --tile does).
    #[arg(long, value_name = "CxR", value_parser = TileGrid::parse, requires = "tile_index")]
    pub tiles: Option<TileGrid>,
    /// With --tiles, the tile to trace, from 0.
    #[arg(long, value_name = "I", requires = "tiles")]
    pub tile_index: Option<u32>,
    /// Trace at most this many pixels at once: a larger image (or tile)
    /// is traced in pieces and put together, so that any size completes
    /// within the GPU's memory. Default: a 4K UHD frame, 8294400.
    #[arg(long, value_name = "PIXELS", default_value_t = DEFAULT_MAX_TILE_PIXELS)]
    pub max_tile_pixels: u64,
    /// Write each pixel's estimated variance of its mean beside the
    /// radiance (the EXR's `variance` layer, from the spread of its
    /// rounds), so that `marbre merge` estimates the merged error even
    /// with one batch a tile. Needs --spp above the preset's
    /// samples_per_frame.
    #[arg(long)]
    pub moments: bool,
    /// Write the denoiser's guides beside the radiance (the EXR's
    /// `albedo` and `normal` layers: the means of the samples' first-hit
    /// albedo and shading normal), so that `marbre merge --denoise`
    /// filters what it puts together.
    #[arg(long)]
    pub guides: bool,
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

pub(crate) fn parse_denoiser(s: &str) -> Result<Denoiser, String> {
    parse_named(s, &Denoiser::ALL, Denoiser::name)
}

pub(crate) fn parse_denoise_quality(s: &str) -> Result<DenoiseQuality, String> {
    parse_named(s, &DenoiseQuality::ALL, DenoiseQuality::label)
}

/// `--auto-exposure`'s metering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MeteringArg {
    Key,
    Massal,
}

/// Samples per pixel without --target-error, and the cap with it.
const DEFAULT_SPP: u32 = 64;
const DEFAULT_MAX_SPP: u32 = 16384;

pub fn run(args: &RenderArgs) -> Result<()> {
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
    let timing = timing(args, loaded.scene.animation.as_ref().map(|a| a.fps))?;
    let render = &mut loaded.scene.render;
    render.view = args.view.unwrap_or(render.view);
    render.transport.light_points = args.light_points.unwrap_or(render.transport.light_points);
    render.transport.strategy = args.strategy.unwrap_or(render.transport.strategy);
    let job = FinalRender {
        size: args.size,
        stop: match args.target_error {
            None => Stop::Samples(spp),
            Some(target) => Stop::TargetError {
                target,
                max_spp: spp,
            },
        },
        auto_exposure: args.auto_exposure.map(|m| match m {
            MeteringArg::Key => Metering::Key,
            MeteringArg::Massal => Metering::MassalRms,
        }),
        kernel: args.kernel,
        output: args.output.clone(),
        denoise: args.denoise,
        denoise_quality: args.denoise_quality,
        denoise_exr: args.denoise_exr,
        allow_placeholders: args.allow_placeholders,
        timing,
        sample_offset: args.sample_offset,
        tile: match (args.tile, args.tiles, args.tile_index) {
            (Some(tile), _, _) => Some(tile),
            (None, Some(grid), Some(index)) => Some(
                grid.tile(args.size, index)
                    .map_err(|e| anyhow::anyhow!("--tiles: {e}"))?,
            ),
            _ => None,
        },
        max_tile_pixels: args.max_tile_pixels,
        moments: args.moments,
        guides: args.guides,
    };
    // Checked first: a range's count (at most MAX_SEQUENCE_FRAMES) then
    // fits.
    marbre_render::final_render::check_job(&job)?;
    let frames = match &job.timing {
        Timing::Sequence { frames, .. } => frames.end() - frames.start() + 1,
        Timing::Still { .. } => 1,
    };
    let ctx = GpuContext::headless()?;
    let mut bar = Bar::new(spp, frames, ctx.describe());
    render_to_file(&ctx, loaded, &job, &mut bar)?;
    Ok(())
}

/// `--frames`, `--time` and `--fps` as the render's timing, refused
/// before any loading of the GPU.
fn timing(args: &RenderArgs, preset_fps: Option<f32>) -> Result<Timing> {
    let fps = args.fps.or(preset_fps).unwrap_or(24.0);
    if !(fps.is_finite() && fps > 0.0) {
        bail!("--fps must be a positive number of frames a second, such as 24 (got {fps})");
    }
    if let Some(time) = args.time
        && !time.is_finite()
    {
        bail!("--time must be a number of seconds (got {time})");
    }
    Ok(match &args.frames {
        Some(frames) => Timing::Sequence {
            frames: frames.clone(),
            fps,
            overwrite: args.overwrite,
            animation: args.animation.clone(),
        },
        None => {
            let time = args.time.unwrap_or(0.0);
            Timing::Still {
                time,
                frame: (f64::from(time) * f64::from(fps)).round().max(0.0) as u32,
            }
        }
    })
}

/// The terminal's progress bar (over every frame's samples), and the
/// render's lines on stderr.
struct Bar {
    bar: indicatif::ProgressBar,
    frames: u32,
}

impl Bar {
    fn new(spp: u32, frames: u32, device: String) -> Self {
        let bar = indicatif::ProgressBar::new(u64::from(spp) * u64::from(frames));
        let template = "{msg} [{bar:40}] {prefix} {elapsed} (eta {eta})";
        bar.set_style(indicatif::ProgressStyle::with_template(template).expect("a valid template"));
        bar.set_message(device);
        Self { bar, frames }
    }
}

impl RenderObserver for Bar {
    fn note(&mut self, line: &str) {
        self.bar.suspend(|| eprintln!("{line}"));
    }

    fn progress(&mut self, progress: &Progress) -> ControlFlow<()> {
        let per_frame = u64::from(progress.max_samples);
        // A render traced in pieces reports them as it reports frames.
        self.bar.set_length(u64::from(progress.frames) * per_frame);
        self.bar
            .set_position(u64::from(progress.frame) * per_frame + u64::from(progress.samples));
        let samples = format!("{}/{} spp,", progress.samples, progress.max_samples);
        self.bar.set_prefix(if progress.frames > 1 {
            let part = if self.frames > 1 { "frame" } else { "piece" };
            format!(
                "{part} {}/{}, {samples}",
                progress.frame + 1,
                progress.frames
            )
        } else {
            samples
        });
        if let Some(e) = progress.relative_error {
            self.bar.set_message(format!("error {:.2} %", 100.0 * e));
        }
        ControlFlow::Continue(())
    }
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
