//! `marbre farm slurm|k8s` with hostile names (issue 47): job folders,
//! presets, mounts, `--marbre` paths and scheduler options holding `"`,
//! `'`, `$(…)`, backticks, `;`, `${IFS}`, spaces and a leading `-`. Each
//! generated script is run by `bash` with stand-in `sbatch`, `kubectl` and
//! `marbre` that record the words they were given, once succeeding and
//! once failing: no planted command may run, and every word must reach the
//! stand-in byte for byte. Values a scheduler cannot carry (newlines,
//! control characters, bytes that are not UTF-8) are refused before
//! anything is written.

use clap::Parser;
use marbre_commands::farm::{self, FarmArgs};
use marbre_core::image_io;
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord};
use marbre_core::tile::Tile;
use std::ffi::{OsStr, OsString};
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: FarmArgs,
}

/// `marbre farm ARGS`, parsed as the command line would be.
fn farm(args: &[OsString]) -> anyhow::Result<()> {
    let cli = Cli::try_parse_from(std::iter::once(OsString::from("farm")).chain(args.to_vec()))?;
    farm::run(&cli.args)
}

fn os(text: &str) -> OsString {
    OsString::from(text)
}

/// The files the planted commands would create, relative to the folder a
/// script runs in.
const PLANTED: [&str; 9] = [
    "PWNEDQ",
    "PLANTED_A",
    "PLANTED_B",
    "PLANTED_C",
    "PLANTED_D",
    "PLANTED_L",
    "PLANTED_M",
    "PLANTED_O",
    "PLANTED_P",
];

/// Job folders' names that hold shell syntax, each planting a file if a
/// script runs it. Slurm's take no quote, space or backslash
/// (`#SBATCH --output` cannot carry them; refused, tested below).
const SLURM_FOLDERS: [&str; 4] = [
    "s$(touch${IFS}PLANTED_A)",
    "b`touch${IFS}PLANTED_C`",
    "k;touch${IFS}PLANTED_D;",
    "-lead&touch${IFS}PLANTED_L|x",
];

/// The same for Kubernetes, whose folders may hold anything a path
/// holds but control characters: the issue's three, and more.
const KUBERNETES_FOLDERS: [&str; 5] = [
    "kq\";touch${IFS}PWNEDQ;\"",
    "s'$(touch PLANTED_B)'",
    "b`touch PLANTED_C`",
    "-lead ;touch PLANTED_L; \\ two  spaces",
    "q'\"'\"$(touch PLANTED_A)\"'",
];

/// A scratch folder holding a preset, the stand-ins in `bin/`, and
/// `work/`, where the scripts run (and a planted `touch` would write).
struct Scratch {
    root: tempfile::TempDir,
}

impl Scratch {
    fn new() -> Self {
        let root = tempfile::tempdir().unwrap();
        for sub in ["bin", "work", "calls"] {
            std::fs::create_dir(root.path().join(sub)).unwrap();
        }
        let scratch = Self { root };
        std::fs::write(
            scratch.preset(),
            include_str!("../../../../tests/data/noisy_ball.ron"),
        )
        .unwrap();
        for (name, body) in [("sbatch", SBATCH), ("kubectl", KUBECTL)] {
            scratch.stand_in(&scratch.path("bin").join(name), body);
        }
        scratch
    }

    fn path(&self, name: &str) -> PathBuf {
        self.root.path().join(name)
    }

    fn preset(&self) -> PathBuf {
        self.path("ball.ron")
    }

    /// An executable bash script at `path` that records its `$0` and
    /// arguments, then runs `body`.
    fn stand_in(&self, path: &Path, body: &str) {
        let text = format!("#!/bin/bash\n{RECORD}{body}");
        std::fs::write(path, text).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }

    /// Runs `bash SCRIPT` in `work/`, the stand-ins first on the PATH,
    /// succeeding (`ok`) or failing; its output and the calls the
    /// stand-ins received, in order.
    fn run(&self, script: &Path, ok: bool, env: &[(&str, &str)]) -> (Output, Vec<Vec<Vec<u8>>>) {
        self.bash(&[script.as_os_str()], ok, env)
    }

    /// Runs `bash ARGS` as [`run`](Self::run) does.
    fn bash(&self, args: &[&OsStr], ok: bool, env: &[(&str, &str)]) -> (Output, Vec<Vec<Vec<u8>>>) {
        let log = self.path("calls/log");
        let _ = std::fs::remove_file(&log);
        let path = format!(
            "{}:{}",
            self.path("bin").display(),
            std::env::var("PATH").unwrap_or_default()
        );
        let out = Command::new("bash")
            .args(args)
            .current_dir(self.path("work"))
            .env("PATH", path)
            .env("STAND_IN_LOG", &log)
            .env("STAND_IN_MODE", if ok { "ok" } else { "fail" })
            .envs(env.iter().copied())
            .output()
            .unwrap();
        self.assert_nothing_planted(&format!("bash {args:?}"));
        (out, calls(&std::fs::read(&log).unwrap_or_default()))
    }

