use super::*;
use std::path::Path;

const MIB: u64 = 1 << 20;

fn options(frames: u64, warm_up_frames: u64) -> SoakOptions {
    SoakOptions {
        frames,
        seed: 1,
        presets: Vec::new(),
        warm_up_frames,
        report: None,
    }
}

/// A driver that has recorded `frames` samples from `sample(frame)`.
fn recorded(options: &SoakOptions, sample: impl Fn(u64) -> MemorySample) -> SoakDriver {
    let mut driver = SoakDriver::new(options);
    for frame in 0..options.frames {
        driver.record(frame, sample(frame));
        assert_eq!(driver.finished(frame), frame + 1 == options.frames);
    }
    driver
}

fn flat(_: u64) -> MemorySample {
    MemorySample {
        rss_bytes: 300 * MIB,
        gpu_allocated_bytes: Some(100 * MIB),
        gpu_resources: Some(200),
        heap: Some(crate::heap::HeapUsage {
            in_use_bytes: 120 * MIB,
            free_bytes: 4 * MIB,
        }),
    }
}

fn repo_presets() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    DEFAULT_PRESETS.iter().map(|p| root.join(p)).collect()
}

/// Whether sanitising would leave the scene exactly as it is.
fn is_sanitized(scene: &Scene) -> bool {
    let mut copy = scene.clone();
    copy.sanitize().is_empty() && copy == *scene
}

fn load(path: &Path) -> Scene {
    marbre_core::preset::load(path)
        .unwrap_or_else(|e| panic!("{e}"))
        .preset
        .scene
}

#[test]
fn flat_memory_passes() {
    let driver = recorded(&options(1000, 200), flat);
    let report = driver.verdict(0).expect("flat memory passes");
    assert!(report.ends_with("soak passed"), "{report}");
    assert!(report.contains("RSS: baseline 300.0 MiB"), "{report}");
    assert!(report.contains("GPU resources: baseline 200"), "{report}");
}

/// 200 KiB a frame: after 800 judged frames, 160 MiB over a 300 MiB
/// baseline, beyond both the 64 MiB and the 25 % allowance.
#[test]
fn a_linear_rss_leak_fails_naming_rss() {
    let driver = recorded(&options(1000, 200), |f| MemorySample {
        rss_bytes: 300 * MIB + f * 200 * 1024,
        ..flat(f)
    });
    let report = driver.verdict(0).expect_err("a leak fails");
    assert!(report.contains("RSS grew"), "{report}");
    assert!(!report.contains("GPU allocated grew"), "{report}");
    assert!(
        report.contains("slope +195.3 MiB per 1000 frames"),
        "{report}"
    );
}

/// One 64 KiB buffer a frame: 50 MiB over the warm-up baseline (112 MiB)
/// by the end, beyond the 32 MiB and 25 % allowance, and one more object
/// every frame.
#[test]
fn a_leaked_buffer_per_frame_fails_naming_the_gpu() {
    let driver = recorded(&options(1000, 200), |f| MemorySample {
        gpu_allocated_bytes: Some(100 * MIB + f * 64 * 1024),
        gpu_resources: Some(200 + f),
        ..flat(f)
    });
    let report = driver.verdict(0).expect_err("a leak fails");
    assert!(report.contains("GPU allocated grew"), "{report}");
    assert!(report.contains("GPU resources grew"), "{report}");
    assert!(!report.contains("RSS grew"), "{report}");
}

#[test]
fn validation_errors_fail_the_run() {
    let driver = recorded(&options(1000, 200), flat);
    let report = driver.verdict(3).expect_err("validation errors fail");
    assert!(report.contains("3 wgpu validation error(s)"), "{report}");
}

/// Backends without an allocator report and platforms without RSS are
/// said to be unmeasured, not failed.
#[test]
fn unmeasured_figures_are_reported_as_such() {
    let driver = recorded(&options(400, 100), |_| MemorySample {
        rss_bytes: 0,
        gpu_allocated_bytes: None,
        gpu_resources: Some(50),
        heap: None,
    });
    let report = driver.verdict(0).expect("nothing grew");
    assert!(
        report.contains("RSS: not reported") && report.contains("GPU allocated: not reported"),
        "{report}"
    );
}

