//! Fractal sums of a lattice noise: fBm, turbulence and marble.

use super::evolution::Evolution;
use super::gradient::{gradient_noise, gradient_noise_f64, gradient_noise4, gradient_noise4_f64};
use super::perlin::{
    Real, improved_noise, improved_noise_f32, improved_noise_massal, improved_noise_massal_f32,
    improved_noise4, improved_noise4_f32,
};
use super::{HashKind, NoiseKind};
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};
use std::ops::RangeInclusive;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/noise/fractal.wgsl");

/// The knobs of a fractal sum. Octave `i` is `amplitude · persistenceⁱ ·
/// noise(p · frequency · lacunarityⁱ)` in the geometric progression, and
/// `amplitude / k · noise(p · frequency · k)` with k = i + 1 in the linear
/// one ([`Progression`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FractalParams {
    /// Number of octaves, 0 to [`FractalParams::MAX_OCTAVES`]. A fractional
    /// part weights the last octave, so the image changes smoothly while the
    /// slider moves.
    pub octaves: f32,
    pub frequency: f32,
    pub amplitude: f32,
    pub persistence: f32,
    pub lacunarity: f32,
    /// Domain warp (Blender's distortion): the sum is taken at `p` moved by
    /// this much times a vector of three decorrelated noises at the base
    /// frequency. 0 leaves `p` alone.
    pub distortion: f32,
    /// How the octaves' frequencies and amplitudes progress; presets
    /// written before it read as geometric, as they were.
    pub progression: Progression,
}

/// How a fractal sum's octaves follow one another.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Progression {
    /// Octave i at `frequency · lacunarityⁱ`, weighted `amplitude ·
    /// persistenceⁱ` (Musgrave's fBm, the lab's sums).
    #[default]
    Geometric,
    /// Massal's harmonics: level k = i + 1 at `frequency · k`, weighted
    /// `amplitude / k`; lacunarity and persistence are unused. His
    /// tutorial's turbulence is this with |noise|, 9 levels and frequency
    /// 0.05 (`Σ_{level=1}^{9} |noise(level · 0.05 · p)| / level`).
    Linear,
}

impl Progression {
    pub const ALL: [Progression; 2] = [Progression::Geometric, Progression::Linear];

    pub fn label(self) -> &'static str {
        match self {
            Progression::Geometric => "geometric (lacunarity)",
            Progression::Linear => "linear (Massal)",
        }
    }
}

impl FractalParams {
    pub const MAX_OCTAVES: f32 = 16.0;
    /// The values a preset is clamped to at load and the panel lets a user
    /// type (its sliders drag over the useful part): one source for both, so
    /// a saved scene always reloads unchanged.
    pub const OCTAVES: RangeInclusive<f32> = 0.0..=Self::MAX_OCTAVES;
    pub const FREQUENCY: RangeInclusive<f32> = 0.0..=1e6;
    pub const AMPLITUDE: RangeInclusive<f32> = -100.0..=100.0;
    /// Above 1 the octaves grow: the sum is not normalised (that would
    /// change every existing texture's contrast) but stays bounded, by
    /// |amplitude| · Σ persistenceⁱ · the noise's bound, at most
    /// 100 · 1.5¹⁶/0.5 · 1.1 ≈ 1.5e5 over 16 octaves, and every pattern
    /// clamps its blend factor to [0, 1].
    pub const PERSISTENCE: RangeInclusive<f32> = 0.0..=1.5;
    pub const LACUNARITY: RangeInclusive<f32> = 1.0..=8.0;
    pub const DISTORTION: RangeInclusive<f32> = -100.0..=100.0;
}

impl Default for FractalParams {
    fn default() -> Self {
        Self {
            octaves: 6.0,
            frequency: 1.0,
            amplitude: 1.0,
            persistence: 0.5,
            lacunarity: 2.0,
            distortion: 0.0,
            progression: Progression::Geometric,
        }
    }
}

