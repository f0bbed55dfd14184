//! `marbre bench`: what accuracy costs in time, one knob at a time.
//!
//! Each knob (samples per pixel, bounces, light selection, direct-light
//! strategy, environment sampling, octaves, octave clamping, texture
//! filtering, noise hash, specialised or uber shader) is swept on a scene
//! chosen to make it matter, everything else fixed. Each variant is
//! rendered afresh at several sample counts, timed, and compared with a
//! high-spp reference cached on disk, so that every variant gives a curve
//! of error against time and variants can be compared at equal error.

mod curve_fit;
mod curves;
mod error_metrics;
mod findings;
mod frame_timer;
mod knob;
mod measure;
mod oidn_timing;
mod plot;
mod report;
mod scale;
mod scenes;
mod sweeps;

pub use curve_fit::log_log_slope;
pub use error_metrics::ErrorMetrics;
pub use frame_timer::TimerKind;
pub use knob::Knob;
pub use measure::Point;
pub use report::CSV_HEADER;

use super::references::ReferenceCache;
use anyhow::{Context, Result};
use clap::Args;
use frame_timer::FrameTimer;
use indicatif::{ProgressBar, ProgressStyle};
use marbre_render::gpu::{GpuContext, Kernel, KernelChoice};
use measure::Bench;
use scale::Scale;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug, Clone)]
pub struct AccuracyBenchArgs {
    /// A small run (48×48, few samples, cheap references): half a minute
    /// on two CPU cores (lavapipe, release build).
    #[arg(long)]
    pub quick: bool,
    /// The knobs to sweep (default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub knobs: Vec<Knob>,
    /// Where results.csv, results.md and the plots go.
    #[arg(long, default_value = "target/marbre-bench")]
    pub out: PathBuf,
    /// Where references are kept between runs.
    #[arg(long, default_value = "target/marbre-references")]
    pub cache: PathBuf,
    /// The folder holding presets/ and envmaps/ (default: the repository
    /// this marbre was built from, wherever it is run).
    #[arg(long, default_value_os_t = repository_root())]
    pub root: PathBuf,
    /// The trace kernel: fragment, compute, cpu, or auto (the fastest on
    /// each sweep's scene, timed first; all the sweep's variants then use
    /// it). References are rendered with the fragment kernel: all kernels
    /// give the same image.
    #[arg(long, default_value_t = KernelChoice::Auto, value_parser = crate::kernel_choice_parser())]
    pub kernel: KernelChoice,
}

/// What a run measured and concluded.
pub struct BenchResults {
    pub adapter: String,
    /// Wall-clock seconds of the whole run, references included.
    pub seconds: f64,
    pub references_rendered: usize,
    pub references_cached: usize,
    pub timer: TimerKind,
    /// The kernel of each sweep: its knob, its scene and the kernel.
    pub kernels: Vec<(Knob, String, Kernel)>,
    pub points: Vec<Point>,
    /// Per knob swept, its findings in words.
    pub findings: Vec<(Knob, Vec<String>)>,
}

/// The repository marbre was built from: its scenes and maps are what the
/// benchmark's figures are about, whatever the working folder.
fn repository_root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .canonicalize()
        .unwrap_or_else(|_| PathBuf::from("."))
}

pub fn run(args: &AccuracyBenchArgs) -> Result<()> {
    if !args.root.join("presets").is_dir() {
        anyhow::bail!(
            "{}: no presets/ folder here; give --root, the folder holding presets/ and envmaps/",
            args.root.display()
        );
    }
    eprintln!("scenes from {} (--root to change)", args.root.display());
    let ctx = GpuContext::headless()?;
    let results = run_on(&ctx, args, true)?;
    println!(
        "adapter: {}; time per frame: {}; kernel: {}; {:.0} s ({} references rendered, {} from the cache)",
        results.adapter,
        results.timer.name(),
        kernel_summary(&results.kernels),
        results.seconds,
        results.references_rendered,
        results.references_cached,
    );
    for (knob, lines) in &results.findings {
        println!("\n{}", knob.title());
        for line in lines {
            println!("  {line}");
        }
    }
    println!(
        "\nwrote {}",
        args.out.join("results.{csv,md}, <knob>.png").display()
    );
    Ok(())
}

