//! `marbre farm slurm` on a real Slurm cluster (issue 30): a one-node
//! cluster on 127.0.0.1 (`slurm_cluster`) runs the job arrays `farm slurm`
//! writes, with the marbre binary on lavapipe. A 4-batch sample array and
//! its merge give the direct render of all the samples, a 4-tile array
//! (with --moments) the direct render bit for bit and an error estimate;
//! a 4-task frame
//! array gives each frame as a direct render of it (a task also takes its
//! index from JOB_COMPLETION_INDEX, as a Kubernetes pod); a task that fails
//! shows FAILED, the merge after it is cancelled, `farm merge` names it,
//! and a rerun of that index alone completes the job. Without Slurm the
//! test skips with a banner (a failure under MARBRE_REQUIRE_GPU=1).

mod slurm_cluster;

use marbre_core::image_decode::{IntegerDecode, decode_file};
use slurm_cluster::SlurmCluster;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

const MARBRE: &str = env!("CARGO_BIN_EXE_marbre");

/// Long enough for a loaded 2-core machine: each task starts marbre and
/// lavapipe (a second or two) and traces a 64×64 image.
const JOB_TIMEOUT: Duration = Duration::from_secs(300);

/// A diffuse ball under a point light and a constant sky: every pixel's
/// estimate is noisy, so batches and frames differ. Two samples a frame.
fn ball_preset() -> String {
    include_str!("../data/noisy_ball.ron").replace("samples_per_frame: 1,", "samples_per_frame: 2,")
}

fn start_or_skip(test: &str) -> Option<SlurmCluster> {
    let cluster = SlurmCluster::start().unwrap_or_else(|e| panic!("[{test}] {e}"));
    if cluster.is_none() {
        if std::env::var_os("MARBRE_REQUIRE_GPU").is_some_and(|v| v == "1") {
            panic!(
                "[{test}] Slurm or munge is not installed (slurmctld, slurmd, slurm-client, \
                 munge), and MARBRE_REQUIRE_GPU=1"
            );
        }
        eprintln!(
            "\n======== SKIPPED {test}: Slurm or munge is not installed \
             (apt-get install slurmctld slurmd slurm-client munge) ========\n"
        );
    }
    cluster
}

/// Runs marbre with `args` and the cluster's environment; its stdout, or
/// a panic with its stderr.
fn marbre(cluster: &SlurmCluster, args: &[&str]) -> String {
    let out = Command::new(MARBRE)
        .args(args)
        .envs(cluster.env())
        .output()
        .expect("running marbre");
    assert!(
        out.status.success(),
        "marbre {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Submits the job in `dir` as its submit.sh does; the tasks' and the
/// merge's job ids.
fn submit(cluster: &SlurmCluster, dir: &Path) -> (u32, u32) {
    let out = Command::new("sh")
        .arg(dir.join("submit.sh"))
        .envs(cluster.env())
        .output()
        .expect("running submit.sh");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "submit.sh failed: {text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // "tasks: job 3 (4 tasks); merge: job 4"
    let ids: Vec<u32> = text
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|n| n.parse().ok())
        .collect();
    (ids[0], ids[2])
}

fn all(state: &str, count: u32) -> BTreeMap<u32, String> {
    (0..count).map(|i| (i, state.to_owned())).collect()
}

fn pixels(path: &Path) -> Vec<[f32; 4]> {
    decode_file(path, IntegerDecode::Linear)
        .unwrap_or_else(|e| panic!("{}: {e:#}", path.display()))
        .pixels
}

/// The largest difference between two images relative to the second's
/// value (at least 0.01).
fn largest_relative_difference(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs() / q[c].abs().max(0.01)))
        .fold(0.0, f32::max)
}