    /// No planted file anywhere under the scratch folder.
    fn assert_nothing_planted(&self, after: &str) {
        let mut stack = vec![self.root.path().to_owned()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let entry = entry.unwrap();
                let name = entry.file_name();
                assert!(
                    !PLANTED.iter().any(|p| OsStr::new(p) == name),
                    "{after} planted {}",
                    entry.path().display()
                );
                if entry.file_type().unwrap().is_dir() {
                    stack.push(entry.path());
                }
            }
        }
    }
}

/// What every stand-in does first: its `$0` and arguments to the log,
/// each ended by a NUL, the call ended by a lone RS character.
const RECORD: &str = "{ printf '%s\\0' \"$0\" \"$@\"; printf '\\036\\0'; } >> \"$STAND_IN_LOG\"\n";

/// sbatch --parsable: job 4242, or a refused submission.
const SBATCH: &str = "if [ \"$STAND_IN_MODE\" = ok ]; then echo '4242;cluster'; exit 0; fi\n\
                      echo 'sbatch: error: Batch job submission failed' >&2\nexit 1\n";

/// kubectl: apply and delete succeed; the Job completes, or fails.
const KUBECTL: &str = "case \"$*\" in\n\
                       *--for=condition=complete*) [ \"$STAND_IN_MODE\" = ok ] ;;\n\
                       *--for=condition=failed*) [ \"$STAND_IN_MODE\" = fail ] ;;\n\
                       *) exit 0 ;;\n\
                       esac\n";

/// marbre: does nothing, or fails.
const MARBRE: &str = "[ \"$STAND_IN_MODE\" = ok ] || exit 3\n";

/// The calls in a stand-ins' log: each its words, `$0` first.
fn calls(log: &[u8]) -> Vec<Vec<Vec<u8>>> {
    let mut calls = vec![Vec::new()];
    for word in log.split(|&b| b == 0).filter(|w| !w.is_empty()) {
        if word == b"\x1e" {
            calls.push(Vec::new());
        } else {
            calls.last_mut().unwrap().push(word.to_vec());
        }
    }
    calls.pop();
    calls
}

/// `words` as a call's expected words.
fn call(words: &[&[u8]]) -> Vec<Vec<u8>> {
    words.iter().map(|w| w.to_vec()).collect()
}

fn bytes(path: &Path) -> &[u8] {
    path.as_os_str().as_bytes()
}

/// The POSIX shell's single-quoted form of `text`, written here
/// independently of marbre's: what a message shows for a folder.
fn sh_quoted(text: &[u8]) -> Vec<u8> {
    let mut out = b"'".to_vec();
    for &b in text {
        if b == b'\'' {
            out.extend_from_slice(b"'\\''");
        } else {
            out.push(b);
        }
    }
    out.push(b'\'');
    out
}

/// `farm COMMAND` with `extra` flags, and each of `defaults` (all
/// `--flag=value`) that `extra` does not give.
fn job(command: &str, defaults: Vec<OsString>, extra: &[OsString]) -> anyhow::Result<()> {
    let flag = |word: &OsString| {
        let bytes = word.as_bytes();
        bytes[..bytes.iter().position(|&b| b == b'=').unwrap_or(bytes.len())].to_vec()
    };
    let mut args = vec![os(command)];
    args.extend(
        defaults
            .into_iter()
            .filter(|d| !extra.iter().any(|e| flag(e) == flag(d))),
    );
    args.extend(extra.iter().cloned());
    farm(&args)
}

/// `--flag=` `value`.
fn flag_of(flag: &str, value: impl AsRef<OsStr>) -> OsString {
    let mut word = OsString::from(format!("--{flag}="));
    word.push(value);
    word
}

/// A Slurm job in `dir` of the scratch's preset: 2 frames of 2 batches
/// of 2 samples, at 16×8, run by `marbre`; `extra` flags replace these.
fn slurm_job(
    scratch: &Scratch,
    dir: &Path,
    marbre: &OsStr,
    extra: &[OsString],
) -> anyhow::Result<()> {
    let defaults = vec![
        flag_of("preset", scratch.preset()),
        os("--size=16x8"),
        os("--spp=4"),
        os("--batches=2"),
        os("--frames=0..1"),
        flag_of("output", dir),
        flag_of("marbre", marbre),
    ];
    job("slurm", defaults, extra)
}

