//! The viewer driven end to end with synthetic input (xdotool under a
//! private Xvfb), as a person would use it, each step checked on the
//! pixels of the screenshot F12 saves:
//!
//! 1. the viewer opens `tests/data/e2e/start.ron` (a grey ball under a
//!    blue sky);
//! 2. a click in the panel's preset path field, the path of `lit.ron`
//!    typed, Enter: the image becomes a white ball lit by a point light on
//!    black (no blue left);
//! 3. the Point light section opened and its intensity slider dragged to
//!    the left end: the image goes black;
//! 4. Ctrl+Z: the light is back, the ball white again.
//!
//! Also: closing the window with an unsaved edit (asked, Esc, then Save);
//! a crashed run's autosave offered when its preset opens, kept for later
//! by Esc, and recovered; a window shrunk to a pixel and back; and a preset that takes
//! seconds to load at start-up (its progress shown, a key pressed meanwhile
//! kept for the scene).
//!
//! The panel is found by its layout: a 1280×720 window (the default size,
//! with a fresh settings folder), the side panel its default 396 points
//! wide on the right at scale 1, and the sections folded from the top so
//! that the Point light section sits at a fixed height whatever messages
//! the Preset section shows.

use crate::xvfb;

use crate::xvfb::{
    TempDir, assert_success, display_or_skip, frames_or_exit, grab_window, marbre_log,
    number_before, quality_line, request_close, serial, spawn_marbre, wait_for_exit,
    wait_for_frames, wait_until, xdotool,
};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::REPO;

/// The side panel's left edge at the default window size.
pub(crate) const PANEL_LEFT: i32 = 884;
/// Height of a folded section header, in pixels.
const HEADER_STEP: i32 = 23;
/// How long one step may take to show: a generous bound that fails
/// loudly, never one a figure depends on. A preset load builds a shader
/// (seconds on lavapipe), each frame takes about a second, and several
/// with both cores busy (issue 47).
pub(crate) const STEP_TIMEOUT: Duration = Duration::from_secs(300);

/// Mean luma (0..1), its standard deviation (a pattern) and mean
/// blue-minus-red of the image's central quarter, the luma of its top-left
/// corner (background), and the mean blue-minus-red of its top sixth
/// (which view of a scene is shown).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Look {
    pub(crate) centre_luma: f64,
    pub(crate) centre_spread: f64,
    pub(crate) centre_blue_excess: f64,
    pub(crate) corner_luma: f64,
    pub(crate) top_blue_excess: f64,
}

fn look(path: &Path) -> Look {
    let image = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    let (w, h) = image.dimensions();
    let luma = |rgb: [f64; 3]| 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    let mean = |xs: std::ops::Range<u32>, ys: std::ops::Range<u32>| {
        let (mut n, mut rgb) = (0.0, [0.0f64; 3]);
        for y in ys {
            for x in xs.clone() {
                let p = image.get_pixel(x, y);
                for c in 0..3 {
                    rgb[c] += f64::from(p[c]) / 255.0;
                }
                n += 1.0;
            }
        }
        rgb.map(|c| c / n)
    };
    let (xs, ys) = (w * 3 / 8..w * 5 / 8, h * 3 / 8..h * 5 / 8);
    let centre = mean(xs.clone(), ys.clone());
    let lumas: Vec<f64> = ys
        .flat_map(|y| xs.clone().map(move |x| (x, y)))
        .map(|(x, y)| {
            let p = image.get_pixel(x, y);
            luma(p.0.map(|c| f64::from(c) / 255.0))
        })
        .collect();
    let centre_mean = lumas.iter().sum::<f64>() / lumas.len() as f64;
    let centre_spread =
        (lumas.iter().map(|l| (l - centre_mean).powi(2)).sum::<f64>() / lumas.len() as f64).sqrt();
    let corner = mean(0..w / 10, 0..h / 10);
    let top = mean(0..w, 0..h / 6);
    Look {
        centre_luma: luma(centre),
        centre_spread,
        centre_blue_excess: centre[2] - centre[0],
        corner_luma: luma(corner),
        top_blue_excess: top[2] - top[0],
    }
}

/// The PNG screenshots in `folder`.
fn pngs(folder: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(folder)
        .map(|dir| {
            dir.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "png"))
                .collect()
        })
        .unwrap_or_default();
    found.sort();
    found
}

pub(crate) struct Session<'a> {
    pub(crate) x: &'a xvfb::Xvfb,
    pub(crate) window: String,
    /// The viewer's process, whose threads a failed wait prints.
    pid: u32,
    screenshots: PathBuf,
    dir: &'a TempDir,
}