#[test]
fn slurm_arrays_render_batches_tiles_and_frames_and_name_a_failed_task() {
    let test = "slurm_arrays_render_batches_tiles_and_frames_and_name_a_failed_task";
    let Some(cluster) = start_or_skip(test) else {
        return;
    };
    let root = cluster.folder().join("renders");
    std::fs::create_dir_all(&root).unwrap();
    let preset = root.join("ball.ron");
    std::fs::write(&preset, ball_preset()).unwrap();
    let preset = preset.to_str().unwrap();
    let job = |name: &str, flags: &[&str]| -> PathBuf {
        let dir = root.join(name);
        let mut args = vec![
            "farm", "slurm", "--preset", preset, "--size", "64x64", "--kernel", "fragment",
            "--cpus", "1", "--marbre", MARBRE, "-o",
        ];
        args.push(dir.to_str().unwrap());
        args.extend_from_slice(flags);
        marbre(&cluster, &args);
        dir
    };
    let direct = |name: &str, flags: &[&str]| -> PathBuf {
        let out = root.join(name);
        let mut args = vec![
            "render", "--preset", preset, "--size", "64x64", "--kernel", "fragment", "-o",
        ];
        args.push(out.to_str().unwrap());
        args.extend_from_slice(flags);
        marbre(&cluster, &args);
        out
    };

    // Four sample batches and a failing one, submitted together.
    let batches = job("batches", &["--spp", "16", "--batches", "4"]);
    let failing = job("failing", &["--spp", "16", "--batches", "4"]);
    // A folder where task 2 writes its file: its render cannot be saved.
    let blocked = failing.join("parts/frame_0000_part_002.exr");
    std::fs::create_dir_all(&blocked).unwrap();
    let frames = job("frames", &["--spp", "4", "--frames", "0..3"]);
    let tiles = job("tiles", &["--spp", "4", "--tiles", "2x2", "--moments"]);
    let (batch_tasks, batch_merge) = submit(&cluster, &batches);
    let (tile_tasks, tile_merge) = submit(&cluster, &tiles);
    let (failing_tasks, failing_merge) = submit(&cluster, &failing);
    let (frame_tasks, frame_merge) = submit(&cluster, &frames);
    let ids = [
        batch_tasks,
        batch_merge,
        failing_tasks,
        failing_merge,
        frame_tasks,
        frame_merge,
    ];
    cluster.wait(&ids, JOB_TIMEOUT).unwrap();

    assert_eq!(cluster.states(batch_tasks).unwrap(), all("COMPLETED", 4));
    assert_eq!(cluster.states(batch_merge).unwrap(), all("COMPLETED", 1));
    let whole = direct("direct.exr", &["--spp", "16"]);
    let d = largest_relative_difference(&pixels(&batches.join("image.exr")), &pixels(&whole));
    assert!(
        d < 1e-4,
        "the merged batches are {d} from the direct render"
    );

    assert_eq!(cluster.states(tile_tasks).unwrap(), all("COMPLETED", 4));
    assert_eq!(cluster.states(tile_merge).unwrap(), all("COMPLETED", 1));
    let four = direct("direct_4.exr", &["--spp", "4"]);
    assert!(
        pixels(&tiles.join("image.exr")) == pixels(&four),
        "the assembled tiles differ from the direct render"
    );
    let merge_log = std::fs::read_to_string(tiles.join("logs/merge.out")).unwrap();
    assert!(
        merge_log.contains("estimated relative error"),
        "single-batch tiles with --moments know their error: {merge_log}"
    );

    assert_eq!(cluster.states(frame_tasks).unwrap(), all("COMPLETED", 4));
    assert_eq!(cluster.states(frame_merge).unwrap(), all("COMPLETED", 1));
    let frame_2 = direct(
        "direct_frame_2.exr",
        &["--spp", "4", "--time", &(2.0f32 / 24.0).to_string()],
    );
    assert!(
        pixels(&frames.join("frames/frame_0002.exr")) == pixels(&frame_2),
        "frame 2 of the array differs from its direct render"
    );
    assert!(
        pixels(&frames.join("frames/frame_0001.exr")) != pixels(&frame_2),
        "frames 1 and 2 traced the same samples"
    );

    // A Kubernetes pod gives the index in JOB_COMPLETION_INDEX: frame 1
    // is written, so the task does nothing. Without an index, an error.
    let task = |env: &[(&str, &str)]| {
        let mut command = Command::new(MARBRE);
        command
            .args(["farm", "task", frames.to_str().unwrap()])
            .env_remove("JOB_COMPLETION_INDEX")
            .env_remove("SLURM_ARRAY_TASK_ID")
            .envs(env.iter().copied());
        command.output().unwrap()
    };
    let indexed = task(&[("JOB_COMPLETION_INDEX", "1")]);
    let said = String::from_utf8_lossy(&indexed.stdout);
    assert!(
        indexed.status.success() && said.contains("task 1: ") && said.contains("nothing to do"),
        "{said}"
    );
    let unindexed = task(&[]);
    assert!(!unindexed.status.success());
    assert!(String::from_utf8_lossy(&unindexed.stderr).contains("no task index"));

    let mut expected = all("COMPLETED", 4);
    expected.insert(2, "FAILED".to_owned());
    assert_eq!(cluster.states(failing_tasks).unwrap(), expected);
    assert_eq!(
        cluster.states(failing_merge).unwrap(),
        all("CANCELLED", 1),
        "the merge waits for every task (afterok)"
    );
    let out = Command::new(MARBRE)
        .args(["farm", "merge", failing.to_str().unwrap()])
        .output()
        .unwrap();
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        message.contains("1 of the 4 tasks")
            && message.contains("sbatch --array=2 ")
            && message.contains("task 2 (frame 0, samples 8..12) FAILED"),
        "{message}"
    );
    assert!(!failing.join("image.exr").exists());

    // The index run again alone; the others' files are left as they are.
    std::fs::remove_dir(&blocked).unwrap();
    let first = failing.join("parts/frame_0000_part_000.exr");
    let written = std::fs::metadata(&first).unwrap().modified().unwrap();
    let tasks_script = failing.join("tasks.sbatch");
    let rerun = cluster
        .sbatch(&["--array=2", tasks_script.to_str().unwrap()])
        .unwrap();
    cluster.wait(&[rerun], JOB_TIMEOUT).unwrap();
    assert_eq!(
        cluster.states(rerun).unwrap(),
        BTreeMap::from([(2, "COMPLETED".to_owned())])
    );
    assert_eq!(
        std::fs::metadata(&first).unwrap().modified().unwrap(),
        written
    );
    let said = marbre(&cluster, &["farm", "merge", failing.to_str().unwrap()]);
    assert!(said.contains("merged 4 parts"), "{said}");
    let d = largest_relative_difference(&pixels(&failing.join("image.exr")), &pixels(&whole));
    assert!(
        d < 1e-4,
        "the job completed by a rerun is {d} from the direct render"
    );

    // The preset edited after the job was written: a task run again is
    // refused rather than trace another scene beside the old one's parts.
    std::fs::remove_file(batches.join("parts/frame_0000_part_001.exr")).unwrap();
    std::fs::write(
        root.join("ball.ron"),
        ball_preset().replace("intensity: 30.0", "intensity: 31.0"),
    )
    .unwrap();
    let out = Command::new(MARBRE)
        .args(["farm", "task", batches.to_str().unwrap(), "1"])
        .output()
        .unwrap();
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && message.contains("changed since the job was written"),
        "{message}"
    );
}
