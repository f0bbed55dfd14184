//! The viewer's time: where the play head is, whether it plays, and the
//! Time section that shows it (play/pause, scrub, frame and time, the
//! animation's rate, length and loop, each track's keys).
//!
//! The play head moves in whole frames of the animation (`frame / fps`),
//! so that what the viewer shows at a frame is what `render --frames`
//! writes for it.

use super::widgets::slider;
use egui::Ui;
use marbre_core::animation::{Animation, Extrapolation, Interpolation};
use marbre_core::scene::Scene;
use web_time::Instant;

/// The play head.
#[derive(Debug, Clone, Default)]
pub struct Timeline {
    /// Seconds from the animation's start.
    pub time: f32,
    /// When playback started and the time then; `None` when paused.
    playing_since: Option<(Instant, f32)>,
}

impl Timeline {
    pub fn playing(&self) -> bool {
        self.playing_since.is_some()
    }

    /// Plays from the current time, or pauses where it is.
    pub fn toggle(&mut self, now: Instant) {
        self.playing_since = match self.playing_since {
            Some(_) => None,
            None => Some((now, self.time)),
        };
    }

    /// Moves the play head to `time` (playback, if on, goes on from there).
    pub fn scrub(&mut self, time: f32, now: Instant) {
        self.time = time;
        if self.playing_since.is_some() {
            self.playing_since = Some((now, time));
        }
    }

    /// The frame under the play head at `fps`.
    pub fn frame(&self, fps: f32) -> u32 {
        (f64::from(self.time) * f64::from(fps) + 1e-6)
            .floor()
            .max(0.0) as u32
    }

    /// Advances a playing head to `now`, on the frame reached: round to
    /// the start when the animation loops, else stopping on the last frame.
    /// Without an animation time runs on (evolving noise moves) at 24
    /// frames a second. Whether the time changed.
    pub fn tick(&mut self, now: Instant, animation: Option<&Animation>) -> bool {
        let Some((since, from)) = self.playing_since else {
            return false;
        };
        let (fps, frames, looping) = match animation {
            Some(a) => (a.fps, Some(a.frame_count()), a.looping),
            None => (24.0, None, false),
        };
        let elapsed = f64::from(from) + now.duration_since(since).as_secs_f64();
        let mut frame = (elapsed * f64::from(fps) + 1e-6).floor() as u64;
        if let Some(count) = frames.map(u64::from) {
            if looping {
                frame %= count;
            } else if frame >= count {
                frame = count - 1;
                self.playing_since = None;
            }
        }
        let time = (frame as f64 / f64::from(fps)) as f32;
        let moved = time != self.time;
        self.time = time;
        moved
    }
}

/// The Time section.
pub(super) fn timeline_ui(ui: &mut Ui, scene: &mut Scene, timeline: &mut Timeline) {
    let now = Instant::now();
    let Some(animation) = &mut scene.animation else {
        ui.label(
            "A still scene: no keys yet. A key button (◆) beside a number starts an animation.",
        );
        if ui
            .button("Animate")
            .on_hover_text("Give the scene a time line (5 s at 24 fps) to key numbers on")
            .clicked()
        {
            scene.animation = Some(Animation::default());
        }
        return;
    };
    ui.horizontal(|ui| {
        let label = if timeline.playing() { "Pause" } else { "Play" };
        if ui.button(label).on_hover_text("Space").clicked() {
            timeline.toggle(now);
        }
        ui.label(format!(
            "frame {} of {} · {:.2} s",
            timeline.frame(animation.fps),
            animation.frame_count(),
            timeline.time
        ));
    });
    let mut time = timeline.time;
    let end = animation.duration.max(1e-3);
    let scrubbed = ui
        .add(slider(&mut time, 0.0..=end, "time").suffix(" s"))
        .on_hover_text("Drag to scrub");
    if scrubbed.changed() {
        let frame = (time * animation.fps).floor();
        timeline.scrub(frame / animation.fps, now);
    }
    // Scrubbing is not typing: the slider keeps no keyboard focus, which
    // would hold Space and Ctrl+Z back (the shortcuts wait for a focused
    // widget).
    if scrubbed.clicked() || scrubbed.drag_stopped() {
        scrubbed.surrender_focus();
    }
    ui.horizontal(|ui| {
        ui.add(
            egui::DragValue::new(&mut animation.fps)
                .range(1.0..=240.0)
                .suffix(" fps"),
        );
        ui.add(
            egui::DragValue::new(&mut animation.duration)
                .range(0.1..=3600.0)
                .speed(0.1)
                .suffix(" s"),
        );
        ui.checkbox(&mut animation.looping, "loop")
            .on_hover_text("Play round; evolving noise repeats over the length, without a seam");
    });
    tracks_ui(ui, animation, timeline.time);
}

