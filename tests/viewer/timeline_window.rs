//! The Time section under Xvfb, as a person uses it, on
//! `tests/data/e2e/timeline.ron` (a ball lit by a point light keyed on at
//! 0 s and off from 1 s): Space plays the scene's time and the light goes
//! out; a click at the start of the time slider scrubs back and it is on
//! again; the environment intensity's key button adds a track, which the
//! preset Ctrl+S writes holds, and Ctrl+Z removes it again.
//!
//! The panel is found by its layout, as in `e2e_window`: the Preset,
//! Materials, Light transport and Render sections folded by clicks, so
//! that the Environment section's rows and the Time section's (the last
//! but Stats) sit at fixed heights.

use crate::e2e_window::{PANEL_LEFT, STEP_TIMEOUT, Session, assert_clean_log, open};
use crate::xvfb::{TempDir, display_or_skip, marbre_log, serial};
use marbre_core::animation::Animation;
use std::path::Path;
use std::time::{Duration, Instant};

use crate::REPO;

/// The preset's animation as the file holds it now.
fn saved_animation(preset: &Path) -> Animation {
    marbre_core::preset::load(preset)
        .unwrap_or_else(|e| panic!("{e}"))
        .preset
        .scene
        .animation
        .expect("the preset keeps its animation")
}

/// Saves with Ctrl+S (the pointer over the image, where no widget takes
/// the keys) and waits until the file holds `tracks` tracks; fails after
/// [`STEP_TIMEOUT`].
fn save_and_count(session: &Session, dir: &TempDir, preset: &Path, tracks: usize) -> Animation {
    session.move_to(400, 300);
    session.focus();
    session.run(&["key", "ctrl+s"]);
    let start = Instant::now();
    loop {
        let animation = saved_animation(preset);
        if animation.tracks.len() == tracks {
            return animation;
        }
        assert!(
            start.elapsed() < STEP_TIMEOUT,
            "the saved preset has {} tracks, not {tracks}: {animation:?}; log:\n{}",
            animation.tracks.len(),
            marbre_log(dir)
        );
        std::thread::sleep(Duration::from_millis(500));
    }
}

/// A click as a slow frame sees it: the pointer rests on the spot, then
/// the button goes down and up in different frames, each step read by
/// the viewer before the next (`Session::settle`).
fn press(session: &Session, x: i32, y: i32) {
    session.move_to(x, y);
    session.run(&["mousedown", "1"]);
    session.settle();
    session.run(&["mouseup", "1"]);
    session.settle();
}

#[test]
fn space_plays_a_click_scrubs_and_a_key_is_undone() {
    const TEST: &str = "space_plays_a_click_scrubs_and_a_key_is_undone";
    let _serial = serial();
    let dir = TempDir::new("timeline");
    let Some(x) = display_or_skip(TEST, &dir, &["xdotool"]) else {
        return;
    };
    let preset = dir.path().join("timeline.ron");
    std::fs::copy(Path::new(REPO).join("tests/data/e2e/timeline.ron"), &preset).unwrap();
    let (_child, session) = open(&x, &dir, &preset);
    session.wait_for("the light on at 0 s", |l| l.centre_luma > 0.6);
    // Fold the Preset, Materials, Light transport and Render sections: the
    // Environment section's rows are then at y = 81 to 150, and the Time
    // section's (under Render) start at y = 288.
    session.focus();
    for header in [12, 35, 219, 242] {
        session.click(PANEL_LEFT + 50, header);
    }

    // Space over the image plays: past 1 s the keyed light is off.
    session.move_to(400, 300);
    session.focus();
    session.run(&["key", "space"]);
    session.wait_for("playing past 1 s (the light off)", |l| l.centre_luma < 0.02);
    // Playback runs on the wall clock: it stops (on the last frame, 1.75 s)
    // at the first frame 2 s after it started (8 frames at 4 fps), and it
    // had run 1 s by the frame the screenshot just seen was taken in: so
    // by a second after now. A scrub during playback would play on from
    // where it set the time. The sleep waits for the play head's own
    // clock, not for the viewer; the frames after it are waited for.
    std::thread::sleep(Duration::from_secs(1));
    session.settle();

    // A press at the time slider's left end scrubs back to 0 s (the
    // pointer first rests there: egui reads it once per slow frame).
    press(&session, PANEL_LEFT + 29, 311);
    session.wait_for("scrubbed to 0 s (the light on)", |l| l.centre_luma > 0.6);

    // The Environment's intensity row, its key button at the row's end.
    press(&session, PANEL_LEFT + 244, 127);
    let keyed = save_and_count(&session, &dir, &preset, 2);
    let track = &keyed.tracks[1];
    assert_eq!(track.path, "environment.intensity");
    assert_eq!(track.keys.len(), 1);
    assert_eq!(track.keys[0].time, 0.0);
    assert_eq!(track.keys[0].value.components(), [1.0]);

    session.run(&["key", "ctrl+z"]);
    // Not in the same frame as the Ctrl+S that follows: that frame would
    // save (a shortcut taken before the widgets) before undoing.
    session.settle();
    let undone = save_and_count(&session, &dir, &preset, 1);
    assert_eq!(undone.tracks[0].path, "point_light.intensity");
    assert_clean_log(&dir);
}