/// A complete noise binding: which lattice noise, which hash, which sum.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct NoiseSettings {
    pub kind: NoiseKind,
    pub hash: HashKind,
    pub fractal: FractalParams,
    /// Evolving noise (issue 29): the 4D noise at a w that moves with time,
    /// its domain drifting. None, as in every preset written before it, is
    /// the 3D noise, and the renderer compiles exactly the code it did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evolution: Option<Evolution>,
}

impl NoiseSettings {
    /// The noise of Massal's tutorial at `frequency` (his is 0.05, for a
    /// scene measured in pixels): his noise (Perlin's with his `grad()`)
    /// summed over 9 linear levels. Taken as |noise| it is his turbulence.
    pub fn massal(frequency: f32) -> Self {
        Self {
            kind: NoiseKind::PerlinMassal,
            hash: HashKind::default(),
            fractal: FractalParams {
                octaves: 9.0,
                frequency,
                amplitude: 1.0,
                progression: Progression::Linear,
                ..FractalParams::default()
            },
            evolution: None,
        }
    }
}

/// One octave of the chosen lattice noise, in f32 as the shader.
pub fn noise(p: Vec3, kind: NoiseKind, hash: HashKind) -> f32 {
    f32::lattice_noise(p.to_array(), kind, hash)
}

/// One octave in double precision: the CPU reference (`marbre noise
/// --cpu`). Perlin's own Java is double precision, and far from the origin
/// f32 has lost the noise's digits (6e-5 off his values at |p| ≈ 950).
pub fn noise_f64(p: DVec3, kind: NoiseKind, hash: HashKind) -> f64 {
    f64::lattice_noise(p.to_array(), kind, hash)
}

/// One octave of the chosen lattice noise in 4D, at (p, w), its lattice
/// periodic in w every `w_period` cells when given; in f32 as the shader.
pub fn noise4(p: Vec3, w: f32, kind: NoiseKind, hash: HashKind, w_period: Option<u32>) -> f32 {
    f32::lattice_noise4(p.to_array(), w, kind, hash, w_period)
}

/// [`noise4`] in double precision: the reference.
pub fn noise4_f64(p: DVec3, w: f64, kind: NoiseKind, hash: HashKind, w_period: Option<u32>) -> f64 {
    f64::lattice_noise4(p.to_array(), w, kind, hash, w_period)
}

/// A precision the noise and its fractal sums are evaluated in: f32 (the
/// shader's twin) or f64 (the reference).
trait NoisePrecision: Real + std::ops::Div<Output = Self> {
    fn lattice_noise(p: [Self; 3], kind: NoiseKind, hash: HashKind) -> Self;
    fn lattice_noise4(
        p: [Self; 3],
        w: Self,
        kind: NoiseKind,
        hash: HashKind,
        w_period: Option<u32>,
    ) -> Self;
    fn abs(self) -> Self;
    fn min(self, other: Self) -> Self;
}

/// The [`NoisePrecision`] of `$t`: its noises are `$gradient` (taking a
/// `$vec`), `$perlin` and `$massal`.
macro_rules! noise_precision {
    ($t:ty, $vec:ty, $gradient:path, $perlin:path, $massal:path, $gradient4:path, $perlin4:path) => {
        impl NoisePrecision for $t {
            fn lattice_noise(p: [$t; 3], kind: NoiseKind, hash: HashKind) -> $t {
                match kind {
                    NoiseKind::Gradient => $gradient(<$vec>::from_array(p), hash),
                    NoiseKind::Perlin => $perlin(p[0], p[1], p[2]),
                    NoiseKind::PerlinMassal => $massal(p[0], p[1], p[2]),
                }
            }
            fn lattice_noise4(
                p: [$t; 3],
                w: $t,
                kind: NoiseKind,
                hash: HashKind,
                w_period: Option<u32>,
            ) -> $t {
                match kind {
                    NoiseKind::Gradient => $gradient4(<$vec>::from_array(p), w, hash, w_period),
                    // Massal's table has no 4D form: both Perlin kinds
                    // evolve with Blender's 32 gradients.
                    NoiseKind::Perlin | NoiseKind::PerlinMassal => {
                        $perlin4([p[0], p[1], p[2], w], w_period)
                    }
                }
            }
            fn abs(self) -> $t {
                <$t>::abs(self)
            }
            fn min(self, other: $t) -> $t {
                <$t>::min(self, other)
            }
        }
    };
}
noise_precision!(
    f32,
    Vec3,
    gradient_noise,
    improved_noise_f32,
    improved_noise_massal_f32,
    gradient_noise4,
    improved_noise4_f32
);
noise_precision!(
    f64,
    DVec3,
    gradient_noise_f64,
    improved_noise,
    improved_noise_massal,
    gradient_noise4_f64,
    improved_noise4
);

