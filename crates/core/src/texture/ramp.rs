//! Colour ramps: a scalar mapped through colour stops, as in Blender's
//! ColorRamp node with linear interpolation.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The most stops a ramp holds (the shader's code is unrolled per stop).
pub const MAX_RAMP_STOPS: usize = 8;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RampStop {
    pub position: f32,
    pub color: Vec3,
}

/// Rec. 709 luminance, the weight a ramp gives an image's colour (twin of
/// `luminance` in shaders/common.wgsl).
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The colour at `t`: the first stop's colour before it, the last's after
/// it, linear between neighbours. `stops` must be sorted by position (the
/// scene's sanitiser sorts them); an empty ramp is black.
pub fn ramp(stops: &[RampStop], t: f32) -> Vec3 {
    let Some(first) = stops.first() else {
        return Vec3::ZERO;
    };
    // NaN compares false everywhere: it gets the first colour too.
    if t.is_nan() || t <= first.position {
        return first.color;
    }
    for pair in stops.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if t <= b.position {
            let span = b.position - a.position;
            let w = if span > 0.0 {
                (t - a.position) / span
            } else {
                1.0
            };
            return a.color.lerp(b.color, w);
        }
    }
    stops[stops.len() - 1].color
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stops() -> [RampStop; 3] {
        [
            RampStop {
                position: 0.2,
                color: Vec3::new(1.0, 0.0, 0.0),
            },
            RampStop {
                position: 0.5,
                color: Vec3::new(0.0, 1.0, 0.0),
            },
            RampStop {
                position: 0.9,
                color: Vec3::new(0.0, 0.0, 1.0),
            },
        ]
    }

    #[test]
    fn endpoints_hold_outside_the_stops() {
        let s = stops();
        assert_eq!(ramp(&s, -3.0), s[0].color);
        assert_eq!(ramp(&s, 0.2), s[0].color);
        assert_eq!(ramp(&s, 0.9), s[2].color);
        assert_eq!(ramp(&s, 7.0), s[2].color);
        assert_eq!(ramp(&s, f32::NAN), s[0].color);
        assert_eq!(ramp(&[], 0.5), Vec3::ZERO);
    }

    #[test]
    fn interpolates_linearly_between_neighbours() {
        let s = stops();
        assert!((ramp(&s, 0.35) - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
        assert!((ramp(&s, 0.8) - Vec3::new(0.0, 0.25, 0.75)).length() < 1e-6);
    }
}
