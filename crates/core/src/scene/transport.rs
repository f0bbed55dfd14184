//! How light transport is estimated: the integrator, how lights are
//! sampled and how the strategies are combined. Every setting is a uniform
//! the shader reads, so all of them switch live without a shader build.

use serde::{Deserialize, Serialize};

/// How a light sample picks its light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum LightSelection {
    /// Every light equally likely.
    Uniform,
    /// In proportion to emitted power.
    #[default]
    Power,
}

impl LightSelection {
    pub const ALL: [LightSelection; 2] = [LightSelection::Uniform, LightSelection::Power];

    pub fn label(self) -> &'static str {
        match self {
            LightSelection::Uniform => "uniform",
            LightSelection::Power => "by power",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Integrator {
    /// The lab's first exercises: what the camera sees, lit directly by the
    /// lights (N light samples per pixel sample), no indirect light.
    Direct,
    /// Paths of up to `max_bounces` reflections.
    #[default]
    Path,
}

/// Which estimators of direct light are used, and how they are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Strategy {
    /// Sample points on the lights (next-event estimation) only.
    Light,
    /// Follow the BSDF's sampled direction only; it finds emitters by hitting them.
    Bsdf,
    /// Both, weighted by Veach's balance heuristic.
    MisBalance,
    /// Both, weighted by the power heuristic (β = 2).
    #[default]
    MisPower,
    /// Like `Bsdf`, but the diffuse lobe's directions are drawn uniformly
    /// over the hemisphere (pdf 1 / 2π) instead of by cosine: the lab's
    /// third way of choosing y (Q4), unbiased and noisier.
    Hemisphere,
}

impl Strategy {
    pub const ALL: [Strategy; 5] = [
        Strategy::Light,
        Strategy::Bsdf,
        Strategy::MisBalance,
        Strategy::MisPower,
        Strategy::Hemisphere,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Strategy::Light => "light sampling",
            Strategy::Bsdf => "BSDF sampling",
            Strategy::MisBalance => "MIS (balance)",
            Strategy::MisPower => "MIS (power)",
            Strategy::Hemisphere => "uniform hemisphere",
        }
    }

    /// The name `marbre render --strategy` takes.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Light => "light",
            Strategy::Bsdf => "bsdf",
            Strategy::MisBalance => "mis-balance",
            Strategy::MisPower => "mis-power",
            Strategy::Hemisphere => "hemisphere",
        }
    }

    /// Whether direction sampling alone finds the light (no light samples).
    pub fn directions_only(self) -> bool {
        matches!(self, Strategy::Bsdf | Strategy::Hemisphere)
    }

    /// Whether the BSDF's diffuse lobe is sampled uniformly over the
    /// hemisphere rather than by cosine.
    pub fn uniform_diffuse(self) -> bool {
        self == Strategy::Hemisphere
    }

    /// The number `crates/core/src/mis.wgsl` reads.
    pub fn id(self) -> u32 {
        self as u32
    }
}

/// Where a light sample's point lies on the light it chose: the lab's
/// exercises 3 and 4 before their estimator is made correct.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum LightPoints {
    /// A fresh random point for every sample: the unbiased estimator.
    #[default]
    Random,
    /// One fixed point per light (exercise 3): a triangle's centroid, the
    /// point of a sphere facing the shading point, weighted as if sampled
    /// (a triangle's area, a sphere's solid angle), so each light acts as
    /// a point light of its power: hard shadows. The light a sample picks
    /// is still chosen at random.
    Centroid,
    /// The same `light_samples` points (light choices and positions) for
    /// every pixel and every frame (exercise 4's wrong image): the error
    /// does not average away but stays as bands and stepped shadows.
    FixedSet,
}

impl LightPoints {
    pub const ALL: [LightPoints; 3] = [
        LightPoints::Random,
        LightPoints::Centroid,
        LightPoints::FixedSet,
    ];

