//! What runs on a farm's nodes: one task of a job (`marbre farm task DIR
//! I`), and the merge that follows every task (`marbre farm merge DIR`).
//! A task is idempotent: a file already written is left alone, and a
//! rerun or a requeue rewrites only its own file (written atomically, so
//! a killed task leaves none). A task that fails leaves its error in
//! `status/`, which the merge names.

use super::plan::{FarmPlan, Scheduler, Split, Task};
use anyhow::{Context, Result, anyhow, bail};
use marbre_core::merge::merge;
use marbre_core::scene::{DenoiseQuality, Denoiser};
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
            output.display()
        );
        let _ = std::fs::remove_file(&note);
        return Ok(());
    }
    match trace(&plan, &task, &output) {
        Ok(()) => {
            let _ = std::fs::remove_file(&note);
            println!("task {index}: wrote {}", output.display());
            Ok(())
        }
        Err(e) => {
            // Best effort: the error itself goes to the task's log too.
            let _ = marbre_core::atomic_write::write_atomic(&note, format!("{e:#}\n").as_bytes());
            Err(e.context(format!("task {index} of {}", dir.display())))
        }
    }
}

/// Traces `task` of `plan` to `output`, refused if the preset changed
/// since the job was written (its other tasks traced the old one).
fn trace(plan: &FarmPlan, task: &Task, output: &Path) -> Result<()> {
    let bytes = std::fs::read(&plan.preset)
        .with_context(|| format!("reading the preset {}", plan.preset.display()))?;
    if marbre_core::render_record::fnv1a_hex(&bytes) != plan.preset_hash {
        bail!(
            "the preset {} changed since the job was written: its tasks would trace two \
             scenes; write the job again into a new folder",
            plan.preset.display()
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

/// Checks that every task of the job in `dir` wrote its file, naming those
/// that failed (with their error) or never ran, then merges each frame's
/// parts into its image.
pub fn merge_job(dir: &Path) -> Result<()> {
    let plan = FarmPlan::read(dir)?;
    let tasks: Vec<Task> = (0..plan.tasks())
        .map(|i| plan.task(i))
        .collect::<Result<_>>()?;
    let missing: Vec<&Task> = tasks
        .iter()
        .filter(|t| !plan.task_output(dir, t).is_file())
        .collect();
    if !missing.is_empty() {
        let indices = index_ranges(missing.iter().map(|t| t.index));
        let rerun = match plan.scheduler {
            Scheduler::Slurm => format!(
                "with Slurm `sbatch --array={indices} {}`, then the merge again",
                dir.join("tasks.sbatch").display()
            ),
            Scheduler::Kubernetes => format!(
                "with Kubernetes `sh {}` again (the finished indices do nothing)",
                dir.join("submit-k8s.sh").display()
            ),
        };
        bail!(
            "{} of the {} tasks of {} have no file; run them again, {rerun}:\n  {}",
            missing.len(),
            tasks.len(),
            dir.display(),
            describe_missing(dir, &plan, &missing).join("\n  ")
        );
    }
    if plan.parts() == 1 {
        println!(
            "every one of the {} frames of {} is written; nothing to merge",
            tasks.len(),
            dir.display()
        );
        return Ok(());
    }
    let display = load_scene_display(&plan)?;
    for frame in plan.frame_numbers() {
        let parts: Vec<_> = tasks
            .iter()
            .filter(|t| t.frame == frame)
            .map(|t| crate::merge::read_batch(&plan.task_output(dir, t)))
            .collect::<Result<_>>()?;
        let merged = merge(&parts).map_err(|e| anyhow!(e))?;
        let output = plan.frame_output(dir, frame);
        let how = crate::merge::MergedOutput {
            display,
            denoise: plan
                .denoise
                .then_some((Denoiser::Oidn, DenoiseQuality::High)),
        };
        crate::merge::write_merged(&merged, &output, &how)?;
        let error = merged.error.map_or(String::new(), |e| {
            format!(
                "; estimated relative error {:.3} % (RMSE {:.5})",
                100.0 * e.relative,
                e.rmse
            )
        });
        println!(
            "frame {frame}: merged {} parts into {} at {} spp{error}",
            parts.len(),
            output.display(),
            merged.record.spp
        );
    }
    Ok(())
}

/// The most failed tasks named one by one.
const FAILURES_LISTED: usize = 20;

/// Why the `missing` tasks have no file: each failed one with its error
/// (up to [`FAILURES_LISTED`]), then the others, which did not run or did
/// not finish, as ranges of indices.
fn describe_missing(dir: &Path, plan: &FarmPlan, missing: &[&Task]) -> Vec<String> {
    let mut lines = Vec::new();
    let mut not_run = Vec::new();
    let mut failed = 0;
    for t in missing {
        match std::fs::read_to_string(FarmPlan::failure_note(dir, t.index)) {
            Ok(error) => {
                failed += 1;
                if failed <= FAILURES_LISTED {
                    lines.push(format!(
                        "task {} ({}) FAILED: {}",
                        t.index,
                        describe_task(plan, t),
                        error.lines().next().unwrap_or("")
                    ));
                }
            }
            Err(_) => not_run.push(t.index),
        }
    }
    if failed > FAILURES_LISTED {
        lines.push(format!(
            "and {} more failed tasks",
            failed - FAILURES_LISTED
        ));
    }
    if let Some(first) = missing.iter().find(|t| not_run.contains(&t.index)) {
        lines.push(format!(
            "tasks {} did not run or did not finish (no file, no error; the first: {})",
            index_ranges(not_run.iter().copied()),
            plan.task_output(dir, first).display()
        ));
    }
    lines
}

/// What task `t` traces, in words.
fn describe_task(plan: &FarmPlan, t: &Task) -> String {
    match plan.split {
        Split::Whole => format!("frame {}", t.frame),
        Split::Batches { .. } => format!(
            "frame {}, samples {}..{}",
            t.frame,
            t.sample_offset,
            t.sample_offset + t.spp
        ),
        Split::Tiles(_) => format!(
            "frame {}, tile {}",
            t.frame,
            t.tile.map_or(String::new(), |tile| tile.to_string())
        ),
    }
}

/// Increasing indices as Slurm's `--array` writes them: `0-3,7,9-10`.
fn index_ranges(indices: impl Iterator<Item = u32>) -> String {
    let mut ranges: Vec<(u32, u32)> = Vec::new();
    for i in indices {
        match ranges.last_mut() {
            Some((_, end)) if *end + 1 == i => *end = i,
            _ => ranges.push((i, i)),
        }
    }
    ranges
        .iter()
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}-{b}")
            }
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// The preset's display, which a merged PNG is shown with.
fn load_scene_display(plan: &FarmPlan) -> Result<marbre_core::scene::DisplaySettings> {
    Ok(marbre_core::preset::load(&plan.preset)
        .with_context(|| format!("reading the preset {}", plan.preset.display()))?
        .preset
        .scene
        .render
        .shown_display())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_are_written_as_slurm_ranges() {
        assert_eq!(
            index_ranges([0, 1, 2, 3, 7, 9, 10].into_iter()),
            "0-3,7,9-10"
        );
        assert_eq!(index_ranges([5].into_iter()), "5");
    }
}
