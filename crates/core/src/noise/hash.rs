//! Lattice hashes that turn an integer cell into a pseudo-random gradient.

use glam::{IVec3, IVec4, UVec3, UVec4, Vec3, Vec4};
use serde::{Deserialize, Serialize};

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/noise/hash.wgsl");

/// How the lab's gradient noise picks a gradient for a lattice corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum HashKind {
    /// pcg3d (Jarzynski & Olano, 2020): integer arithmetic only, so the CPU and
    /// every GPU agree bit for bit at any distance from the origin.
    #[default]
    Pcg,
    /// pcg3d of the cell modulo 256 in each axis: the lattice repeats every
    /// 256 cells, as Perlin's does, so a far-off texture offset can be moved
    /// back near the origin by whole periods without changing the noise
    /// (`noise::rebase`), keeping f32's precision. Near the origin it is the
    /// same noise as `Pcg` in the cells 0..256.
    PcgTiled,
    /// The lab's `fract(sin(dot(p, k)) * 43758.5453)`. Kept for fidelity with
    /// the course material. It depends on the accuracy of `sin`, which WGSL only
    /// bounds on [-π, π], and the 43758 factor amplifies every error, so GPUs
    /// disagree with the CPU (and with each other) once `dot(p, k)` is large.
    Sin,
}

impl HashKind {
    pub const ALL: [HashKind; 3] = [HashKind::Pcg, HashKind::PcgTiled, HashKind::Sin];

    pub fn label(self) -> &'static str {
        match self {
            HashKind::Pcg => "pcg3d (integer)",
            HashKind::PcgTiled => "pcg3d tiled (256 cells)",
            HashKind::Sin => "fract(sin) (lab)",
        }
    }
}

/// The pcg3d hash: three rounds of an LCG and cross-multiplication.
#[inline]
pub fn pcg3d(v: UVec3) -> UVec3 {
    let mut v = v
        .wrapping_mul(UVec3::splat(1_664_525))
        .wrapping_add(UVec3::splat(1_013_904_223));
    v.x = v.x.wrapping_add(v.y.wrapping_mul(v.z));
    v.y = v.y.wrapping_add(v.z.wrapping_mul(v.x));
    v.z = v.z.wrapping_add(v.x.wrapping_mul(v.y));
    v ^= v >> 16;
    v.x = v.x.wrapping_add(v.y.wrapping_mul(v.z));
    v.y = v.y.wrapping_add(v.z.wrapping_mul(v.x));
    v.z = v.z.wrapping_add(v.x.wrapping_mul(v.y));
    v
}

