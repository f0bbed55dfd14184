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
}

impl Strategy {
    pub const ALL: [Strategy; 4] = [
        Strategy::Light,
        Strategy::Bsdf,
        Strategy::MisBalance,
        Strategy::MisPower,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Strategy::Light => "light sampling",
            Strategy::Bsdf => "BSDF sampling",
            Strategy::MisBalance => "MIS (balance)",
            Strategy::MisPower => "MIS (power)",
        }
    }

    /// The number `crates/core/src/mis.wgsl` reads.
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
            strategy: Strategy::MisPower,
            russian_roulette_from: 3,
            sample_clamp: None,
        }
    }
}

impl TransportSettings {
    pub const MAX_LIGHT_SAMPLES: u32 = 64;

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