impl Session<'_> {
    pub(crate) fn run(&self, args: &[&str]) {
        let out = xdotool(self.x, args);
        assert!(
            out.status.success(),
            "xdotool {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }

    pub(crate) fn focus(&self) {
        self.run(&["windowfocus", "--sync", &self.window]);
    }

    /// Returns once the viewer has read the input sent so far: two more
    /// frames shown ([`wait_for_frames`]). egui reads input once a frame,
    /// so steps that must reach it in different frames (the pointer
    /// resting before a press, a drag's press, moves and release, a key
    /// after the focus moved) are sent with this between them: a fixed
    /// sleep was outrun by a loaded machine's slower frames (issue 47).
    pub(crate) fn settle(&self) {
        wait_for_frames(self.dir, 2);
    }

    /// Moves the pointer to `(x, y)` and lets the viewer see it there.
    pub(crate) fn move_to(&self, x: i32, y: i32) {
        self.run(&["mousemove", &x.to_string(), &y.to_string()]);
        self.settle();
    }

    /// A click at `(x, y)`: the pointer rests there first (a press where
    /// egui still has the pointer elsewhere would hit what it was over),
    /// and the viewer has handled the click when this returns.
    pub(crate) fn click(&self, x: i32, y: i32) {
        self.move_to(x, y);
        self.run(&["click", "1"]);
        self.settle();
    }

    /// Folds the Preset, Materials and Environment sections, opens Point
    /// light and drags its intensity slider (logarithmic, 0 to 10 000, the
    /// fourth row of the section) from its knob to the far left. Each step
    /// waits until the viewer has read it: egui reads the pointer once per
    /// frame, and a press, moves and release within one slow frame would
    /// be a click on the knob.
    pub(crate) fn drag_light_intensity_to_zero(&self) {
        for header in 0..4 {
            self.click(PANEL_LEFT + 50, 12 + header * HEADER_STEP);
        }
        let (knob_x, knob_y) = (PANEL_LEFT + 79, 173);
        self.move_to(knob_x, knob_y);
        self.run(&["mousedown", "1"]);
        self.settle();
        for x in [knob_x - 20, knob_x - 40, knob_x - 60, PANEL_LEFT + 5] {
            self.move_to(x, knob_y);
        }
        self.run(&["mouseup", "1"]);
        self.settle();
    }

    /// Presses F12 until a screenshot satisfies `wanted`, returning its
    /// look; fails after [`STEP_TIMEOUT`] with the last look seen. Each
    /// F12 waits for its own screenshot (the viewer saves it within the
    /// frame that reads the key), however long the frame takes.
    pub(crate) fn wait_for(&self, what: &str, wanted: impl Fn(&Look) -> bool) -> Look {
        let start = Instant::now();
        let mut last = None;
        while start.elapsed() < STEP_TIMEOUT {
            let before = pngs(&self.screenshots).len();
            self.focus();
            self.run(&["key", "F12"]);
            while pngs(&self.screenshots).len() == before && start.elapsed() < STEP_TIMEOUT {
                std::thread::sleep(Duration::from_millis(200));
            }
            // The PNG is renamed into place once complete (atomic save).
            if let Some(latest) = pngs(&self.screenshots).last() {
                let seen = look(latest);
                if wanted(&seen) {
                    return seen;
                }
                last = Some(seen);
            }
            std::thread::sleep(Duration::from_millis(500));
        }
        panic!(
            "{what}: not seen within {STEP_TIMEOUT:?}; last screenshot: {last:?}; marbre's log:\n{}\n\
             its threads:\n{}",
            marbre_log(self.dir),
            xvfb::backtraces(self.pid)
        );
    }
}

/// Starts the viewer on `preset` and finds its window.
pub(crate) fn open<'a>(
    x: &'a xvfb::Xvfb,
    dir: &'a TempDir,
    preset: &Path,
) -> (xvfb::Guard, Session<'a>) {
    open_with(x, dir, preset, &[])
}

