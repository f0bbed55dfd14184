//! The lab's gradient noise: hashed corner gradients, dot products with the
//! offset to each corner, and trilinear interpolation by the smoothstep
//! `u = f²(3 − 2f)`.

use super::hash::{
    HashKind, gradient_pcg, gradient_pcg_tiled, gradient_sin, gradient4_pcg, gradient4_pcg_tiled,
    gradient4_sin, wrap_w,
};
use super::perlin::Real;
use glam::{DVec3, IVec3, IVec4, Vec3};

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

fn corner_gradient4(cell: IVec4, hash: HashKind) -> [f32; 4] {
    match hash {
        HashKind::Pcg => gradient4_pcg(cell),
        HashKind::PcgTiled => gradient4_pcg_tiled(cell),
        HashKind::Sin => gradient4_sin(cell.as_vec4()),
    }
    .to_array()
}

/// A provable bound on the 4D gradient noise: |g|·|f − c| ≤ 2·2.
pub const GRADIENT_NOISE4_BOUND: f32 = 4.0;

/// The 4D gradient noise (evolving noise, issue 29): corner gradients in
/// [-1, 1]⁴ from pcg4d (or the 4D sin hash), the same smoothstep fade, the
/// interpolation along x, y, z, then w. With `w_period` P the lattice's w
/// wraps modulo P cells before hashing, so the noise at w + P is the
/// noise at w. In f32, as the shader.
pub fn gradient_noise4(p: Vec3, w: f32, hash: HashKind, w_period: Option<u32>) -> f32 {
    gradient_noise4_generic([p.x, p.y, p.z, w], hash, w_period)
}

/// [`gradient_noise4`] in f64: the reference.
pub fn gradient_noise4_f64(p: DVec3, w: f64, hash: HashKind, w_period: Option<u32>) -> f64 {
    gradient_noise4_generic([p.x, p.y, p.z, w], hash, w_period)
}

