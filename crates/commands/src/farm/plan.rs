//! A farm job's plan (`DIR/farm.ron`): what the render is and how it is
//! cut into tasks. Every task and the merge read it, so that the mapping
//! from an array index to a frame and a part of it (a sample batch or a
//! tile) is written in one place, not in each scheduler's script.

use super::shown_path;
use anyhow::{Context, Result, bail};
use marbre_core::capped_read::{FileKind, read_capped_to_string};
use marbre_core::image_io::ImageFormat;
use marbre_core::tile::{Tile, TileGrid};
use serde::{Deserialize, Serialize};
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

/// The plan's file name in the job's folder.
pub const PLAN_FILE: &str = "farm.ron";

/// A plan is a few hundred bytes.
const PLAN: FileKind = FileKind {
    name: "a farm plan",
    max_bytes: 1 << 20,
};

/// How each frame is cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Split {
    /// One task traces the whole frame.
    Whole,
    /// `batches` tasks each trace `spp / batches` samples from their own
    /// offset (`render --sample-offset`).
    Batches { batches: u32 },
    /// One task per tile of a grid (`render --tiles`).
    Tiles(TileGrid),
}

/// Who runs the tasks: what `farm merge` tells to run again.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Scheduler {
    Slurm,
    Kubernetes,
}

/// The most tasks a job may have: far more than a scheduler runs at once
/// (Slurm's default `MaxArraySize` is 1001), and few enough that every
/// count fits a `u32`.
pub const MAX_TASKS: u64 = 1 << 20;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FarmPlan {
    /// The preset, as an absolute path: the nodes read it from the shared
    /// folder.
    pub preset: PathBuf,
    /// Its bytes' FNV-1a hash when the job was written: a preset edited
    /// since is another job, whose folder must not hold this one's files.
    pub preset_hash: String,
    pub size: (u32, u32),
    /// Samples per pixel of each frame, all its tasks together.
    pub spp: u32,
    pub split: Split,
    /// The animation frames to render (both ends included); `None`: one
    /// still, frame 0 at time 0.
    pub frames: Option<RangeInclusive<u32>>,
    /// Frames a second, which place a frame in time.
    pub fps: f32,
    /// `fragment`, `compute` or `auto`.
    pub kernel: String,
    /// The merged images' format: `exr` (linear radiance) or `png`.
    pub format: String,
    /// Each part records its variance (`render --moments`), so that a
    /// merge of single-batch tiles knows its error.
    pub moments: bool,
    /// Each part records the denoiser's guides (`render --guides`) and the
    /// merge denoises.
    pub denoise: bool,
    pub scheduler: Scheduler,
}

/// What one array index traces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Task {
    pub index: u32,
    pub frame: u32,
    pub time: f32,
    /// Which batch or tile of the frame (0 when whole).
    pub part: u32,
    pub spp: u32,
    pub sample_offset: u32,
    pub tile: Option<Tile>,
}

impl FarmPlan {
    /// An error if the plan cannot be cut as it says: batches that do not
    /// divide the samples, a grid finer than the image or of one tile,
    /// too many tasks, layers asked of a job without a merge.
    pub fn check(&self) -> Result<()> {
        if !(1..=16384).contains(&self.size.0) || !(1..=16384).contains(&self.size.1) {
            bail!(
                "a {}×{} image: each side must be 1 to 16384",
                self.size.0,
                self.size.1
            );
        }
        match self.split {
            Split::Whole => {}
            Split::Batches { batches } => {
                if batches < 2 || !self.spp.is_multiple_of(batches) {
                    bail!(
                        "--batches {batches} must be 2 or more and divide --spp {} (each batch \
                         traces spp / batches samples)",
                        self.spp
                    );
                }
            }
            Split::Tiles(grid) => {
                if grid.count() == 1 {
                    bail!("--tiles 1x1 is the whole image: leave --tiles out");
                }
                grid.tile(self.size, 0)
                    .map_err(|e| anyhow::anyhow!("--tiles: {e}"))?;
            }
        }
        if self.task_count() > MAX_TASKS {
            bail!(
                "{} tasks ({} frames × {} parts) are more than a job may have ({MAX_TASKS}): \
                 cut coarser or split the frames into several jobs",
                self.task_count(),
                self.frame_count(),
                self.parts()
            );
        }
        if (self.moments || self.denoise) && self.parts() == 1 {
            bail!(
                "--moments and --denoise act on the merge of a frame's parts: cut the frames \
                 into --batches or --tiles"
            );
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            bail!("--fps must be a positive number of frames a second");
        }
        self.kernel
            .parse::<marbre_render::gpu::KernelChoice>()
            .map_err(|e| anyhow::anyhow!("the kernel `{}`: {e}", self.kernel))?;
        ImageFormat::from_path(Path::new(&format!("x.{}", self.format)))?;
        Ok(())
    }