/// Each Slurm script, run: the array's task and the merge exec the
/// `--marbre` binary with the folder as one word, and submit.sh hands
/// sbatch the scripts' paths and the array's job id; a failing sbatch
/// stops submit.sh; nothing planted runs.
#[test]
fn slurm_scripts_hand_hostile_folders_over_word_for_word() {
    let scratch = Scratch::new();
    // A marbre whose own path is hostile, found on the PATH by a name
    // with a leading `-`.
    let marbre_name = "-marbre'$(touch PLANTED_M)\"";
    scratch.stand_in(&scratch.path("bin").join(marbre_name), MARBRE);
    let marbre_path = scratch.path("bin").join(marbre_name);
    let sbatch = scratch.path("bin").join("sbatch");
    for (i, name) in SLURM_FOLDERS.iter().enumerate() {
        let dir = scratch.path("work").join(name);
        // Half the jobs name marbre by its path, half by its name alone.
        let marbre = if i % 2 == 0 {
            marbre_path.as_os_str()
        } else {
            OsStr::new(marbre_name)
        };
        slurm_job(&scratch, &dir, marbre, &[]).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        for ok in [true, false] {
            let (out, got) = scratch.run(
                &dir.join("tasks.sbatch"),
                ok,
                &[("SLURM_ARRAY_TASK_ID", "3")],
            );
            assert_eq!(
                out.status.code(),
                Some(if ok { 0 } else { 3 }),
                "{name}: {out:?}"
            );
            assert_eq!(
                got,
                [call(&[
                    bytes(&marbre_path),
                    b"farm",
                    b"task",
                    bytes(&dir),
                    b"3"
                ])],
                "{name}"
            );
            let (out, got) = scratch.run(&dir.join("merge.sbatch"), ok, &[]);
            assert_eq!(
                out.status.code(),
                Some(if ok { 0 } else { 3 }),
                "{name}: {out:?}"
            );
            assert_eq!(
                got,
                [call(&[bytes(&marbre_path), b"farm", b"merge", bytes(&dir)])],
                "{name}"
            );
            let (out, got) = scratch.run(&dir.join("submit.sh"), ok, &[]);
            let tasks = call(&[
                bytes(&sbatch),
                b"--parsable",
                bytes(&dir.join("tasks.sbatch")),
            ]);
            if ok {
                assert!(out.status.success(), "{name}: {out:?}");
                assert_eq!(
                    String::from_utf8_lossy(&out.stdout),
                    "tasks: job 4242 (4 tasks); merge: job 4242\n"
                );
                let merge = call(&[
                    bytes(&sbatch),
                    b"--parsable",
                    b"--dependency=afterok:4242",
                    b"--kill-on-invalid-dep=yes",
                    bytes(&dir.join("merge.sbatch")),
                ]);
                assert_eq!(got, [tasks, merge], "{name}");
            } else {
                assert!(!out.status.success(), "{name}: {out:?}");
                assert_eq!(got, [tasks], "{name}: no merge without tasks");
            }
        }
    }
}