/// 4D gradient noise in the precision `T`, operation for operation as
/// `gradient_noise4` in `gradient.wgsl`.
fn gradient_noise4_generic<T: Real>(p: [T; 4], hash: HashKind, w_period: Option<u32>) -> T {
    let i = p.map(Real::floor);
    let f = [p[0] - i[0], p[1] - i[1], p[2] - i[2], p[3] - i[3]];
    let cell = IVec4::from_array(i.map(Real::to_i32));
    let (three, two) = (T::from_f64(3.0), T::from_f64(2.0));
    let u = f.map(|f| f * f * (three - two * f));
    let corner = |dx: i32, dy: i32, dz: i32, dw: i32| {
        let c = cell.wrapping_add(IVec4::new(dx, dy, dz, dw));
        let c = IVec4::new(c.x, c.y, c.z, wrap_w(c.w, w_period));
        let g = corner_gradient4(c, hash).map(|v| T::from_f64(f64::from(v)));
        let d = [dx, dy, dz, dw].map(T::from_i32);
        g[0] * (f[0] - d[0]) + g[1] * (f[1] - d[1]) + g[2] * (f[2] - d[2]) + g[3] * (f[3] - d[3])
    };
    let lerp = |a: T, b: T, t: T| a + (b - a) * t;
    // The 3D interpolation of the cube at w offset `dw`.
    let cube = |dw: i32| {
        let x00 = lerp(corner(0, 0, 0, dw), corner(1, 0, 0, dw), u[0]);
        let x10 = lerp(corner(0, 1, 0, dw), corner(1, 1, 0, dw), u[0]);
        let x01 = lerp(corner(0, 0, 1, dw), corner(1, 0, 1, dw), u[0]);
        let x11 = lerp(corner(0, 1, 1, dw), corner(1, 1, 1, dw), u[0]);
        let y0 = lerp(x00, x10, u[1]);
        let y1 = lerp(x01, x11, u[1]);
        lerp(y0, y1, u[2])
    };
    lerp(cube(0), cube(1), u[3])
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

    /// The 4D noise against an independent formulation in f64: the sum over
    /// the 16 corners of the hypercube, each corner's dot product weighted
    /// by the product of its fade weights (`Π (u or 1 − u)`), rather than
    /// nested interpolations; and the corner hash composed by hand from the
    /// published pcg4d. Equal to rounding.
    #[test]
    fn noise4_matches_the_corner_sum_formulation() {
        use crate::noise::hash::pcg4d;
        use glam::UVec4;
        let reference = |p: [f64; 4], period: Option<u32>| {
            let cell = p.map(f64::floor);
            let f: Vec<f64> = (0..4).map(|a| p[a] - cell[a]).collect();
            let u: Vec<f64> = f.iter().map(|f| f * f * (3.0 - 2.0 * f)).collect();
            let mut sum = 0.0;
            for corner in 0..16u32 {
                let d: Vec<i64> = (0..4).map(|a| i64::from((corner >> a) & 1)).collect();
                let mut c: Vec<i64> = (0..4).map(|a| cell[a] as i64 + d[a]).collect();
                if let Some(period) = period {
                    c[3] = c[3].rem_euclid(i64::from(period));
                }
                let h = pcg4d(UVec4::new(
                    c[0] as u32,
                    c[1] as u32,
                    c[2] as u32,
                    c[3] as u32,
                ));
                let g = [h.x, h.y, h.z, h.w].map(|h| f64::from(h >> 8) / 8_388_608.0 - 1.0);
                let dot: f64 = (0..4).map(|a| g[a] * (f[a] - d[a] as f64)).sum();
                let weight: f64 = (0..4)
                    .map(|a| if d[a] == 1 { u[a] } else { 1.0 - u[a] })
                    .product();
                sum += weight * dot;
            }
            sum
        };
        let mut spread = (f64::MAX, f64::MIN);
        for (k, p) in sample_points(3000, 40.0).enumerate() {
            let w = f64::from(p.x * 0.7 - p.z * 0.3) + k as f64 * 0.013;
            let p = p.as_dvec3();
            for period in [None, Some(3)] {
                let got = gradient_noise4_f64(p, w, HashKind::Pcg, period);
                let want = reference([p.x, p.y, p.z, w], period);
                assert!((got - want).abs() < 1e-12, "{p} {w}: {got} vs {want}");
                spread = (spread.0.min(got), spread.1.max(got));
            }
        }
        assert!(spread.0 < -0.4 && spread.1 > 0.4, "{spread:?}");
    }

    /// With a period P in w, the noise at w + P is the noise at w, to the
    /// bit (w and w + P exact in f32: multiples of 1/64); without one it
    /// differs.
    #[test]
    fn noise4_is_periodic_in_w_given_a_period() {
        for hash in HashKind::ALL {
            for (k, p) in sample_points(2000, 20.0).enumerate() {
                let w = (k % 640) as f32 / 64.0 - 5.0;
                for period in [1u32, 2, 5] {
                    let at = gradient_noise4(p, w, hash, Some(period));
                    let next = gradient_noise4(p, w + period as f32, hash, Some(period));
                    assert_eq!(at, next, "{p} w {w} P {period} {hash:?}");
                    let twice = gradient_noise4(p, w - 2.0 * period as f32, hash, Some(period));
                    assert_eq!(at, twice, "{p} w {w} P {period} {hash:?}");
                }
            }
        }
        let p = Vec3::new(0.3, 0.6, 0.9);
        let differ = (0..64)
            .filter(|&k| {
                let w = k as f32 / 8.0 + 0.25;
                gradient_noise4(p, w, HashKind::Pcg, None)
                    != gradient_noise4(p, w + 3.0, HashKind::Pcg, None)
            })
            .count();
        assert!(differ > 60, "{differ}");
    }

    /// Continuous across the lattice's w planes, including the planes where
    /// a period wraps; zero at every 4D lattice point; within its bound.
    #[test]
    fn noise4_is_continuous_in_w_zero_on_the_lattice_and_bounded() {
        for hash in HashKind::ALL {
            for period in [None, Some(2)] {
                for p in sample_points(2000, 8.0) {
                    for plane in [-2.0f32, 0.0, 1.0, 2.0, 3.0] {
                        let lo = gradient_noise4(p, plane - 1e-5, hash, period);
                        let hi = gradient_noise4(p, plane + 1e-5, hash, period);
                        assert!((lo - hi).abs() < 1e-3, "{p} w {plane}: {lo} {hi}");
                    }
                    let v = gradient_noise4(p, p.x * 0.37, hash, period);
                    assert!(v.abs() <= GRADIENT_NOISE4_BOUND);
                    let lattice = p.floor();
                    assert_eq!(gradient_noise4(lattice, 3.0, hash, period), 0.0);
                }
            }
        }
    }

    /// The f32 twin stays close to the f64 reference.
    #[test]
    fn noise4_f32_is_close_to_the_reference() {
        for (k, p) in sample_points(5000, 30.0).enumerate() {
            let w = k as f32 * 0.017 - 40.0;
            let r = gradient_noise4_f64(p.as_dvec3(), f64::from(w), HashKind::Pcg, Some(7));
            let s = gradient_noise4(p, w, HashKind::Pcg, Some(7));
            assert!((r - f64::from(s)).abs() < 1e-5, "{p} {w}: {r} {s}");
        }
    }
}
