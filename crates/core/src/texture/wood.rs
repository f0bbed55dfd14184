//! Wood: concentric rings around an axis, their radius perturbed by
//! turbulence (the texture report's BOIS).

use super::checker::odd;
use crate::noise::{NoiseSettings, turbulence};
use glam::Vec3;

/// The report's ring axis: through the origin, tilted 15° from z towards x,
/// so that a board cut along a principal plane shows elliptic rings rather
/// than perfect circles or straight stripes.
pub fn default_axis() -> Vec3 {
    let tilt = 15.0_f32.to_radians();
    Vec3::new(tilt.sin(), 0.0, tilt.cos())
}

/// 0 in the dark rings, 1 in the pale ones: the distance from `p` to the
/// axis through the origin along `axis` (unit length), plus `turbulence_amount ·
/// turbulence(p)`, in rings of `ring_width`.
pub fn wood(
    p: Vec3,
    axis: Vec3,
    ring_width: f32,
    turbulence_amount: f32,
    noise: &NoiseSettings,
) -> f32 {
    rings(
        p,
        axis,
        ring_width,
        turbulence_amount * turbulence(p, noise),
    )
}

/// [`wood`] given its radius perturbation: the renderer evaluates the
/// turbulence once per hit and shares it.
pub fn rings(p: Vec3, axis: Vec3, ring_width: f32, perturbation: f32) -> f32 {
    let radius = (p - p.dot(axis) * axis).length();
    odd(((radius + perturbation) / ring_width).floor())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without turbulence the rings repeat every two ring widths in radius
    /// and alternate every one.
    #[test]
    fn rings_are_periodic_in_radius() {
        let axis = default_axis();
        let across = axis.cross(Vec3::Y).normalize();
        let width = 0.12;
        let noise = NoiseSettings::default();
        for r in [0.01_f32, 0.05, 0.3, 0.71, 2.0] {
            let p = across * r + axis * 3.0;
            let here = wood(p, axis, width, 0.0, &noise);
            let one_ring = across * (r + width) + axis * 3.0;
            let two_rings = across * (r + 2.0 * width) + axis * -1.0;
            assert_eq!(wood(two_rings, axis, width, 0.0, &noise), here, "r = {r}");
            assert_eq!(
                wood(one_ring, axis, width, 0.0, &noise),
                1.0 - here,
                "r = {r}"
            );
        }
    }

    #[test]
    fn turbulence_moves_the_rings() {
        let axis = default_axis();
        let noise = NoiseSettings::default();
        let moved = (0..200)
            .map(|k| Vec3::new(k as f32 * 0.013, 0.3, k as f32 * -0.007))
            .filter(|&p| wood(p, axis, 0.12, 0.0, &noise) != wood(p, axis, 0.12, 0.3, &noise))
            .count();
        assert!(moved > 20, "{moved} of 200 points changed ring");
    }
}
