//! The `marbre` command line: the viewer, and headless tools around the same
//! renderer. The names of commands and flags are a contract: scripts and
//! tests rely on them.

use clap::{Args, Parser, Subcommand};
use marbre::app::soak::command as soak;
use marbre_commands::{
    accuracy_bench, bake, bvh_bench, convergence_bench, edit_bench, farm, merge, noise, parameters,
    presets_bench, render, tx,
};
use marbre_render::gpu::KernelChoice;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "marbre",
    version,
    about = "Interactive ray tracer for procedural textures"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    viewer: ViewerArgs,
}

#[derive(Args)]
struct ViewerArgs {
    /// Preset to open (default: presets/default.ron).
    #[arg(long)]
    preset: Option<PathBuf>,
    /// OBJ file to open as a new, unsaved scene: framed by the camera,
    /// with its MTL materials, and a default light if no material emits
    /// (Save then asks where to write the preset; the OBJ is never written).
    #[arg(long, value_name = "FILE", conflicts_with = "preset", value_parser = parse_obj_path)]
    obj: Option<PathBuf>,
    /// Environment map to use instead of the preset's.
    #[arg(long)]
    env: Option<PathBuf>,
    /// Run this many frames, then exit (for tests and scripts). A frame
    /// traces within the budget; an idle window shows only those with
    /// something new, and the closing `quality:` line counts both.
    #[arg(long)]
    exit_after_frames: Option<u64>,
    /// Exit once the image holds this many samples per pixel (tracing
    /// stops there): a run that ends when its image is done, however
    /// fast the machine traces.
    #[arg(long, value_parser = marbre_commands::parse_spp)]
    exit_after_spp: Option<u32>,
    /// Exit once the denoiser has made this many images.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    exit_after_denoised: Option<u32>,
    /// Save the whole window, UI included, as PNG just before exiting.
    #[arg(long, value_name = "FILE.png", value_parser = parse_window_screenshot)]
    window_screenshot: Option<PathBuf>,
    /// Development mode: read the WGSL files from the source tree
    /// (`shaders/`, and each CPU twin's beside it under `crates/`) and
    /// rebuild the trace pipeline
    /// when one changes (a shader that fails to build leaves the old
    /// pipeline, and the panel shows the error).
    #[arg(long)]
    dev: bool,
    /// The trace kernel: fragment, compute, cpu (native code on this
    /// machine's cores, for the scenes it traces), or auto (the fastest
    /// here, timed on the first scene and remembered).
    #[arg(long, default_value_t = KernelChoice::Auto, value_parser = marbre_commands::kernel_choice_parser())]
    kernel: KernelChoice,
    /// Trace time per frame in ms: the panel stays live while a slow
    /// adapter refines the image a band at a time; 0 traces a whole round
    /// of samples every frame.
    #[arg(long, default_value_t = marbre::app::DEFAULT_FRAME_BUDGET_MS, value_parser = marbre::app::parse_budget_ms)]
    frame_budget_ms: f32,
    /// Stop tracing at this many samples per pixel, as a render's sample
    /// count does (default: trace on, or to the Quality strip's target).
    #[arg(long, value_parser = marbre_commands::parse_spp)]
    max_spp: Option<u32>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a preset offscreen to PNG (tone-mapped) or EXR (linear radiance).
    Render(render::RenderArgs),
    /// Evaluate noise at `x,y,z` lines read from stdin, one value per line.
    Noise(noise::NoiseArgs),
    /// Render a TX text (the IFT528 report's texture language) on the
    /// report's preview scene, print it back, or render a gallery.
    Tx(tx::TxArgs),
    /// Bake one material property of one object to an image in its (u, v)
    /// square (sRGB PNG for colours, linear EXR for data), with the
    /// mapping written beside it.
    Bake(bake::BakeArgs),
    /// List every number of a preset a keyframe track can animate, by the
    /// path tracks name it with (as the panel's key buttons do), and its
    /// value (or the animation's value at --at T).
    Parameters(parameters::ParametersArgs),
    /// Put the sample batches and tiles of one render (`render
    /// --sample-offset` and `--tile` EXR files, as a farm writes them)
    /// together into one EXR or PNG, batches weighted by their samples,
    /// and print its estimated error.
    Merge(merge::MergeArgs),
    /// Cut a render into independent tasks for a render farm (frames,
    /// sample batches, tiles): write a Slurm job array or a Kubernetes
    /// Indexed Job with its merge, run one task, or merge a job.
    Farm(farm::FarmArgs),
    /// Accuracy against time: one knob at a time (samples, bounces, light
    /// selection, strategies, environment sampling, octaves, filtering,
    /// hash, shader), each variant's error against a cached high-spp
    /// reference; writes a CSV, a Markdown report and plots.
    Bench(accuracy_bench::AccuracyBenchArgs),
    /// Time every shipped preset at several resolutions.
    BenchPresets(presets_bench::PresetsBenchArgs),
    /// Build the BVH of a heavy generated mesh and time its GPU traversal.
    BenchBvh(bvh_bench::BvhBenchArgs),
    /// Time and error at increasing samples per pixel against a cached
    /// high-spp reference (default: the Cornell box at 512x512).
    BenchConvergence(convergence_bench::ConvergenceBenchArgs),
    /// The CPU cost of one frame of a slider drag: an edited scene handed
    /// to the renderer (parameter, camera and display edits).
    BenchEdit(edit_bench::EditBenchArgs),
    /// Run the viewer for many frames under seeded random edits, preset
    /// loads and a simulated device loss; fail if memory (RSS, GPU bytes,
    /// GPU objects) grows beyond a bound after the warm-up or wgpu reports
    /// a validation error.
    Soak(soak::SoakArgs),
}

