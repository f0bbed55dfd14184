//! Waves (the texture report's VAGUE): a sine height field over uv that
//! only tilts the normal.

use glam::Vec2;
use std::f32::consts::TAU;

/// The gradient over uv of the height `amplitude · sin(2π · frequency ·
/// direction·uv)`, `direction` of unit length: the crests run across it.
pub fn waves_gradient(uv: Vec2, frequency: f32, amplitude: f32, direction: Vec2) -> Vec2 {
    let phase = TAU * frequency * direction.dot(uv);
    amplitude * TAU * frequency * phase.cos() * direction
}

#[cfg(test)]
mod tests {
    use super::*;

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