#[test]
fn the_report_csv_has_one_row_per_recorded_frame() {
    let dir = tempfile::Builder::new()
        .prefix("soak-report")
        .tempdir()
        .unwrap();
    let path = dir.path().join("soak.csv");
    let options = SoakOptions {
        report: Some(path.clone()),
        ..options(300, 100)
    };
    let driver = recorded(&options, |f| MemorySample {
        gpu_allocated_bytes: (f != 7).then_some(100 * MIB),
        heap: (f != 9).then_some(flat(f).heap.unwrap()),
        ..flat(f)
    });
    driver.verdict(0).expect("flat memory passes");
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 301);
    assert_eq!(
        lines[0],
        "frame,rss_bytes,gpu_allocated_bytes,gpu_resources,heap_in_use_bytes,heap_free_bytes"
    );
    assert_eq!(lines[1], "0,314572800,104857600,200,125829120,4194304");
    assert_eq!(lines[8], "7,314572800,,200,125829120,4194304");
    assert_eq!(lines[10], "9,314572800,104857600,200,,");
}

#[test]
fn an_unwritable_report_fails_the_run_naming_the_file() {
    let dir = tempfile::Builder::new()
        .prefix("soak-report-unwritable")
        .tempdir()
        .unwrap();
    // A folder where the file should be: the rename cannot replace it.
    let path = dir.path().join("soak.csv");
    std::fs::create_dir_all(path.join("inside")).unwrap();
    let options = SoakOptions {
        report: Some(path.clone()),
        ..options(300, 100)
    };
    let report = recorded(&options, flat).verdict(0).unwrap_err();
    assert!(
        report.contains(&format!("{}: cannot write the report", path.display())),
        "{report}"
    );
}

#[test]
fn default_warm_up_is_a_fifth_within_limits() {
    assert_eq!(SoakOptions::default_warm_up(10_000), 2000);
    assert_eq!(SoakOptions::default_warm_up(100_000), 2000);
    assert_eq!(SoakOptions::default_warm_up(300), 60);
    assert_eq!(SoakOptions::default_warm_up(120), 50);
    assert_eq!(SoakOptions::default_warm_up(60), 30);
}

#[test]
fn preset_arguments_expand_folders_and_refuse_missing_files() {
    let dir = tempfile::Builder::new()
        .prefix("soak-presets")
        .tempdir()
        .unwrap();
    for name in ["b.ron", "a.ron", "notes.txt"] {
        std::fs::write(dir.path().join(name), "").unwrap();
    }
    let single = dir.path().join("b.ron");
    let files = SoakOptions::preset_files(&[dir.path().to_owned(), single.clone()]).unwrap();
    assert_eq!(
        files,
        [dir.path().join("a.ron"), dir.path().join("b.ron"), single]
    );
    let missing = dir.path().join("missing.ron");
    let err = SoakOptions::preset_files(std::slice::from_ref(&missing)).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!("{}: no such preset file", missing.display())
    );
}

/// The same seed and starting scene give the same actions and the same
/// scene after every frame; another seed gives other edits.
#[test]
fn step_is_deterministic_for_a_seed() {
    let start = load(&repo_presets()[0]);
    let run = |seed: u64| {
        let options = SoakOptions {
            seed,
            ..options(2000, 400)
        };
        let mut driver = SoakDriver::new(&options);
        let mut scene = start.clone();
        (0..2000)
            .map(|frame| (driver.step(frame, &mut scene), scene.clone()))
            .collect::<Vec<_>>()
    };
    let (a, b, other) = (run(5), run(5), run(6));
    assert!(a.iter().any(|(action, _)| *action != ScriptAction::Nothing));
    assert!(a == b, "two runs with seed 5 differ");
    assert!(a != other, "seeds 5 and 6 made the same edits");
    assert!(a.iter().any(|(_, scene)| *scene != start));
}

