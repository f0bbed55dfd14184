//! The node editor driven as a person would (xdotool under a private
//! Xvfb), each step read back from the preset the viewer saves (Ctrl+S)
//! and the image F12 saves:
//!
//! 1. the grey ball's graph opened from the panel's "node graph" button;
//! 2. Shift+A with the pointer on the material's diffuse socket, "checker"
//!    typed, Enter: a checker 3D node on the diffuse, and the ball shows a
//!    checker;
//! 3. three notches of the wheel down over the new node's header (zoomed
//!    out about the pointer, so the header stays under it), then the
//!    header dragged 100 px left and 60 down: the node moves along the drag
//!    by more than it (the zoom is below 1/1.2²), and no other node gets a
//!    position;
//! 4. Delete: the diffuse is a constant again and the ball plain; Ctrl+Z:
//!    the checker is back.
//!
//! The places are the default window's (1280×720, fresh settings) with the
//! Preset section folded, so that the button sits at a fixed height.

use crate::REPO;
use crate::e2e_window::{PANEL_LEFT, STEP_TIMEOUT, assert_clean_log, open};
use crate::xvfb::{TempDir, display_or_skip, marbre_log, serial};
use marbre_core::scene::texture_graph::NodePath;
use marbre_core::scene::{MaterialKey, Pattern, PatternKind, Texture};
use std::path::Path;
use std::time::{Duration, Instant};

/// Where Shift+A is pressed: left of the material's node, nearer its
/// diffuse socket (at 719, 157 with the graph's window where it opens, the
/// material's node on the right) than any other input. The new node's
/// top-left goes here.
const ADD_AT: (i32, i32) = (600, 140);
/// On the new node's header row, clear of the sockets.
const HEADER: (i32, i32) = (ADD_AT.0 + 60, ADD_AT.1 + 22);
const DRAG: (i32, i32) = (-100, 60);

/// The saved preset's diffuse tree and the graph positions of the ball's
/// material, once the file shows `wanted` (both it): fails after
/// [`STEP_TIMEOUT`], with the log.
fn saved(
    dir: &TempDir,
    path: &Path,
    what: &str,
    wanted: impl Fn(&Texture, &[(String, glam::Vec2)]) -> bool,
) -> (Texture, Vec<(String, glam::Vec2)>) {
    let start = Instant::now();
    let mut last = None;
    while start.elapsed() < STEP_TIMEOUT {
        if let Ok(loaded) = marbre_core::preset::load(path) {
            let scene = loaded.preset.scene;
            let diffuse = scene.spheres[0].material.diffuse.clone();
            let positions: Vec<(String, glam::Vec2)> = scene
                .graph_layout
                .get(MaterialKey::Sphere(0))
                .map(|l| {
                    ["diffuse", "diffuse.a", "diffuse.b", "specular", "roughness"]
                        .into_iter()
                        .filter_map(|p| {
                            let node: NodePath = p.parse().unwrap();
                            l.position(&node).map(|at| (p.to_owned(), at))
                        })
                        .collect()
                })
                .unwrap_or_default();
            if wanted(&diffuse, &positions) {
                return (diffuse, positions);
            }
            last = Some((diffuse, positions));
        }
        std::thread::sleep(Duration::from_millis(300));
    }
    panic!(
        "{what}: not within {STEP_TIMEOUT:?}; the saved preset's diffuse and positions are {last:?}; log:\n{}",
        marbre_log(dir)
    );
}

fn is_checker(t: &Texture, _: &[(String, glam::Vec2)]) -> bool {
    t.pattern.kind() == PatternKind::Checker
}