/// Maps the top 24 bits of a hash to [-1, 1). 24 bits fit an f32 mantissa
/// exactly, so the GPU computes the same value to the last bit.
fn unit_signed(h: u32) -> f32 {
    (h >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0
}

/// Gradient of the integer cell `cell` through pcg3d, each component in [-1, 1).
pub fn gradient_pcg(cell: IVec3) -> Vec3 {
    let h = pcg3d(cell.as_uvec3());
    Vec3::new(unit_signed(h.x), unit_signed(h.y), unit_signed(h.z))
}

/// Gradient of the cell modulo 256 (`cell & 255` is the non-negative
/// remainder in two's complement, as in the shader).
pub fn gradient_pcg_tiled(cell: IVec3) -> Vec3 {
    gradient_pcg(cell & IVec3::splat(LATTICE_PERIOD - 1))
}

/// The pcg4d hash (Jarzynski & Olano, 2020), pcg3d's 4D form: the evolving
/// noise's corners (x, y, z, w).
pub fn pcg4d(v: UVec4) -> UVec4 {
    let mut v = v
        .wrapping_mul(UVec4::splat(1_664_525))
        .wrapping_add(UVec4::splat(1_013_904_223));
    v.x = v.x.wrapping_add(v.y.wrapping_mul(v.w));
    v.y = v.y.wrapping_add(v.z.wrapping_mul(v.x));
    v.z = v.z.wrapping_add(v.x.wrapping_mul(v.y));
    v.w = v.w.wrapping_add(v.y.wrapping_mul(v.z));
    v ^= v >> 16;
    v.x = v.x.wrapping_add(v.y.wrapping_mul(v.w));
    v.y = v.y.wrapping_add(v.z.wrapping_mul(v.x));
    v.z = v.z.wrapping_add(v.x.wrapping_mul(v.y));
    v.w = v.w.wrapping_add(v.y.wrapping_mul(v.z));
    v
}

/// 4D gradient of the cell through pcg4d, each component in [-1, 1).
pub fn gradient4_pcg(cell: IVec4) -> Vec4 {
    let h = pcg4d(cell.as_uvec4());
    Vec4::new(
        unit_signed(h.x),
        unit_signed(h.y),
        unit_signed(h.z),
        unit_signed(h.w),
    )
}

/// 4D gradient of the cell modulo 256 in every axis.
pub fn gradient4_pcg_tiled(cell: IVec4) -> Vec4 {
    gradient4_pcg(cell & IVec4::splat(LATTICE_PERIOD - 1))
}

/// The lab's sin hash in 4D: its three rows extended by a w column, and a
/// fourth row, constants of the same kind (chosen here; the lab has no 4D
/// form).
pub fn gradient4_sin(cell: Vec4) -> Vec4 {
    let p = Vec4::new(
        cell.dot(Vec4::new(127.1, 311.7, 74.7, 201.3)),
        cell.dot(Vec4::new(269.5, 183.3, 246.1, 97.9)),
        cell.dot(Vec4::new(113.5, 271.9, 124.6, 157.1)),
        cell.dot(Vec4::new(191.3, 61.7, 233.9, 151.3)),
    );
    let s = Vec4::new(p.x.sin(), p.y.sin(), p.z.sin(), p.w.sin()) * 43_758.547;
    (s - s.floor()) * 2.0 - Vec4::ONE
}

/// The lattice w-coordinate of an evolving noise's corner: wrapped modulo
/// `period` cells when looping (so the noise at w and w + period is the
/// same), else unchanged.
pub fn wrap_w(cell_w: i32, period: Option<u32>) -> i32 {
    match period {
        Some(p) if p > 0 => cell_w.rem_euclid(p.min(i32::MAX as u32) as i32),
        _ => cell_w,
    }
}

/// The period, in cells, of the tiled hash and of Perlin's permutation.
pub const LATTICE_PERIOD: i32 = 256;

/// The lab's hash, in f32 as a shader computes it.
pub fn gradient_sin(cell: Vec3) -> Vec3 {
    let p = Vec3::new(
        cell.dot(Vec3::new(127.1, 311.7, 74.7)),
        cell.dot(Vec3::new(269.5, 183.3, 246.1)),
        cell.dot(Vec3::new(113.5, 271.9, 124.6)),
    );
    let s = Vec3::new(p.x.sin(), p.y.sin(), p.z.sin()) * 43_758.547;
    (s - s.floor()) * 2.0 - Vec3::ONE
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg3d_matches_published_algorithm_on_zero() {
        // Hand evaluation of the published pcg3d on (0, 0, 0):
        // v = (c, c, c) with c = 1013904223, then the cross steps in u32.
        let c: u32 = 1_013_904_223;
        let mut v = [c, c, c];
        v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[2]));
        v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
        v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
        for x in &mut v {
            *x ^= *x >> 16;
        }
        v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[2]));
        v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
        v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
        assert_eq!(pcg3d(UVec3::ZERO), UVec3::from_array(v));
    }

    #[test]
    fn pcg4d_matches_published_algorithm_on_one_cell() {
        // The published pcg4d on (1, 2, 3, 4), step by step in u32.
        let mut v = [1u32, 2, 3, 4].map(|c| c.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
        let round = |v: &mut [u32; 4]| {
            v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[3]));
            v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
            v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
            v[3] = v[3].wrapping_add(v[1].wrapping_mul(v[2]));
        };
        round(&mut v);
        for x in &mut v {
            *x ^= *x >> 16;
        }
        round(&mut v);
        assert_eq!(pcg4d(UVec4::new(1, 2, 3, 4)), UVec4::from_array(v));
    }

    #[test]
    fn wrap_w_is_the_non_negative_remainder() {
        assert_eq!(wrap_w(-1, Some(3)), 2);
        assert_eq!(wrap_w(7, Some(3)), 1);
        assert_eq!(wrap_w(-7, None), -7);
        assert_eq!(wrap_w(5, Some(0)), 5);
    }

    #[test]
    fn gradients_stay_in_the_unit_cube_and_are_not_constant() {
        let mut sum = Vec3::ZERO;
        let mut n = 0.0;
        for x in -20..20 {
            for y in -20..20 {
                for z in -5..5 {
                    let g = gradient_pcg(IVec3::new(x, y, z));
                    assert!(g.abs().max_element() <= 1.0);
                    sum += g;
                    n += 1.0;
                }
            }
        }
        // Mean of a uniform on [-1, 1] is 0, with standard error 0.577/sqrt(n).
        let mean = sum / n;
        assert!(
            mean.abs().max_element() < 4.0 * 0.577 / f32::sqrt(n),
            "{mean}"
        );
    }
}