/// A Kubernetes job in `dir` of the scratch's preset, its claim mounted
/// at `mount`: one 16×8 still of 4 samples in 2 tiles; `extra` flags
/// replace these.
fn kubernetes_job(
    scratch: &Scratch,
    dir: &Path,
    mount: &Path,
    extra: &[OsString],
) -> anyhow::Result<()> {
    let defaults = vec![
        flag_of("preset", scratch.preset()),
        os("--size=16x8"),
        os("--spp=4"),
        os("--tiles=2x1"),
        os("--image=registry.example/marbre:0.1"),
        os("--claim=renders"),
        flag_of("output", dir),
        flag_of("mount", mount),
    ];
    job("k8s", defaults, extra)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// submit-k8s.sh, run: kubectl gets the manifests' paths and the Jobs'
/// names as single words; when the Job fails, the script stops with a
/// message that names the folder quoted for the shell, and runs nothing
/// planted (the issue's `kq";touch${IFS}PWNEDQ;"` did). The manifests'
/// words are the folder's and the mount's, exactly.
#[test]
fn the_kubernetes_submit_script_hands_hostile_folders_over_word_for_word() {
    let scratch = Scratch::new();
    let kubectl = scratch.path("bin").join("kubectl");
    for name in KUBERNETES_FOLDERS {
        let dir = scratch.path("work").join(name);
        kubernetes_job(&scratch, &dir, scratch.root.path(), &[])
            .unwrap_or_else(|e| panic!("{name}: {e:#}"));
        let tasks_job = json(&dir.join("tasks-job.json"));
        let merge_job = json(&dir.join("merge-job.json"));
        let pod = &tasks_job["spec"]["template"]["spec"];
        assert_eq!(
            pod["containers"][0]["args"],
            serde_json::json!(["farm", "task", dir.to_str().unwrap()])
        );
        assert_eq!(
            merge_job["spec"]["template"]["spec"]["containers"][0]["args"],
            serde_json::json!(["farm", "merge", dir.to_str().unwrap()])
        );
        assert_eq!(
            pod["containers"][0]["volumeMounts"][0]["mountPath"],
            scratch.root.path().to_str().unwrap()
        );
        let job =
            |v: &serde_json::Value| format!("job/{}", v["metadata"]["name"].as_str().unwrap());
        let (tasks, merge) = (job(&tasks_job), job(&merge_job));
        let start = [
            call(&[
                bytes(&kubectl),
                b"delete",
                b"--ignore-not-found",
                tasks.as_bytes(),
                merge.as_bytes(),
            ]),
            call(&[
                bytes(&kubectl),
                b"apply",
                b"-f",
                bytes(&dir.join("tasks-job.json")),
            ]),
            call(&[
                bytes(&kubectl),
                b"wait",
                b"--for=condition=complete",
                b"--timeout=10s",
                tasks.as_bytes(),
            ]),
        ];
        let script = dir.join("submit-k8s.sh");
        let (out, got) = scratch.run(&script, true, &[]);
        assert!(out.status.success(), "{name}: {out:?}");
        let mut expected = start.to_vec();
        expected.push(call(&[
            bytes(&kubectl),
            b"apply",
            b"-f",
            bytes(&dir.join("merge-job.json")),
        ]));
        assert_eq!(got, expected, "{name}");

        let (out, got) = scratch.run(&script, false, &[]);
        assert_eq!(out.status.code(), Some(1), "{name}: {out:?}");
        let mut expected = start.to_vec();
        expected.push(call(&[
            bytes(&kubectl),
            b"wait",
            b"--for=condition=failed",
            b"--timeout=0s",
            tasks.as_bytes(),
        ]));
        assert_eq!(got, expected, "{name}");
        let mut said = format!("{tasks} failed: run marbre farm merge ").into_bytes();
        said.extend(sh_quoted(bytes(&dir)));
        said.extend_from_slice(b" to see which tasks\n");
        assert_eq!(
            out.stderr,
            said,
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Whether `e`'s whole message, an error of
/// marbre's own (not the command line's), holds `part`.
fn says(e: &anyhow::Error, part: &str) -> bool {
    e.downcast_ref::<clap::Error>().is_none() && format!("{e:#}").contains(part)
}

/// A path in `dir` whose last name is `name`'s bytes.
fn named(dir: &Path, name: &[u8]) -> PathBuf {
    dir.join(OsStr::from_bytes(name))
}

/// Values that no scheduler's file can carry (a newline, a control
/// character, bytes that are not UTF-8), and Slurm folders and options
/// that an `#SBATCH` line would misread, are refused naming the flag, and
/// nothing is written: no job folder, no planted file.
#[test]
fn what_a_scheduler_cannot_carry_is_refused_before_anything_is_written() {
    let scratch = Scratch::new();
    let work = scratch.path("work");
    let marbre = scratch.path("bin").join("sbatch");
    let bad_preset = named(scratch.root.path(), b"ball\xff.ron");
    std::fs::copy(scratch.preset(), &bad_preset).unwrap();
    let flag = |name: &str, value: &[u8]| {
        let mut word = OsString::from(name);
        word.push(OsStr::from_bytes(value));
        word
    };
    let slurm: [(&[u8], Vec<OsString>, &str); 10] = [
        (
            b"p",
            vec![flag("--partition=", b"gpu\ntouch PLANTED_P")],
            "--partition",
        ),
        (b"g", vec![flag("--gres=", b"gpu:1 x")], "--gres"),
        (b"t", vec![flag("--time=", b"1:00\r")], "--time"),
        (b"q", vec![flag("--gres=", b"gpu\"x")], "--gres"),
        (b"n", vec![flag("--marbre=", b"/opt/mar\nbre")], "--marbre"),
        (
            b"u",
            vec![flag("--marbre=", b"/opt/mar\xffbre")],
            "--marbre",
        ),
        (b"j\nb", vec![], "the job's folder (-o)"),
        (b"j\xffb", vec![], "the job's folder (-o)"),
        (b"kq\";touch${IFS}PWNEDQ;\"", vec![], "cannot hold '\"'"),
        (b"s'$(touch PLANTED_B)'", vec![], "cannot hold '\\''"),
    ];
    for (name, extra, option) in &slurm {
        let dir = named(&work, name);
        let e = slurm_job(&scratch, &dir, marbre.as_os_str(), extra).unwrap_err();
        assert!(says(&e, option), "{name:?}: {e:#}");
        assert!(
            std::fs::symlink_metadata(&dir).is_err(),
            "{name:?} was written"
        );
    }
    let mut preset_flag = OsString::from("--preset=");
    preset_flag.push(&bad_preset);
    let dir = work.join("preset");
    let e = slurm_job(&scratch, &dir, marbre.as_os_str(), &[preset_flag.clone()]).unwrap_err();
    assert!(says(&e, "--preset"), "{e:#}");
    assert!(std::fs::symlink_metadata(&dir).is_err());

    let kubernetes: [(&[u8], Vec<OsString>, &str); 6] = [
        (
            b"i",
            vec![flag("--image=", b"reg/marbre\ntouch PLANTED_O")],
            "--image",
        ),
        (
            b"c",
            vec![flag("--claim=", b"x\";touch${IFS}PLANTED_O;\"")],
            "--claim",
        ),
        (
            b"m",
            vec![flag(
                "--mount=",
                &[bytes(scratch.root.path()), b"/\x1b"].concat(),
            )],
            "--mount",
        ),
        (b"j\nb", vec![], "the job's folder (-o)"),
        (b"j\xffb", vec![], "the job's folder (-o)"),
        (b"pr", vec![preset_flag], "--preset"),
    ];
    for (name, extra, option) in &kubernetes {
        let dir = named(&work, name);
        let e = kubernetes_job(&scratch, &dir, scratch.root.path(), extra).unwrap_err();
        assert!(says(&e, option), "{name:?}: {e:#}");
        assert!(
            std::fs::symlink_metadata(&dir).is_err(),
            "{name:?} was written"
        );
    }
    scratch.assert_nothing_planted("the refusals");
}

/// The plan's preset, read back from farm.ron on its own.
fn planned_preset(dir: &Path) -> PathBuf {
    #[derive(serde::Deserialize)]
    struct Plan {
        preset: PathBuf,
    }
    let text = std::fs::read_to_string(dir.join("farm.ron")).unwrap();
    ron::from_str::<Plan>(&text).unwrap().preset
}

/// Hostile values a scheduler can carry reach it as given: Slurm's
/// options in their `#SBATCH` lines, which bash then runs as comments;
/// Kubernetes' image, mount and preset in the JSON, with submit-k8s.sh
/// running nothing of them.
#[test]
fn hostile_values_a_scheduler_carries_reach_it_exactly() {
    let scratch = Scratch::new();
    let marbre = scratch.path("bin").join("-m");
    scratch.stand_in(&marbre, MARBRE);
    let preset = scratch.path("p'$(touch PLANTED_P)\"`touch PLANTED_A` ;x.ron");
    std::fs::copy(scratch.preset(), &preset).unwrap();
    let options = [
        ("partition", "gpu$(touch${IFS}PLANTED_P)"),
        ("gres", "gpu:1;touch${IFS}PLANTED_O;"),
        ("time", "-1`touch${IFS}PLANTED_A`"),
    ];
    let mut extra: Vec<OsString> = options
        .iter()
        .map(|(flag, value)| os(&format!("--{flag}={value}")))
        .collect();
    let mut preset_flag = OsString::from("--preset=");
    preset_flag.push(&preset);
    extra.push(preset_flag.clone());
    let dir = scratch.path("work").join("options");
    slurm_job(&scratch, &dir, marbre.as_os_str(), &extra).unwrap();
    let tasks = std::fs::read_to_string(dir.join("tasks.sbatch")).unwrap();
    for (flag, value) in options {
        assert!(
            tasks.contains(&format!("\n#SBATCH --{flag}={value}\n")),
            "{tasks}"
        );
    }
    assert_eq!(planned_preset(&dir), preset);
    for ok in [true, false] {
        let (_, got) = scratch.run(
            &dir.join("tasks.sbatch"),
            ok,
            &[("SLURM_ARRAY_TASK_ID", "0")],
        );
        assert_eq!(
            got,
            [call(&[bytes(&marbre), b"farm", b"task", bytes(&dir), b"0"])]
        );
        scratch.run(&dir.join("merge.sbatch"), ok, &[]);
    }

    let mount = scratch.path("m'\"$(touch PLANTED_M) `touch PLANTED_C`");
    std::fs::create_dir(&mount).unwrap();
    let preset = mount.join("-p'$(touch PLANTED_P)\".ron");
    std::fs::copy(scratch.preset(), &preset).unwrap();
    let image = "reg/m'\"$(touch${IFS}PLANTED_O)`touch${IFS}PLANTED_O`;x";
    let dir = mount.join("job \"$(touch PLANTED_D)\"");
    let mut preset_flag = OsString::from("--preset=");
    preset_flag.push(&preset);
    kubernetes_job(
        &scratch,
        &dir,
        &mount,
        &[os(&format!("--image={image}")), preset_flag],
    )
    .unwrap();
    let job = json(&dir.join("tasks-job.json"));
    let container = &job["spec"]["template"]["spec"]["containers"][0];
    assert_eq!(container["image"], image);
    assert_eq!(
        container["volumeMounts"][0]["mountPath"],
        mount.to_str().unwrap()
    );
    assert_eq!(container["args"][2], dir.to_str().unwrap());
    assert_eq!(planned_preset(&dir), preset);
    for ok in [true, false] {
        let (out, _) = scratch.run(&dir.join("submit-k8s.sh"), ok, &[]);
        assert_eq!(out.status.success(), ok, "{out:?}");
    }
}

/// The command `farm merge` tells the user to run, between its
/// backquotes after `with`.
fn rerun_hint(message: &str, scheduler: &str, after: &str) -> String {
    let start = message.find(&format!("with {scheduler} `")).unwrap() + scheduler.len() + 7;
    let end = start + message[start..].find(&format!("`{after}")).unwrap();
    message[start..end].to_owned()
}

/// `farm merge` of a job whose tasks did not run names the command that
/// runs them again; that command, run by bash, hands sbatch (or
/// submit-k8s.sh) the job's folder as it is, and plants nothing.
#[test]
fn the_rerun_command_farm_merge_gives_names_the_folder_exactly() {
    let scratch = Scratch::new();
    let sbatch = scratch.path("bin").join("sbatch");
    let kubectl = scratch.path("bin").join("kubectl");
    for name in SLURM_FOLDERS {
        let dir = scratch.path("work").join(name);
        slurm_job(&scratch, &dir, sbatch.as_os_str(), &[]).unwrap();
        let e = farm(&[os("merge"), dir.clone().into()]).unwrap_err();
        let hint = rerun_hint(&format!("{e:#}"), "Slurm", ", then the merge again");
        assert!(hint.starts_with("sbatch --array=0-3 "), "{hint}");
        let (out, got) = scratch.bash(&[OsStr::new("-c"), OsStr::new(&hint)], true, &[]);
        assert!(out.status.success(), "{out:?}");
        assert_eq!(
            got,
            [call(&[
                bytes(&sbatch),
                b"--array=0-3",
                bytes(&dir.join("tasks.sbatch"))
            ])],
            "{hint}"
        );
    }
    for name in KUBERNETES_FOLDERS {
        let dir = scratch.path("work").join(name);
        kubernetes_job(&scratch, &dir, scratch.root.path(), &[]).unwrap();
        let e = farm(&[os("merge"), dir.clone().into()]).unwrap_err();
        let hint = rerun_hint(&format!("{e:#}"), "Kubernetes", " again (the finished");
        assert!(hint.starts_with("sh "), "{hint}");
        let (out, got) = scratch.bash(&[OsStr::new("-c"), OsStr::new(&hint)], true, &[]);
        assert!(out.status.success(), "{out:?}");
        assert_eq!(
            got[1],
            call(&[
                bytes(&kubectl),
                b"apply",
                b"-f",
                bytes(&dir.join("tasks-job.json"))
            ]),
            "{hint}"
        );
    }
}

/// `farm ARGS` on another thread, failed if it has not returned within a
/// minute: a read that waits on a FIFO would hang the test run instead.
fn farm_within_a_minute(args: Vec<OsString>) -> anyhow::Result<()> {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(farm(&args).map_err(|e| format!("{e:#}")));
    });
    receive
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("still waiting after a minute: a FIFO was opened")
        .map_err(anyhow::Error::msg)
}

fn mkfifo(path: &Path) {
    let _ = std::fs::remove_file(path);
    let status = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(status.success());
}

/// A sparse file of `bytes` at `path` (no disk used).
fn sparse(path: &Path, bytes: u64) {
    let _ = std::fs::remove_file(path);
    std::fs::File::create(path).unwrap().set_len(bytes).unwrap();
}

/// `farm task` and `farm merge` read the plan, the preset and the failed
/// tasks' notes through the capped reader: a FIFO is refused at once, a
/// device or an oversize file by its size, each naming the file.
#[test]
fn the_farm_refuses_a_fifo_a_device_or_an_oversize_file_among_its_inputs() {
    let scratch = Scratch::new();
    let dir = scratch.path("work").join("job");
    slurm_job(&scratch, &dir, OsStr::new("/bin/true"), &[]).unwrap();
    let (plan, plan_text) = (
        dir.join("farm.ron"),
        std::fs::read(dir.join("farm.ron")).unwrap(),
    );
    let task = || vec![os("task"), dir.clone().into(), os("0")];
    let merge = || vec![os("merge"), dir.clone().into()];
    mkfifo(&plan);
    for args in [task(), merge()] {
        let e = farm_within_a_minute(args).unwrap_err();
        assert!(says(&e, &format!("reading {}", plan.display())), "{e:#}");
        assert!(says(&e, "not a regular file (it is a FIFO)"), "{e:#}");
    }
    sparse(&plan, (1 << 20) + 1);
    let e = farm_within_a_minute(task()).unwrap_err();
    assert!(
        says(&e, "larger than the 1 MiB a farm plan may have"),
        "{e:#}"
    );
    std::fs::remove_file(&plan).unwrap();
    std::fs::write(&plan, &plan_text).unwrap();

    let preset = scratch.preset();
    let said = format!("reading the preset {}: ", preset.display());
    mkfifo(&preset);
    let e = farm_within_a_minute(task()).unwrap_err();
    assert!(
        says(&e, &format!("{said}not a regular file (it is a FIFO)")),
        "{e:#}"
    );
    std::fs::remove_file(&preset).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &preset).unwrap();
    let e = farm_within_a_minute(task()).unwrap_err();
    assert!(
        says(&e, &format!("{said}not a regular file (it is a device)")),
        "{e:#}"
    );
    std::fs::remove_file(&preset).unwrap();
    sparse(&preset, (64 << 20) + 1);
    let e = farm_within_a_minute(task()).unwrap_err();
    assert!(says(&e, &format!("{said}larger than the 64 MiB")), "{e:#}");

    let (fifo, big) = (
        dir.join("status/task_0.failed"),
        dir.join("status/task_1.failed"),
    );
    mkfifo(&fifo);
    sparse(&big, (1 << 20) + 1);
    let e = farm_within_a_minute(merge()).unwrap_err();
    for (note, why) in [
        (&fifo, "not a regular file (it is a FIFO)"),
        (&big, "larger than the 1 MiB a failed task's note may have"),
    ] {
        assert!(
            says(
                &e,
                &format!("its note {} cannot be read: {why}", note.display())
            ),
            "{e:#}"
        );
    }
    assert!(says(&e, "tasks 2-3 did not run"), "{e:#}");
}

/// Writes the part of `frame`, samples `offset..offset + spp` of `tile`
/// of a 16×8 image, with its render record, to `path`: what a task of
/// [`slurm_job`]'s plan writes, made without a GPU.
fn write_part(path: &Path, frame: u32, offset: u32, spp: u32, tile: Tile) {
    let (width, height) = tile.size();
    let pixels = vec![[0.25 + offset as f32, 0.5, 0.75, 1.0]; (width * height) as usize];
    let record = RenderRecord {
        spp,
        sample_offset: offset,
        image: (16, 8),
        tile,
        frame,
        time: frame as f32 / 24.0,
        scene: "0123456789abcdef".into(),
        kernel: "fragment".into(),
        adapter: "stand-in".into(),
        version: "0".into(),
    };
    let text = record.to_text();
    image_io::save_exr_layers(
        width,
        height,
        &pixels,
        &[],
        Some((RECORD_ATTRIBUTE, &text)),
        path,
    )
    .unwrap();
}

/// A part of task `(frame, part)` of [`slurm_job`]'s plan (2 batches of
/// 2 samples a frame).
fn part(dir: &Path, frame: u32, part: u32) -> PathBuf {
    dir.join(format!("parts/frame_{frame:04}_part_{part:03}.exr"))
}

/// Every part of [`slurm_job`]'s two frames, as the plan gives them.
fn write_every_part(dir: &Path) {
    for frame in 0..2 {
        for batch in 0..2 {
            write_part(
                &part(dir, frame, batch),
                frame,
                2 * batch,
                2,
                Tile::whole((16, 8)),
            );
        }
    }
}

/// `farm merge` merges the parts the plan gave, and refuses a part whose
/// record is another task's (another frame, other samples, another tile),
/// naming the file: a frame-1 part was merged as frame 0.
#[test]
fn farm_merge_refuses_a_part_whose_record_is_another_tasks() {
    let scratch = Scratch::new();
    let dir = scratch.path("work").join("job");
    slurm_job(&scratch, &dir, OsStr::new("/bin/true"), &[]).unwrap();
    write_every_part(&dir);
    farm(&[os("merge"), dir.clone().into()]).unwrap();
    assert!(dir.join("frames/frame_0001.exr").is_file());

    for b in 0..2 {
        std::fs::copy(part(&dir, 1, b), part(&dir, 0, b)).unwrap();
    }
    let e = farm(&[os("merge"), dir.clone().into()]).unwrap_err();
    let first = part(&dir, 0, 0);
    assert!(
        says(
            &e,
            &format!(
                "{}: its record disagrees with the plan of task 0",
                first.display()
            )
        ) && says(&e, "frame 1, not 0"),
        "{e:#}"
    );

    write_every_part(&dir);
    write_part(&part(&dir, 1, 1), 1, 0, 4, Tile::whole((16, 8)));
    let e = farm(&[os("merge"), dir.clone().into()]).unwrap_err();
    assert!(says(&e, &part(&dir, 1, 1).display().to_string()), "{e:#}");
    assert!(says(&e, "samples 0..4, not 2..4"), "{e:#}");

    // Tiles swapped between their files: the merge would place each by
    // its record, but the files are not the tasks' own.
    let dir = scratch.path("work").join("tiles");
    kubernetes_job(&scratch, &dir, scratch.root.path(), &[]).unwrap();
    let (left, right) = (
        Tile::parse("0,0,8,8").unwrap(),
        Tile::parse("8,0,16,8").unwrap(),
    );
    write_part(&part(&dir, 0, 0), 0, 0, 4, right);
    write_part(&part(&dir, 0, 1), 0, 0, 4, left);
    let e = farm(&[os("merge"), dir.clone().into()]).unwrap_err();
    assert!(says(&e, &part(&dir, 0, 0).display().to_string()), "{e:#}");
    assert!(says(&e, "tile 8,0,16,8, not 0,0,8,8"), "{e:#}");
    write_part(&part(&dir, 0, 0), 0, 0, 4, left);
    write_part(&part(&dir, 0, 1), 0, 0, 4, right);
    farm(&[os("merge"), dir.clone().into()]).unwrap();
    assert!(dir.join("image.exr").is_file());
}

/// Marks `path` read-only (which root, running the tests in CI, could
/// still write: marbre's saves check the mark itself).
fn mark_read_only(path: &Path) {
    let mut permissions = std::fs::metadata(path).unwrap().permissions();
    permissions.set_readonly(true);
    std::fs::set_permissions(path, permissions).unwrap();
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A read-only file in the way: `farm slurm` names it and leaves no job
/// skeleton behind (its subfolders, plan and other scripts removed), and
/// `farm merge` names the frame before merging any.
#[test]
fn a_read_only_file_is_named_and_a_failed_job_leaves_nothing_behind() {
    let scratch = Scratch::new();
    let dir = scratch.path("work").join("job");
    std::fs::create_dir(&dir).unwrap();
    let submit = dir.join("submit.sh");
    std::fs::write(&submit, "old").unwrap();
    mark_read_only(&submit);
    let e = slurm_job(&scratch, &dir, OsStr::new("/bin/true"), &[]).unwrap_err();
    assert!(
        says(&e, &format!("writing {}: ", submit.display())) && says(&e, "read-only"),
        "{e:#}"
    );
    assert_eq!(names(&dir), ["submit.sh"]);

    let dir = scratch.path("work").join("again");
    slurm_job(&scratch, &dir, OsStr::new("/bin/true"), &[]).unwrap();
    let plan = dir.join("farm.ron");
    mark_read_only(&plan);
    let e = slurm_job(&scratch, &dir, OsStr::new("/bin/true"), &[]).unwrap_err();
    assert!(
        says(&e, &format!("writing {}: ", plan.display())) && says(&e, "read-only"),
        "{e:#}"
    );

    write_every_part(&dir);
    let frame = dir.join("frames/frame_0000.exr");
    std::fs::write(&frame, "kept").unwrap();
    mark_read_only(&frame);
    let e = farm(&[os("merge"), dir.clone().into()]).unwrap_err();
    assert!(
        says(&e, &format!("cannot write {}: ", frame.display())) && says(&e, "read-only"),
        "{e:#}"
    );
    assert_eq!(
        names(&dir.join("frames")),
        ["frame_0000.exr"],
        "no frame merged"
    );
}
