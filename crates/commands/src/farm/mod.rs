//! `marbre farm`: a render cut into independent tasks (frames, sample
//! batches, tiles) for a render farm (issue 30). `farm slurm` and `farm
//! k8s` write the job's plan and the scheduler's files into a shared
//! folder; on the nodes, `farm task DIR I` traces task I and `farm merge
//! DIR` checks that every task wrote its file and merges each frame.

mod carry;
mod job_folder;
mod merge;
mod plan;
mod scripts;
mod shell;
mod task;

use plan::{FarmPlan, Scheduler, Split};
use scripts::{KubernetesOptions, SlurmOptions};
use shell::quoted;

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use marbre_core::capped_read::{PRESET, read_capped};
use marbre_core::tile::TileGrid;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct FarmArgs {
    #[command(subcommand)]
    pub command: FarmCommand,
}

#[derive(Subcommand, Debug)]
pub enum FarmCommand {
    /// Write a Slurm job: a job array of the tasks, a merge job after them
    /// (afterok), and submit.sh, which submits both.
    Slurm {
        #[command(flatten)]
        job: JobArgs,
        /// The partition to run in.
        #[arg(long)]
        partition: Option<String>,
        /// Generic resources each task asks for, such as gpu:1.
        #[arg(long)]
        gres: Option<String>,
        /// Each task's time limit, as sbatch --time takes it.
        #[arg(long)]
        time: Option<String>,
        /// CPUs per task (lavapipe's threads follow it).
        #[arg(long)]
        cpus: Option<u32>,
        /// marbre's path on the nodes (default: this binary's).
        #[arg(long)]
        marbre: Option<PathBuf>,
    },
    /// Write a Kubernetes Indexed Job of the tasks, a merge Job, and
    /// submit-k8s.sh, which applies the first, waits, then the second.
    K8s {
        #[command(flatten)]
        job: JobArgs,
        /// The container image with marbre on its PATH.
        #[arg(long)]
        image: String,
        /// The persistent volume claim that holds the job's folder and the
        /// preset.
        #[arg(long)]
        claim: String,
        /// Where the claim is mounted in the pods, the same path as on this
        /// machine (default: the deepest folder holding both the job's
        /// folder and the preset).
        #[arg(long)]
        mount: Option<PathBuf>,
        /// Tasks running at once.
        #[arg(long, default_value_t = 8)]
        parallelism: u32,
        /// GPUs per task (nvidia.com/gpu); 0 for lavapipe on the CPU.
        #[arg(long, default_value_t = 1)]
        gpus: u32,
        /// CPUs per task.
        #[arg(long, default_value_t = 4)]
        cpus: u32,
    },
    /// Trace task INDEX of the job in DIR (what a node runs); a task whose
    /// file is written already does nothing. Without INDEX, the index the
    /// scheduler gives: JOB_COMPLETION_INDEX (a Kubernetes Indexed Job's
    /// pod) or SLURM_ARRAY_TASK_ID (a Slurm array's task).
    Task { dir: PathBuf, index: Option<u32> },
    /// Check that every task of the job in DIR wrote its file (naming
    /// those that failed or never ran) and merge each frame's parts.
    Merge { dir: PathBuf },
}