/// [`open`], with `extra` arguments for the viewer.
fn open_with<'a>(
    x: &'a xvfb::Xvfb,
    dir: &'a TempDir,
    preset: &Path,
    extra: &[&str],
) -> (xvfb::Guard, Session<'a>) {
    let cwd = dir.subdir("cwd");
    let mut args: Vec<OsString> = vec!["--preset".into(), preset.into()];
    args.extend(extra.iter().map(OsString::from));
    let child = spawn_marbre(x, dir, &cwd, &args);
    let found = xdotool(
        x,
        &["search", "--sync", "--onlyvisible", "--name", "^marbre$"],
    );
    let window = String::from_utf8_lossy(&found.stdout)
        .lines()
        .next()
        .unwrap_or_else(|| panic!("no marbre window; log:\n{}", marbre_log(dir)))
        .to_owned();
    let session = Session {
        x,
        window,
        pid: child.0.id(),
        screenshots: cwd.join("screenshots"),
        dir,
    };
    (child, session)
}

/// Neither a panic nor a GPU error the viewer did not catch in its log.
pub(crate) fn assert_clean_log(dir: &TempDir) {
    let log = marbre_log(dir);
    for bad in ["panicked", "uncaptured GPU error", "Validation Error"] {
        assert!(!log.contains(bad), "marbre's log has {bad:?}:\n{log}");
    }
}

#[test]
fn typed_path_slider_and_undo_show_on_the_pixels() {
    const TEST: &str = "typed_path_slider_and_undo_show_on_the_pixels";
    let _serial = serial();
    let dir = TempDir::new("e2e");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let start = Path::new(REPO).join("tests/data/e2e/start.ron");
    let lit = Path::new(REPO).join("tests/data/e2e/lit.ron");
    let (_child, session) = open(&x, &dir, &start);

    let first = session.wait_for("the start scene (blue sky)", |l| {
        l.corner_luma > 0.2 && l.centre_blue_excess > 0.2
    });

    // The typed-path route: click the path field, replace its text, Enter.
    session.focus();
    session.click(PANEL_LEFT + 190, 34);
    session.run(&["key", "ctrl+a"]);
    session.run(&["type", "--delay", "20", &lit.display().to_string()]);
    session.run(&["key", "Return"]);
    let loaded = session.wait_for("lit.ron loaded (white ball on black)", |l| {
        l.corner_luma < 0.02 && l.centre_luma > 0.6 && l.centre_blue_excess.abs() < 0.05
    });

    session.drag_light_intensity_to_zero();
    let dark = session.wait_for("the light's intensity dragged to 0 (black)", |l| {
        l.centre_luma < 0.02
    });

    // Ctrl+Z undoes the whole drag in one step.
    session.run(&["mousemove", "400", "300"]);
    session.focus();
    session.run(&["key", "ctrl+z"]);
    let undone = session.wait_for("Ctrl+Z (the light back)", |l| {
        l.centre_luma > 0.6 && l.corner_luma < 0.02
    });
    println!("start {first:?}\nloaded {loaded:?}\ndark {dark:?}\nundone {undone:?}");
    assert_clean_log(&dir);
}

/// Closing the window (the window manager's close request) with unsaved
/// edits asks first: Esc cancels and the viewer goes on; closing again and
/// choosing Save (the default button: Enter) writes the edit to the preset
/// file and quits.
#[test]
fn closing_with_unsaved_edits_asks_and_save_writes_the_preset() {
    const TEST: &str = "closing_with_unsaved_edits_asks_and_save_writes_the_preset";
    let _serial = serial();
    let dir = TempDir::new("e2e-quit");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let preset = dir.path().join("lit.ron");
    std::fs::copy(Path::new(REPO).join("tests/data/e2e/lit.ron"), &preset).unwrap();
    let intensity = || {
        marbre_core::preset::load(&preset)
            .unwrap_or_else(|e| panic!("{e}"))
            .preset
            .scene
            .point_light
            .expect("lit.ron has a point light")
            .intensity
    };
    assert_eq!(intensity(), 40.0);
    let (mut child, session) = open(&x, &dir, &preset);
    session.wait_for("lit.ron", |l| l.corner_luma < 0.02 && l.centre_luma > 0.6);
    session.drag_light_intensity_to_zero();
    session.wait_for("the light's intensity dragged to 0", |l| {
        l.centre_luma < 0.02
    });

    // Each request is handled once two more frames are shown: a viewer
    // that quit on it has exited by then.
    request_close(&x, &session.window);
    let closed = frames_or_exit(&mut child, &dir, 2);
    assert!(
        closed.is_none(),
        "closed ({closed:?}) without asking about the unsaved edit; log:\n{}",
        marbre_log(&dir)
    );
    session.focus();
    session.run(&["key", "Escape"]);
    let cancelled = frames_or_exit(&mut child, &dir, 2);
    assert!(
        cancelled.is_none(),
        "Esc must cancel the quit, not {cancelled:?}; log:\n{}",
        marbre_log(&dir)
    );
    assert_eq!(intensity(), 40.0, "nothing saved yet");

    request_close(&x, &session.window);
    let asked = frames_or_exit(&mut child, &dir, 2);
    assert!(
        asked.is_none(),
        "closed ({asked:?}) without asking the second time; log:\n{}",
        marbre_log(&dir)
    );
    session.focus();
    // Save is the default: Enter chooses it, although the slider dragged
    // a moment ago had the keyboard focus.
    session.run(&["key", "Return"]);
    let status = wait_for_exit(&mut child, &dir, STEP_TIMEOUT);
    assert_success(status, &dir);
    assert!(
        intensity() < 1e-3,
        "Save then quit: the file holds the edit, intensity {}",
        intensity()
    );
    assert_clean_log(&dir);
}

