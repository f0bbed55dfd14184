//! Waves (the texture report's VAGUE): a sine height field over uv that
//! only tilts the normal.

use glam::Vec2;
use std::f32::consts::TAU;

/// The height of the waves in [0, 1]: `0.5 + 0.5 · sin(2π · frequency ·
/// direction·uv)`. As a bump texture it ripples the surface.
pub fn waves(uv: Vec2, frequency: f32, direction: Vec2) -> f32 {
    0.5 + 0.5 * (TAU * frequency * direction.dot(uv)).sin()
}

/// The gradient over uv of the height `amplitude · sin(2π · frequency ·
/// direction·uv)`, `direction` of unit length: the crests run across it.
pub fn waves_gradient(uv: Vec2, frequency: f32, amplitude: f32, direction: Vec2) -> Vec2 {
    let phase = TAU * frequency * direction.dot(uv);
    amplitude * TAU * frequency * phase.cos() * direction
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `waves` is the height whose gradient `waves_gradient` gives, for an
    /// amplitude of one half.
    #[test]
    fn waves_and_their_gradient_agree() {
        let (f, d) = (2.0, Vec2::new(0.8, 0.6));
        let e = 1e-3;
        let uv = Vec2::new(0.3, -0.1);
        let numeric = Vec2::new(
            waves(uv + Vec2::X * e, f, d) - waves(uv - Vec2::X * e, f, d),
            waves(uv + Vec2::Y * e, f, d) - waves(uv - Vec2::Y * e, f, d),
        ) / (2.0 * e);
        assert!((numeric - waves_gradient(uv, f, 0.5, d)).length() < 1e-2);
    }

    /// The gradient matches central differences of the height.
    #[test]
    fn gradient_is_the_derivative_of_the_height() {
        let (f, a, d) = (3.0, 0.05, Vec2::new(0.6, 0.8));
        let height = |uv: Vec2| a * (TAU * f * d.dot(uv)).sin();
        let h = 1e-3;
        for uv in [
            Vec2::new(0.1, 0.2),
            Vec2::new(0.77, -0.3),
            Vec2::new(2.0, 1.5),
        ] {
            let numeric = Vec2::new(
                (height(uv + Vec2::X * h) - height(uv - Vec2::X * h)) / (2.0 * h),
                (height(uv + Vec2::Y * h) - height(uv - Vec2::Y * h)) / (2.0 * h),
            );
            let analytic = waves_gradient(uv, f, a, d);
            assert!(
                (numeric - analytic).length() < 2e-3,
                "{numeric} vs {analytic}"
            );
        }
    }
}
