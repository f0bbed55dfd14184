//! `marbre render` as a user runs it, for what it says on stderr: no
//! Wayland noise where `XDG_RUNTIME_DIR` is unset, the EXR that auto
//! exposure leaves unscaled, and an output path through a missing folder
//! or a file refused with the folder or the file named.

use crate::REPO;
use crate::xvfb::TempDir;
use marbre_render::gpu::testing::gpu_or_skip;
use std::path::Path;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_marbre");

/// `marbre render` of the default preset, tiny, to `output`, with no
/// runtime folder and nothing steering Mesa's device selection.
fn render(output: &Path, extra: &[&str]) -> Output {
    Command::new(BIN)
        .args(["render", "--preset", "presets/default.ron", "--size", "8x8"])
        .args(["--spp", "1", "--kernel", "fragment", "-o"])
        .arg(output)
        .args(extra)
        .current_dir(REPO)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("NODEVICE_SELECT")
        .env_remove("MESA_VK_DEVICE_SELECT")
        .output()
        .unwrap_or_else(|e| panic!("cannot run {BIN}: {e}"))
}

#[test]
fn render_says_what_it_did_and_nothing_else() {
    const TEST: &str = "render_says_what_it_did_and_nothing_else";
    let dir = TempDir::new("render-cli");
    if gpu_or_skip(TEST).is_none() {
        return;
    }
    let output = dir.path().join("x.exr");
    let run = render(&output, &["--auto-exposure"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{}: {stderr}", run.status);
    assert!(output.is_file(), "no {}: {stderr}", output.display());
    assert!(
        stderr.contains("auto exposure does not scale") && stderr.contains("unscaled radiance"),
        "{stderr}"
    );
    assert!(
        stderr.contains("auto exposure: "),
        "the exposure is reported: {stderr}"
    );
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
}

/// Refused before any GPU work: no adapter needed.
#[test]
fn render_into_a_missing_folder_names_it_and_makes_nothing() {
    let dir = TempDir::new("render-cli-missing");
    let output = dir.path().join("renders/today/x.png");
    let run = render(&output, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "{stderr}");
    let folder = dir.path().join("renders");
    assert!(
        stderr.contains(&format!("the folder {} does not exist", folder.display())),
        "{stderr}"
    );
    assert!(!folder.exists(), "a folder was made");
}

/// Refused before any GPU work: no adapter needed.
#[test]
fn render_through_a_file_names_the_file() {
    let dir = TempDir::new("render-cli-file");
    let file = dir.path().join("notes.txt");
    std::fs::write(&file, "a file").unwrap();
    let output = file.join("x.png");
    let run = render(&output, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!("{} is a file, not a folder", file.display())),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "a file");
}

/// `render --denoise` of the default preset, tiny, to `output`, with
/// `MARBRE_OIDN_DIR` set to `oidn_dir` or unset.
fn render_denoised(output: &Path, oidn_dir: Option<&Path>) -> Output {
    let mut command = Command::new(BIN);
    command
        .args([
            "render",
            "--preset",
            "presets/default.ron",
            "--size",
            "16x16",
        ])
        .args(["--spp", "2", "--kernel", "fragment", "--denoise", "-o"])
        .arg(output)
        .current_dir(REPO);
    match oidn_dir {
        Some(dir) => command.env("MARBRE_OIDN_DIR", dir),
        None => command.env_remove("MARBRE_OIDN_DIR"),
    };
    command
        .output()
        .unwrap_or_else(|e| panic!("cannot run {BIN}: {e}"))
}

/// `render --denoise` says what denoised the image: OIDN where its library
/// is found; with `MARBRE_OIDN_DIR` pointing at an empty folder, the
/// à-trous filter, and why (the folder named), the render still written.
#[test]
fn render_denoise_says_which_denoiser_ran_and_falls_back_without_oidn() {
    const TEST: &str = "render_denoise_says_which_denoiser_ran_and_falls_back_without_oidn";
    let dir = TempDir::new("render-cli-denoise");
    if gpu_or_skip(TEST).is_none() {
        return;
    }
    let empty = dir.path().join("no-oidn");
    std::fs::create_dir(&empty).unwrap();
    let output = dir.path().join("fallback.png");
    let run = render_denoised(&output, Some(&empty));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{}: {stderr}", run.status);
    assert!(output.is_file(), "{stderr}");
    assert!(
        stderr.contains("denoised by à-trous, as OIDN's library")
            && stderr.contains(&empty.display().to_string()),
        "{stderr}"
    );
    if marbre_oidn::library_or_skip(TEST).is_none() {
        return;
    }
    let run = render_denoised(&dir.path().join("oidn.png"), None);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{}: {stderr}", run.status);
    assert!(
        stderr.contains("denoised by OIDN 2.") && stderr.contains("(high)"),
        "{stderr}"
    );
}

/// `--window-screenshot` is checked before any window opens, as every
/// output is (issue 47): a name that is not a PNG's (it once wrote PNG
/// bytes into `s.txt`) and a FIFO already there (it once turned
/// `/dev/full` into a PNG) are refused naming the file, and the FIFO
/// stays a FIFO. No display is needed: the refusal comes first.
#[test]
fn a_window_screenshot_that_is_not_a_png_file_is_refused_before_the_window() {
    let dir = TempDir::new("screenshot-output");
    let text = dir.path().join("s.txt");
    let fifo = dir.path().join("pipe.png");
    let status = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(status.success(), "mkfifo failed");
    for (output, why) in [(&text, "must end in .png"), (&fifo, "FIFO")] {
        let run = Command::new(BIN)
            .arg("--window-screenshot")
            .arg(output)
            .args(["--exit-after-frames", "1"])
            .current_dir(REPO)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap_or_else(|e| panic!("cannot run {BIN}: {e}"));
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success(),
            "{}: accepted; {stderr}",
            output.display()
        );
        assert!(
            stderr.contains(&output.display().to_string()) && stderr.contains(why),
            "{}: {stderr}",
            output.display()
        );
    }
    assert!(!text.exists(), "s.txt was written");
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
}
