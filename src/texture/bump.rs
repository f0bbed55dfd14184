//! Bump mapping: a height field's gradient over the surface's (u, v) tilts
//! the shading normal.

use glam::Vec3;

/// The normal of the surface displaced by a small height `h(u, v)` along
/// `n` (Blinn 1978), given ∂h/∂u, ∂h/∂v and the tangents ∂p/∂u, ∂p/∂v of an
/// orthogonal frame: `normalize(n − (∂h/∂u)·∂p/∂u/|∂p/∂u|² −
/// (∂h/∂v)·∂p/∂v/|∂p/∂v|²)`. A zero-length or non-finite result falls back
/// to `n`, so a degenerate frame or gradient never makes a NaN normal.
pub fn bumped_normal(n: Vec3, dp_du: Vec3, dp_dv: Vec3, dh_du: f32, dh_dv: f32) -> Vec3 {
    let along = |dp: Vec3, dh: f32| {
        let len2 = dp.length_squared();
        if len2 > 0.0 {
            dp * (dh / len2)
        } else {
            Vec3::ZERO
        }
    };
    let tilted = n - along(dp_du, dh_du) - along(dp_dv, dh_dv);
    let len = tilted.length();
    if len > 0.0 && len.is_finite() {
        tilted / len
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_height_leaves_the_normal_unchanged() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        let got = bumped_normal(n, Vec3::X, Vec3::new(0.0, 0.8, -0.6), 0.0, 0.0);
        assert!((got - n).length() < 1e-7);
    }

    /// A slope s along u on a flat patch tilts the normal to (−s, 0, 1)/|·|,
    /// the normal of the plane z = s·x.
    #[test]
    fn a_slope_tilts_the_normal_like_the_displaced_plane() {
        let s = 0.5;
        let got = bumped_normal(Vec3::Z, Vec3::X, Vec3::Y, s, 0.0);
        let expected = Vec3::new(-s, 0.0, 1.0).normalize();
        assert!((got - expected).length() < 1e-6, "{got}");
        // Longer tangents (a bigger object for the same uv) tilt it less.
        let bigger = bumped_normal(Vec3::Z, 2.0 * Vec3::X, Vec3::Y, s, 0.0);
        assert!(bigger.z > got.z);
    }

    #[test]
    fn degenerate_frames_and_gradients_never_give_nan() {
        let n = Vec3::Y;
        for (du, dv, hu, hv) in [
            (Vec3::ZERO, Vec3::ZERO, 1.0, 1.0),
            (Vec3::X, Vec3::Z, f32::INFINITY, 0.0),
            (Vec3::X, Vec3::Z, f32::NAN, 0.0),
            (Vec3::Y, Vec3::ZERO, 1.0, 0.0),
            (Vec3::new(1e-30, 0.0, 0.0), Vec3::Z, 1.0, 0.0),
        ] {
            let got = bumped_normal(n, du, dv, hu, hv);
            assert!(got.is_finite(), "{du} {dv} {hu} {hv}: {got}");
            assert!((got.length() - 1.0).abs() < 1e-5);
        }
    }
}
