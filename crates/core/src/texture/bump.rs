//! Bump mapping: a height field's gradient over the surface's (u, v) tilts
//! the shading normal, which is then kept facing the viewer.

use glam::Vec3;

/// The shader code of [`facing_shading_normal`].
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/texture/bump.wgsl");

/// The normal of the surface displaced by a small height `h(u, v)` along
/// `n` (Blinn 1978), given ∂h/∂u, ∂h/∂v and the tangents ∂p/∂u, ∂p/∂v of an
/// orthogonal frame: `normalize(n − (∂h/∂u)·∂p/∂u/|∂p/∂u|² −
/// (∂h/∂v)·∂p/∂v/|∂p/∂v|²)`. A vanished or non-finite result falls back to
/// `n`, so a degenerate frame or gradient never makes a NaN normal, nor one
/// pointing wherever rounding left it (see [`MIN_TILTED_LENGTH`]).
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
    if len >= MIN_TILTED_LENGTH && len.is_finite() {
        tilted / len
    } else {
        n
    }
}

/// The shortest tilted normal [`bumped_normal`] normalises (of a unit `n`).
/// The tilt lies in the tangent plane, so with a proper frame the tilted
/// normal is at least 1 long; a shorter one means the tangents had a part
/// along `n` that cancelled it (a degenerate frame), and its direction is
/// rounding noise: with a tangent equal to `n` and a slope of 1, 24 % of
/// 10,000 random unit normals left a non-zero vector (at most 1.5e-7 long),
/// 19 % of them pointing along −n, below the surface. 1e-3 keeps every
/// proper result and rejects those.
pub const MIN_TILTED_LENGTH: f32 = 1e-3;

/// The least cosine between the shading normal and the viewer that
/// [`facing_shading_normal`] asks for (`FACING_MIN_COS` in
/// `crates/core/src/texture/bump.wgsl`): 0.57° above the view's horizon, or less
/// where the geometric normal itself faces the viewer less.
pub const FACING_MIN_COS: f32 = 0.01;

/// The shading normal the BSDF may use, given the bumped normal `n_s`, the
/// geometric normal `n_g` (facing the viewer) and the direction `wo` to the
/// viewer, all unit length; the twin of `facing_shading_normal` in
/// `crates/core/src/texture/bump.wgsl`.
///
/// A bump can tilt `n_s` away from the viewer: every BSDF value is then 0
/// (a black pixel on a lit surface), and one that barely faces it divides
/// by n·wo ≈ 0. So a normal with n_s·wo below c_min = min(FACING_MIN_COS,
/// n_g·wo) is bent towards the viewer, `normalize(n_s + (c_min −
/// n_s·wo)·wo)`, the least change (within the plane of n_s and wo) that
/// leaves it facing the viewer; its cosine with wo is then c_min / √(1 +
/// c_min² − (n_s·wo)²). Asking no more than the geometric normal gives
/// leaves an unbumped normal seen at a grazing angle as it is. pbrt-v4 and
/// Mitsuba likewise keep shading normals on the viewer's side of the
/// geometric one. Where even the bent normal is unusable (a non-finite
/// input), `n_g` serves.
pub fn facing_shading_normal(n_s: Vec3, n_g: Vec3, wo: Vec3) -> Vec3 {
    let c = n_s.dot(wo);
    let c_min = FACING_MIN_COS.min(n_g.dot(wo));
    if c >= c_min {
        return n_s;
    }
    let bent = n_s + (c_min - c) * wo;
    let len = bent.length();
    if len > 0.0 && len.is_finite() {
        bent / len
    } else {
        n_g
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

    /// Unit vectors spread over the sphere (a Fibonacci lattice).
    fn directions(n: usize) -> impl Iterator<Item = Vec3> {
        (0..n).map(move |k| {
            let z = 1.0 - (2 * k + 1) as f32 / n as f32;
            let phi = k as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize()
        })
    }

    /// A tangent along the normal with a slope of 1 cancels the normal to
    /// a rounding residue, whose direction is noise: the normal stays.
    #[test]
    fn a_tilt_that_cancels_the_normal_falls_back_to_it() {
        for n in directions(10_000) {
            assert_eq!(bumped_normal(n, n, n.any_orthonormal_vector(), 1.0, 0.0), n);
        }
    }

    /// A normal that faces the viewer by c_min = min(FACING_MIN_COS,
    /// n_g·wo) is kept; one that does not is bent within the plane of it
    /// and the viewer to face it by c_min / √(1 + c_min² − c²), c its old
    /// cosine. The geometric normal itself is always kept.
    #[test]
    fn normals_facing_away_are_bent_just_above_the_view() {
        let n_g = Vec3::Z;
        for wo in directions(200).filter(|w| w.z > 0.0) {
            assert_eq!(facing_shading_normal(n_g, n_g, wo), n_g);
            let c_min = FACING_MIN_COS.min(wo.z);
            for n_s in directions(200).filter(|n| n.z > 0.0) {
                let got = facing_shading_normal(n_s, n_g, wo);
                let c = n_s.dot(wo);
                if c >= c_min {
                    assert_eq!(got, n_s);
                    continue;
                }
                let expected = c_min / (1.0 + c_min * c_min - c * c).sqrt();
                assert!((got.dot(wo) - expected).abs() < 1e-5, "{n_s} {wo}: {got}");
                assert!((got.length() - 1.0).abs() < 1e-5);
                assert!(got.cross(n_s).dot(wo).abs() < 1e-5, "left the plane");
                assert!(got.dot(n_g) > 0.0);
            }
        }
        assert_eq!(facing_shading_normal(Vec3::NAN, n_g, Vec3::Y), n_g);
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