/// Over 10,000 frames (the soak) the driver asks for every action
/// and makes every kind of edit, and every scene it leaves passes the
/// scene's own sanitising unchanged. Preset loads are done here as the
/// viewer does them, with the real presets.
#[test]
fn ten_thousand_steps_make_every_edit_and_keep_the_scene_valid() {
    let presets = repo_presets();
    let options = SoakOptions {
        presets: presets.clone(),
        ..options(10_000, 2000)
    };
    let mut driver = SoakDriver::new(&options);
    let mut scene = load(&presets[0]);
    assert!(is_sanitized(&scene), "the starting preset is not sanitised");
    let (mut loads, mut losses, mut renders, mut nothing) = (Vec::new(), 0, 0, 0);
    for frame in 0..options.frames {
        match driver.step(frame, &mut scene) {
            ScriptAction::Nothing => nothing += 1,
            ScriptAction::LoadPreset(path) => {
                scene = load(&path);
                loads.push(path);
            }
            ScriptAction::LoseDevice => losses += 1,
            ScriptAction::StartRender { .. } => renders += 1,
        }
        assert!(
            is_sanitized(&scene),
            "frame {frame}: the edited scene does not pass sanitising unchanged"
        );
    }
    eprintln!("{}", driver.summary(0));
    assert_eq!(losses, 1);
    assert_eq!(renders, 1);
    assert!(loads.len() >= presets.len(), "{loads:?}");
    for preset in &presets {
        assert!(loads.contains(preset), "{} never loaded", preset.display());
    }
    assert!(nothing > 9000, "{nothing} frames without a load or loss");
    assert!(
        driver.parameter_edits > 5000,
        "{} parameter edits",
        driver.parameter_edits
    );
    for kind in Structural::ALL {
        assert!(
            driver.structural_edits[kind as usize] >= 5,
            "{} {} edits: {:?}",
            driver.structural_edits[kind as usize],
            kind.name(),
            driver.structural_edits
        );
    }
}

/// A frame asked for twice (the viewer could not present it) gets its
/// action once: a preset is not loaded twice, the device not lost twice.
#[test]
fn a_repeated_frame_gets_no_second_action() {
    let options = SoakOptions {
        presets: repo_presets(),
        ..options(300, 100)
    };
    let mut driver = SoakDriver::new(&options);
    let mut scene = Scene::default();
    let mut actions = Vec::new();
    for frame in 0..300 {
        for _ in 0..2 {
            let action = driver.step(frame, &mut scene);
            if action != ScriptAction::Nothing {
                actions.push((frame, action));
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    assert_eq!(
        actions,
        [
            (75, ScriptAction::LoadPreset(root.join(DEFAULT_PRESETS[0]))),
            (150, ScriptAction::LoadPreset(root.join(DEFAULT_PRESETS[1]))),
            (187, ScriptAction::LoseDevice),
            (225, ScriptAction::LoadPreset(root.join(DEFAULT_PRESETS[2]))),
            (
                297,
                ScriptAction::StartRender {
                    size: END_RENDER_SIZE,
                    spp: END_RENDER_SPP,
                    output: std::env::temp_dir()
                        .join(format!("marbre-soak-{}.exr", std::process::id())),
                }
            ),
        ]
    );
}

#[test]
fn progress_is_printed_after_each_tenth_but_not_at_the_end() {
    let driver = SoakDriver::new(&options(1000, 200));
    let lines: Vec<(u64, String)> = (0..1000)
        .filter_map(|frame| {
            driver
                .progress_line(frame, &flat(frame))
                .map(|l| (frame, l))
        })
        .collect();
    let frames: Vec<u64> = lines.iter().map(|(f, _)| *f).collect();
    assert_eq!(frames, [99, 199, 299, 399, 499, 599, 699, 799, 899]);
    assert_eq!(
        lines[0].1,
        "soak: frame 100 of 1000: RSS 300.0 MiB, GPU 100.0 MiB in 200 objects, \
         heap 120.0 MiB held + 4.0 MiB free"
    );
    let unmeasured = MemorySample {
        rss_bytes: 0,
        gpu_allocated_bytes: None,
        gpu_resources: Some(7),
        heap: None,
    };
    assert_eq!(
        driver.progress_line(499, &unmeasured).as_deref(),
        Some("soak: frame 500 of 1000: RSS 0.0 MiB, 7 GPU objects")
    );
    let tiny = SoakDriver::new(&options(5, 2));
    assert_eq!(
        (0..5)
            .filter(|&f| tiny.progress_line(f, &flat(f)).is_some())
            .count(),
        4,
        "a run shorter than ten frames reports every frame but the last"
    );
}