    fn frame_count(&self) -> u64 {
        let frames = self.frame_numbers();
        u64::from(frames.end() - frames.start()) + 1
    }

    fn task_count(&self) -> u64 {
        self.frame_count() * u64::from(self.parts())
    }

    /// Tasks a frame is cut into.
    pub fn parts(&self) -> u32 {
        match self.split {
            Split::Whole => 1,
            Split::Batches { batches } => batches,
            Split::Tiles(grid) => grid.count(),
        }
    }

    /// The frames traced, in order.
    pub fn frame_numbers(&self) -> RangeInclusive<u32> {
        self.frames.clone().unwrap_or(0..=0)
    }

    /// Tasks in all: the array's length (at most [`MAX_TASKS`] in a
    /// checked plan).
    pub fn tasks(&self) -> u32 {
        self.task_count().min(MAX_TASKS) as u32
    }

    /// What array index `index` traces: frame after frame, and each
    /// frame's parts in order.
    pub fn task(&self, index: u32) -> Result<Task> {
        if index >= self.tasks() {
            bail!(
                "task {index} is out of range: the job has tasks 0 to {}",
                self.tasks() - 1
            );
        }
        let parts = self.parts();
        let (frame, part) = (self.frame_numbers().start() + index / parts, index % parts);
        let (spp, sample_offset, tile) = match self.split {
            Split::Whole => (self.spp, 0, None),
            Split::Batches { batches } => {
                let each = self.spp / batches;
                (each, part * each, None)
            }
            Split::Tiles(grid) => {
                let tile = grid.tile(self.size, part).map_err(|e| anyhow::anyhow!(e))?;
                (self.spp, 0, Some(tile))
            }
        };
        Ok(Task {
            index,
            frame,
            time: if self.frames.is_some() {
                frame as f32 / self.fps
            } else {
                0.0
            },
            part,
            spp,
            sample_offset,
            tile,
        })
    }

    /// The file a task writes in the job's folder `dir`: the frame itself
    /// when it is one task, else a part (always EXR) for the merge.
    pub fn task_output(&self, dir: &Path, task: &Task) -> PathBuf {
        if self.parts() == 1 {
            self.frame_output(dir, task.frame)
        } else {
            dir.join("parts")
                .join(format!("frame_{:04}_part_{:03}.exr", task.frame, task.part))
        }
    }

    /// The finished image of `frame`.
    pub fn frame_output(&self, dir: &Path, frame: u32) -> PathBuf {
        if self.frames.is_some() {
            dir.join("frames")
                .join(format!("frame_{frame:04}.{}", self.format))
        } else {
            dir.join(format!("image.{}", self.format))
        }
    }

    /// Where a failed task leaves its error, for the merge to name.
    pub fn failure_note(dir: &Path, index: u32) -> PathBuf {
        dir.join("status").join(format!("task_{index}.failed"))
    }