/// What each octave adds: the signed noise (fBm), its absolute value
/// (turbulence), or `(1 - |noise|)²`, sharp ridges where noise crosses 0
/// (ridged, after Musgrave).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FractalShape {
    Signed,
    Absolute,
    Ridged,
}

impl FractalShape {
    /// The id the shader switches on (`NoiseParams::shape`).
    pub fn id(self) -> u32 {
        match self {
            FractalShape::Signed => 0,
            FractalShape::Absolute => 1,
            FractalShape::Ridged => 2,
        }
    }

    fn apply<T: NoisePrecision>(self, v: T) -> T {
        match self {
            FractalShape::Signed => v,
            FractalShape::Absolute => v.abs(),
            FractalShape::Ridged => (T::ONE - v.abs()) * (T::ONE - v.abs()),
        }
    }
}

/// Offsets that decorrelate the three components of the domain warp.
const WARP_OFFSETS: [Vec3; 3] = [
    Vec3::new(5.2, 1.3, 7.1),
    Vec3::new(1.7, 9.2, 3.4),
    Vec3::new(8.3, 2.8, 4.9),
];

/// The lattice noise a sum's octaves read: 3D, or with an evolution 4D at
/// the moment's w. Without a loop octave i reads w·rᵢ, rᵢ = fᵢ/f₀ its
/// frequency over the first's (Blender's 4D fBm scales w with each octave;
/// measured in the first octave's cells, a frequency edit leaves the speed
/// alone). While looping every octave reads w itself, its lattice periodic
/// in the loop's P cells: so the sum at w + P is the sum at w for any
/// lacunarity, where scaling w by a non-integer rᵢ would break the seam.
struct OctaveNoise<T> {
    kind: NoiseKind,
    hash: HashKind,
    /// The moment's w and the loop's period, for an evolving noise.
    evolution: Option<(T, Option<u32>)>,
}

impl<T: NoisePrecision> OctaveNoise<T> {
    fn new(s: &NoiseSettings) -> Self {
        Self {
            kind: s.kind,
            hash: s.hash,
            evolution: s
                .evolution
                .map(|e: Evolution| (T::from_f64(f64::from(e.w_now())), e.w_period)),
        }
    }

    /// The noise at `q`, for an octave whose frequency is `ratio` times the
    /// first's.
    fn at(&self, q: [T; 3], ratio: T) -> T {
        match self.evolution {
            None => T::lattice_noise(q, self.kind, self.hash),
            Some((w, None)) => T::lattice_noise4(q, w * ratio, self.kind, self.hash, None),
            Some((w, period)) => T::lattice_noise4(q, w, self.kind, self.hash, period),
        }
    }
}

/// `p` moved by the domain warp of `s` (unchanged without distortion).
pub fn warped(p: Vec3, s: &NoiseSettings) -> Vec3 {
    Vec3::from_array(warped_generic(p.to_array(), s))
}

fn warped_generic<T: NoisePrecision>(p: [T; 3], s: &NoiseSettings) -> [T; 3] {
    let amount = T::from_f64(f64::from(s.fractal.distortion));
    if s.fractal.distortion == 0.0 {
        return p;
    }
    let frequency = T::from_f64(f64::from(s.fractal.frequency));
    let q = p.map(|c| c * frequency);
    let noise = OctaveNoise::new(s);
    let [a, b, c] = WARP_OFFSETS.map(|o| {
        let o = o.to_array().map(|c| T::from_f64(f64::from(c)));
        noise.at([q[0] + o[0], q[1] + o[1], q[2] + o[2]], T::ONE)
    });
    [p[0] + amount * a, p[1] + amount * b, p[2] + amount * c]
}

