//! `marbre soak` end to end: the real viewer under Xvfb, driven by seeded
//! random edits, preset loads and a simulated device loss, its memory
//! judged at the end (see `marbre::app::soak`).
//!
//! - `a_short_soak_passes_and_writes_its_report`: 300 frames (100 of
//!   warm-up) must end in a pass, with the loads and the device loss the
//!   schedule promises, no validation error, and a CSV of every frame's
//!   memory.
//! - `a_missing_preset_is_refused_before_the_window_opens`: needs no
//!   display.
//!
//! Skips loudly without Xvfb or a GPU adapter, and fails instead with
//! `MARBRE_REQUIRE_GPU=1` (see `xvfb`).

use crate::xvfb::{
    TempDir, assert_success, display_or_skip, marbre_log, serial, spawn_marbre, wait_for_exit,
};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use crate::REPO;

/// 300 small frames, three preset loads and a device loss (each a shader
/// build of a second or more on lavapipe with two cores): a minute or two;
/// this leaves several times that.
const SOAK_TIMEOUT: Duration = Duration::from_secs(600);

/// One row of the `--report` CSV.
#[derive(Debug)]
struct Row {
    frame: u64,
    rss_bytes: u64,
    gpu_allocated_bytes: Option<u64>,
    gpu_resources: Option<u64>,
    heap_in_use_bytes: Option<u64>,
}

fn parse_rows(csv: &str) -> Vec<Row> {
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("frame,rss_bytes,gpu_allocated_bytes,gpu_resources,heap_in_use_bytes,heap_free_bytes"),
        "the CSV header"
    );
    lines
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), 6, "CSV row `{line}`");
            let optional = |s: &str| (!s.is_empty()).then(|| s.parse().unwrap());
            Row {
                frame: fields[0].parse().unwrap(),
                rss_bytes: fields[1].parse().unwrap(),
                gpu_allocated_bytes: optional(fields[2]),
                gpu_resources: optional(fields[3]),
                heap_in_use_bytes: optional(fields[4]),
            }
        })
        .collect()
}

#[test]
fn a_short_soak_passes_and_writes_its_report() {
    const TEST: &str = "a_short_soak_passes_and_writes_its_report";
    // One window at a time: a second one's load changes when the soak's
    // allocations land, which its memory limits judge.
    let _serial = serial();
    let dir = TempDir::new("soak");
    let Some(x) = display_or_skip(TEST, &dir, &[]) else {
        return;
    };
    let csv = dir.path().join("soak.csv");
    let start = Instant::now();
    let mut child = spawn_marbre(
        &x,
        &dir,
        Path::new(REPO),
        &[
            "soak".into(),
            "--frames".into(),
            "300".into(),
            "--warm-up".into(),
            "100".into(),
            "--report".into(),
            csv.clone().into(),
        ],
    );
    assert_success(wait_for_exit(&mut child, &dir, SOAK_TIMEOUT), &dir);
    eprintln!(
        "{TEST}: marbre ran for {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let log = marbre_log(&dir);
    eprintln!("{TEST}: its log:\n{log}");
    assert!(
        log.lines().any(|l| l == "soak passed"),
        "no pass verdict:\n{log}"
    );
    assert!(
        log.contains("soak: 300 frames recorded of 300 (warm-up 100, seed 1)"),
        "the summary line is missing or counts other frames:\n{log}"
    );
    // Over 300 frames the driver loads a preset every 75 frames (75, 150,
    // 225) and loses the device once, at frame 187.
    assert!(
        log.contains("3 preset loads; 1 device loss(es); 0 validation error(s)"),
        "the loads, the loss or the validation count differ:\n{log}"
    );
    // It exits with a Render dialog render under way (started 3 frames
    // before the end, far from done): cancelled, nothing written, its
    // thread and device joined before main returns. The debug binary
    // checks that last point itself (src/exit_check.rs): a GPU thread alive
    // at exit would have failed the exit status above.
    let render = std::env::temp_dir().join(format!("marbre-soak-{}.exr", child.0.id()));
    assert!(
        log.contains(&format!("render: started {}", render.display())),
        "the end-of-run render did not start:\n{log}"
    );
    assert!(
        !render.exists(),
        "the cancelled render wrote {}",
        render.display()
    );

    let text = std::fs::read_to_string(&csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let rows = parse_rows(&text);
    // One row per frame, recorded after each present, frames 0 to 299.
    let frames: Vec<u64> = rows.iter().map(|r| r.frame).collect();
    assert_eq!(frames, (0..300).collect::<Vec<u64>>(), "the CSV's frames");
    for row in &rows {
        // A Vulkan device, winit and egui hold tens of MiB at the least; the
        // renderer alone has dozens of buffers, textures and pipelines;
        // lavapipe's Vulkan reports its allocator.
        assert!(row.rss_bytes > 32 << 20, "{row:?}");
        assert!(row.gpu_resources.is_some_and(|n| n > 10), "{row:?}");
        assert!(row.gpu_allocated_bytes.is_some_and(|b| b > 0), "{row:?}");
        // glibc reports its heap; what it holds is part of the resident set.
        if cfg!(all(target_os = "linux", target_env = "gnu")) {
            assert!(
                row.heap_in_use_bytes
                    .is_some_and(|b| b > 1 << 20 && b < row.rss_bytes * 4),
                "{row:?}"
            );
        }
    }
}

#[test]
fn a_missing_preset_is_refused_before_the_window_opens() {
    let dir = TempDir::new("soak-missing");
    let missing = dir.path().join("missing.ron");
    let out = Command::new(env!("CARGO_BIN_EXE_marbre"))
        .args(["soak", "--frames", "10", "--presets"])
        .arg(&missing)
        .env("MARBRE_CONFIG_DIR", dir.subdir("config"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!("{}: no such preset file", missing.display())),
        "{stderr}"
    );
}