    /// The plan as `farm.ron` holds it (paths as RON strings, which is
    /// why a job's paths must be UTF-8: [`super::carry::path_text`]).
    pub fn text(&self) -> Result<String> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
            .context("writing the plan as RON")
    }

    /// The plan of the job in `dir`, read through the capped reader: a
    /// FIFO or a device in its place is refused rather than waited on or
    /// read without end.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(PLAN_FILE);
        let text = read_capped_to_string(&path, PLAN).with_context(|| {
            format!(
                "reading {}: is {} a folder `marbre farm` wrote?",
                shown_path(&path),
                shown_path(dir)
            )
        })?;
        let plan: Self =
            ron::from_str(&text).with_context(|| format!("reading {}", shown_path(&path)))?;
        plan.check()
            .with_context(|| format!("{} is not a plan marbre can run", shown_path(&path)))?;
        Ok(plan)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(split: Split, frames: Option<RangeInclusive<u32>>) -> FarmPlan {
        FarmPlan {
            preset: PathBuf::from("/shared/p.ron"),
            preset_hash: "0123456789abcdef".into(),
            size: (64, 48),
            spp: 64,
            split,
            frames,
            fps: 24.0,
            kernel: "auto".into(),
            format: "exr".into(),
            moments: false,
            denoise: false,
            scheduler: Scheduler::Slurm,
        }
    }

    /// Index → frame and part, frame after frame: batches take their
    /// offsets, tiles their grid cell, frames their time.
    #[test]
    fn indices_map_to_frames_and_parts() {
        let p = plan(Split::Batches { batches: 4 }, Some(10..=12));
        assert_eq!(p.tasks(), 12);
        let t = p.task(6).unwrap();
        assert_eq!((t.frame, t.part, t.spp, t.sample_offset), (11, 2, 16, 32));
        assert!((t.time - 11.0 / 24.0).abs() < 1e-6);
        let e = p.task(12).unwrap_err().to_string();
        assert!(e.contains("tasks 0 to 11"), "{e}");
        let p = plan(
            Split::Tiles(TileGrid {
                columns: 2,
                rows: 2,
            }),
            None,
        );
        let t = p.task(3).unwrap();
        assert_eq!(t.tile, Some(Tile::parse("32,24,64,48").unwrap()));
        assert_eq!((t.frame, t.time, t.spp), (0, 0.0, 64));
        let dir = Path::new("/job");
        assert_eq!(
            p.task_output(dir, &t),
            dir.join("parts/frame_0000_part_003.exr")
        );
        assert_eq!(p.frame_output(dir, 0), dir.join("image.exr"));
        let p = plan(Split::Whole, Some(0..=3));
        let t = p.task(2).unwrap();
        assert_eq!(p.task_output(dir, &t), dir.join("frames/frame_0002.exr"));
    }

    #[test]
    fn plans_that_cannot_be_cut_are_refused() {
        let e = plan(Split::Batches { batches: 5 }, None)
            .check()
            .unwrap_err();
        assert!(e.to_string().contains("divide --spp 64"), "{e}");
        let e = plan(
            Split::Tiles(TileGrid {
                columns: 65,
                rows: 1,
            }),
            None,
        )
        .check()
        .unwrap_err();
        assert!(format!("{e:#}").contains("does not divide"), "{e:#}");
        let mut p = plan(Split::Whole, None);
        p.format = "jpg".into();
        assert!(p.check().is_err());
        let e = plan(
            Split::Tiles(TileGrid {
                columns: 1,
                rows: 1,
            }),
            None,
        )
        .check()
        .unwrap_err();
        assert!(e.to_string().contains("1x1"), "{e}");
        let e = plan(
            Split::Tiles(TileGrid {
                columns: 64,
                rows: 48,
            }),
            Some(0..=999),
        )
        .check()
        .unwrap_err();
        assert!(e.to_string().contains("3072000 tasks"), "{e}");
        let e = plan(Split::Whole, Some(0..=u32::MAX)).check().unwrap_err();
        assert!(e.to_string().contains("more than a job may have"), "{e}");
        let mut p = plan(Split::Whole, None);
        p.moments = true;
        assert!(
            p.check()
                .unwrap_err()
                .to_string()
                .contains("--batches or --tiles")
        );
        let mut p = plan(Split::Whole, None);
        p.kernel = "fast".into();
        assert!(p.check().unwrap_err().to_string().contains("fast"));
    }

    #[test]
    fn a_plan_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let p = plan(
            Split::Tiles(TileGrid {
                columns: 4,
                rows: 2,
            }),
            Some(0..=9),
        );
        std::fs::write(dir.path().join(PLAN_FILE), p.text().unwrap()).unwrap();
        assert_eq!(FarmPlan::read(dir.path()).unwrap(), p);
        let e = FarmPlan::read(&dir.path().join("nowhere")).unwrap_err();
        assert!(
            e.to_string().contains("a folder `marbre farm` wrote"),
            "{e}"
        );
    }
}