/// Sums `shape(noise)` over the octaves, at the warped point.
pub fn fractal_sum(p: Vec3, s: &NoiseSettings, shape: FractalShape) -> f32 {
    fractal_sum_generic(p.to_array(), s, shape)
}

/// [`fractal_sum`] in double precision: the CPU reference.
pub fn fractal_sum_f64(p: DVec3, s: &NoiseSettings, shape: FractalShape) -> f64 {
    fractal_sum_generic(p.to_array(), s, shape)
}

fn fractal_sum_generic<T: NoisePrecision>(p: [T; 3], s: &NoiseSettings, shape: FractalShape) -> T {
    let p = warped_generic(p, s);
    let f = &s.fractal;
    let param = |v: f32| T::from_f64(f64::from(v));
    let octaves = param(f.octaves.clamp(0.0, FractalParams::MAX_OCTAVES));
    let whole = f.octaves.clamp(0.0, FractalParams::MAX_OCTAVES).ceil() as u32;
    let noise = OctaveNoise::new(s);
    let mut frequency = param(f.frequency);
    let mut amplitude = param(f.amplitude);
    // fᵢ/f₀, kept beside the frequency (not divided: f₀ may be 0).
    let mut ratio = T::ONE;
    let mut sum = T::ZERO;
    for i in 0..whole {
        // The last octave fades in with the fractional part of `octaves`.
        let weight = (octaves - T::from_i32(i as i32)).min(T::ONE);
        if f.progression == Progression::Linear {
            let k = T::from_i32(i as i32 + 1);
            frequency = param(f.frequency) * k;
            amplitude = param(f.amplitude) / k;
            ratio = k;
        }
        let v = noise.at(p.map(|c| c * frequency), ratio);
        sum = sum + weight * amplitude * shape.apply(v);
        frequency = frequency * param(f.lacunarity);
        amplitude = amplitude * param(f.persistence);
        ratio = ratio * param(f.lacunarity);
    }
    sum
}

/// How many octaves a pixel footprint `width` wide (in the noise's space)
/// resolves, pbrt's rule generalised to any lacunarity L: octave i, of
/// frequency f·Lⁱ, is kept while its period is more than two footprints
/// (f·Lⁱ·width < 1/2), so n = (−1 − log2(f·width)) / log2(L); the last, partial
/// octave fades in by smoothstep(0.3, 0.7) of its fraction. Never more than
/// `octaves`; a zero width (no footprint) or L ≤ 1 keeps them all. In the
/// linear progression level i + 1 has frequency f·(i + 1), so the rule
/// gives n = 1/(2·f·width) − 1.
pub fn footprint_octaves(f: &FractalParams, width: f32) -> f32 {
    let octaves = f.octaves.clamp(0.0, FractalParams::MAX_OCTAVES);
    let linear = f.progression == Progression::Linear;
    if !(width > 0.0 && (f.lacunarity > 1.0 || linear) && f.frequency > 0.0) {
        return octaves;
    }
    let n = if linear {
        (0.5 / (f.frequency * width) - 1.0).max(0.0)
    } else {
        ((-1.0 - (f.frequency * width).log2()) / f.lacunarity.log2()).max(0.0)
    };
    let whole = n.floor();
    let x = ((n - whole - 0.3) / 0.4).clamp(0.0, 1.0);
    (whole + x * x * (3.0 - 2.0 * x)).min(octaves)
}

/// The mean of |noise| for each lattice noise (the gradient noise ≈ 0.146,
/// Perlin's ≈ 0.220), measured over many points (the test
/// `mean_abs_noise_is_the_measured_mean` holds them to it).
pub fn mean_abs_noise(kind: NoiseKind) -> f32 {
    match kind {
        NoiseKind::Gradient => MEAN_ABS_GRADIENT,
        NoiseKind::Perlin | NoiseKind::PerlinMassal => MEAN_ABS_PERLIN,
    }
}