/// What to render and how to cut it.
#[derive(Args, Debug)]
pub struct JobArgs {
    /// The preset to render (it must be readable from the nodes).
    #[arg(long)]
    pub preset: PathBuf,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, value_parser = crate::render::parse_size)]
    pub size: (u32, u32),
    /// Samples per pixel of each frame, all its tasks together.
    #[arg(long, default_value_t = 64, value_parser = crate::parse_spp)]
    pub spp: u32,
    /// Cut each frame into this many sample batches (they must divide
    /// --spp).
    #[arg(long, conflicts_with = "tiles")]
    pub batches: Option<u32>,
    /// Cut each frame into a COLUMNSxROWS grid of tiles.
    #[arg(long, value_name = "CxR", value_parser = TileGrid::parse)]
    pub tiles: Option<TileGrid>,
    /// The animation frames FIRST..LAST (both included); without it, one
    /// still.
    #[arg(long, value_parser = marbre_render::frame_sequence::parse_frame_range)]
    pub frames: Option<std::ops::RangeInclusive<u32>>,
    /// Frames a second (default: the preset's animation's, else 24).
    #[arg(long)]
    pub fps: Option<f32>,
    /// The trace kernel: fragment, compute, cpu or auto.
    #[arg(long, default_value = "auto", value_parser = crate::kernel_choice_parser())]
    pub kernel: marbre_render::gpu::KernelChoice,
    /// The finished images' format: exr (linear radiance) or png.
    #[arg(long, default_value = "exr", value_parser = ["exr", "png"])]
    pub format: String,
    /// Each part records its variance (`render --moments`), so that the
    /// merge of single-batch tiles knows its error.
    #[arg(long)]
    pub moments: bool,
    /// Each part records the denoiser's guides (`render --guides`) and the
    /// merge denoises each frame.
    #[arg(long)]
    pub denoise: bool,
    /// The job's folder, shared with the nodes: the plan, the scripts,
    /// the tasks' files, logs and the finished images go there.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &FarmArgs) -> Result<()> {
    match &args.command {
        FarmCommand::Slurm {
            job,
            partition,
            gres,
            time,
            cpus,
            marbre,
        } => {
            let marbre = match marbre {
                Some(path) => path.clone(),
                None => std::env::current_exe().context("finding marbre's own path")?,
            };
            let options = SlurmOptions {
                partition: partition.clone(),
                gres: gres.clone(),
                time: time.clone(),
                cpus: *cpus,
            };
            // Checked before anything is written.
            let dir = absolute(&job.output)?;
            carry::slurm_folder(&dir)?;
            carry::path_text("--preset", &job.preset)?;
            carry::path_text("--marbre", &marbre)?;
            for (flag, value) in options.given() {
                carry::slurm_value(flag, value)?;
            }
            let plan = plan_job(job, Scheduler::Slurm, &dir)?;
            write_job(&dir, &plan, scripts::slurm(&plan, &dir, &marbre, &options))?;
            println!(
                "wrote a Slurm job of {} tasks to {}: submit it with `sh {}`",
                plan.tasks(),
                dir.display(),
                quoted(&dir.join("submit.sh").to_string_lossy())
            );
            Ok(())
        }
        FarmCommand::K8s {
            job,
            image,
            claim,
            mount,
            parallelism,
            gpus,
            cpus,
        } => {
            // Checked before anything is written.
            let (dir, preset) = (absolute(&job.output)?, absolute(&job.preset)?);
            carry::path_text("the job's folder (-o)", &dir)?;
            carry::path_text("--preset", &preset)?;
            carry::image(image)?;
            carry::claim(claim)?;
            let mount = match mount {
                Some(path) => absolute(path)?,
                None => shared_folder(&dir, &preset)?,
            };
            carry::path_text("--mount", &mount)?;
            for (what, path) in [("the job's folder", &dir), ("the preset", &preset)] {
                if !path.starts_with(&mount) {
                    bail!(
                        "{what} {} is not under the claim's mount {}: the pods would not see it",
                        path.display(),
                        mount.display()
                    );
                }
            }
            let plan = plan_job(job, Scheduler::Kubernetes, &dir)?;
            let options = KubernetesOptions {
                image: image.clone(),
                claim: claim.clone(),
                mount,
                parallelism: (*parallelism).max(1),
                gpus: *gpus,
                cpus: (*cpus).max(1),
            };
            write_job(&dir, &plan, scripts::kubernetes(&plan, &dir, &options))?;
            println!(
                "wrote a Kubernetes job of {} tasks to {}: run it with `sh {}`",
                plan.tasks(),
                dir.display(),
                quoted(&dir.join("submit-k8s.sh").to_string_lossy())
            );
            Ok(())
        }
        FarmCommand::Task { dir, index } => task::run_task(dir, task_index(*index)?),
        FarmCommand::Merge { dir } => merge::merge_job(dir),
    }
}

/// `path`, absolute, so that the nodes find it.
fn absolute(path: &Path) -> Result<PathBuf> {
    std::path::absolute(path).with_context(|| format!("making {} absolute", shown_path(path)))
}

/// `path` as a message shows it: lossy where it is not UTF-8, its control
/// characters escaped (a folder's name must not drive the terminal).
fn shown_path(path: &Path) -> String {
    marbre_core::shown::shown(&path.to_string_lossy())
}

