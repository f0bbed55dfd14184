//! The scene's time: whether an animation can be traced on a scene, and
//! the scene traced at a moment. Here, in `scene`, rather than in
//! `animation`, so that the animation's data (which the scene holds) does
//! not import the scene back.

use super::Scene;
use crate::animation::{Animation, Naming, ParamPath, Track};

impl Animation {
    /// Why the animation cannot be traced on `scene`, each problem naming
    /// its field (`animation.tracks[1].keys[2].time`); empty when it can.
    pub fn problems(&self, scene: &Scene) -> Vec<String> {
        let mut out = Vec::new();
        if !(self.fps.is_finite() && self.fps > 0.0) {
            out.push(format!(
                "animation.fps: {} is not a frame rate (a positive number, such as 24)",
                self.fps
            ));
        }
        if !(self.duration.is_finite() && self.duration > 0.0) {
            out.push(format!(
                "animation.duration: {} is not a length in seconds (a positive number)",
                self.duration
            ));
        }
        for (i, track) in self.tracks.iter().enumerate() {
            if let Err(e) = track.check(scene) {
                out.push(format!("animation.tracks[{i}] (`{}`): {e}", track.path));
            }
        }
        out
    }
}

impl Track {
    /// Whether the track can be traced on `scene`: its path names a
    /// parameter there, its keys are in strictly increasing time order,
    /// finite, and have the parameter's number of components.
    pub fn check(&self, scene: &Scene) -> Result<(), String> {
        let path = self.parsed_path()?;
        let current = scene.parameter(&path)?;
        if self.keys.is_empty() {
            return Err("the track has no keys".into());
        }
        for (i, key) in self.keys.iter().enumerate() {
            if !key.time.is_finite() {
                return Err(format!("keys[{i}].time: {} is not a time", key.time));
            }
            if i > 0 && key.time <= self.keys[i - 1].time {
                return Err(format!(
                    "keys[{i}].time: {} does not come after the key before it ({}): key times must increase",
                    key.time,
                    self.keys[i - 1].time
                ));
            }
            let value = key.value.components();
            if let Some(bad) = value.iter().find(|v| !v.is_finite()) {
                return Err(format!("keys[{i}].value: {bad} is not a finite number"));
            }
            if value.len() != current.len() {
                return Err(format!(
                    "keys[{i}].value: {} component(s) for a parameter of {}",
                    value.len(),
                    current.len()
                ));
            }
        }
        Ok(())
    }
}

impl Scene {
    /// Whether anything traced changes with time: an animation's tracks,
    /// or a noise that evolves.
    pub fn moves(&self) -> bool {
        self.animation
            .as_ref()
            .is_some_and(|a| !a.tracks.is_empty())
            || self
                .materials()
                .any(|m| m.signals().iter().any(|s| s.noise.evolution.is_some()))
    }

    /// Inserts a key of value `components` at `time` on the track of the
    /// parameter `path` names, however it names it (the panel names
    /// elements by index): an existing track on the same parameter gets
    /// the key, a new track is named as the CLI lists parameters
    /// ([`Naming::Names`]). A path that names no number is refused.
    pub fn insert_key(
        &mut self,
        path: &ParamPath,
        time: f32,
        components: &[f32],
    ) -> Result<(), String> {
        self.parameter(path)?;
        let name = self.parameter_name(path, Naming::Names)?;
        let same = |track: &Track| {
            track
                .parsed_path()
                .and_then(|p| self.parameter_name(&p, Naming::Names))
                .is_ok_and(|p| p == name)
        };
        let track_path = self
            .animation
            .iter()
            .flat_map(|a| &a.tracks)
            .find(|t| same(t))
            .and_then(|t| t.parsed_path().ok())
            .unwrap_or(name);
        self.animation
            .get_or_insert_with(Default::default)
            .insert_key(&track_path, time, components);
        Ok(())
    }

    /// The scene as traced at `time` seconds: each track's value written
    /// in (a track that no longer fits the scene, after an edit, is left
    /// out: [`Animation::problems`] names it) and each evolving noise's
    /// moment set. Without an animation only the noise moves.
    pub fn at_time(&self, time: f32) -> Scene {
        let mut scene = self.clone();
        let loop_duration = self.animation.as_ref().and_then(Animation::loop_duration);
        if let Some(animation) = &self.animation {
            for track in &animation.tracks {
                if let (Ok(path), Some(value)) = (track.parsed_path(), track.value_at(time)) {
                    // A path that stopped resolving, or a value the field
                    // cannot take, leaves the parameter as it was.
                    let _ = scene.set_parameter(&path, &value);
                }
            }
        }
        for material in scene.materials_mut() {
            material.for_each_noise_mut(&mut |noise| {
                if let Some(evolution) = &mut noise.evolution {
                    evolution.at(time, loop_duration);
                }
            });
        }
        scene
    }
}
