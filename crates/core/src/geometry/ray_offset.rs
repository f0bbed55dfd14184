//! The robust ray offset, the twin of `offset_ray` in `ray_offset.wgsl`
//! beside this file.

use glam::Vec3;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile =
    crate::wgsl_file!("crates/core/src/geometry/ray_offset.wgsl");

/// Below this magnitude a coordinate moves by a fixed [`FLOAT_SCALE`]
/// (integer steps of its bits would be too small near zero).
pub const ORIGIN: f32 = 1.0 / 32.0;
/// The fixed step near the origin, times the normal.
pub const FLOAT_SCALE: f32 = 1.0 / 65536.0;
/// Elsewhere the step in units in the last place, times the normal.
pub const INT_SCALE: f32 = 256.0;

/// A new ray's origin off the surface at `p` on the side `n` points to:
/// Wächter & Binder, "A Fast and Robust Method for Avoiding
/// Self-Intersection" (Ray Tracing Gems ch. 6). Each coordinate moves by
/// `INT_SCALE · n` units in its last place, so the step grows with the
/// coordinate's magnitude, as the error of a computed hit point does: one
/// offset serves every scene scale where a fixed ε is either lost in the
/// rounding of large coordinates (acne) or visible at small ones
/// (peter-panning).
#[inline]
pub fn offset_ray(p: Vec3, n: Vec3) -> Vec3 {
    // `as i32` truncates and saturates like WGSL's f32 → i32 conversion,
    // and the bits add with wrapping like WGSL's i32.
    let of_i = (INT_SCALE * n).to_array().map(|x| x as i32);
    let axis = |p: f32, n: f32, of: i32| {
        let step = if p < 0.0 { -of } else { of };
        let p_i = f32::from_bits((p.to_bits() as i32).wrapping_add(step) as u32);
        if p.abs() < ORIGIN {
            p + FLOAT_SCALE * n
        } else {
            p_i
        }
    };
    Vec3::new(
        axis(p.x, n.x, of_i[0]),
        axis(p.y, n.y, of_i[1]),
        axis(p.z, n.z, of_i[2]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_coordinates_move_by_ulps_small_ones_by_the_fixed_step() {
        let moved = offset_ray(Vec3::new(1000.0, -1000.0, 0.0), Vec3::new(1.0, 1.0, 1.0));
        let ulp = |x: f32| f32::from_bits(x.abs().to_bits() + 1) - x.abs();
        assert_eq!(moved.x, 1000.0 + 256.0 * ulp(1000.0));
        assert_eq!(moved.y, -1000.0 + 256.0 * ulp(1000.0));
        assert_eq!(moved.z, FLOAT_SCALE);
    }
}
