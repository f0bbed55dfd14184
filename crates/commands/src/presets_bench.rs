//! `marbre bench-presets`: milliseconds per frame for every shipped preset,
//! with each trace kernel (fragment and compute, timed interleaved), the
//! kernel `auto` picks, and what specialising the shader gains.

use anyhow::{Context, Result};
use clap::Args;
use marbre_core::aa_scenes;
use marbre_core::scene::Scene;
use marbre_core::texture::ImageSet;
use marbre_render::gpu::kernel;
use marbre_render::gpu::{Feature, FeatureSet, GpuContext, Kernel, KernelChoice, Renderer};
use marbre_render::session::{
    LoadedScene, accumulate, load_scene, pick_kernel, renderer_with, trace_frame,
};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct PresetsBenchArgs {
    /// Folder of presets to time.
    #[arg(long, default_value = "presets")]
    pub presets: PathBuf,
    /// Frames timed per measurement, after warm-up.
    #[arg(long, default_value_t = 30)]
    pub frames: u32,
    /// Sizes to time, WIDTHxHEIGHT.
    #[arg(long, value_delimiter = ',', default_values = ["1280x720", "640x360"], value_parser = super::render::parse_size)]
    pub sizes: Vec<(u32, u32)>,
    /// The kernel of the uber / specialised columns, of the build column
    /// and of the anti-aliasing tables: fragment, compute, cpu, or auto
    /// (the one `auto` picks for each preset). Every kernel's frame times
    /// are measured whatever this is (the CPU kernel's where it traces the
    /// preset).
    #[arg(long, default_value_t = KernelChoice::Auto, value_parser = crate::kernel_choice_parser())]
    pub kernel: KernelChoice,
}

/// Untimed frames of each renderer before the timed ones: the first draw
/// compiles the pipeline on many drivers, and on lavapipe the next few
/// still run slow.
const WARM_UP_FRAMES: u32 = 3;

/// [`time_interleaved`] after [`WARM_UP_FRAMES`].
fn time_interleaved(
    ctx: &GpuContext,
    renderers: &mut [&mut Renderer],
    frames: u32,
) -> Result<Vec<f64>> {
    marbre_render::session::time_interleaved(ctx, renderers, WARM_UP_FRAMES, frames)
}

/// [`time_interleaved`] of one renderer.
fn time_frames(ctx: &GpuContext, renderer: &mut Renderer, frames: u32) -> Result<f64> {
    Ok(time_interleaved(ctx, &mut [renderer], frames)?[0])
}

/// Wall-clock times, in ms, to build the preset's trace pipeline for
/// `kernel` (the renderer with it), and then to draw its first small frame:
/// some drivers finish compiling the shader at the first draw.
fn time_build(ctx: &GpuContext, loaded: &LoadedScene, kernel: Kernel) -> Result<(f64, f64)> {
    let start = Instant::now();
    let mut renderer = renderer_with(ctx, loaded, (64, 36), kernel)?;
    let built = start.elapsed().as_secs_f64() * 1000.0;
    let start = Instant::now();
    trace_frame(ctx, &mut renderer)?;
    Ok((built, start.elapsed().as_secs_f64() * 1000.0))
}

/// One preset at one size: both kernels' median ms per frame (compute
/// `None` where the adapter cannot run it), and the uber shader's with
/// the kernel used.
struct SizeTimes {
    size: (u32, u32),
    fragment_ms: f64,
    compute_ms: Option<f64>,
    /// The CPU kernel's, where it traces the preset.
    cpu_ms: Option<f64>,
    uber_ms: f64,
}

impl SizeTimes {
    fn ms(&self, kernel: Kernel) -> f64 {
        match kernel {
            Kernel::Fragment => self.fragment_ms,
            Kernel::Compute => self.compute_ms.unwrap_or(f64::NAN),
            Kernel::Cpu => self.cpu_ms.unwrap_or(f64::NAN),
        }
    }

    /// The kernel measured fastest here ([`kernel::fastest`]).
    fn faster(&self) -> Kernel {
        let others: Vec<(Kernel, f64)> = [
            (Kernel::Compute, self.compute_ms),
            (Kernel::Cpu, self.cpu_ms),
        ]
        .into_iter()
        .filter_map(|(k, ms)| ms.map(|ms| (k, ms)))
        .collect();
        kernel::fastest(self.fragment_ms, &others)
    }
}

