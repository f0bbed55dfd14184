//! Ray–sphere distance, the twin of `sphere_distance` in `sphere.wgsl`
//! beside this file.

use glam::Vec3;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/geometry/sphere.wgsl");

/// `NO_HIT` in the shaders: the distance of a miss.
pub const NO_HIT: f32 = 3.0e38;

/// The smallest positive root of |o + t d − c| = r for a unit `d`, or
/// [`NO_HIT`]. Haines et al., "Precision Improvements for Ray/Sphere
/// Intersection" (Ray Tracing Gems ch. 7): the discriminant r² − |f⊥|² is
/// taken from the perpendicular part of f = o − c, which a sphere small
/// and far away keeps to full precision where b² − |f|² + r² cancels, and
/// the roots come from the stable quadratic q = b ± √disc, t = c/q and q,
/// where b ∓ √disc would cancel for the near root.
#[inline]
pub fn sphere_distance(o: Vec3, d: Vec3, center: Vec3, radius: f32) -> f32 {
    let f = o - center;
    let b = -f.dot(d);
    let perp = f + b * d;
    let r2 = radius * radius;
    let disc = r2 - perp.dot(perp);
    if disc < 0.0 {
        return NO_HIT;
    }
    let q = b + if b >= 0.0 { 1.0 } else { -1.0 } * disc.sqrt();
    if q == 0.0 {
        return NO_HIT;
    }
    let c = f.dot(f) - r2;
    let t0 = c / q;
    let t1 = q;
    let near = t0.min(t1);
    let far = t0.max(t1);
    if near > 0.0 {
        return near;
    }
    if far > 0.0 {
        return far;
    }
    NO_HIT
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_through_the_centre_meets_the_near_side_then_from_inside_the_far_one() {
        let c = Vec3::new(0.0, 0.0, 5.0);
        assert_eq!(sphere_distance(Vec3::ZERO, Vec3::Z, c, 1.0), 4.0);
        assert_eq!(sphere_distance(c, Vec3::Z, c, 1.0), 1.0);
        assert_eq!(sphere_distance(Vec3::ZERO, -Vec3::Z, c, 1.0), NO_HIT);
        assert_eq!(sphere_distance(Vec3::ZERO, Vec3::X, c, 1.0), NO_HIT);
    }
}