/// Each track with its keys: a key's time, value and interpolation, and
/// delete; the track's extrapolation.
fn tracks_ui(ui: &mut Ui, animation: &mut Animation, now: f32) {
    let mut remove_track = None;
    for (t, track) in animation.tracks.iter_mut().enumerate() {
        ui.push_id(("track", t), |ui| {
            egui::CollapsingHeader::new(&track.path)
                .default_open(false)
                .show(ui, |ui| {
                    let mut remove_key = None;
                    for (k, key) in track.keys.iter_mut().enumerate() {
                        ui.horizontal(|ui| {
                            ui.push_id(k, |ui| {
                                let on_it = (key.time - now).abs() < 1e-4;
                                let time =
                                    format!("{}{:.2} s", if on_it { "at " } else { "" }, key.time);
                                ui.label(time);
                                let value: Vec<String> = key
                                    .value
                                    .components()
                                    .iter()
                                    .map(|v| format!("{v:.3}"))
                                    .collect();
                                ui.label(value.join(", "));
                                egui::ComboBox::from_id_salt("interpolation")
                                    .selected_text(key.interpolation.label())
                                    .show_ui(ui, |ui| {
                                        for i in Interpolation::ALL {
                                            ui.selectable_value(
                                                &mut key.interpolation,
                                                i,
                                                i.label(),
                                            );
                                        }
                                    });
                                if ui
                                    .small_button("×")
                                    .on_hover_text("Delete this key")
                                    .clicked()
                                {
                                    remove_key = Some(k);
                                }
                            });
                        });
                    }
                    if let Some(k) = remove_key {
                        track.keys.remove(k);
                    }
                    ui.horizontal(|ui| {
                        egui::ComboBox::from_id_salt("extrapolation")
                            .selected_text(track.extrapolation.label())
                            .show_ui(ui, |ui| {
                                for e in Extrapolation::ALL {
                                    ui.selectable_value(&mut track.extrapolation, e, e.label());
                                }
                            })
                            .response
                            .on_hover_text(
                                "Before the first key and after the last: hold, or repeat the keys",
                            );
                        if ui.button("Delete track").clicked() {
                            remove_track = Some(t);
                        }
                    });
                });
        });
    }
    // A track without keys animates nothing: it goes with its last key.
    animation.tracks.retain(|t| !t.keys.is_empty());
    if let Some(t) = remove_track.filter(|&t| t < animation.tracks.len()) {
        animation.tracks.remove(t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn animation(looping: bool) -> Animation {
        Animation {
            duration: 1.0,
            fps: 10.0,
            looping,
            tracks: Vec::new(),
        }
    }

    /// Playback moves in whole frames, loops round or stops on the last
    /// frame; scrubbing sets the time, and a pause holds it.
    #[test]
    fn playback_moves_in_frames_and_loops_or_stops() {
        let start = Instant::now();
        let at = |s: f64| start + Duration::from_secs_f64(s);
        let mut t = Timeline::default();
        t.toggle(start);
        assert!(t.tick(at(0.25), Some(&animation(true))));
        assert_eq!(t.time, 0.2, "frame 2 of 10 fps");
        t.tick(at(1.35), Some(&animation(true)));
        assert_eq!(t.frame(10.0), 3, "round the 10-frame loop");
        t.tick(at(5.0), Some(&animation(false)));
        assert_eq!(t.frame(10.0), 9, "stopped on the last frame");
        assert!(!t.playing());
        t.scrub(0.5, at(6.0));
        assert_eq!(t.time, 0.5);
        assert!(!t.tick(at(7.0), Some(&animation(false))), "paused");
        t.toggle(at(7.0));
        t.tick(at(7.1), Some(&animation(false)));
        assert_eq!(t.frame(10.0), 6);
    }
}