/// A run that crashed with unsaved edits left its autosave (written here
/// as the viewer writes it: a preset and an info file named by the dead
/// process's pid). The next start on its preset offers it once the preset
/// is in; Esc closes the offer and keeps the files for later; the start
/// after that offers it again, and Recover (the default button: Enter)
/// brings the edits back and removes the files.
#[test]
fn a_crashed_runs_autosave_is_offered_kept_for_later_and_recovered() {
    const TEST: &str = "a_crashed_runs_autosave_is_offered_kept_for_later_and_recovered";
    let _serial = serial();
    let dir = TempDir::new("e2e-recovery");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let start = Path::new(REPO).join("tests/data/e2e/start.ron");
    let lit = Path::new(REPO).join("tests/data/e2e/lit.ron");
    // Beyond Linux's pid_max (2^22): a writer that is surely gone.
    let dead_pid = 1u32 << 23;
    let config = dir.subdir("config");
    let recovered = config.join(format!("recovery-{dead_pid}.ron"));
    let info = config.join(format!("recovery-{dead_pid}-info.ron"));
    std::fs::copy(&lit, &recovered).unwrap();
    std::fs::write(
        &info,
        format!(
            "(source: {:?}, saved_at: \"2026-11-22 18:00:00\", pid: {dead_pid})",
            start.display().to_string()
        ),
    )
    .unwrap();
    let start_look = |l: &Look| l.corner_luma > 0.2 && l.centre_blue_excess > 0.2;
    let lit_look = |l: &Look| l.corner_luma < 0.02 && l.centre_luma > 0.6;

    {
        let (_child, session) = open(&x, &dir, &start);
        session.wait_for("the start scene behind the offer", start_look);
        session.focus();
        session.run(&["key", "Escape"]);
        session.settle();
        // Had Esc left the offer open, Enter would choose its default,
        // Recover, which removes the files in the frame that reads the
        // key: once the viewer has read it, they must still be there.
        session.run(&["key", "Return"]);
        session.settle();
        assert!(
            recovered.is_file() && info.is_file(),
            "Esc must keep the autosave for the next start; log:\n{}",
            marbre_log(&dir)
        );
        session.wait_for("the start scene after Esc", start_look);
        assert_clean_log(&dir);
    }

    let (_child, session) = open(&x, &dir, &start);
    session.wait_for("the start scene behind the second offer", start_look);
    session.focus();
    session.run(&["key", "Return"]);
    session.wait_for("the recovered edits (lit.ron's white ball)", lit_look);
    assert!(
        !recovered.exists() && !info.exists(),
        "a recovered autosave is removed; log:\n{}",
        marbre_log(&dir)
    );
    assert_clean_log(&dir);
}

/// Shrunk to 1×1 (as small as X allows; a minimised window reports 0×0,
/// which the viewer skips the same way) and grown back, the window keeps
/// rendering: no panic, no GPU validation error, the scene as before.
#[test]
fn shrinking_the_window_to_a_pixel_and_back_keeps_rendering() {
    const TEST: &str = "shrinking_the_window_to_a_pixel_and_back_keeps_rendering";
    let _serial = serial();
    let dir = TempDir::new("e2e-resize");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let lit = Path::new(REPO).join("tests/data/e2e/lit.ron");
    let (_child, session) = open(&x, &dir, &lit);
    let lit_look = |l: &Look| l.corner_luma < 0.02 && l.centre_luma > 0.6;
    session.wait_for("lit.ron", lit_look);
    for (w, h) in [(1, 1), (200, 100), (1, 1), (1280, 720)] {
        session.run(&[
            "windowsize",
            &session.window,
            &w.to_string(),
            &h.to_string(),
        ]);
        // At each size, frames drawn after the resize reached the viewer.
        session.settle();
    }
    session.wait_for("lit.ron after the resizes", lit_look);
    assert_clean_log(&dir);
}

