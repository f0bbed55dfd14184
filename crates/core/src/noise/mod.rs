//! CPU reference of every noise function the shaders evaluate.
//!
//! The WGSL beside each module (`hash.wgsl`, `gradient.wgsl`, `perlin.wgsl`,
//! `fractal.wgsl`) mirrors these functions operation for operation, so that
//! the parity tests (GPU against CPU) and the `marbre noise --cpu` command
//! can check the shader against a trusted implementation. The CPU side is
//! the reference: when the two disagree, the shader is wrong.

pub mod evolution;
pub mod fractal;
pub mod gradient;
pub mod hash;
pub mod perlin;
pub mod points;
pub mod rebase;

pub use evolution::Evolution;
pub use fractal::{
    FractalParams, FractalShape, NoiseSettings, Progression, dropped_octaves_mean, fbm,
    footprint_octaves, fractal_sum, marble, mean_abs_noise, noise, noise4, noise4_f64, ridged,
    turbulence, warped,
};
pub use gradient::{gradient_noise, gradient_noise4};
pub use hash::HashKind;
pub use perlin::{improved_noise, improved_noise_f32};

use serde::{Deserialize, Serialize};

/// Which lattice noise a fractal sum is built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum NoiseKind {
    /// The lab's gradient noise: hashed corner gradients in [-1, 1]³ and a
    /// cubic (smoothstep) interpolation.
    #[default]
    Gradient,
    /// Ken Perlin's improved noise (2002): permutation table, 12 edge
    /// gradients and a quintic fade. Its hash is the permutation table, so it
    /// ignores [`HashKind`].
    Perlin,
    /// Perlin's improved noise with the gradient table of Massal's
    /// tutorial (his `grad()`, which differs at h = 13 and 14); ignores
    /// [`HashKind`] too.
    PerlinMassal,
}

impl NoiseKind {
    pub const ALL: [NoiseKind; 3] = [
        NoiseKind::Gradient,
        NoiseKind::Perlin,
        NoiseKind::PerlinMassal,
    ];

    pub fn label(self) -> &'static str {
        match self {
            NoiseKind::Gradient => "gradient (lab)",
            NoiseKind::Perlin => "Perlin improved",
            NoiseKind::PerlinMassal => "Perlin, Massal's grad",
        }
    }
}
