//! The lab's gradient noise: hashed corner gradients, dot products with the
//! offset to each corner, and trilinear interpolation by the smoothstep
//! `u = f²(3 − 2f)`.

use super::hash::{HashKind, gradient_pcg, gradient_pcg_tiled, gradient_sin};
use super::perlin::Real;
use glam::{DVec3, IVec3, Vec3};

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/noise/gradient.wgsl");

/// A provable bound on |gradient_noise|: each corner value is
/// |g|·|f − c| ≤ √3·√3 = 3, and the interpolation is a convex combination.
/// The values actually observed stay far inside it (see the tests).
pub const GRADIENT_NOISE_BOUND: f32 = 3.0;

fn corner_gradient(cell: IVec3, hash: HashKind) -> Vec3 {
    match hash {
        HashKind::Pcg => gradient_pcg(cell),
        HashKind::PcgTiled => gradient_pcg_tiled(cell),
        HashKind::Sin => gradient_sin(cell.as_vec3()),
    }
}

/// Gradient noise at `p`; zero at every lattice point. The f32 evaluation
/// the shader performs.
pub fn gradient_noise(p: Vec3, hash: HashKind) -> f32 {
    gradient_noise_generic(p.to_array(), hash)
}

/// Gradient noise in double precision: the CPU reference (`marbre noise
/// --cpu`). The corner gradients are the same (they depend on the integer
/// cell only); the offsets, dot products and interpolation keep f64's
/// digits far from the origin.
pub fn gradient_noise_f64(p: DVec3, hash: HashKind) -> f64 {
    gradient_noise_generic(p.to_array(), hash)
}

/// Gradient noise in the precision `T`, operation for operation as
/// `gradient.wgsl`.
fn gradient_noise_generic<T: Real>(p: [T; 3], hash: HashKind) -> T {
    let i = p.map(Real::floor);
    let f = [p[0] - i[0], p[1] - i[1], p[2] - i[2]];
    let cell = IVec3::from_array(i.map(Real::to_i32));
    let (three, two) = (T::from_f64(3.0), T::from_f64(2.0));
    let u = f.map(|f| f * f * (three - two * f));
    let corner = |dx: i32, dy: i32, dz: i32| {
        let c = IVec3::new(dx, dy, dz);
        // Wrapping, as WGSL's i32 addition: beyond 2³¹ the cell saturates
        // (f32 → i32 `as`, like the shader's conversion) and its +1
        // neighbour must not overflow.
        let g = corner_gradient(cell.wrapping_add(c), hash).to_array();
        let g = g.map(|v| T::from_f64(f64::from(v)));
        let d = [dx, dy, dz].map(T::from_i32);
        g[0] * (f[0] - d[0]) + g[1] * (f[1] - d[1]) + g[2] * (f[2] - d[2])
    };
    let lerp = |a: T, b: T, t: T| a + (b - a) * t;
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u[0]);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u[0]);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u[0]);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u[0]);
    let y0 = lerp(x00, x10, u[1]);
    let y1 = lerp(x01, x11, u[1]);
    lerp(y0, y1, u[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_points(n: usize, scale: f32) -> impl Iterator<Item = Vec3> {
        // A low-discrepancy (R3) sequence: deterministic and well spread.
        let a = Vec3::new(0.819_172_5, 0.671_043_5, 0.549_700_5);
        (0..n).map(move |k| {
            let v = a * k as f32;
            (v - v.floor() - 0.5) * 2.0 * scale
        })
    }

    #[test]
    fn zero_at_every_lattice_point() {
        for hash in HashKind::ALL {
            for x in -4..4 {
                for y in -4..4 {
                    for z in -4..4 {
                        let p = Vec3::new(x as f32, y as f32, z as f32);
                        assert_eq!(gradient_noise(p, hash), 0.0, "{p} {hash:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn continuous_across_cell_faces() {
        // Points 1e-6 either side of a face differ by at most the gradient
        // bound times the distance (≤ 3·2e-6·few); a discontinuity would show
        // a jump of order 0.1.
        for hash in HashKind::ALL {
            for p in sample_points(2000, 8.0) {
                for axis in 0..3 {
                    let mut lo = p;
                    let mut hi = p;
                    let face = p[axis].round();
                    lo[axis] = face - 1e-6 * face.abs().max(1.0);
                    hi[axis] = face + 1e-6 * face.abs().max(1.0);
                    let jump = (gradient_noise(lo, hash) - gradient_noise(hi, hash)).abs();
                    assert!(jump < 1e-4, "jump {jump} at {p} axis {axis} {hash:?}");
                }
            }
        }
    }

    #[test]
    fn range_over_a_million_samples() {
        for hash in HashKind::ALL {
            let (mut lo, mut hi) = (f32::MAX, f32::MIN);
            for p in sample_points(1_000_000, 50.0) {
                let v = gradient_noise(p, hash);
                lo = lo.min(v);
                hi = hi.max(v);
            }
            assert!(lo >= -GRADIENT_NOISE_BOUND && hi <= GRADIENT_NOISE_BOUND);
            // Not degenerate: it uses a good part of its range, both signs.
            assert!(lo < -0.5 && hi > 0.5, "{hash:?}: [{lo}, {hi}]");
        }
    }
}
