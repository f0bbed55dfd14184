//! What runs on a farm's nodes: one task of a job (`marbre farm task DIR
//! I`). A task is idempotent: a file already written is left alone, and a
//! rerun or a requeue rewrites only its own file (written atomically, so
//! a killed task leaves none). A task that fails leaves its error in
//! `status/`, which the merge names.

use super::plan::{FarmPlan, Task};
use super::shown_path;
use anyhow::{Context, Result, anyhow, bail};
use marbre_core::capped_read::{PRESET, read_capped};
use marbre_core::scene::DenoiseQuality;
use marbre_render::final_render::{
    DEFAULT_MAX_TILE_PIXELS, FinalRender, Progress, RenderObserver, Stop, render_to_file,
};
use marbre_render::frame_sequence::Timing;
use marbre_render::gpu::GpuContext;
use marbre_render::session::load_scene;
use std::ops::ControlFlow;
use std::path::Path;

/// Runs task `index` of the job in `dir`, unless its file is written.
pub fn run_task(dir: &Path, index: u32) -> Result<()> {
    let plan = FarmPlan::read(dir)?;
    let task = plan.task(index)?;
    let output = plan.task_output(dir, &task);
    let note = FarmPlan::failure_note(dir, index);
    if output.is_file() {
        println!(
            "task {index}: {} is written already; nothing to do",
            shown_path(&output)
        );
        let _ = std::fs::remove_file(&note);
        return Ok(());
    }
    match trace(&plan, &task, &output) {
        Ok(()) => {
            let _ = std::fs::remove_file(&note);
            println!("task {index}: wrote {}", shown_path(&output));
            Ok(())
        }
        Err(e) => {
            // Best effort: the error itself goes to the task's log too.
            let _ = marbre_core::atomic_write::write_atomic(&note, format!("{e:#}\n").as_bytes());
            Err(e.context(format!("task {index} of {}", shown_path(dir))))
        }
    }
}

/// Traces `task` of `plan` to `output`, refused if the preset changed
/// since the job was written (its other tasks traced the old one).
fn trace(plan: &FarmPlan, task: &Task, output: &Path) -> Result<()> {
    let bytes = read_capped(&plan.preset, PRESET)
        .with_context(|| format!("reading the preset {}", shown_path(&plan.preset)))?;
    if marbre_core::render_record::fnv1a_hex(&bytes) != plan.preset_hash {
        bail!(
            "the preset {} changed since the job was written: its tasks would trace two \
             scenes; write the job again into a new folder",
            shown_path(&plan.preset)
        );
    }
    let loaded = load_scene(&plan.preset, None)?;
    let job = FinalRender {
        size: plan.size,
        stop: Stop::Samples(task.spp),
        auto_exposure: None,
        kernel: plan
            .kernel
            .parse()
            .map_err(|e| anyhow!("the plan's kernel: {e}"))?,
        output: output.to_path_buf(),
        denoise: None,
        denoise_quality: DenoiseQuality::High,
        denoise_exr: false,
        allow_placeholders: false,
        timing: Timing::Still {
            time: task.time,
            frame: task.frame,
        },
        sample_offset: task.sample_offset,
        tile: task.tile,
        max_tile_pixels: DEFAULT_MAX_TILE_PIXELS,
        moments: plan.moments,
        guides: plan.denoise,
    };
    let ctx = GpuContext::headless()?;
    render_to_file(&ctx, loaded, &job, &mut Log)?;
    Ok(())
}

/// A task's lines go to its log (the scheduler's output file).
struct Log;

impl RenderObserver for Log {
    fn note(&mut self, line: &str) {
        eprintln!("{line}");
    }

    fn progress(&mut self, _: &Progress) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}
