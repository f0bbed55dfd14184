//! Marble veins (the texture report's MARBRE): a sine across the veins,
//! its phase perturbed by turbulence.

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

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

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
