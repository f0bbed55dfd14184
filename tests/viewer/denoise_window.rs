//! OIDN in the window: the viewer never waits for the denoiser.

use crate::REPO;
use crate::xvfb::{
    TempDir, assert_success, display_or_skip, marbre_log, number_before, quality_line, serial,
    spawn_marbre, wait_for_exit,
};
use std::path::Path;
use std::time::Duration;

/// The Cornell box (about a second a round on lavapipe) shown through
/// OIDN's balanced network, which takes seconds on the same two cores at
/// the window's size (its thread runs at a lower priority than the
/// trace's): the window keeps drawing all the while. Each image OIDN
/// filtered was read back and filtered while several frames were drawn; a
/// viewer that waited for it would draw one. The run ends once the first
/// image is denoised, however long that takes on a loaded machine.
#[test]
fn the_window_keeps_drawing_while_oidn_denoises() {
    const TEST: &str = "the_window_keeps_drawing_while_oidn_denoises";
    let _serial = serial();
    let dir = TempDir::new("denoise-window");
    let Some(x) = display_or_skip(TEST, &dir, &[]) else {
        return;
    };
    if marbre_oidn::library_or_skip(TEST).is_none() {
        return;
    }
    let cornell = std::fs::read_to_string(Path::new(REPO).join("presets/cornell.ron")).unwrap();
    let obj = Path::new(REPO).join("presets/scenes/cornell-box/CornellBox-Original.obj");
    let denoised = cornell
        .replace(
            "render: (max_bounces: 8)",
            "render: (max_bounces: 8, denoise: true, denoiser: Oidn, denoise_quality: Balanced)",
        )
        .replace(
            "\"scenes/cornell-box/CornellBox-Original.obj\"",
            &format!("{:?}", obj.display().to_string()),
        );
    assert_ne!(denoised, cornell, "the Cornell preset's render line moved");
    let preset = dir.path().join("cornell-denoised.ron");
    std::fs::write(&preset, denoised).unwrap();
    let mut child = spawn_marbre(
        &x,
        &dir,
        Path::new(REPO),
        &[
            "--preset".into(),
            preset.into(),
            "--exit-after-denoised".into(),
            "1".into(),
        ],
    );
    assert_success(
        wait_for_exit(&mut child, &dir, Duration::from_secs(600)),
        &dir,
    );
    let quality = quality_line(&dir);
    let log = marbre_log(&dir);
    let line = log
        .lines()
        .find(|l| l.starts_with("denoise: "))
        .unwrap_or_else(|| panic!("no denoise line:\n{log}"));
    eprintln!("{TEST}: {quality}\n{TEST}: {line}");
    assert!(
        line.contains("OIDN 2.") && line.contains("(balanced)"),
        "{line}"
    );
    assert!(number_before(line, "images") >= 1, "{line}");
    assert!(number_before(line, "frames") >= 3, "{line}");
}