/// Quads a side of the start-up test's grid mesh.
const GRID_QUADS: usize = 60;

/// A preset whose OBJ is the grid: its camera looks down on the grid lit
/// white by a point light; its second saved view looks away from it, into
/// the blue sky.
const SLOW_PRESET: &str = r#"(
    format_version: 2,
    description: "e2e: a grid mesh read from a pipe, slow to load",
    scene: (
        camera: (target: (0.0, 0.0, 0.0), distance: 2.5, yaw_degrees: 0.0, pitch_degrees: 60.0, fov_degrees: 40.0),
        views: [
            (name: "grid", camera: (target: (0.0, 0.0, 0.0), distance: 2.5, yaw_degrees: 0.0, pitch_degrees: 60.0, fov_degrees: 40.0)),
            (name: "sky", camera: (target: (0.0, 0.0, 40.0), distance: 2.0, yaw_degrees: 0.0, pitch_degrees: -30.0, fov_degrees: 40.0)),
        ],
        spheres: [],
        ground: None,
        meshes: [(name: "grid", obj: "grid.obj")],
        point_light: Some((position: (0.0, 3.0, 0.0), color: (1.0, 1.0, 1.0), intensity: 40.0)),
        environment: (source: Constant(radiance: (0.1, 0.2, 0.9)), intensity: 1.0, background_visible: true),
        render: (samples_per_frame: 1, exposure: 0.0, tone_map: Clamp, max_bounces: 1),
    ),
)"#;

/// Writes a flat `quads`×`quads` grid over [-1, 1]² at y = 0 as an OBJ.
fn write_grid_obj(path: &Path, quads: usize) {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for j in 0..=quads {
        for i in 0..=quads {
            let (x, z) = (i as f64 / quads as f64, j as f64 / quads as f64);
            writeln!(out, "v {:.5} 0 {:.5}", 2.0 * x - 1.0, 2.0 * z - 1.0).unwrap();
        }
    }
    for j in 0..quads {
        for i in 0..quads {
            let a = j * (quads + 1) + i + 1;
            let (b, c, d) = (a + 1, a + quads + 1, a + quads + 2);
            writeln!(out, "f {a} {d} {b}\nf {a} {c} {d}").unwrap();
        }
    }
    out.flush().unwrap();
}

/// Whether the Preset section shows a load's progress bar: its fill, egui's
/// selection blue (which egui shades from frame to frame), across a good
/// part of the row under Undo and Redo.
fn progress_bar_shown(window: &image::RgbImage) -> bool {
    let left = PANEL_LEFT as u32 + 25;
    let filled = (110..145)
        .flat_map(|y| (left..window.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let [r, g, b] = window.get_pixel(x, y).0.map(i32::from);
            r < 20 && g > 50 && b > 80 && b - g > 15
        })
        .count();
    filled >= 500
}

/// A preset that is slow to load at start-up (held before its meshes are
/// read while the file `MARBRE_TEST_HOLD_LOADS` names exists, which the
/// test removes when it chooses, as a slow disk or a network share would
/// deliver the OBJ): the window draws at once, the panel showing the
/// load's progress, and keys pressed meanwhile (Ctrl+2: the preset's second
/// saved view) and F12 after them act on the scene once it is drawn, rather
/// than on the empty placeholder shown until then.
#[test]
fn a_slow_preset_at_start_shows_its_progress_and_keeps_keys_pressed_meanwhile() {
    const TEST: &str = "a_slow_preset_at_start_shows_its_progress_and_keeps_keys_pressed_meanwhile";
    let _serial = serial();
    let dir = TempDir::new("e2e-slow-start");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let folder = dir.subdir("slow");
    write_grid_obj(&folder.join("grid.obj"), GRID_QUADS);
    let hold = xvfb::hold_loads(&dir);
    std::fs::write(&hold, "").unwrap();
    let preset = folder.join("slow.ron");
    std::fs::write(&preset, SLOW_PRESET).unwrap();
    let (_child, session) = open(&x, &dir, &preset);
    let loading = || progress_bar_shown(&grab_window(&x, &session.window));
    let wait_while =
        |what: &str, still: &dyn Fn() -> bool| wait_until(what, STEP_TIMEOUT, &dir, || !still());

    // The loader is held: the bar stays until the test lets it go.
    wait_while("the progress bar while the preset loads", &|| !loading());
    session.focus();
    session.run(&["key", "ctrl+2"]);
    session.run(&["key", "F12"]);
    // The viewer has read both keys (an F12 it did not hold would have
    // saved the placeholder within that frame).
    session.settle();
    assert!(loading(), "the load cannot end while it is held");
    assert!(
        pngs(&session.screenshots).is_empty(),
        "F12 waits for the scene"
    );
    std::fs::remove_file(&hold).unwrap();
    wait_while("the end of the load (the progress bar gone)", &loading);
    wait_while("the screenshot F12 asked for during the load", &|| {
        pngs(&session.screenshots).is_empty()
    });
    // The held keys in order: Ctrl+2 recalled the sky view, then F12 saved it
    // (not the placeholder, black, nor the preset's own view of the grid).
    let first = look(&pngs(&session.screenshots)[0]);
    assert!(
        first.centre_blue_excess > 0.2 && first.corner_luma > 0.05,
        "the screenshot taken by the F12 pressed during the load: {first:?}"
    );
    assert_clean_log(&dir);
}

