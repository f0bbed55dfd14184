//! Marble: the texture report's veins (MARBRE), a sine across the veins,
//! its phase perturbed by turbulence, and Massal's tutorial's marble, a
//! sine along the diagonal x + y shifted by his turbulence.

use crate::noise::{NoiseSettings, turbulence};
use glam::Vec3;

/// The vein weight in [0, 1]: `max(0, sin(frequency · axis·p +
/// turbulence_amount · turbulence(p)))`, where the turbulence's own
/// frequency is the noise settings' (the report's FREQTURB). Negative lobes
/// of the sine give the dominant colour, as in the report.
pub fn marble_veins(
    p: Vec3,
    axis: Vec3,
    frequency: f32,
    turbulence_amount: f32,
    noise: &NoiseSettings,
) -> f32 {
    (frequency * axis.dot(p) + turbulence_amount * turbulence(p, noise))
        .sin()
        .max(0.0)
}

/// Massal's marble (his tutorial's `material::marble`):
/// `0.5 · sin((x + y) · stripe_frequency + turbulence) + 0.5`, in [0, 1],
/// given the turbulence at the point (his is
/// [`NoiseSettings::massal`]'s, taken as |noise|, with the stripe
/// frequency equal to the noise's, 0.05 in his pixel-sized scene).
pub fn massal_marble_stripes(p: Vec3, stripe_frequency: f32, turbulence: f32) -> f32 {
    0.5 * ((p.x + p.y) * stripe_frequency + turbulence).sin() + 0.5
}

/// [`massal_marble_stripes`] with the turbulence of `noise` at `p`.
pub fn massal_marble(p: Vec3, stripe_frequency: f32, noise: &NoiseSettings) -> f32 {
    massal_marble_stripes(p, stripe_frequency, turbulence(p, noise))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::perlin::improved_noise_massal;
    use glam::DVec3;
    use std::f32::consts::PI;

    /// His `case material::marble:` transcribed in f64: the 9-level
    /// turbulence of his noise at 0.05, then `noiseCoef = 0.5f * sinf((x +
    /// y) * 0.05f + noiseCoef) + 0.5f`. The pattern's CPU twin (f32, the
    /// shader's) follows it within 5e-5 over his 640 × 480 scene: the
    /// turbulence's own 4e-5 (`linear_turbulence_is_massals`) halved by
    /// the 0.5 in front of the sine, plus the f32 rounding of (x + y) · f.
    #[test]
    fn massal_marble_is_his_formula() {
        fn his_marble(p: DVec3) -> f64 {
            let mut noise_coef = 0.0;
            for level in 1..10 {
                let level = f64::from(level);
                noise_coef += (1.0 / level)
                    * improved_noise_massal(
                        level * 0.05 * p.x,
                        level * 0.05 * p.y,
                        level * 0.05 * p.z,
                    )
                    .abs();
            }
            0.5 * ((p.x + p.y) * 0.05 + noise_coef).sin() + 0.5
        }
        let noise = NoiseSettings::massal(0.05);
        let (mut lo, mut hi) = (1.0_f64, 0.0_f64);
        for k in 0..3000 {
            let k = f64::from(k);
            let p = DVec3::new(k * 0.713 % 640.0, k * 0.291 % 480.0, 40.0 + k * 0.031);
            let expected = his_marble(p);
            let got = massal_marble(p.as_vec3(), 0.05, &noise);
            assert!(
                (f64::from(got) - expected).abs() < 5e-5,
                "{p}: {got} vs {expected}"
            );
            lo = lo.min(expected);
            hi = hi.max(expected);
        }
        // The stripes swing over nearly all of [0, 1].
        assert!(lo < 0.02 && hi > 0.98, "{lo}..{hi}");
    }

    /// Without turbulence it is a sine across the diagonal: constant along
    /// x − y, and a half period apart across it gives 1 − t.
    #[test]
    fn massal_marble_stripes_run_along_the_diagonal() {
        let f = 3.0;
        for t in [0.0_f32, 0.3, 1.1, 2.5] {
            let p = Vec3::new(t, 0.2, 5.0);
            let along = p + Vec3::new(0.7, -0.7, -3.0);
            let a = massal_marble_stripes(p, f, 0.0);
            assert!((a - massal_marble_stripes(along, f, 0.0)).abs() < 1e-5);
            let across = p + Vec3::new(PI / f, 0.0, 0.0);
            assert!((massal_marble_stripes(across, f, 0.0) - (1.0 - a)).abs() < 1e-5);
            // The turbulence shifts the phase: t at p + its shift.
            let shifted = massal_marble_stripes(p, f, 0.4);
            let moved = massal_marble_stripes(p + Vec3::new(0.4 / f, 0.0, 0.0), f, 0.0);
            assert!((shifted - moved).abs() < 1e-5);
        }
    }

    #[test]
    fn without_turbulence_it_is_a_half_wave_rectified_sine_along_the_axis() {
        let noise = NoiseSettings::default();
        let axis = Vec3::new(0.0, 0.6, 0.8);
        for t in [0.1_f32, 0.25, 0.5, 0.9, 1.3, 1.75] {
            let p = axis * t * PI + Vec3::new(5.0, -0.8, 0.6) * 0.0;
            let expected = (2.0 * t * PI).sin().max(0.0);
            let got = marble_veins(p, axis, 2.0, 0.0, &noise);
            assert!((got - expected).abs() < 1e-5, "{t}: {got} vs {expected}");
        }
        // Moving across the axis changes nothing.
        let side = Vec3::new(1.0, 0.0, 0.0);
        let p = axis * 0.3;
        assert_eq!(
            marble_veins(p, axis, 2.0, 0.0, &noise),
            marble_veins(p + side * 4.0, axis, 2.0, 0.0, &noise)
        );
    }
}