/// Times the fragment kernel, the compute kernel (if `compute`) and the
/// uber shader with `used`, interleaved.
fn time_size(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    size: (u32, u32),
    compute: bool,
    used: Kernel,
    frames: u32,
) -> Result<SizeTimes> {
    let mut fragment = renderer_with(ctx, loaded, size, Kernel::Fragment)?;
    let mut compute_renderer = if compute {
        Some(renderer_with(ctx, loaded, size, Kernel::Compute)?)
    } else {
        None
    };
    let mut cpu_renderer = if marbre_render::cpu_kernel::support(&loaded.scene).is_ok() {
        Some(renderer_with(ctx, loaded, size, Kernel::Cpu)?)
    } else {
        None
    };
    // The uber shader is a GPU kernel's: the CPU kernel has no shader to
    // specialise in that sense.
    let uber_kernel = if used == Kernel::Cpu {
        Kernel::Fragment
    } else {
        used
    };
    let mut uber = renderer_with(ctx, loaded, size, uber_kernel)?;
    uber.set_feature_override(ctx, Some(FeatureSet::all()))?;
    let mut renderers: Vec<&mut Renderer> = vec![&mut fragment, &mut uber];
    let with_compute = compute_renderer.is_some();
    if let Some(c) = compute_renderer.as_mut() {
        renderers.push(c);
    }
    if let Some(c) = cpu_renderer.as_mut() {
        renderers.push(c);
    }
    let times = time_interleaved(ctx, &mut renderers, frames)?;
    let mut rest = times[2..].iter().copied();
    Ok(SizeTimes {
        size,
        fragment_ms: times[0],
        uber_ms: times[1],
        compute_ms: if with_compute { rest.next() } else { None },
        cpu_ms: rest.next(),
    })
}

/// Where `auto`'s pick was not the kernel measured faster.
struct Miss {
    preset: String,
    size: (u32, u32),
    picked: Kernel,
    /// How much slower the pick was, as a fraction.
    slower_by: f64,
}

