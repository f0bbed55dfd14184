//! The per-sample random numbers of `shaders/random.wgsl`, bit for bit: a
//! PCG state seeded by pcg3d of (pixel, sample), then PCG-RXS-M-XS steps.
//! Drawing the same numbers in the same order as the shader is what lets
//! the CPU kernel trace the GPU kernels' paths (the parity tests compare
//! images pixel by pixel, not only in the mean).

use glam::UVec3;
use marbre_core::noise::hash::pcg3d;

pub struct Rng(u32);

impl Rng {
    /// `rng_seed(pixel, sample_index)`.
    pub fn seeded(pixel: (u32, u32), sample_index: u32) -> Self {
        Self(pcg3d(UVec3::new(pixel.0, pixel.1, sample_index)).x)
    }

    /// `rand()`: a number in [0, 1) with 24 random bits.
    pub fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let s = self.0;
        let mut w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
        w ^= w >> 22;
        (w >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}
