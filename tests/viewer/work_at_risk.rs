//! What keeps a user's work safe in the window (issue 28), driven as a
//! person would with synthetic input (xdotool under a private Xvfb, which
//! runs no desktop portal: no file dialog can open):
//!
//! - `save_as_without_a_file_dialog_writes_the_typed_path_and_keeps_the_original`:
//!   Ctrl+Shift+S asks where to save in a field of its own; Enter there
//!   saves to the typed path, and the preset the scene came from keeps
//!   what it held. It used to put the path in the Preset field, whose
//!   Enter *opens* the path: the unsaved-changes question followed, and its
//!   default answer, Save, overwrote the original.
//! - `an_autosave_is_offered_with_its_own_preset_only`: a run that died
//!   while editing one preset left its autosave; a start on another preset
//!   does not offer it (it used to, and Enter replaced the preset asked
//!   for), and opening the first preset does.
//! - `the_scene_keeps_rendering_under_the_recovery_prompt`: with the offer
//!   up, the window draws about as many frames as without it (it used to
//!   fall to about a third: egui's whole pass, a backdrop over the whole
//!   window included, was drawn again every frame).
//! - `recovered_edits_survive_a_second_crash`: an edit autosaved, the
//!   viewer killed, its edits recovered at the next start, the viewer
//!   killed again: the start after offers them again (issue 47). Recover
//!   used to count them saved, delete their file and write none, so the
//!   second crash lost them.
//! - `keys_typed_for_the_panel_fire_no_shortcut`: "h3" typed after a click
//!   beside a text field, or into a field at once after the click that
//!   focuses it, neither hides the panel (H) nor recalls a saved view
//!   (which takes Ctrl+digit now).

use crate::REPO;
use crate::e2e_window::{Look, PANEL_LEFT, STEP_TIMEOUT, Session, assert_clean_log, open};
use crate::xvfb::{
    Guard, TempDir, Xvfb, assert_success, display_or_skip, grab_window, marbre_log, number_before,
    quality_line, request_close, serial, wait_for_exit, xdotool,
};
use std::path::Path;
use std::time::{Duration, Instant};

/// Beyond Linux's pid_max (2^22): the pid of a run that is surely gone.
const DEAD_PID: u32 = 1 << 23;

/// egui's dark theme fills the side panel, and dialogs, with this grey.
const PANEL_FILL: [u8; 3] = [27, 27, 27];

/// Leaves in `config` what a run that died while editing `source` leaves:
/// its autosave (here a copy of `scene`) and the info file naming `source`.
/// Returns both files' paths.
fn autosave_left_by_a_dead_run(
    config: &Path,
    source: &Path,
    scene: &Path,
) -> [std::path::PathBuf; 2] {
    let preset = config.join(format!("recovery-{DEAD_PID}.ron"));
    let info = config.join(format!("recovery-{DEAD_PID}-info.ron"));
    std::fs::copy(scene, &preset).unwrap();
    std::fs::write(
        &info,
        format!(
            "(source: {:?}, saved_at: \"2026-11-22 18:00:00\", pid: {DEAD_PID})",
            source.display().to_string()
        ),
    )
    .unwrap();
    [preset, info]
}

/// The point light's intensity in the preset at `path`.
fn intensity(path: &Path) -> f32 {
    marbre_core::preset::load(path)
        .unwrap_or_else(|e| panic!("{e}"))
        .preset
        .scene
        .point_light
        .expect("the preset has a point light")
        .intensity
}