#[test]
fn the_node_editor_adds_zooms_moves_deletes_and_undoes() {
    const TEST: &str = "the_node_editor_adds_zooms_moves_deletes_and_undoes";
    let _serial = serial();
    let dir = TempDir::new("node-editor");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let preset = dir.path().join("ball.ron");
    std::fs::copy(Path::new(REPO).join("tests/data/e2e/start.ron"), &preset).unwrap();
    let (_child, session) = open(&x, &dir, &preset);
    let plain = session.wait_for("the grey ball", |l| l.centre_luma > 0.2);
    assert!(plain.centre_spread < 0.05, "{plain:?}");

    // Each step waits until the viewer has read it (`Session::settle`):
    // egui reads input once a frame, and a slow frame would merge steps.
    session.focus();
    session.click(PANEL_LEFT + 50, 12);
    session.click(PANEL_LEFT + 86, 81);
    // The graph's window, opened by that click, is drawn.
    session.settle();

    // Add a checker on the diffuse.
    let mv = |(x, y): (i32, i32)| session.move_to(x, y);
    mv(ADD_AT);
    session.focus();
    session.run(&["key", "shift+a"]);
    session.settle();
    session.run(&["type", "--delay", "50", "checker"]);
    session.settle();
    session.run(&["key", "Return"]);
    session.settle();
    session.run(&["key", "ctrl+s"]);
    let (_, added) = saved(&dir, &preset, "Shift+A, checker, Enter, Ctrl+S", is_checker);
    let checker = session.wait_for("a checker on the ball", |l| l.centre_spread > 0.08);
    let place = |positions: &[(String, glam::Vec2)], path: &str| {
        positions
            .iter()
            .find(|(p, _)| p == path)
            .map(|(_, at)| *at)
            .unwrap_or_else(|| panic!("no position for {path}: {positions:?}"))
    };
    let at_add = place(&added, "diffuse");

    // Zoom out about the header, then drag it.
    mv(HEADER);
    for _ in 0..3 {
        session.run(&["click", "5"]);
        session.settle();
    }
    session.run(&["mousedown", "1"]);
    session.settle();
    for k in 1..=4 {
        mv((HEADER.0 + DRAG.0 * k / 4, HEADER.1 + DRAG.1 * k / 4));
    }
    session.run(&["mouseup", "1"]);
    session.settle();
    session.focus();
    session.run(&["key", "ctrl+s"]);
    // Zoomed out, a drag on screen moves the node further in the graph,
    // along the drag. (How far a notch of X's wheel reaches egui varies:
    // under Xvfb each reaches the viewer twice, 1.2⁻⁶ for three.)
    let drag = glam::Vec2::new(DRAG.0 as f32, DRAG.1 as f32);
    let (_, moved) = saved(
        &dir,
        &preset,
        "the drag saved (the node somewhere else)",
        |t, positions| {
            is_checker(t, positions)
                && positions
                    .iter()
                    .any(|(p, at)| p == "diffuse" && *at != at_add)
        },
    );
    let at_drag = place(&moved, "diffuse");
    let in_graph = at_drag - at_add;
    let zoom = drag.length() / in_graph.length();
    assert!(
        zoom < 1.0 / 1.2f32.powi(2) && in_graph.normalize().dot(drag.normalize()) > 0.999,
        "added at {at_add}, dragged to {at_drag}: a drag of {DRAG:?} on screen, at a zoom of {zoom}"
    );
    assert_eq!(
        moved.len(),
        1,
        "only the dragged node has a position: {moved:?}"
    );

    // Delete the selected node, then undo.
    session.focus();
    session.run(&["key", "Delete"]);
    session.settle();
    session.run(&["key", "ctrl+s"]);
    let (constant, _) = saved(&dir, &preset, "Delete, Ctrl+S", |t, _| {
        t.pattern == Pattern::Constant
    });
    let plain_again = session.wait_for("the plain ball", |l| l.centre_spread < 0.05);
    session.run(&["key", "ctrl+z"]);
    session.settle();
    session.run(&["key", "ctrl+s"]);
    saved(&dir, &preset, "Ctrl+Z, Ctrl+S", is_checker);
    let back = session.wait_for("the checker back", |l| l.centre_spread > 0.08);
    println!(
        "{TEST}: plain {plain:?}\nchecker {checker:?}\nafter delete {plain_again:?} ({constant:?})\nundone {back:?}\nadded at {at_add}, dragged to {at_drag} at a zoom of {zoom}"
    );
    assert_clean_log(&dir);
}
