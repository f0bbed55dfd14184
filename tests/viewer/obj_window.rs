//! OBJ files opened in the viewer as scenes of their own
//! (`marbre_core::obj_scene`):
//!
//! - `the_cornell_box_opens_from_its_obj_file_alone`: `marbre --obj` on the
//!   Cornell box's OBJ shows what its preset shows (red and green walls,
//!   the white lamp, black outside: its own `Ke` light and no other).
//! - `a_dropped_obj_becomes_the_scene_and_save_leaves_it_alone`: an `.obj`
//!   dropped on the window (by the XDND protocol, as a file manager drops
//!   it) replaces the scene rather than being read as an environment map;
//!   Ctrl+S then writes nothing (the scene has no preset file: Save asks
//!   where, here in Save as's own field, no file dialog opening under
//!   Xvfb), and Enter there writes `<name>.ron` beside the OBJ, which
//!   stays byte for byte as it was.
//! - `the_command_line_refuses_a_non_obj_file_for_obj`: `--obj` names the
//!   file when it is not an OBJ file.

use crate::REPO;
use crate::e2e_window::{STEP_TIMEOUT, assert_clean_log, open};
use crate::window::cornell_box_in_the_window;
use crate::xvfb::{
    TempDir, assert_success, display_or_skip, drop_file, marbre_log, request_close, serial,
    wait_for_exit, wait_until,
};
use std::path::Path;

/// The Cornell box's OBJ and MTL files, as the repository ships them.
const CORNELL: &str = "presets/scenes/cornell-box";

#[test]
fn the_cornell_box_opens_from_its_obj_file_alone() {
    cornell_box_in_the_window(
        "cornell-obj",
        "fragment",
        [
            "--obj",
            "presets/scenes/cornell-box/CornellBox-Original.obj",
        ],
    );
}

#[test]
fn a_dropped_obj_becomes_the_scene_and_save_leaves_it_alone() {
    const TEST: &str = "a_dropped_obj_becomes_the_scene_and_save_leaves_it_alone";
    let _serial = serial();
    let dir = TempDir::new("obj-drop");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    // A copy, so that a write to it would show and harm nothing.
    let folder = dir.subdir("cornell");
    for name in ["CornellBox-Original.obj", "CornellBox-Original.mtl"] {
        std::fs::copy(Path::new(REPO).join(CORNELL).join(name), folder.join(name)).unwrap();
    }
    let obj = folder.join("CornellBox-Original.obj");
    let mtl = folder.join("CornellBox-Original.mtl");
    let preset = folder.join("CornellBox-Original.ron");
    let originals = [&obj, &mtl].map(|f| std::fs::read(f).unwrap());
    let untouched = || {
        for (file, bytes) in [&obj, &mtl].iter().zip(&originals) {
            assert_eq!(
                &std::fs::read(file).unwrap(),
                bytes,
                "{} was written",
                file.display()
            );
        }
    };

    let start = Path::new(REPO).join("tests/data/e2e/start.ron");
    let (mut child, session) = open(&x, &dir, &start);
    session.wait_for("the start scene (blue sky)", |l| {
        l.corner_luma > 0.2 && l.centre_blue_excess > 0.2
    });

    // Read as an environment map, the OBJ would fail to decode and leave
    // the blue sky; as a scene, the sky goes and the box's black outside
    // fills the corners, its lit back wall the centre.
    drop_file(&x, &session.window, &obj);
    let cornell = session.wait_for("the dropped Cornell box", |l| {
        l.corner_luma < 0.03 && l.centre_luma > 0.1 && l.centre_blue_excess < 0.05
    });
    println!("{TEST}: after the drop {cornell:?}");

    // Ctrl+S: the scene has no preset file yet, so nothing is written
    // (where no dialog can open, Save as asks for the path instead).
    // A save is written within the frame that reads the key: once the
    // viewer has read it, a wrong write would be there.
    session.focus();
    session.run(&["key", "ctrl+s"]);
    session.settle();
    untouched();
    assert!(!preset.exists(), "Save wrote {} unasked", preset.display());

    // Save as's field holds the suggestion, `<name>.ron` beside the OBJ,
    // and has the keyboard: Enter saves there.
    session.run(&["key", "Return"]);
    wait_until("Save as writing the preset", STEP_TIMEOUT, &dir, || {
        preset.exists()
    });
    let saved = marbre_core::preset::load(&preset)
        .unwrap_or_else(|e| panic!("Save as: {e}; log:\n{}", marbre_log(&dir)))
        .preset;
    untouched();
    assert_eq!(saved.scene.meshes.len(), 1);
    assert_eq!(
        saved.scene.meshes[0].obj, obj,
        "the preset refers to the OBJ"
    );
    assert_eq!(
        saved.scene.point_light, None,
        "the box's own lamp lights it"
    );
    let text = std::fs::read_to_string(&preset).unwrap();
    assert!(
        text.contains("obj: \"CornellBox-Original.obj\""),
        "the OBJ is named relative to the preset:\n{text}"
    );

    // Saved: closing asks nothing.
    request_close(&x, &session.window);
    assert_success(wait_for_exit(&mut child, &dir, STEP_TIMEOUT), &dir);
    untouched();
    assert_clean_log(&dir);
}

#[test]
fn the_command_line_refuses_a_non_obj_file_for_obj() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_marbre"))
        .args(["--obj", "presets/cornell.ron"])
        .current_dir(REPO)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("presets/cornell.ron: not an OBJ file"),
        "{stderr}"
    );
}