/// Runs the sweeps of `args` on `ctx` and writes the results into
/// `args.out`, with a progress bar if `show_progress`.
pub fn run_on(
    ctx: &GpuContext,
    args: &AccuracyBenchArgs,
    show_progress: bool,
) -> Result<BenchResults> {
    let started = Instant::now();
    let scale = if args.quick {
        Scale::quick()
    } else {
        Scale::full()
    };
    let knobs: Vec<Knob> = Knob::ALL
        .into_iter()
        .filter(|k| args.knobs.is_empty() || args.knobs.contains(k))
        .collect();
    let mut sweeps = Vec::new();
    for &knob in &knobs {
        sweeps.extend(sweeps::sweeps(knob, &scale, &args.root)?);
    }
    let progress = if show_progress {
        ProgressBar::new(sweeps.iter().map(Bench::samples).sum())
    } else {
        ProgressBar::hidden()
    };
    progress.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {percent}% eta {eta} {msg}")
            .context("the progress bar's template")?
            .progress_chars("=> "),
    );
    let timer = FrameTimer::new(ctx);
    let cache = ReferenceCache::new(&args.cache);
    let bench = Bench {
        ctx,
        cache: &cache,
        timer: &timer,
        progress: &progress,
        kernel: args.kernel,
    };
    let (mut points, mut rendered, mut cached) = (Vec::new(), 0, 0);
    let mut kernels = Vec::new();
    for sweep in &sweeps {
        let measured = bench.measure(sweep)?;
        kernels.push((sweep.knob, sweep.scene_name.clone(), measured.kernel));
        points.extend(measured.points);
        rendered += measured.references_rendered;
        cached += measured.references_cached;
    }
    progress.finish_and_clear();
    let results = BenchResults {
        adapter: ctx.describe(),
        seconds: started.elapsed().as_secs_f64(),
        references_rendered: rendered,
        references_cached: cached,
        timer: timer.kind(),
        kernels,
        findings: knobs
            .iter()
            .map(|&k| {
                let mut lines = findings::findings(k, &points);
                if k == Knob::Denoise && !args.quick {
                    lines.extend(oidn_timing::measure(ctx, &args.root)?);
                }
                Ok((k, lines))
            })
            .collect::<Result<_>>()?,
        points,
    };
    write(args, &scale, &results)?;
    Ok(results)
}

fn write(args: &AccuracyBenchArgs, scale: &Scale, results: &BenchResults) -> Result<()> {
    let out = &args.out;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    report::write_csv(&out.join("results.csv"), &results.points, &results.adapter)?;
    let mut knobs = Vec::new();
    for (knob, findings) in &results.findings {
        let plot_name = format!("{}.png", knob.id());
        let curves = curves::curves_of(&results.points, *knob);
        plot::plot(&out.join(&plot_name), *knob, &curves, &results.adapter)?;
        knobs.push(report::KnobReport {
            knob: *knob,
            points: results.points.iter().filter(|p| p.knob == *knob).collect(),
            findings: findings.clone(),
            plot: plot_name,
        });
    }
    let run = report::RunInfo {
        adapter: &results.adapter,
        timer: results.timer.name(),
        kernel: &format!(
            "{} (`--kernel {}`)",
            kernel_summary(&results.kernels),
            args.kernel.fixed().map_or("auto", Kernel::name)
        ),
        scale,
        quick: args.quick,
        seconds: results.seconds,
        references_rendered: results.references_rendered,
        references_cached: results.references_cached,
    };
    report::write_markdown(&out.join("results.md"), &run, &knobs)
}

/// The kernel the sweeps used: one name where they all used one, else
/// which sweeps used which.
fn kernel_summary(kernels: &[(Knob, String, Kernel)]) -> String {
    let Some((_, _, first)) = kernels.first() else {
        return "none (no sweeps)".to_string();
    };
    if kernels.iter().all(|(_, _, k)| k == first) {
        return first.to_string();
    }
    Kernel::ALL
        .iter()
        .map(|&kernel| {
            let sweeps: Vec<String> = kernels
                .iter()
                .filter(|(_, _, k)| *k == kernel)
                .map(|(knob, scene, _)| format!("{}/{scene}", knob.id()))
                .collect();
            format!("{kernel} for {}", sweeps.join(", "))
        })
        .collect::<Vec<_>>()
        .join("; ")
}