/// `--obj`'s file: one ending in `.obj` (any case), which the viewer
/// opens as a mesh wherever it comes from (and reopens at the next start).
fn parse_obj_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
    {
        Ok(path)
    } else {
        Err(format!(
            "{text}: not an OBJ file (the name must end in .obj)"
        ))
    }
}

/// `--window-screenshot`'s file: a PNG that can be written there, checked
/// before the window opens as every other output is (issue 47): a name
/// not ending in `.png`, a missing folder, or a device node or FIFO
/// already there is refused, naming the file.
fn parse_window_screenshot(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    if marbre_core::image_io::ImageFormat::from_path(&path)
        .is_ok_and(|f| f == marbre_core::image_io::ImageFormat::Png)
    {
        marbre_core::image_io::check_output(&path).map_err(|e| format!("{e:#}"))?;
        Ok(path)
    } else {
        Err(format!(
            "{text}: a window screenshot is a PNG (the name must end in .png)"
        ))
    }
}

fn main() -> ExitCode {
    marbre::heap::limit_arenas();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    // Every command but the viewer and the soak (which open a window).
    if cli
        .command
        .as_ref()
        .is_some_and(|c| !matches!(c, Command::Soak(_)))
    {
        marbre::headless::quiet_device_select();
        // A save stopped half way leaves no temporary behind.
        if let Err(e) = marbre_commands::interrupt::remove_temporaries_on_signal() {
            eprintln!("marbre: warning: {e:#}");
        }
    }
    let result = match cli.command {
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Noise(args)) => noise::run(&args),
        Some(Command::Tx(args)) => tx::run(&args),
        Some(Command::Bake(args)) => bake::run(&args),
        Some(Command::Parameters(args)) => parameters::run(&args),
        Some(Command::Merge(args)) => merge::run(&args),
        Some(Command::Farm(args)) => farm::run(&args),
        Some(Command::Bench(args)) => accuracy_bench::run(&args),
        Some(Command::BenchPresets(args)) => presets_bench::run(&args),
        Some(Command::BenchBvh(args)) => bvh_bench::run(&args),
        Some(Command::BenchConvergence(args)) => convergence_bench::run(&args),
        Some(Command::BenchEdit(args)) => edit_bench::run(&args),
        Some(Command::Soak(args)) => soak::run(&args),
        None => marbre::app::run(marbre::app::ViewerOptions {
            preset: cli.viewer.preset,
            obj: cli.viewer.obj,
            env: cli.viewer.env,
            exit_after_frames: cli.viewer.exit_after_frames,
            exit_after_spp: cli.viewer.exit_after_spp,
            exit_after_denoised: cli.viewer.exit_after_denoised,
            window_screenshot: cli.viewer.window_screenshot,
            dev: cli.viewer.dev,
            soak: None,
            kernel: cli.viewer.kernel,
            frame_budget_ms: cli.viewer.frame_budget_ms,
            max_spp: cli.viewer.max_spp,
        }),
    };
    let mut code = match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("marbre: error: {e:#}");
            ExitCode::FAILURE
        }
    };
    if let Err(why) = marbre::exit_check::check() {
        eprintln!("marbre: error: {why}");
        code = ExitCode::FAILURE;
    }
    code
}
