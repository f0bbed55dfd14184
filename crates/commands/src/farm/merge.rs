//! `marbre farm merge DIR`, which follows every task: it checks that each
//! task wrote its file (naming those that failed or never ran) and that
//! each part's record is the one the plan gave its task, then merges each
//! frame's parts into its image.

use super::plan::{FarmPlan, Scheduler, Split, Task};
use super::shell::quoted;
use super::shown_path;
use anyhow::{Context, Result, anyhow, bail};
use marbre_core::capped_read::{FileKind, read_capped_to_string};
use marbre_core::merge::{Batch, merge};
use marbre_core::scene::{DenoiseQuality, Denoiser};
use marbre_core::shown::shown;
use marbre_core::tile::Tile;
use std::io::ErrorKind;
use std::path::Path;

/// A failed task's note: its error, a few lines.
const FAILURE_NOTE: FileKind = FileKind {
    name: "a failed task's note",
    max_bytes: 1 << 20,
};

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
                shown(&quoted(&dir.join("tasks.sbatch").to_string_lossy()))
            ),
            Scheduler::Kubernetes => format!(
                "with Kubernetes `sh {}` again (the finished indices do nothing)",
                shown(&quoted(&dir.join("submit-k8s.sh").to_string_lossy()))
            ),
        };
        bail!(
            "{} of the {} tasks of {} have no file; run them again, {rerun}:\n  {}",
            missing.len(),
            tasks.len(),
            shown_path(dir),
            describe_missing(dir, &plan, &missing).join("\n  ")
        );
    }
    if plan.parts() == 1 {
        println!(
            "every one of the {} frames of {} is written; nothing to merge",
            tasks.len(),
            shown_path(dir)
        );
        return Ok(());
    }
    // A frame that cannot be written is found before any is merged.
    for frame in plan.frame_numbers() {
        let output = plan.frame_output(dir, frame);
        marbre_core::atomic_write::check_writable(&output)
            .with_context(|| format!("cannot write {}", shown_path(&output)))?;
    }
    let display = load_scene_display(&plan)?;
    for frame in plan.frame_numbers() {
        let parts: Vec<_> = tasks
            .iter()
            .filter(|t| t.frame == frame)
            .map(|t| read_part(dir, &plan, t))
            .collect::<Result<_>>()?;
        let merged = merge(&parts).map_err(|e| anyhow!(e))?;
        let output = plan.frame_output(dir, frame);
        let how = crate::merge::MergedOutput {
            display,
            denoise: plan
                .denoise
                .then_some((Denoiser::Oidn, DenoiseQuality::High)),
        };
        crate::merge::write_merged(&merged, &output, &how)
            .with_context(|| format!("writing {}", shown_path(&output)))?;
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
            shown_path(&output),
            merged.record.spp
        );
    }
    Ok(())
}

/// Task `t`'s part, refused unless its record is the one the plan gave
/// the task: its frame, its samples and its tile of an image of the
/// plan's size. A part copied or renamed from another task's would
/// otherwise be merged as this one's.
fn read_part(dir: &Path, plan: &FarmPlan, t: &Task) -> Result<Batch> {
    let path = plan.task_output(dir, t);
    let part = crate::merge::read_batch(&path)?;
    let record = &part.record;
    let tile = t.tile.unwrap_or(Tile::whole(plan.size));
    let disagrees = [
        ("frame", record.frame.to_string(), t.frame.to_string()),
        (
            "samples",
            format!("{:?}", record.samples()),
            format!(
                "{:?}",
                u64::from(t.sample_offset)..u64::from(t.sample_offset + t.spp)
            ),
        ),
        (
            "image",
            format!("{}x{}", record.image.0, record.image.1),
            format!("{}x{}", plan.size.0, plan.size.1),
        ),
        ("tile", record.tile.to_string(), tile.to_string()),
    ]
    .into_iter()
    .filter(|(_, found, planned)| found != planned)
    .map(|(what, found, planned)| format!("{what} {found}, not {planned}"))
    .collect::<Vec<_>>();
    if !disagrees.is_empty() {
        bail!(
            "{}: its record disagrees with the plan of task {} ({}): {}; the file is another \
             task's or another job's: remove it and run task {} again",
            shown_path(&path),
            t.index,
            describe_task(plan, t),
            disagrees.join(", "),
            t.index
        );
    }
    Ok(part)
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
        let note = FarmPlan::failure_note(dir, t.index);
        match read_capped_to_string(&note, FAILURE_NOTE) {
            Ok(error) => {
                failed += 1;
                if failed <= FAILURES_LISTED {
                    lines.push(format!(
                        "task {} ({}) FAILED: {}",
                        t.index,
                        describe_task(plan, t),
                        shown(error.lines().next().unwrap_or(""))
                    ));
                }
            }
            Err(e) if e.kind() == ErrorKind::NotFound => not_run.push(t.index),
            Err(e) => {
                failed += 1;
                if failed <= FAILURES_LISTED {
                    lines.push(format!(
                        "task {} ({}) FAILED, and its note {} cannot be read: {e}",
                        t.index,
                        describe_task(plan, t),
                        shown_path(&note)
                    ));
                }
            }
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
            shown_path(&plan.task_output(dir, first))
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
        .with_context(|| format!("reading the preset {}", shown_path(&plan.preset)))?
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
