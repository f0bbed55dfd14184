//! Texture coordinates of a surface point: 2D (u, v) from the primitive, or
//! a 3D texture point through a transform.
//!
//! Conventions, in this y-up world: a sphere or cylinder's u runs around +y,
//! like the environment's lat-long map (`envmap::direction_to_uv`); a plane
//! or polygon's (u, v) are its coordinates on two axes that span one unit
//! texture square, oblique axes included (the texture report's ATX).

use crate::envmap::direction_to_uv;
use glam::{Affine3A, EulerRot, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::f32::consts::PI;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/texture/mapping.wgsl");

/// (u, v) of the point at `offset` from a sphere's centre: longitude around
/// +y and latitude from the south pole, each in [0, 1]. Finite everywhere,
/// the poles and the centre included (there u = 0.5).
pub fn sphere_uv(offset: Vec3) -> Vec2 {
    direction_to_uv(offset.normalize_or(Vec3::NEG_Y))
}

/// (u, v) on a cylinder around +y whose base is at `offset.y = 0`: u around
/// the axis (as on a sphere), v the height in units of `height`.
pub fn cylinder_uv(offset: Vec3, height: f32) -> Vec2 {
    let u = if offset.x == 0.0 && offset.z == 0.0 {
        0.5
    } else {
        (offset.x.atan2(offset.z) + PI) / (2.0 * PI)
    };
    Vec2::new(u, offset.y / height)
}

/// The coordinates (u, v) of `p` in the frame `origin + u·u_axis +
/// v·v_axis`, the axes possibly oblique; a point off the plane projects along
/// its normal. Degenerate (parallel or zero) axes give (0, 0).
pub fn plane_uv(p: Vec3, origin: Vec3, u_axis: Vec3, v_axis: Vec3) -> Vec2 {
    // Normal equations of the least-squares fit: [U·U U·V; U·V V·V] (u, v) =
    // (U·d, V·d), solved by Cramer's rule.
    let d = p - origin;
    let (uu, uv, vv) = (u_axis.dot(u_axis), u_axis.dot(v_axis), v_axis.dot(v_axis));
    let det = uu * vv - uv * uv;
    // Also catches NaN axes, for which every comparison is false.
    if det.is_nan() || det <= 1e-12 * uu * vv {
        return Vec2::ZERO;
    }
    let (du, dv) = (u_axis.dot(d), v_axis.dot(d));
    Vec2::new((du * vv - dv * uv) / det, (dv * uu - du * uv) / det)
}

/// The report's default frame of a polygon: the first vertex as origin, the
/// first edge as u, and the last edge made orthogonal to it (keeping its
/// length) as v. None for fewer than three vertices or a degenerate start.
pub fn polygon_frame(vertices: &[Vec3]) -> Option<(Vec3, Vec3, Vec3)> {
    let [first, second, .., last] = vertices else {
        return None;
    };
    let u = *second - *first;
    let v = *last - *first;
    let along = v.dot(u) / u.length_squared();
    let orthogonal = v - along * u;
    if !along.is_finite() || orthogonal.length_squared() == 0.0 {
        return None;
    }
    Some((*first, u, orthogonal * (v.length() / orthogonal.length())))
}

/// (u, v) inside a triangle with vertex texture coordinates: its barycentric
/// coordinates (the oblique frame of its two edges) weight the vertices' uv.
pub fn triangle_uv(p: Vec3, vertices: [Vec3; 3], uvs: [Vec2; 3]) -> Vec2 {
    let b = plane_uv(
        p,
        vertices[0],
        vertices[1] - vertices[0],
        vertices[2] - vertices[0],
    );
    uvs[0] * (1.0 - b.x - b.y) + uvs[1] * b.x + uvs[2] * b.y
}

/// Where a 3D texture sits in object (or world) space: scaled, then rotated
/// (x, then y, then z, in degrees), then moved. The texture point of a
/// surface point is its image under the inverse.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TextureTransform {
    pub translate: Vec3,
    pub rotate_degrees: Vec3,
    pub scale: Vec3,
}

impl Default for TextureTransform {
    fn default() -> Self {
        Self {
            translate: Vec3::ZERO,
            rotate_degrees: Vec3::ZERO,
            scale: Vec3::ONE,
        }
    }
}