    pub fn label(self) -> &'static str {
        match self {
            LightPoints::Random => "random",
            LightPoints::Centroid => "centroid",
            LightPoints::FixedSet => "fixed set",
        }
    }

    /// The name `marbre render --light-points` takes.
    pub fn name(self) -> &'static str {
        match self {
            LightPoints::Random => "random",
            LightPoints::Centroid => "centroid",
            LightPoints::FixedSet => "fixed-set",
        }
    }

    /// The number `crates/core/src/lights.wgsl` reads.
    pub fn id(self) -> u32 {
        self as u32
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TransportSettings {
    pub integrator: Integrator,
    /// Light samples at each shading point (the lab's N points).
    pub light_samples: u32,
    pub light_selection: LightSelection,
    /// Where on its light each light sample lies (random, or the lab's
    /// fixed points).
    pub light_points: LightPoints,
    pub strategy: Strategy,
    /// Paths longer than this many bounces may end at random, with the
    /// survivors weighted up (Russian roulette); 0 never ends them early.
    pub russian_roulette_from: u32,
    /// Firefly clamp: a sample brighter than this (in its largest channel)
    /// is scaled down to it. Off (`None`) by default: it removes fireflies
    /// by darkening the image, a bias `marbre bench` measures.
    pub sample_clamp: Option<f32>,
}

impl Default for TransportSettings {
    fn default() -> Self {
        Self {
            integrator: Integrator::Path,
            light_samples: 1,
            light_selection: LightSelection::Power,
            light_points: LightPoints::Random,
            strategy: Strategy::MisPower,
            russian_roulette_from: 3,
            sample_clamp: None,
        }
    }
}

impl TransportSettings {
    pub const MAX_LIGHT_SAMPLES: u32 = 64;

    /// The strategy the shader runs. Fixed light points have no density
    /// to weigh against BSDF sampling, so with them MIS falls back to
    /// light sampling alone: the lab's estimator, whose bias is the point.
    pub fn effective_strategy(&self) -> Strategy {
        match (self.light_points, self.strategy) {
            (LightPoints::Random, s) => s,
            (_, Strategy::MisBalance | Strategy::MisPower) => Strategy::Light,
            (_, s) => s,
        }
    }

    pub(crate) fn sanitize(&mut self, notes: &mut Vec<String>) {
        let n = self.light_samples.clamp(1, Self::MAX_LIGHT_SAMPLES);
        if n != self.light_samples {
            notes.push(format!(
                "render: light samples {} clamped to {n}",
                self.light_samples
            ));
            self.light_samples = n;
        }
        if let Some(c) = self.sample_clamp
            && !(c.is_finite() && c > 0.0)
        {
            notes.push(format!(
                "render: sample clamp {c} is not a positive number: off"
            ));
            self.sample_clamp = None;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn old_presets_read_random_points_and_their_strategy() {
        let t: TransportSettings = ron::from_str("(light_samples: 4, strategy: Bsdf)").unwrap();
        assert_eq!(t.light_points, LightPoints::Random);
        assert_eq!(t.effective_strategy(), Strategy::Bsdf);
        let t: TransportSettings =
            ron::from_str("(light_points: FixedSet, strategy: Hemisphere)").unwrap();
        assert_eq!(t.light_points, LightPoints::FixedSet);
        assert_eq!(t.strategy, Strategy::Hemisphere);
    }

    #[test]
    fn fixed_points_turn_mis_into_light_sampling() {
        let mut t = TransportSettings {
            light_points: LightPoints::Centroid,
            ..TransportSettings::default()
        };
        assert_eq!(t.effective_strategy(), Strategy::Light);
        t.strategy = Strategy::Hemisphere;
        assert_eq!(t.effective_strategy(), Strategy::Hemisphere);
        t.light_points = LightPoints::Random;
        t.strategy = Strategy::MisBalance;
        assert_eq!(t.effective_strategy(), Strategy::MisBalance);
    }
}
