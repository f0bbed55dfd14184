//! Whether a frame is shown or only traced (issue 33).
//!
//! The window shows the last complete round (`passes/accumulation.rs`): a
//! frame that traces a band of a round changes nothing on screen. Where
//! the trace runs on this machine's cores (lavapipe, the CPU kernel),
//! showing such a frame is not free: the display pass, the panel's layer
//! and the copy to the window took about 14 ms of a 26 ms frame on the
//! default preset, so the trace had about half the machine. So while
//! nobody touches the window, the viewer traces band after band and shows
//! a frame only when it has something new: a round completed (or a
//! preview), input, egui asking for a repaint (an animation, a tooltip's
//! delay), and at least every [`STATS_REFRESH`], as often as the panel's
//! figures refresh, so they and its messages stay fresh. Input is still read between bands, each within the
//! frame budget: the window answers as fast as before. Blender's and
//! Cycles' viewports likewise redraw when samples are ready, not per tile.
//!
//! On a GPU adapter every frame is shown (unless the CPU kernel traces):
//! the trace runs beside the display there, and the swapchain paces the
//! loop. A result that lands between rounds (an OIDN image, a shader
//! build, a hot reload) shows with the next frame shown, within the
//! panel's refresh.

use super::ui_layer::STATS_REFRESH;
use std::time::Duration;
use web_time::Instant;

/// What the schedule knows of the last frame shown.
#[derive(Debug, Clone)]
pub struct PresentSchedule {
    /// When the last frame was shown.
    shown_at: Instant,
    /// The renderer's count of images made (rounds and previews) then.
    images: u32,
    /// When egui asked to be drawn again (None: on input only).
    repaint_at: Option<Instant>,
    /// Input (or any window event) since the last frame shown.
    input: bool,
}

/// The state of this frame the decision reads.
#[derive(Debug, Clone, Copy)]
pub struct FrameState {
    pub now: Instant,
    /// The renderer's count of images made so far (rounds and previews).
    pub images: u32,
    /// Whether frames may go unshown at all: a trace on this machine's
    /// cores, no animation playing, no script, not the run's last frame,
    /// not paused at the target error (with nothing to trace, a frame
    /// that is not shown does nothing).
    pub may_skip: bool,
}

impl PresentSchedule {
    pub fn new(now: Instant) -> Self {
        Self {
            shown_at: now,
            images: 0,
            repaint_at: Some(now),
            input: true,
        }
    }

    /// A window event arrived: the next frame is shown.
    pub fn note_input(&mut self) {
        self.input = true;
    }

    /// Whether this frame is shown, or only traces.
    pub fn shows(&self, state: &FrameState) -> bool {
        !state.may_skip
            || self.input
            || state.images != self.images
            || self.repaint_at.is_some_and(|at| state.now >= at)
            || state.now.duration_since(self.shown_at) >= STATS_REFRESH
    }

    /// A frame was shown with `images` made, egui asking to be drawn again
    /// after `repaint_delay` (`Duration::MAX`: on input only).
    pub fn shown(&mut self, now: Instant, images: u32, repaint_delay: Duration) {
        self.shown_at = now;
        self.images = images;
        self.repaint_at = now.checked_add(repaint_delay);
        self.input = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Duration = Duration::from_millis(1);

    /// A schedule whose last frame was shown at `start` with 3 images made
    /// and egui idle.
    fn settled(start: Instant) -> PresentSchedule {
        let mut s = PresentSchedule::new(start);
        s.shown(start, 3, Duration::MAX);
        s
    }

    fn state(now: Instant, images: u32) -> FrameState {
        FrameState {
            now,
            images,
            may_skip: true,
        }
    }

    /// Between rounds, with nobody at the window, frames only trace, until
    /// the longest gap has passed.
    #[test]
    fn an_idle_window_traces_without_showing_until_the_gap_is_up() {
        let start = Instant::now();
        let s = settled(start);
        assert!(!s.shows(&state(start + 12 * MS, 3)));
        assert!(!s.shows(&state(start + STATS_REFRESH - MS, 3)));
        assert!(s.shows(&state(start + STATS_REFRESH, 3)));
    }

    /// A new image (a round or a preview) is shown at once.
    #[test]
    fn a_completed_round_is_shown() {
        let start = Instant::now();
        assert!(settled(start).shows(&state(start + MS, 4)));
    }

    /// Any input is answered in the next frame, and only that one.
    #[test]
    fn input_shows_the_next_frame() {
        let start = Instant::now();
        let mut s = settled(start);
        s.note_input();
        assert!(s.shows(&state(start + MS, 3)));
        s.shown(start + MS, 3, Duration::MAX);
        assert!(!s.shows(&state(start + 2 * MS, 3)));
    }

    /// egui's own schedule (an animation asks for the next frame, a
    /// tooltip for one after its delay) is kept.
    #[test]
    fn egui_repaints_are_kept() {
        let start = Instant::now();
        let mut s = settled(start);
        s.shown(start, 3, Duration::ZERO);
        assert!(s.shows(&state(start + MS, 3)));
        s.shown(start, 3, 100 * MS);
        assert!(!s.shows(&state(start + 99 * MS, 3)));
        assert!(s.shows(&state(start + 100 * MS, 3)));
    }

    /// Where frames may not go unshown (a GPU adapter, an animation, a
    /// script, the last frame), every frame is shown.
    #[test]
    fn every_frame_is_shown_where_skipping_is_off() {
        let start = Instant::now();
        let s = settled(start);
        let mut busy = state(start + MS, 3);
        busy.may_skip = false;
        assert!(s.shows(&busy));
    }

    /// The first frame is shown.
    #[test]
    fn the_first_frame_is_shown() {
        let start = Instant::now();
        assert!(PresentSchedule::new(start).shows(&state(start, 0)));
    }
}
