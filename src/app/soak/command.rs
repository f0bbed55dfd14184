//! `marbre soak`: the viewer window under seeded random edits for many
//! frames, its memory judged at the end (see `app::soak`).

use super::{DEFAULT_PRESETS, SoakOptions};
use crate::app::{ViewerOptions, run as run_viewer};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct SoakArgs {
    /// Frames to run.
    #[arg(long, default_value_t = 10_000)]
    pub frames: u64,
    /// Seeds the random edits: the same seed replays the same run.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Presets to load in turn: .ron files or folders of them (default: a
    /// handful of the repository's quick ones, under presets/).
    #[arg(long, num_args = 1..)]
    pub presets: Vec<PathBuf>,
    /// The preset to start from (default: presets/default.ron).
    #[arg(long)]
    pub preset: Option<PathBuf>,
    /// Frames before memory is held to its baseline (default: a fifth of
    /// the run, at least 50, at most 2000, at most half the run).
    #[arg(long)]
    pub warm_up: Option<u64>,
    /// Write the memory of every frame to this CSV file.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// The trace kernel, as the viewer's `--kernel`.
    #[arg(
        long,
        default_value_t = marbre_render::gpu::KernelChoice::Auto,
        value_parser = marbre_commands::kernel_choice_parser()
    )]
    pub kernel: marbre_render::gpu::KernelChoice,
    /// Trace time per frame in ms, as the viewer's `--frame-budget-ms`.
    #[arg(long, default_value_t = crate::app::DEFAULT_FRAME_BUDGET_MS, value_parser = crate::app::parse_budget_ms)]
    pub frame_budget_ms: f32,
}

pub fn run(args: &SoakArgs) -> Result<()> {
    let presets = if args.presets.is_empty() {
        DEFAULT_PRESETS.iter().map(PathBuf::from).collect()
    } else {
        args.presets.clone()
    };
    let soak = SoakOptions {
        frames: args.frames,
        seed: args.seed,
        presets: SoakOptions::preset_files(&presets)?,
        warm_up_frames: args
            .warm_up
            .unwrap_or_else(|| SoakOptions::default_warm_up(args.frames)),
        report: args.report.clone(),
    };
    run_viewer(ViewerOptions {
        preset: args.preset.clone(),
        soak: Some(soak),
        kernel: args.kernel,
        frame_budget_ms: args.frame_budget_ms,
        ..ViewerOptions::default()
    })
}