/// The mean luma (0..1) of `xs` × `ys` in a grabbed window.
fn mean_luma(img: &image::RgbImage, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> f64 {
    let mut sum = 0.0;
    let mut n = 0.0;
    for y in ys {
        for x in xs.clone() {
            let p = img.get_pixel(x, y).0;
            sum += (0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
                / 255.0;
            n += 1.0;
        }
    }
    sum / n
}

/// The image restarts only when what it shows changes (issue 31). On the
/// default preset, whose colour ramp rows are wider than the panel, the
/// panel opens at its width (its edge at `PANEL_LEFT`: rows too wide
/// scroll rather than widen it and shrink the image); folding and opening
/// sections keeps the samples; and at a first launch (a fresh settings
/// folder, `--kernel auto`) the kernel chosen by timing both, a few
/// seconds in, keeps them too. The viewer's closing line counts the
/// images thrown away: none. The test waits for each event (the timing
/// stored in the settings, a first image, each click read), however
/// long a loaded machine takes.
#[test]
fn sections_and_the_first_kernel_choice_keep_the_image() {
    const TEST: &str = "sections_and_the_first_kernel_choice_keep_the_image";
    let _serial = serial();
    let dir = TempDir::new("keep-image");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let preset = Path::new(REPO).join("presets/default.ron");
    let (mut child, session) = open_with(&x, &dir, &preset, &["--kernel", "auto"]);
    // `auto` stores the kernel it found faster once both are timed.
    let config = dir.path().join("config");
    let stored_kernel = || {
        let (settings, _) = marbre_core::viewer_files::Settings::load(&config);
        settings.kernels.into_values().next()
    };
    wait_until(
        "the kernels timed and one stored",
        STEP_TIMEOUT,
        &dir,
        || stored_kernel().is_some(),
    );
    // F12's screenshot finishes the first round; the frames after it show it.
    session.wait_for("a first image", |_| true);
    session.settle();
    let window = grab_window(&x, &session.window);
    let (edge, rows) = (PANEL_LEFT as u32, 300..340);
    let (image, panel) = (
        mean_luma(&window, edge - 14..edge - 4, rows.clone()),
        mean_luma(&window, edge + 2..edge + 6, rows),
    );
    assert!(
        image > 0.25 && panel < 0.15,
        "the panel's edge is not at x = {edge}: image side luma {image:.3}, panel side {panel:.3}"
    );
    // Preset folded and opened; the marble's diffuse folded and opened.
    for (x, y) in [(50, 12), (50, 12), (60, 265), (60, 265)] {
        session.click(PANEL_LEFT + x, y);
    }
    session.move_to(400, 300);
    request_close(&x, &session.window);
    assert_success(wait_for_exit(&mut child, &dir, STEP_TIMEOUT), &dir);
    let line = quality_line(&dir);
    eprintln!("{TEST}: {line}");
    let kernel = stored_kernel().expect("stored above");
    assert!(
        line.contains(&format!("({kernel} kernel)")),
        "the viewer did not switch to the {kernel} kernel auto chose: {line}"
    );
    assert!(
        number_before(&line, "spp") > 0,
        "nothing accumulated: {line}"
    );
    assert_eq!(
        number_before(&line, "restarts"),
        0,
        "an image was thrown away: {line}\n{}",
        marbre_log(&dir)
    );
    assert_clean_log(&dir);
}