const MEAN_ABS_GRADIENT: f32 = 0.146;
const MEAN_ABS_PERLIN: f32 = 0.220;

/// What the octaves that [`footprint_octaves`] drops from `f`'s sum add on
/// average, with `kept` octaves left: for turbulence each dropped octave
/// adds its amplitude times the mean |noise| (pbrt's `Turbulence`), so a
/// far or small turbulence fades to its mean rather than to 0 (BRIQUE's
/// FREQ 14 bricks went black). Signed and ridged sums add nothing: fBm's
/// mean is 0, and ridged sums keep the rule they had.
pub fn dropped_octaves_mean(s: &NoiseSettings, shape: FractalShape, kept: f32) -> f32 {
    let f = &s.fractal;
    if shape != FractalShape::Absolute {
        return 0.0;
    }
    let octaves = f.octaves.clamp(0.0, FractalParams::MAX_OCTAVES);
    let mut amplitude = f.amplitude;
    let mut sum = 0.0;
    for i in 0..octaves.ceil() as u32 {
        let i_f = i as f32;
        if f.progression == Progression::Linear {
            amplitude = f.amplitude / (i_f + 1.0);
        }
        let full = (octaves - i_f).min(1.0);
        let shown = (kept - i_f).clamp(0.0, 1.0);
        sum += (full - shown) * amplitude;
        amplitude *= f.persistence;
    }
    sum * mean_abs_noise(s.kind)
}

/// Fractional Brownian motion: a sum of octaves of signed noise.
pub fn fbm(p: Vec3, s: &NoiseSettings) -> f32 {
    fractal_sum(p, s, FractalShape::Signed)
}

/// Turbulence: a sum of octaves of |noise|, with creases where noise crosses 0.
pub fn turbulence(p: Vec3, s: &NoiseSettings) -> f32 {
    fractal_sum(p, s, FractalShape::Absolute)
}

/// Ridged noise: a sum of octaves of `(1 - |noise|)²`.
pub fn ridged(p: Vec3, s: &NoiseSettings) -> f32 {
    fractal_sum(p, s, FractalShape::Ridged)
}

