//! Evolving noise (issue 29): a fourth lattice coordinate w that moves with
//! time, and a drift that moves the whole domain, as Blender's 4D noise.
//!
//! A noise with an [`Evolution`] is evaluated in 4D at `(p − drift·t, w(t))`;
//! without one it is the 3D noise of every preset written before, to the
//! bit. The saved fields say how the noise evolves; the two that are not
//! saved say which moment is traced, set by [`Evolution::at`] from the
//! scene's time (the animation's `Scene::at_time` calls it on every noise).

use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::ops::RangeInclusive;

/// How a noise changes with time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Evolution {
    /// w at time 0, in lattice cells of the first octave.
    pub w: f32,
    /// Lattice cells of w per second.
    pub speed: f32,
    /// How far the noise's domain moves per second, in the noise's input
    /// units (before its frequency): a feature at `q` at time 0 is at
    /// `q + drift·t` at time t.
    pub drift: Vec3,
    /// The moment traced, in seconds; not saved (the scene's time sets it).
    #[serde(skip)]
    pub time: f32,
    /// The lattice period in w while looping: the noise at w and at w + P
    /// is the same, so a loop's last frame meets its first. Not saved.
    #[serde(skip)]
    pub w_period: Option<u32>,
    /// The loop's duration in seconds while looping, which `w_now` reduces
    /// the time modulo. Not saved.
    #[serde(skip)]
    pub loop_duration: Option<f32>,
}

impl Default for Evolution {
    fn default() -> Self {
        Self {
            w: 0.0,
            speed: 0.5,
            drift: Vec3::ZERO,
            time: 0.0,
            w_period: None,
            loop_duration: None,
        }
    }
}

impl Evolution {
    /// The values a preset is clamped to and the panel lets a user type.
    pub const W: RangeInclusive<f32> = -1e4..=1e4;
    pub const SPEED: RangeInclusive<f32> = -100.0..=100.0;
    pub const DRIFT: RangeInclusive<f32> = -1e3..=1e3;
    /// The most cells a loop's w lattice may have: the shader packs the
    /// period into 24 bits (`NoiseParams::flags`).
    pub const MAX_PERIOD: u32 = (1 << 24) - 1;

    /// Sets the moment traced to `time` seconds. With a loop of
    /// `loop_duration` D seconds, the w lattice gets a period of
    /// P = max(1, round(|speed|·D)) cells and w runs over exactly one
    /// period in D (speed snapped to P/D, its sign kept), so the frame at
    /// D is the frame at 0; without a loop w = w0 + speed·t, unbounded.
    /// With speed 0, w stays at w0 and needs no period.
    pub fn at(&mut self, time: f32, loop_duration: Option<f32>) {
        self.time = time;
        self.loop_duration = loop_duration.filter(|d| *d > 0.0 && d.is_finite());
        // A still w meets itself without a period, and keeps the look it
        // has outside a loop (a period wraps the lattice's cells).
        self.w_period = self
            .loop_duration
            .filter(|_| self.speed != 0.0)
            .map(|d| ((self.speed.abs() * d).round() as u32).clamp(1, Self::MAX_PERIOD));
    }

    /// w at the moment traced: w0 + speed·t, or while looping
    /// w0 ± P·(t mod D)/D, which is w0 again at every whole loop.
    pub fn w_now(&self) -> f32 {
        match (self.w_period, self.loop_duration) {
            (Some(period), Some(d)) if self.speed != 0.0 => {
                let phase = self.time.rem_euclid(d) / d;
                self.w + self.speed.signum() * period as f32 * phase
            }
            _ => self.w + self.speed * self.time,
        }
    }

    /// How far the domain has moved at the moment traced: drift·t. The
    /// noise is taken at `p − offset_now()`, so its features move along
    /// +drift. A loop does not wrap it (the domain has no period in
    /// general): a loop is seamless without drift.
    pub fn offset_now(&self) -> Vec3 {
        self.drift * self.time
    }

    /// Values a preset may hold that the renderer cannot take, replaced
    /// (non-finite ones by 0, the rest clamped to the ranges above).
    pub fn sanitized(self) -> Self {
        let clamp = |v: f32, r: RangeInclusive<f32>| {
            if v.is_finite() {
                v.clamp(*r.start(), *r.end())
            } else {
                0.0
            }
        };
        Self {
            w: clamp(self.w, Self::W),
            speed: clamp(self.speed, Self::SPEED),
            drift: Vec3::new(
                clamp(self.drift.x, Self::DRIFT),
                clamp(self.drift.y, Self::DRIFT),
                clamp(self.drift.z, Self::DRIFT),
            ),
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_loop_w_runs_at_speed_and_the_domain_drifts() {
        let mut e = Evolution {
            w: 1.5,
            speed: 0.25,
            drift: Vec3::new(1.0, 0.0, -2.0),
            ..Evolution::default()
        };
        e.at(4.0, None);
        assert_eq!(e.w_period, None);
        assert_eq!(e.w_now(), 2.5);
        assert_eq!(e.offset_now(), Vec3::new(4.0, 0.0, -8.0));
    }

    /// A loop snaps the speed to whole periods: w at D is w at 0, exactly,
    /// and halfway through it has run half a period.
    #[test]
    fn a_loop_returns_w_to_its_start() {
        for speed in [0.3, 1.0, 2.7, -1.4] {
            let mut e = Evolution {
                w: 0.75,
                speed,
                ..Evolution::default()
            };
            let d = 4.0;
            e.at(0.0, Some(d));
            let start = e.w_now();
            let period = e.w_period.expect("looping");
            assert_eq!(period, ((speed.abs() * d).round() as u32).max(1));
            e.at(d, Some(d));
            assert_eq!(e.w_now(), start, "speed {speed}");
            e.at(2.0 * d, Some(d));
            assert_eq!(e.w_now(), start, "speed {speed}");
            e.at(d / 2.0, Some(d));
            let half = e.w_now() - start;
            assert!(
                (half - speed.signum() * period as f32 / 2.0).abs() < 1e-5,
                "{half}"
            );
        }
    }

    #[test]
    fn speed_zero_in_a_loop_stays_at_w0_without_a_period() {
        let mut e = Evolution {
            w: 3.0,
            speed: 0.0,
            ..Evolution::default()
        };
        e.at(1.3, Some(2.0));
        assert_eq!(e.w_period, None);
        assert_eq!(e.w_now(), 3.0);
    }

    /// Only the saved fields are written: the moment is the scene's.
    #[test]
    fn the_moment_is_not_saved() {
        let mut e = Evolution::default();
        e.at(2.0, Some(1.0));
        let text = ron::to_string(&e).expect("serialise");
        assert!(
            !text.contains("time") && !text.contains("period") && !text.contains("loop"),
            "{text}"
        );
        let back: Evolution = ron::from_str(&text).expect("parse");
        assert_eq!(back.time, 0.0);
        assert_eq!((back.w_period, back.loop_duration), (None, None));
        assert_eq!((back.w, back.speed, back.drift), (e.w, e.speed, e.drift));
    }
}
