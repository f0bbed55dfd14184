//! Time in the scene: a preset's optional `animation` (its length, frame
//! rate, whether it loops) and its keyframe tracks, each on one parameter
//! named by a [`ParamPath`].
//!
//! The scene saved and edited holds the tracks; what is traced at time
//! `t` is [`Scene::at_time`], the scene with every track's value written
//! in and every evolving noise's moment set. Two moments of the same
//! scene differ in numbers only, so the renderer's `Change` between them
//! is a parameter change and no code is generated again.

pub mod curve;
pub mod param_path;

pub use curve::{Extrapolation, Interpolation, Key, KeyValue};
pub use param_path::{Naming, ParamPath, Step};

use serde::{Deserialize, Serialize};

/// A scene's time line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Animation {
    /// Seconds from the first frame to the end of the last.
    pub duration: f32,
    /// Frames a second.
    pub fps: f32,
    /// Whether it plays round: the viewer starts again at the end, and
    /// evolving noise is periodic over `duration` so the last frame meets
    /// the first without a seam.
    #[serde(rename = "loop")]
    pub looping: bool,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tracks: Vec<Track>,
}

impl Default for Animation {
    fn default() -> Self {
        Self {
            duration: 5.0,
            fps: 24.0,
            looping: false,
            tracks: Vec::new(),
        }
    }
}

impl Animation {
    /// The frames: `duration · fps`, rounded, at least 1.
    pub fn frame_count(&self) -> u32 {
        (f64::from(self.duration) * f64::from(self.fps))
            .round()
            .max(1.0) as u32
    }

    /// The time of frame `frame`, in seconds.
    pub fn time_of(&self, frame: u32) -> f32 {
        (f64::from(frame) / f64::from(self.fps)) as f32
    }

    /// The loop's length, when it loops: what evolving noise repeats over.
    pub fn loop_duration(&self) -> Option<f32> {
        self.looping.then_some(self.duration)
    }

    /// The track on `path`, if any.
    pub fn track(&self, path: &ParamPath) -> Option<&Track> {
        self.tracks
            .iter()
            .find(|t| t.parsed_path().as_ref() == Ok(path))
    }

    /// Inserts (or replaces) the key at `time` on `path`'s track, made if
    /// it has none.
    pub fn insert_key(&mut self, path: &ParamPath, time: f32, components: &[f32]) {
        let index = match self
            .tracks
            .iter()
            .position(|t| t.parsed_path().as_ref() == Ok(path))
        {
            Some(i) => i,
            None => {
                self.tracks.push(Track {
                    path: path.to_string(),
                    keys: Vec::new(),
                    extrapolation: Extrapolation::Hold,
                });
                self.tracks.len() - 1
            }
        };
        let keys = &mut self.tracks[index].keys;
        let value = KeyValue::from_components(components);
        match keys.iter().position(|k| k.time >= time) {
            Some(i) if keys[i].time == time => keys[i].value = value,
            at => keys.insert(
                at.unwrap_or(keys.len()),
                Key {
                    time,
                    value,
                    interpolation: Interpolation::Smooth,
                },
            ),
        }
    }
}

/// The keys of one parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Track {
    /// The parameter's [`ParamPath`], as text.
    pub path: String,
    pub keys: Vec<Key>,
    #[serde(default, skip_serializing_if = "is_hold")]
    pub extrapolation: Extrapolation,
}

fn is_hold(e: &Extrapolation) -> bool {
    *e == Extrapolation::Hold
}

impl Track {
    pub fn parsed_path(&self) -> Result<ParamPath, String> {
        ParamPath::parse(&self.path)
    }

    /// The track's value at `time`; `None` without keys.
    pub fn value_at(&self, time: f32) -> Option<Vec<f32>> {
        curve::value_at(&self.keys, self.extrapolation, time)
    }
}

#[cfg(test)]
mod tests;