/// The lab's marble: `sin(p.x · stripe_frequency + fbm(p))`, in [-1, 1].
pub fn marble(p: Vec3, s: &NoiseSettings, stripe_frequency: f32) -> f32 {
    (p.x * stripe_frequency + fbm(p, s)).sin()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_abs_noise_is_the_measured_mean() {
        for kind in NoiseKind::ALL {
            let one = settings(kind, 1.0, 1.0);
            let n = 200_000;
            // An irrational stride: the points fill the cells evenly.
            let mean = (0..n)
                .map(|i| {
                    let t = i as f32;
                    let p = Vec3::new(t * 0.618_034, t * 0.414_213_6, t * 0.732_050_8) % 251.0;
                    turbulence(p, &one)
                })
                .sum::<f32>()
                / n as f32;
            let want = mean_abs_noise(kind);
            assert!(
                (mean - want).abs() < 0.01,
                "{kind:?}: measured {mean}, constant {want}"
            );
        }
    }

    #[test]
    fn dropped_turbulence_octaves_add_their_mean_and_kept_ones_nothing() {
        let s = settings(NoiseKind::Gradient, 3.0, 1.0);
        let m = mean_abs_noise(NoiseKind::Gradient);
        assert_eq!(dropped_octaves_mean(&s, FractalShape::Absolute, 3.0), 0.0);
        // Amplitudes 1, 0.5, 0.25: all dropped, the last two, half the second.
        assert!((dropped_octaves_mean(&s, FractalShape::Absolute, 0.0) - 1.75 * m).abs() < 1e-6);
        assert!((dropped_octaves_mean(&s, FractalShape::Absolute, 1.0) - 0.75 * m).abs() < 1e-6);
        assert!((dropped_octaves_mean(&s, FractalShape::Absolute, 1.5) - 0.5 * m).abs() < 1e-6);
        assert_eq!(dropped_octaves_mean(&s, FractalShape::Signed, 0.0), 0.0);
    }

    fn settings(kind: NoiseKind, octaves: f32, amplitude: f32) -> NoiseSettings {
        NoiseSettings {
            kind,
            hash: HashKind::Pcg,
            fractal: FractalParams {
                octaves,
                amplitude,
                ..FractalParams::default()
            },
            evolution: None,
        }
    }

    fn evolving(kind: NoiseKind, lacunarity: f32, distortion: f32) -> NoiseSettings {
        NoiseSettings {
            kind,
            hash: HashKind::Pcg,
            fractal: FractalParams {
                octaves: 5.5,
                frequency: 1.3,
                lacunarity,
                distortion,
                ..FractalParams::default()
            },
            evolution: Some(Evolution {
                w: 0.25,
                speed: 0.7,
                ..Evolution::default()
            }),
        }
    }

    /// A loop's last frame is its first, to the bit, for every sum and
    /// any lacunarity (every octave's lattice periodic in the loop's
    /// period): at t = D by the time's reduction, and just before D it
    /// approaches the sum at w₀ + P, which the periodic lattice makes the
    /// sum at w₀.
    #[test]
    fn an_evolving_sum_loops_without_a_seam() {
        for kind in NoiseKind::ALL {
            for lacunarity in [2.0, 1.93] {
                for distortion in [0.0, 0.4] {
                    let mut s = evolving(kind, lacunarity, distortion);
                    let d = 3.0;
                    let at = |s: &mut NoiseSettings, t: f32| {
                        s.evolution.as_mut().expect("evolving").at(t, Some(d));
                        *s
                    };
                    let first = at(&mut s, 0.0);
                    let last = at(&mut s, d);
                    let mut wrapped = first;
                    let e = wrapped.evolution.as_mut().expect("evolving");
                    e.w += e.w_period.expect("looping") as f32;
                    for p in points() {
                        for shape in [
                            FractalShape::Signed,
                            FractalShape::Absolute,
                            FractalShape::Ridged,
                        ] {
                            let a = fractal_sum(p, &first, shape);
                            assert_eq!(a, fractal_sum(p, &last, shape));
                            assert_eq!(a, fractal_sum(p, &wrapped, shape), "{kind:?} {p}");
                        }
                        assert_eq!(marble(p, &first, 2.0), marble(p, &last, 2.0));
                    }
                }
            }
        }
    }

    /// Evolving noise changes with time (its w moves), and without a loop
    /// octave i reads w·fᵢ/f₀: one octave at w is the 4D noise at
    /// (p·f₀, w).
    #[test]
    fn an_evolving_sum_moves_with_w() {
        for kind in NoiseKind::ALL {
            let mut s = evolving(kind, 2.0, 0.0);
            s.fractal.octaves = 1.0;
            let e = s.evolution.as_mut().expect("evolving");
            e.at(2.0, None);
            let w = e.w_now();
            for p in points() {
                assert_eq!(fbm(p, &s), noise4(p * 1.3, w, kind, HashKind::Pcg, None));
            }
            s.fractal.octaves = 4.0;
            let before: Vec<f32> = points().map(|p| fbm(p, &s)).collect();
            s.evolution.as_mut().expect("evolving").at(2.5, None);
            let moved = points()
                .zip(&before)
                .filter(|(p, b)| fbm(*p, &s) != **b)
                .count();
            assert!(moved > 450, "{kind:?}: {moved}");
        }
    }

    fn points() -> impl Iterator<Item = Vec3> {
        (0..500).map(|k| {
            let k = k as f32;
            Vec3::new(k * 0.37, k * 0.11 - 20.0, 3.0 - k * 0.053)
        })
    }

    /// The footprint rule: a footprint of half the first octave's period
    /// keeps no octave, each halving of it one more, fading in between;
    /// no footprint keeps them all.
    #[test]
    fn footprint_octaves_follow_the_nyquist_rule() {
        let f = FractalParams {
            octaves: 8.0,
            frequency: 2.0,
            lacunarity: 2.0,
            ..FractalParams::default()
        };
        assert_eq!(footprint_octaves(&f, 0.0), 8.0);
        assert_eq!(footprint_octaves(&f, 0.25), 0.0);
        assert_eq!(footprint_octaves(&f, 0.125), 1.0);
        assert_eq!(footprint_octaves(&f, 0.25 / 8.0), 3.0);
        assert_eq!(footprint_octaves(&f, 1e-9), 8.0);
        // Between whole counts, the partial octave fades in smoothly.
        let mid = footprint_octaves(&f, 0.25 / 2f32.powf(2.5));
        assert!((mid - 2.5).abs() < 1e-4, "{mid}");
        let early = footprint_octaves(&f, 0.25 / 2f32.powf(2.2));
        assert_eq!(early, 2.0);
        let three = FractalParams {
            lacunarity: 3.0,
            ..f
        };
        assert!((footprint_octaves(&three, 0.25 / 9.0) - 2.0).abs() < 1e-4);
    }

    /// One octave of ridged noise is `(1 - |noise|)²`, in [0, 1], and
    /// equal to 1 exactly where the noise crosses 0 (at lattice points).
    #[test]
    fn one_ridged_octave_is_the_squared_complement_of_abs_noise() {
        for kind in NoiseKind::ALL {
            let s = settings(kind, 1.0, 1.0);
            for p in points() {
                let n = noise(p, kind, HashKind::Pcg);
                let r = ridged(p, &s);
                assert_eq!(r, (1.0 - n.abs()) * (1.0 - n.abs()));
                assert!((0.0..=1.0).contains(&r));
            }
            assert_eq!(ridged(Vec3::new(3.0, -2.0, 5.0), &s), 1.0);
        }
    }

    /// Without distortion the warp is the identity; with it, the sum is
    /// the plain sum at a point moved by at most `distortion · max |noise|`.
    #[test]
    fn domain_warp_moves_the_point_by_at_most_the_distortion() {
        for kind in NoiseKind::ALL {
            let mut s = settings(kind, 4.0, 1.0);
            for p in points() {
                assert_eq!(warped(p, &s), p);
            }
            s.fractal.distortion = 0.5;
            let mut moved = 0;
            for p in points() {
                let q = warped(p, &s);
                // Each noise is within about ±1.1 (Perlin's bound, ~1.04).
                assert!((q - p).abs().max_element() <= 0.5 * 1.1, "{p} -> {q}");
                moved += usize::from(q != p);
                let plain = NoiseSettings {
                    fractal: FractalParams {
                        distortion: 0.0,
                        ..s.fractal
                    },
                    ..s
                };
                assert_eq!(fbm(p, &s), fbm(q, &plain));
            }
            assert!(moved > 400, "{kind:?}: only {moved} points moved");
        }
    }

    #[test]
    fn zero_octaves_give_zero() {
        for kind in NoiseKind::ALL {
            let s = settings(kind, 0.0, 1.0);
            for p in points() {
                assert_eq!(fbm(p, &s), 0.0);
                assert_eq!(turbulence(p, &s), 0.0);
            }
        }
    }

    #[test]
    fn fbm_is_linear_in_amplitude() {
        for kind in NoiseKind::ALL {
            let one = settings(kind, 5.0, 1.0);
            let three = settings(kind, 5.0, 3.0);
            for p in points() {
                let (a, b) = (fbm(p, &one), fbm(p, &three));
                assert!((3.0 * a - b).abs() <= 1e-5 * (1.0 + b.abs()), "{a} {b}");
            }
        }
    }

    #[test]
    fn one_octave_is_the_plain_noise() {
        let s = settings(NoiseKind::Perlin, 1.0, 1.0);
        for p in points() {
            assert_eq!(fbm(p, &s), noise(p, NoiseKind::Perlin, HashKind::Pcg));
        }
    }

    #[test]
    fn fractional_octaves_interpolate_between_whole_ones() {
        let lo = settings(NoiseKind::Gradient, 3.0, 1.0);
        let mid = settings(NoiseKind::Gradient, 3.25, 1.0);
        let hi = settings(NoiseKind::Gradient, 4.0, 1.0);
        for p in points() {
            let expected = 0.75 * fbm(p, &lo) + 0.25 * fbm(p, &hi);
            assert!((fbm(p, &mid) - expected).abs() < 1e-5);
        }
    }

    /// Massal's turbulence, transcribed from his tutorial in f64 (his
    /// `noise()` is Perlin's with his `grad()`, `improved_noise_massal`):
    /// `for (level = 1; level < 10; level++) noiseCoef += (1.0f / level) *
    /// fabsf(noise(level * 0.05 * x, …))`, over his pixel-sized scene. The
    /// linear progression with 9 levels is his loop to rounding at the
    /// frequency a preset stores (0.05 in f32), and within 5e-5 of his
    /// exact 0.05 (f32's 0.05 is 7.5e-10 off, which moves level k's
    /// argument by k · 640 · 7.5e-10 and the sum by at most Σ 8.5 · 640 ·
    /// 7.5e-10 ≈ 4e-5); the f32 twin (the shader's) is as close.
    #[test]
    fn linear_turbulence_is_massals() {
        fn his_turbulence(f: f64, x: f64, y: f64, z: f64) -> f64 {
            let mut noise_coef = 0.0;
            for level in 1..10 {
                let level = f64::from(level);
                noise_coef += (1.0 / level)
                    * improved_noise_massal(level * f * x, level * f * y, level * f * z).abs();
            }
            noise_coef
        }
        let s = NoiseSettings::massal(0.05);
        let stored = f64::from(s.fractal.frequency);
        let mut spread = (f64::MAX, f64::MIN);
        for k in 0..2000 {
            let k = f64::from(k);
            let p = DVec3::new(k * 0.713 % 640.0, k * 0.291 % 480.0, 30.0 + k * 0.057);
            let got = fractal_sum_f64(p, &s, FractalShape::Absolute);
            let same_frequency = his_turbulence(stored, p.x, p.y, p.z);
            assert!(
                (got - same_frequency).abs() < 1e-12,
                "{p}: {got} vs {same_frequency}"
            );
            let expected = his_turbulence(0.05, p.x, p.y, p.z);
            assert!((got - expected).abs() < 5e-5, "{p}: {got} vs {expected}");
            let single = turbulence(p.as_vec3(), &s);
            assert!(
                (f64::from(single) - expected).abs() < 5e-5,
                "{p}: f32 {single} vs {expected}"
            );
            spread = (spread.0.min(expected), spread.1.max(expected));
        }
        // Not a constant: the reference spans a real range.
        assert!(spread.1 - spread.0 > 0.5, "{spread:?}");
        // The geometric progression with the same knobs is another sum.
        let geometric = NoiseSettings {
            fractal: FractalParams {
                progression: Progression::Geometric,
                ..s.fractal
            },
            ..s
        };
        let p = Vec3::new(123.4, 56.7, 89.1);
        assert!((turbulence(p, &geometric) - turbulence(p, &s)).abs() > 1e-3);
    }

    /// The footprint rule in the linear progression: level k has frequency
    /// k·f, kept while k·f·width < 1/2, so n = 1/(2·f·width) − 1.
    #[test]
    fn linear_footprint_octaves_keep_the_levels_below_nyquist() {
        let f = NoiseSettings::massal(2.0).fractal;
        assert_eq!(footprint_octaves(&f, 0.0), 9.0);
        assert_eq!(footprint_octaves(&f, 0.25), 0.0);
        assert_eq!(footprint_octaves(&f, 0.125), 1.0);
        assert_eq!(footprint_octaves(&f, 0.25 / 4.0), 3.0);
        assert_eq!(footprint_octaves(&f, 1e-6), 9.0);
        let mid = footprint_octaves(&f, 0.25 / 3.5);
        assert!((mid - 2.5).abs() < 1e-4, "{mid}");
    }

    #[test]
    fn turbulence_is_non_negative_and_marble_is_a_sine() {
        let s = settings(NoiseKind::Gradient, 6.0, 1.0);
        for p in points() {
            assert!(turbulence(p, &s) >= 0.0);
            assert!(marble(p, &s, 4.0).abs() <= 1.0);
        }
    }
}