/// The schedulers' variables that hold a task's index, in the order read.
const INDEX_VARIABLES: [&str; 2] = ["JOB_COMPLETION_INDEX", "SLURM_ARRAY_TASK_ID"];

/// The task index given, or the one the scheduler set.
fn task_index(given: Option<u32>) -> Result<u32> {
    if let Some(index) = given {
        return Ok(index);
    }
    for name in INDEX_VARIABLES {
        if let Ok(value) = std::env::var(name) {
            return value
                .trim()
                .parse()
                .with_context(|| format!("{name}={value:?} is not a task index"));
        }
    }
    bail!(
        "no task index: give it (`marbre farm task DIR 3`), or run under a Kubernetes Indexed \
         Job or a Slurm array ({} unset)",
        INDEX_VARIABLES.join(" and ")
    )
}

/// The deepest folder holding both `dir` and `preset`, where a claim
/// mounted serves both; refused when that is the root.
fn shared_folder(dir: &Path, preset: &Path) -> Result<PathBuf> {
    let shared: PathBuf = dir
        .components()
        .zip(preset.components())
        .take_while(|(a, b)| a == b)
        .map(|(a, _)| a)
        .collect();
    if shared.parent().is_none() {
        bail!(
            "the job's folder {} and the preset {} share no folder but the root: give \
             --mount, the folder the claim holds",
            dir.display(),
            preset.display()
        );
    }
    Ok(shared)
}

/// The job's plan from the flags, checked: the preset read (through
/// the capped reader), batches that start on a round of its samples, and
/// the job's folder `dir` holding no other job. Nothing is written.
fn plan_job(job: &JobArgs, scheduler: Scheduler, dir: &Path) -> Result<FarmPlan> {
    let preset_path = absolute(&job.preset)?;
    let preset = marbre_core::preset::load(&preset_path)
        .with_context(|| format!("reading the preset {}", shown_path(&preset_path)))?
        .preset;
    let bytes = read_capped(&preset_path, PRESET)
        .with_context(|| format!("reading the preset {}", shown_path(&preset_path)))?;
    let plan = FarmPlan {
        preset_hash: marbre_core::render_record::fnv1a_hex(&bytes),
        preset: preset_path,
        size: job.size,
        spp: job.spp,
        split: match (job.batches, job.tiles) {
            (Some(batches), _) => Split::Batches { batches },
            (None, Some(grid)) => Split::Tiles(grid),
            (None, None) => Split::Whole,
        },
        frames: job.frames.clone(),
        fps: job
            .fps
            .or(preset.scene.animation.as_ref().map(|a| a.fps))
            .unwrap_or(24.0),
        kernel: job.kernel.to_string(),
        format: job.format.clone(),
        moments: job.moments,
        denoise: job.denoise,
        scheduler,
    };
    plan.check()?;
    let per_round = preset.scene.render.samples_per_frame.max(1);
    let per_task = plan.task(0)?.spp;
    if let Split::Batches { .. } = plan.split
        && !per_task.is_multiple_of(per_round)
    {
        bail!(
            "each batch traces {per_task} samples, not a multiple of the preset's \
             samples_per_frame ({per_round}): a batch starts where a round of the long render \
             starts"
        );
    }
    if plan.moments && per_task <= per_round {
        bail!(
            "--moments measures each part's spread over its rounds, and each part traces \
             {per_task} samples, one round of the preset's {per_round}: give more --spp"
        );
    }
    // Tasks skip the files already written: a folder holding another
    // job's parts would hand them to this job's merge.
    if std::fs::symlink_metadata(dir.join(plan::PLAN_FILE)).is_ok() {
        let existing = FarmPlan::read(dir)?;
        if existing != plan {
            bail!(
                "{} already holds another job (its {} differs from this one's); give a new \
                 folder, or remove that one",
                shown_path(dir),
                plan::PLAN_FILE
            );
        }
    }
    Ok(plan)
}

/// Writes the job's plan and its scheduler's `files` into `dir`, or,
/// when a write fails, nothing new ([`job_folder::write`]).
fn write_job(dir: &Path, plan: &FarmPlan, files: Vec<(&str, String)>) -> Result<()> {
    let mut all = vec![(plan::PLAN_FILE, plan.text()?)];
    all.extend(files);
    job_folder::write(dir, &all)
}