impl TextureTransform {
    /// The affine map from surface points to texture points. A zero scale
    /// is kept off the inverse (it would be infinite) by a floor of 1e-6.
    pub fn to_texture(&self) -> Affine3A {
        let r = self.rotate_degrees;
        let rotation = Quat::from_euler(
            EulerRot::ZYX,
            r.z.to_radians(),
            r.y.to_radians(),
            r.x.to_radians(),
        );
        let scale = self.scale.signum() * self.scale.abs().max(Vec3::splat(1e-6));
        Affine3A::from_scale_rotation_translation(scale, rotation, self.translate).inverse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_uv_is_finite_at_the_poles_and_centre() {
        for d in [
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::ZERO,
            Vec3::new(1e-30, 1.0, 0.0),
            Vec3::new(0.0, -5.0, -1e-38),
        ] {
            let uv = sphere_uv(d);
            assert!(uv.is_finite(), "{d}: {uv}");
            assert!(
                (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
                "{d}: {uv}"
            );
        }
        assert_eq!(sphere_uv(Vec3::Y).y, 1.0);
        assert_eq!(sphere_uv(Vec3::NEG_Y).y, 0.0);
    }

    /// Across the seam (towards -z) u wraps from 1 to 0: a texture periodic in
    /// u sees neighbouring points, not a jump.
    #[test]
    fn cylinder_seam_is_continuous_modulo_one() {
        let e = 1e-4;
        for y in [0.0_f32, 0.3, 1.0] {
            let left = cylinder_uv(Vec3::new(-e, y, -1.0), 2.0);
            let right = cylinder_uv(Vec3::new(e, y, -1.0), 2.0);
            let gap = (left.x - right.x).abs();
            assert!(gap.min(1.0 - gap) < 1e-4, "{left} {right}");
            assert_eq!(left.y, y / 2.0);
        }
        // A quarter turn is a quarter of u.
        let a = cylinder_uv(Vec3::new(0.0, 0.0, 1.0), 1.0);
        let b = cylinder_uv(Vec3::new(1.0, 0.0, 0.0), 1.0);
        assert!((b.x - a.x - 0.25).abs() < 1e-6);
    }

    #[test]
    fn plane_uv_equals_the_coordinates_on_the_given_axes() {
        let origin = Vec3::new(1.0, 2.0, -3.0);
        // Oblique, like the report's ATX example U = (1,0,0), V = (1,0,1).
        for (u_axis, v_axis) in [
            (Vec3::X, Vec3::Z),
            (Vec3::X, Vec3::new(1.0, 0.0, 1.0)),
            (Vec3::new(0.3, 0.0, -0.2), Vec3::new(0.0, 2.0, 0.5)),
        ] {
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.25, 0.75), (-3.5, 2.0)] {
                let p = origin + a * u_axis + b * v_axis;
                let uv = plane_uv(p, origin, u_axis, v_axis);
                assert!(
                    (uv - Vec2::new(a, b)).length() < 1e-4,
                    "{u_axis} {v_axis}: {uv}"
                );
                // Off the plane, along its normal: the same (u, v).
                let n = u_axis.cross(v_axis).normalize();
                assert!((plane_uv(p + 0.7 * n, origin, u_axis, v_axis) - uv).length() < 1e-4);
            }
        }
        assert_eq!(
            plane_uv(Vec3::ONE, Vec3::ZERO, Vec3::X, Vec3::X),
            Vec2::ZERO
        );
    }

    #[test]
    fn polygon_frame_orthogonalises_the_last_edge() {
        let quad = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
        ];
        let (o, u, v) = polygon_frame(&quad).unwrap();
        assert_eq!(o, Vec3::ZERO);
        assert_eq!(u, Vec3::new(2.0, 0.0, 0.0));
        assert!(u.dot(v).abs() < 1e-6);
        assert!((v.length() - 2.0_f32.sqrt()).abs() < 1e-6);
        assert!(polygon_frame(&quad[..2]).is_none());
        assert!(polygon_frame(&[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]).is_none());
    }

    #[test]
    fn triangle_uv_interpolates_the_vertices() {
        let v = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let uvs = [
            Vec2::new(0.1, 0.1),
            Vec2::new(0.9, 0.1),
            Vec2::new(0.5, 0.9),
        ];
        for (i, &vertex) in v.iter().enumerate() {
            assert!((triangle_uv(vertex, v, uvs) - uvs[i]).length() < 1e-6);
        }
        let centroid = (v[0] + v[1] + v[2]) / 3.0;
        let expected = (uvs[0] + uvs[1] + uvs[2]) / 3.0;
        assert!((triangle_uv(centroid, v, uvs) - expected).length() < 1e-6);
    }

    #[test]
    fn transform_maps_the_texture_frame_back_to_the_unit_frame() {
        let t = TextureTransform {
            translate: Vec3::new(1.0, 2.0, 3.0),
            rotate_degrees: Vec3::new(0.0, 90.0, 0.0),
            scale: Vec3::splat(2.0),
        };
        let m = t.to_texture();
        // The texture's origin sits at `translate`.
        assert!(m.transform_point3(Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        // Its x axis, scaled by 2 and turned 90° about y, points to -z.
        let x = m.transform_point3(Vec3::new(1.0, 2.0, 1.0));
        assert!((x - Vec3::X).length() < 1e-5, "{x}");
        let flat = TextureTransform {
            scale: Vec3::ZERO,
            ..Default::default()
        };
        assert!(flat.to_texture().matrix3.is_finite());
    }
}
