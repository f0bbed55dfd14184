//! Coordinate rebasing: a far-off noise domain moved back near the origin by
//! whole periods of the lattice, where f32 still resolves a cell finely.
//!
//! A texture offset by 1e5 through its mapping evaluates noise at
//! `L·p + t` with |t| = 1e5, where consecutive f32 values are 1/128 apart:
//! every octave is sampled on that grid, and octaves finer than the grid
//! collapse to the lattice values (zero). Where the noise repeats (Perlin's
//! permutation table and the tiled pcg3d hash both read the cell modulo 256)
//! and every octave's frequency is a whole multiple of the first, the whole
//! fractal sum repeats every `256 / frequency` in its input, so the offset can
//! be reduced by whole periods in f64 on the CPU before the shader sees it.
//! In exact arithmetic the sum is unchanged; in f32 it is then evaluated with
//! the precision of a point near the origin. It is always on where it is
//! exact, so a user never has to choose it; the lab's gradient noise with the
//! plain pcg3d or sin hash does not repeat, and keeps its offset.

use super::{HashKind, NoiseKind, NoiseSettings, Progression, hash::LATTICE_PERIOD};
use glam::Vec3;

/// The period of the fractal sum in its input space, where it has one: the
/// lattice repeats every 256 cells and each octave's frequency
/// `frequency · lacunarityⁱ` is an integer multiple of the first (an integer
/// lacunarity, or the linear progression's `frequency · k`). The domain warp samples at the base frequency, so it repeats
/// with the same period.
pub fn period(noise: &NoiseSettings) -> Option<f64> {
    let lattice_repeats = match noise.kind {
        NoiseKind::Perlin | NoiseKind::PerlinMassal => true,
        NoiseKind::Gradient => noise.hash == HashKind::PcgTiled,
    };
    let f = &noise.fractal;
    let whole_lacunarity = (f.lacunarity >= 1.0 && f.lacunarity.fract() == 0.0)
        || f.progression == Progression::Linear;
    let frequency = f64::from(f.frequency);
    (lattice_repeats && whole_lacunarity && frequency > 0.0 && frequency.is_finite())
        .then(|| f64::from(LATTICE_PERIOD) / frequency)
}

/// `offset` less the whole number of periods nearest to it, so each component
/// lies within half a period of 0; unchanged where the noise has no period.
/// The reduction is done in f64: exact when the period is a power of two (a
/// frequency of 2ᵏ), otherwise within half an ulp of the result, a constant
/// shift of the whole texture far below what f32 resolves at the original
/// offset.
pub fn rebase(offset: Vec3, noise: &NoiseSettings) -> Vec3 {
    let Some(period) = period(noise) else {
        return offset;
    };
    let reduce = |c: f32| {
        let c = f64::from(c);
        (c - period * (c / period).round()) as f32
    };
    Vec3::new(reduce(offset.x), reduce(offset.y), reduce(offset.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::{FractalParams, FractalShape};

    fn settings(kind: NoiseKind, hash: HashKind, frequency: f32, lacunarity: f32) -> NoiseSettings {
        NoiseSettings {
            kind,
            hash,
            fractal: FractalParams {
                frequency,
                lacunarity,
                ..FractalParams::default()
            },
            evolution: None,
        }
    }

    /// Only noise whose lattice repeats, summed at whole multiples of the
    /// first frequency, has a period.
    #[test]
    fn a_period_exists_only_where_the_sum_repeats() {
        let perlin = settings(NoiseKind::Perlin, HashKind::Sin, 2.0, 2.0);
        assert_eq!(period(&perlin), Some(128.0));
        let tiled = settings(NoiseKind::Gradient, HashKind::PcgTiled, 0.5, 3.0);
        assert_eq!(period(&tiled), Some(512.0));
        for hash in [HashKind::Pcg, HashKind::Sin] {
            assert_eq!(period(&settings(NoiseKind::Gradient, hash, 1.0, 2.0)), None);
        }
        assert_eq!(
            period(&settings(NoiseKind::Perlin, HashKind::Pcg, 1.0, 2.1)),
            None
        );
        assert_eq!(
            period(&settings(NoiseKind::Perlin, HashKind::Pcg, 0.0, 2.0)),
            None
        );
        // Linear levels are whole multiples whatever the (unused) lacunarity.
        let mut linear = settings(NoiseKind::PerlinMassal, HashKind::Pcg, 0.5, 2.1);
        linear.fractal.progression = crate::noise::Progression::Linear;
        assert_eq!(period(&linear), Some(512.0));
        // And the sum does repeat: 9 levels, one period apart.
        let p = glam::DVec3::new(3.7, -1.2, 0.4);
        let shifted = p + glam::DVec3::new(512.0, -1024.0, 512.0);
        let sum = |q| crate::noise::fractal::fractal_sum_f64(q, &linear, FractalShape::Absolute);
        assert!((sum(p) - sum(shifted)).abs() < 1e-12);
    }

    /// 1e5 + 0.3 is 100000.296875 in f32; less the nearest whole number of
    /// periods of 256 (391) it is −95.703125, exactly (a power-of-two
    /// period).
    #[test]
    fn reduces_by_whole_periods_exactly() {
        let s = settings(NoiseKind::Perlin, HashKind::Pcg, 1.0, 2.0);
        let t = Vec3::new(100_000.3, -1e6, 7.5);
        let r = rebase(t, &s);
        assert_eq!(r, Vec3::new(-95.703_125, -64.0, 7.5));
        assert!(r.abs().max_element() <= 128.0);
        let plain = settings(NoiseKind::Gradient, HashKind::Pcg, 1.0, 2.0);
        assert_eq!(rebase(t, &plain), t);
    }
}
