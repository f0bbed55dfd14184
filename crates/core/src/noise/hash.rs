//! Lattice hashes that turn an integer cell into a pseudo-random gradient.

use glam::{IVec3, UVec3, Vec3};
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