/// Waits until `path` exists; false after [`STEP_TIMEOUT`].
fn appears(path: &Path) -> bool {
    let deadline = Instant::now() + STEP_TIMEOUT;
    while !path.exists() {
        if Instant::now() > deadline {
            return false;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    true
}

/// The fraction of the pixels in columns `xs` and rows `ys` of `window`
/// that have exactly `colour`.
fn fraction_of(
    window: &image::RgbImage,
    xs: std::ops::Range<u32>,
    ys: std::ops::Range<u32>,
    colour: [u8; 3],
) -> f64 {
    let all = xs.len() * ys.len();
    let matching = ys
        .flat_map(|y| xs.clone().map(move |x| (x, y)))
        .filter(|&(x, y)| window.get_pixel(x, y).0 == colour)
        .count();
    matching as f64 / all as f64
}

#[test]
fn save_as_without_a_file_dialog_writes_the_typed_path_and_keeps_the_original() {
    const TEST: &str = "save_as_without_a_file_dialog_writes_the_typed_path_and_keeps_the_original";
    let _serial = serial();
    let dir = TempDir::new("risk-sa");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let mine = dir.path().join("mine.ron");
    let copy = dir.path().join("copy.ron");
    let other = dir.path().join("other.ron");
    std::fs::copy(Path::new(REPO).join("tests/data/e2e/lit.ron"), &mine).unwrap();
    std::fs::copy(Path::new(REPO).join("tests/data/e2e/start.ron"), &other).unwrap();
    let other_bytes = std::fs::read(&other).unwrap();
    let (mut child, session) = open(&x, &dir, &mine);
    session.wait_for("mine.ron", |l| l.corner_luma < 0.02 && l.centre_luma > 0.6);
    session.drag_light_intensity_to_zero();
    session.wait_for("the light's intensity dragged to 0", |l| {
        l.centre_luma < 0.02
    });
    // The drag folded the Preset section: unfold it, so that its path
    // field is there to take the keys, as it was when the bug showed.
    session.click(PANEL_LEFT + 50, 12);

    session.focus();
    session.run(&["key", "ctrl+shift+s"]);
    std::thread::sleep(Duration::from_millis(1500));
    session.run(&["key", "ctrl+a"]);
    session.run(&["type", "--delay", "20", &copy.display().to_string()]);
    session.run(&["key", "Return"]);
    std::thread::sleep(Duration::from_secs(3));
    // Had Enter opened the typed path, this would answer the question
    // about the unsaved changes with its default, Save.
    session.run(&["key", "Return"]);
    let copied = appears(&copy);
    std::thread::sleep(Duration::from_secs(2));
    assert_eq!(intensity(&mine), 40.0, "the original preset was written");
    assert!(
        copied,
        "Save as wrote nothing to {}; log:\n{}",
        copy.display(),
        marbre_log(&dir)
    );
    assert!(intensity(&copy) < 1e-3, "the copy lacks the edit");

    // Save as never replaces a file without asking: naming one that
    // exists asks, and Esc keeps it; a second Esc closes Save as.
    session.run(&["key", "ctrl+shift+s"]);
    std::thread::sleep(Duration::from_millis(1500));
    session.run(&["key", "ctrl+a"]);
    session.run(&["type", "--delay", "20", &other.display().to_string()]);
    session.run(&["key", "Return"]);
    std::thread::sleep(Duration::from_secs(3));
    session.run(&["key", "Escape"]);
    std::thread::sleep(Duration::from_secs(2));
    session.run(&["key", "Escape"]);
    std::thread::sleep(Duration::from_secs(2));
    assert_eq!(
        std::fs::read(&other).unwrap(),
        other_bytes,
        "{} was replaced without asking",
        other.display()
    );

    // The scene is now copy.ron's, saved: closing asks nothing, and the
    // next start opens copy.ron.
    request_close(&x, &session.window);
    assert_success(wait_for_exit(&mut child, &dir, STEP_TIMEOUT), &dir);
    let settings = std::fs::read_to_string(dir.path().join("config/settings.ron")).unwrap();
    assert!(
        settings.contains(&format!(
            "last_preset: Some({:?})",
            copy.display().to_string()
        )),
        "the last preset is not copy.ron: {settings}"
    );
    assert_eq!(intensity(&mine), 40.0);
    assert_clean_log(&dir);
}

#[test]
fn an_autosave_is_offered_with_its_own_preset_only() {
    const TEST: &str = "an_autosave_is_offered_with_its_own_preset_only";
    let _serial = serial();
    let dir = TempDir::new("risk-offer");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    // mine.ron shows what start.ron shows; its unsaved edits, autosaved,
    // made it lit.ron's white ball on black.
    let mine = dir.path().join("mine.ron");
    std::fs::copy(Path::new(REPO).join("tests/data/e2e/start.ron"), &mine).unwrap();
    let lit = Path::new(REPO).join("tests/data/e2e/lit.ron");
    let files = autosave_left_by_a_dead_run(&dir.subdir("config"), &mine, &lit);
    let start_look = |l: &Look| l.corner_luma > 0.2 && l.centre_blue_excess > 0.2;
    let lit_look = |l: &Look| l.corner_luma < 0.02 && l.centre_luma > 0.6;

    let start = Path::new(REPO).join("tests/data/e2e/start.ron");
    let (_child, session) = open(&x, &dir, &start);
    session.wait_for("start.ron", start_look);
    // Were mine.ron's autosave offered over start.ron, Enter would choose
    // the offer's default, Recover.
    session.focus();
    session.run(&["key", "Return"]);
    std::thread::sleep(Duration::from_secs(5));
    assert!(
        files.iter().all(|f| f.is_file()),
        "mine.ron's autosave was offered and recovered over start.ron; log:\n{}",
        marbre_log(&dir)
    );
    session.wait_for("start.ron still", start_look);

    // Opening mine.ron offers its autosave: Enter (Recover) brings the
    // edits back, once the offer is up.
    session.click(PANEL_LEFT + 190, 34);
    session.run(&["key", "ctrl+a"]);
    session.run(&["type", "--delay", "20", &mine.display().to_string()]);
    session.run(&["key", "Return"]);
    let deadline = Instant::now() + STEP_TIMEOUT;
    while files.iter().any(|f| f.exists()) {
        assert!(
            Instant::now() < deadline,
            "opening mine.ron did not offer its autosave; log:\n{}",
            marbre_log(&dir)
        );
        std::thread::sleep(Duration::from_secs(2));
        session.focus();
        session.run(&["key", "Return"]);
    }
    session.wait_for(
        "mine.ron's recovered edits (lit.ron's white ball)",
        lit_look,
    );
    assert_clean_log(&dir);
}

/// Frames the viewer draws on the Cornell box (a round takes about a
/// second on lavapipe, so each frame traces a budgeted part of one) in
/// `seconds` after its window shows, as its quality line counts them when
/// closed; with `offer`, an autosave of the box is offered from the start.
/// Also the window's pixels just before it closed.
fn frames_on_the_cornell_box(test: &str, offer: bool, seconds: u64) -> (u64, image::RgbImage) {
    let dir = TempDir::new(if offer {
        "risk-offer-frames"
    } else {
        "risk-frames"
    });
    let x = display_or_skip(test, &dir, &["xdotool"]).expect("checked by the caller");
    let cornell = Path::new(REPO).join("presets/cornell.ron");
    let config = dir.subdir("config");
    if offer {
        let lit = Path::new(REPO).join("tests/data/e2e/lit.ron");
        autosave_left_by_a_dead_run(&config, &cornell, &lit);
    }
    let (mut child, session) = open(&x, &dir, &cornell);
    std::thread::sleep(Duration::from_secs(seconds));
    let window = grab_window(&x, &session.window);
    request_close(&x, &session.window);
    assert_success(wait_for_exit(&mut child, &dir, STEP_TIMEOUT), &dir);
    let line = quality_line(&dir);
    eprintln!("{test} (offer: {offer}): {line}");
    (number_before(&line, "frames").into(), window)
}

#[test]
fn the_scene_keeps_rendering_under_the_recovery_prompt() {
    const TEST: &str = "the_scene_keeps_rendering_under_the_recovery_prompt";
    let _serial = serial();
    {
        let dir = TempDir::new("risk-frames-check");
        if display_or_skip(TEST, &dir, &["xdotool"]).is_none() {
            return;
        }
    }
    const SECONDS: u64 = 40;
    let (plain, plain_window) = frames_on_the_cornell_box(TEST, false, SECONDS);
    let (prompted, prompted_window) = frames_on_the_cornell_box(TEST, true, SECONDS);
    // The prompt's box, centred on the window, is filled with the dialogs'
    // grey (text aside, about three quarters of it): the second run
    // counted its frames under it, the first with the box in view.
    let (xs, ys) = (560..720, 330..400);
    assert!(
        fraction_of(&plain_window, xs.clone(), ys.clone(), PANEL_FILL) < 0.1,
        "a dialog over the plain run's image"
    );
    assert!(
        fraction_of(&prompted_window, xs, ys, PANEL_FILL) > 0.4,
        "no prompt over the image in the second run"
    );
    assert!(
        prompted as f64 >= 0.6 * plain as f64,
        "{prompted} frames under the prompt in {SECONDS} s, {plain} without"
    );
}

#[test]
fn keys_typed_for_the_panel_fire_no_shortcut() {
    const TEST: &str = "keys_typed_for_the_panel_fire_no_shortcut";
    let _serial = serial();
    let dir = TempDir::new("risk-keys");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    // The default preset's own camera shows the warm evening sky at the
    // top of the image (blue − red −0.07); its saved view 3 looks down at
    // the ground, whose polished cells mirror the blue sky (0.19), as
    // `number_keys_recall_saved_views` says.
    let preset = Path::new(REPO).join("presets/default.ron");
    let own_view = |l: &Look| l.top_blue_excess < 0.05;
    let (_child, session) = open(&x, &dir, &preset);
    session.wait_for("default.ron from its own camera", own_view);
    // The panel is the right of the window from x = 820 or so on (the
    // material editor widens it): its fill covers much of it.
    let panel_shown = || {
        let window = grab_window(&x, &session.window);
        fraction_of(&window, 1000..window.width(), 0..560, PANEL_FILL) > 0.3
    };
    assert!(panel_shown(), "no panel to begin with");

    // A click beside the Recent button, on the panel but on no widget,
    // then "h3", as a path typed where the click missed its field.
    session.focus();
    session.click(1200, 58);
    session.run(&["type", "--delay", "20", "h3"]);
    std::thread::sleep(Duration::from_secs(3));
    assert!(panel_shown(), "h typed on the panel hid it");
    session.wait_for("no saved view recalled by 3 typed on the panel", own_view);

    // A click in the preset path field and "h3" at once, in the frame
    // that gives the field the keyboard.
    session.run(&[
        "mousemove",
        "1000",
        "34",
        "click",
        "1",
        "type",
        "--delay",
        "20",
        "h3",
    ]);
    std::thread::sleep(Duration::from_secs(3));
    assert!(panel_shown(), "h typed into the path field hid the panel");
    session.wait_for("no saved view recalled by 3 typed into the field", own_view);

    // Over the image (clicked, so that the field lets the keyboard go), H
    // hides the panel. Not in the click's own frame, where the field still
    // had the keyboard as it began: a screenshot taken after the click
    // marks a later frame (a frame may take seconds, F12 finishing a round).
    session.click(400, 300);
    session.wait_for("a frame after the click on the image", |_| true);
    session.run(&["key", "h"]);
    let deadline = Instant::now() + STEP_TIMEOUT;
    while panel_shown() {
        assert!(
            Instant::now() < deadline,
            "H over the image did not hide the panel; log:\n{}",
            marbre_log(&dir)
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    assert_clean_log(&dir);
}

/// How long an autosave may take to appear: the viewer's interval (20 s
/// after the first unsaved frame) and then a step.
const AUTOSAVE_TIMEOUT: Duration = Duration::from_secs(20 + STEP_TIMEOUT.as_secs());

/// Waits until `done`, polling; fails loudly, with the log, after
/// `timeout`.
fn wait_until(what: &str, timeout: Duration, dir: &TempDir, mut done: impl FnMut() -> bool) {
    let deadline = Instant::now() + timeout;
    while !done() {
        assert!(
            Instant::now() < deadline,
            "{what}: not within {timeout:?}; marbre's log:\n{}",
            marbre_log(dir)
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The recovery files a viewer with pid `pid` writes in `config`: its
/// autosaved preset, and the info file written after it that makes it an
/// offer.
fn recovery_files(config: &Path, pid: u32) -> [std::path::PathBuf; 2] {
    [
        config.join(format!("recovery-{pid}.ron")),
        config.join(format!("recovery-{pid}-info.ron")),
    ]
}

/// Whether a prompt's box covers the middle of `window` (the image there
/// is black or lit, never the dialogs' grey).
fn prompt_shown(x: &Xvfb, window: &str) -> bool {
    fraction_of(&grab_window(x, window), 560..720, 330..400, PANEL_FILL) > 0.4
}

/// Kills the viewer as a crash would (SIGKILL: no clean exit, nothing
/// removed), asserting that it was still running, and waits until its
/// window is gone, so that the next start's window is the only one.
fn crash(x: &Xvfb, mut child: Guard, dir: &TempDir) {
    use std::os::unix::process::ExitStatusExt;
    child.0.kill().unwrap();
    let status = child.0.wait().unwrap();
    assert_eq!(
        status.signal(),
        Some(9),
        "marbre ended by itself ({status}) before the kill; log:\n{}",
        marbre_log(dir)
    );
    wait_until("the killed viewer's window gone", STEP_TIMEOUT, dir, || {
        xdotool(x, &["search", "--onlyvisible", "--name", "^marbre$"])
            .stdout
            .is_empty()
    });
}

/// Answers the recovery offer of `files` with Enter (Recover, the
/// default) once the offer is up, until the files are gone (recovered).
fn recover(session: &Session, files: &[std::path::PathBuf], dir: &TempDir) {
    wait_until("the recovery offered and taken", STEP_TIMEOUT, dir, || {
        if files.iter().all(|f| !f.exists()) {
            return true;
        }
        if prompt_shown(session.x, &session.window) {
            session.focus();
            session.run(&["key", "Return"]);
        }
        false
    });
}

#[test]
fn recovered_edits_survive_a_second_crash() {
    const TEST: &str = "recovered_edits_survive_a_second_crash";
    let _serial = serial();
    let dir = TempDir::new("risk-twice");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let mine = dir.path().join("mine.ron");
    std::fs::copy(Path::new(REPO).join("tests/data/e2e/lit.ron"), &mine).unwrap();
    let config = dir.subdir("config");
    let lit_look = |l: &Look| l.corner_luma < 0.02 && l.centre_luma > 0.6;
    let dark_look = |l: &Look| l.centre_luma < 0.02;

    // The edit, autosaved on the viewer's own schedule, then a crash.
    let (child, session) = open(&x, &dir, &mine);
    session.wait_for("mine.ron", lit_look);
    session.drag_light_intensity_to_zero();
    session.wait_for("the light's intensity dragged to 0", dark_look);
    let first = recovery_files(&config, child.0.id());
    wait_until("the edit's autosave", AUTOSAVE_TIMEOUT, &dir, || {
        first[1].is_file()
    });
    assert!(intensity(&first[0]) < 1e-3, "the autosave lacks the edit");
    crash(&x, child, &dir);

    // Recovered, the edits are unsaved work of this run: it writes its
    // own recovery file (at once, before the first run's is removed).
    let (child, session) = open(&x, &dir, &mine);
    recover(&session, &first, &dir);
    session.wait_for("the recovered edit", dark_look);
    let second = recovery_files(&config, child.0.id());
    wait_until(
        "the recovered edits' autosave",
        AUTOSAVE_TIMEOUT,
        &dir,
        || second[1].is_file(),
    );
    assert!(
        intensity(&second[0]) < 1e-3,
        "the recovered edits' autosave lacks the edit"
    );
    crash(&x, child, &dir);

    // The second crash lost nothing: the next start offers the edit again.
    let (_child, session) = open(&x, &dir, &mine);
    recover(&session, &second, &dir);
    session.wait_for("the edit recovered after the second crash", dark_look);
    assert_eq!(intensity(&mine), 40.0, "mine.ron itself was written");
    assert_clean_log(&dir);
}