pub fn run(args: &PresetsBenchArgs) -> Result<()> {
    let ctx = GpuContext::headless()?;
    let mut presets: Vec<PathBuf> = std::fs::read_dir(&args.presets)
        .with_context(|| format!("reading {}", args.presets.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    presets.sort();
    // `--kernel compute` where the adapter cannot run it stops here, saying why.
    let resolved = kernel::resolve(&ctx, args.kernel)?;
    let compute_why_not = kernel::compute_support(&ctx).err();
    let compute = compute_why_not.is_none();
    println!("adapter: {}", ctx.describe());
    println!(
        "frames per measurement: {}, 1 sample per pixel per frame, after {WARM_UP_FRAMES} warm-up frames; the median wall-clock frame with a GPU sync",
        args.frames
    );
    println!(
        "kernels: fragment (fs_trace) and compute (cs_trace), the same WGSL body, timed interleaved (a frame of each in turn, with the uber shader), so their ratio holds on a busy machine{}",
        compute_why_not
            .as_ref()
            .map_or(String::new(), |why| format!(
                "; compute n/a on this adapter: {why}"
            ))
    );
    println!(
        "auto picks: what `--kernel auto` runs (both kernels timed on the preset at up to 320x180, compute kept only if 5 % faster); with it, compute / fragment as auto measured it"
    );
    println!(
        "--kernel {}: the kernel of the uber / specialised columns and of the anti-aliasing tables{}",
        kernel_choice_name(args.kernel),
        if args.kernel == KernelChoice::Auto {
            " (for each preset, the one auto picks)"
        } else {
            ""
        }
    );
    println!(
        "specialised: the shader holds only what the preset uses; uber: every feature compiled in"
    );
    println!(
        "build: a new trace pipeline with the {resolved} kernel (what a structural edit costs), from WGSL to a pipeline + its first small frame; cold only with an empty Mesa shader cache (MESA_SHADER_CACHE_DIR=$(mktemp -d))"
    );
    let header: Vec<String> = args
        .sizes
        .iter()
        .map(|(w, h)| {
            format!(
                "{w}x{h} fragment ms | {w}x{h} compute ms | compute / fragment | {w}x{h} --kernel ms (fps) | {w}x{h} uber ms | uber / specialised"
            )
        })
        .collect();
    println!(
        "| preset | features | auto picks | build ms (pipeline + first frame) | {} |",
        header.join(" | ")
    );
    println!("|---|---|---|---|{}", "---|".repeat(6 * args.sizes.len()));
    // The largest size measured: `auto` times at most 320x180 of it.
    let pick_size = args
        .sizes
        .iter()
        .copied()
        .max_by_key(|(w, h)| u64::from(*w) * u64::from(*h))
        .unwrap_or((1280, 720));
    let mut used_kernels = Vec::new();
    let mut misses = Vec::new();
    let mut measured = 0;
    for path in &presets {
        let mut loaded = load_scene(path, None)?;
        loaded.scene.render.samples_per_frame = 1;
        let name = path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let features = FeatureSet::for_scene(&loaded.scene).0.len();
        let (pipeline_ms, first_frame_ms) = time_build(&ctx, &loaded, resolved)?;
        let (auto, timings) = pick_kernel(&ctx, &loaded, pick_size, KernelChoice::Auto)?;
        let used = args.kernel.fixed().unwrap_or(auto);
        used_kernels.push(used);
        let auto_cell = match &timings {
            Some(t) => format!("{auto} ({:.2})", t.ms(auto) / t.fragment_ms),
            None => format!("{auto} (untimed)"),
        };
        let mut cells = Vec::new();
        for &size in &args.sizes {
            let t = time_size(&ctx, &loaded, size, compute, used, args.frames)?;
            let specialised = t.ms(used);
            let (compute_cell, ratio_cell) = match t.compute_ms {
                Some(c) => (format!("{c:.1}"), format!("{:.2}", c / t.fragment_ms)),
                None => ("n/a".to_string(), "n/a".to_string()),
            };
            cells.push(format!(
                "{:.1} | {compute_cell} | {ratio_cell} | {used} {specialised:.1} ({:.0}) | {:.1} | {:.2}",
                t.fragment_ms,
                1000.0 / specialised,
                t.uber_ms,
                t.uber_ms / specialised
            ));
            if compute {
                measured += 1;
                if auto != t.faster() {
                    misses.push(Miss {
                        preset: name.clone(),
                        size: t.size,
                        picked: auto,
                        slower_by: t.ms(auto) / t.ms(t.faster()) - 1.0,
                    });
                }
            }
        }
        println!(
            "| {name} | {features} | {auto_cell} | {pipeline_ms:.0} + {first_frame_ms:.0} | {} |",
            cells.join(" | ")
        );
    }
    println!();
    report_auto(compute, measured, &misses);
    println!();
    anti_aliasing_table(&ctx, &presets, &used_kernels, args.kernel, args.frames)
}

/// The kernel choice as `--kernel` spells it.
fn kernel_choice_name(choice: KernelChoice) -> &'static str {
    choice.fixed().map_or("auto", Kernel::name)
}

/// Says whether `auto` ever picked the kernel measured slower, and by how much.
fn report_auto(compute: bool, measured: usize, misses: &[Miss]) {
    if !compute {
        println!(
            "auto: the compute kernel cannot run here, so auto is the fragment kernel, untimed"
        );
        return;
    }
    if misses.is_empty() {
        println!(
            "auto picked the kernel measured faster in all {measured} of {measured} (preset, size) measurements"
        );
        return;
    }
    println!(
        "auto picked the kernel measured slower in {} of {measured} (preset, size) measurements:",
        misses.len()
    );
    for m in misses {
        println!(
            "  {} at {}x{}: auto picked {}, {:.1} % slower than the other",
            m.preset,
            m.size.0,
            m.size.1,
            m.picked,
            100.0 * m.slower_by
        );
    }
    println!(
        "  (auto times 5 frames at up to 320x180; a miss by a few % is a near tie within this machine's noise)"
    );
}

/// What procedural anti-aliasing costs, per preset that compiles the
/// footprint in (ms per frame with the switches on and off), and what it
/// buys, on grazing grounds where only the texture can be wrong
/// ([`aa_scenes`]): the error of one sample per pixel against 256 point
/// samples per pixel, filtered and not. Each preset with its kernel of the
/// main table (`kernels`, in the order of `presets`); each grazing ground
/// with `choice`'s.
fn anti_aliasing_table(
    ctx: &GpuContext,
    presets: &[PathBuf],
    kernels: &[Kernel],
    choice: KernelChoice,
    frames: u32,
) -> Result<()> {
    let size = AA_SIZE;
    println!(
        "procedural anti-aliasing at {}x{}: its cost on each preset that uses it, ms per frame (filtered and point sampled timed interleaved)",
        size.0, size.1
    );
    println!("| preset | kernel | ms filtered | ms point sampled | filtered / point |");
    println!("|---|---|---|---|---|");
    for (path, &kernel) in presets.iter().zip(kernels) {
        let mut loaded = load_scene(path, None)?;
        loaded.scene.render.samples_per_frame = 1;
        if !FeatureSet::for_scene(&loaded.scene).contains(Feature::Footprint) {
            continue;
        }
        let mut filtered = renderer_with(ctx, &loaded, size, kernel)?;
        let mut point = renderer_with(ctx, &loaded, size, kernel)?;
        point.set_scene(ctx, &point_sampled(&loaded.scene))?;
        let times = time_interleaved(ctx, &mut [&mut filtered, &mut point], frames)?;
        let (filtered_ms, point_ms) = (times[0], times[1]);
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        println!(
            "| {name} | {kernel} | {filtered_ms:.1} | {point_ms:.1} | {:.2} |",
            filtered_ms / point_ms
        );
    }
    println!();
    println!(
        "and what it buys: a Lambert ground in white light seen 8 degrees from grazing, RMSE of 1 spp against 256 spp point sampled"
    );
    println!(
        "| texture | kernel | RMSE filtered | RMSE point sampled | filtered / point | ms filtered | ms point |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, texture) in aa_scenes::textures() {
        let point = aa_scenes::grazing_ground(texture);
        let mut filtered = point.clone();
        filtered.render.filter_checkers = true;
        filtered.render.clamp_octaves = true;
        let loaded = LoadedScene {
            scene: point.clone(),
            env: None,
            images: ImageSet::empty(),
            notes: Vec::new(),
            substitutes: Vec::new(),
        };
        let (kernel, _) = pick_kernel(ctx, &loaded, size, choice)?;
        let mut renderer = Renderer::with_kernel(ctx, &point, None, size, kernel)?;
        let point_ms = time_frames(ctx, &mut renderer, frames)?;
        let point_image = one_sample(ctx, &mut renderer)?;
        renderer.reset_accumulation();
        accumulate(ctx, &mut renderer, 256, |_| {})?;
        let (_, _, reference) = renderer.read_radiance(ctx)?;
        renderer.set_scene(ctx, &filtered)?;
        let filtered_ms = time_frames(ctx, &mut renderer, frames)?;
        let filtered_image = one_sample(ctx, &mut renderer)?;
        let e_filtered = rmse(&filtered_image, &reference);
        let e_point = rmse(&point_image, &reference);
        println!(
            "| {name} | {kernel} | {e_filtered:.4} | {e_point:.4} | {:.2} | {filtered_ms:.1} | {point_ms:.1} |",
            e_filtered / e_point
        );
    }
    Ok(())
}

/// `scene` with footprint filtering off.
fn point_sampled(scene: &Scene) -> Scene {
    let mut point = scene.clone();
    point.render.filter_checkers = false;
    point.render.clamp_octaves = false;
    point
}

/// The image size of the anti-aliasing table.
const AA_SIZE: (u32, u32) = (320, 180);

/// A fresh image of one sample per pixel.
fn one_sample(ctx: &GpuContext, renderer: &mut Renderer) -> Result<Vec<[f32; 4]>> {
    renderer.reset_accumulation();
    accumulate(ctx, renderer, 1, |_| {})?;
    Ok(renderer.read_radiance(ctx)?.2)
}

/// Root mean square difference over every colour channel, each tone-mapped
/// by x / (1 + x) so that a few bright pixels do not decide it.
fn rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let map = |x: f32| f64::from(x / (1.0 + x.max(0.0)));
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (map(p[c]) - map(q[c])).powi(2)))
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}
