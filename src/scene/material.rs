//! Materials and the procedural textures that drive their properties.

use crate::noise::{FractalParams, NoiseSettings};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// What drives a property across a surface. Each pattern yields a blend
/// factor `t` in [0, 1] between the texture's two values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum Pattern {
    /// `t = 0`: the first value everywhere.
    #[default]
    Constant,
    /// A 3D checkerboard of cubes of side `size`: `t` is 0 or 1.
    Checker { size: f32 },
    /// `t = 0.5 + 0.5 · fbm(p)`, clamped.
    Fbm { noise: NoiseSettings },
    /// `t = turbulence(p)` (a sum of |noise|), clamped.
    Turbulence { noise: NoiseSettings },
    /// `t = 0.5 + 0.5 · sin(p.x · stripe_frequency + fbm(p))`.
    Marble {
        noise: NoiseSettings,
        stripe_frequency: f32,
    },
}

impl Pattern {
    pub const NAMES: [&'static str; 5] = ["constant", "checker", "fBm", "turbulence", "marble"];

    /// Index into [`Pattern::NAMES`]; also the pattern id in the shader.
    pub fn index(&self) -> usize {
        match self {
            Pattern::Constant => 0,
            Pattern::Checker { .. } => 1,
            Pattern::Fbm { .. } => 2,
            Pattern::Turbulence { .. } => 3,
            Pattern::Marble { .. } => 4,
        }
    }

    /// The pattern with index `i`, keeping the noise settings of `self` where
    /// both have some, so switching the dropdown does not lose the tuning.
    pub fn with_index(&self, i: usize) -> Pattern {
        let noise = self.noise().copied().unwrap_or_default();
        match i {
            1 => Pattern::Checker { size: 1.0 },
            2 => Pattern::Fbm { noise },
            3 => Pattern::Turbulence { noise },
            4 => Pattern::Marble {
                noise,
                stripe_frequency: 4.0,
            },
            _ => Pattern::Constant,
        }
    }

    pub fn noise(&self) -> Option<&NoiseSettings> {
        match self {
            Pattern::Fbm { noise }
            | Pattern::Turbulence { noise }
            | Pattern::Marble { noise, .. } => Some(noise),
            Pattern::Constant | Pattern::Checker { .. } => None,
        }
    }

    pub fn noise_mut(&mut self) -> Option<&mut NoiseSettings> {
        match self {
            Pattern::Fbm { noise }
            | Pattern::Turbulence { noise }
            | Pattern::Marble { noise, .. } => Some(noise),
            Pattern::Constant | Pattern::Checker { .. } => None,
        }
    }

    fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
        if let Pattern::Checker { size } = self
            && !(size.is_finite() && *size > 1e-4)
        {
            notes.push(format!("{what}: checker size {size} set to 1"));
            *size = 1.0;
        }
        if let Pattern::Marble {
            stripe_frequency, ..
        } = self
            && !stripe_frequency.is_finite()
        {
            notes.push(format!("{what}: marble stripe frequency reset"));
            *stripe_frequency = 4.0;
        }
        if let Some(n) = self.noise_mut() {
            sanitize_fractal(&mut n.fractal, what, notes);
        }
    }
}

fn sanitize_fractal(f: &mut FractalParams, what: &str, notes: &mut Vec<String>) {
    let d = FractalParams::default();
    let mut clamp = |name: &str, v: &mut f32, lo: f32, hi: f32, fallback: f32| {
        let c = if v.is_finite() {
            v.clamp(lo, hi)
        } else {
            fallback
        };
        if c != *v {
            notes.push(format!("{what}: {name} {v} clamped to {c}"));
            *v = c;
        }
    };
    clamp(
        "octaves",
        &mut f.octaves,
        0.0,
        FractalParams::MAX_OCTAVES,
        d.octaves,
    );
    clamp("frequency", &mut f.frequency, 0.0, 1e6, d.frequency);
    clamp("amplitude", &mut f.amplitude, -100.0, 100.0, d.amplitude);
    clamp("persistence", &mut f.persistence, 0.0, 1.5, d.persistence);
    clamp("lacunarity", &mut f.lacunarity, 1.0, 8.0, d.lacunarity);
}

/// A colour property: `mix(a, b, t)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ColorTexture {
    pub pattern: Pattern,
    pub a: Vec3,
    pub b: Vec3,
}

impl ColorTexture {
    pub fn constant(c: Vec3) -> Self {
        Self {
            pattern: Pattern::Constant,
            a: c,
            b: c,
        }
    }
}

impl Default for ColorTexture {
    fn default() -> Self {
        Self::constant(Vec3::splat(0.5))
    }
}

/// A scalar property: `mix(a, b, t)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ScalarTexture {
    pub pattern: Pattern,
    pub a: f32,
    pub b: f32,
}

impl ScalarTexture {
    pub fn constant(v: f32) -> Self {
        Self {
            pattern: Pattern::Constant,
            a: v,
            b: v,
        }
    }
}

impl Default for ScalarTexture {
    fn default() -> Self {
        Self::constant(0.5)
    }
}

/// A Lambert diffuse lobe plus a GGX specular lobe, and an optional perfect
/// mirror that takes a fraction `mirror` of the light.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Material {
    pub diffuse: ColorTexture,
    pub specular: ColorTexture,
    /// GGX roughness (perceptual; α = roughness²), 0 (polished) to 1.
    pub roughness: ScalarTexture,
    /// Fraction of light reflected by a perfect mirror, 0 to 1.
    pub mirror: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            diffuse: ColorTexture::constant(Vec3::splat(0.7)),
            specular: ColorTexture::constant(Vec3::splat(0.04)),
            roughness: ScalarTexture::constant(0.4),
            mirror: 0.0,
        }
    }
}

impl Material {
    /// The textures of this material, for walking them all.
    pub fn patterns(&self) -> [&Pattern; 3] {
        [
            &self.diffuse.pattern,
            &self.specular.pattern,
            &self.roughness.pattern,
        ]
    }

    pub(crate) fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
        self.diffuse
            .pattern
            .sanitize(&format!("{what} diffuse"), notes);
        self.specular
            .pattern
            .sanitize(&format!("{what} specular"), notes);
        self.roughness
            .pattern
            .sanitize(&format!("{what} roughness"), notes);
        for (name, c) in [
            ("diffuse", &mut self.diffuse),
            ("specular", &mut self.specular),
        ] {
            for v in [&mut c.a, &mut c.b] {
                let s = if v.is_finite() {
                    v.clamp(Vec3::ZERO, Vec3::ONE)
                } else {
                    Vec3::ZERO
                };
                if s != *v {
                    notes.push(format!("{what} {name}: colour {v} clamped to [0, 1]"));
                    *v = s;
                }
            }
        }
        for v in [
            &mut self.roughness.a,
            &mut self.roughness.b,
            &mut self.mirror,
        ] {
            let s = if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                0.0
            };
            if s != *v {
                notes.push(format!("{what}: {v} clamped to [0, 1]"));
                *v = s;
            }
        }
    }
}
