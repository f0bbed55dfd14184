//! CPU twin of `crates/core/src/bsdf.wgsl`: Lambert plus GGX (Smith, separable)
//! with an optional perfect mirror, its value and sampling density
//! together, and its sampling from four uniform numbers. Written line for
//! line after the shader so the chi² and property tests can check the
//! sampler against its pdf on the CPU, and the GPU against the CPU.

use crate::texture::luminance;
use glam::{Mat3, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/bsdf.wgsl");

/// The material at a shading point, as `SurfacePoint` holds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    pub diffuse: Vec3,
    pub specular: Vec3,
    /// GGX α = roughness², kept above 1e-3 (see [`Surface::alpha_for`]).
    pub alpha: f32,
    pub mirror: f32,
}

impl Surface {
    /// The GGX α of a roughness, as `surface_at` derives it: clamped to
    /// [0, 1], squared, and kept above 1e-3 so D stays finite.
    pub fn alpha_for(roughness: f32) -> f32 {
        let r = roughness.clamp(0.0, 1.0);
        (r * r).max(1e-3)
    }
}

/// The GGX normal distribution D(h) from cos²θh and sin²θh given apart:
/// the textbook denominator cos²θh (α² − 1) + 1 is 1 − cos²θh + α² cos²θh,
/// and near the peak cos θh rounds to 1 in steps of 6e-8, so 1 − cos²θh
/// keeps few digits where a lobe of roughness 0.05 has sin²θh ~ 1e-5 (the
/// chi² test rejected that D against its own samples).
pub fn ggx_d(cos2: f32, sin2: f32, a: f32) -> f32 {
    let a2 = a * a;
    let k = sin2 + cos2 * a2;
    a2 / (PI * k * k)
}

/// Smith's masking G1 for GGX at cos θ = `n_v`.
pub fn smith_g1(n_v: f32, a: f32) -> f32 {
    let a2 = a * a;
    2.0 * n_v / (n_v + (a2 + (1.0 - a2) * n_v * n_v).sqrt())
}

/// The chance of sampling the GGX lobe rather than the diffuse one.
pub fn specular_probability(s: &Surface) -> f32 {
    let d = luminance(s.diffuse);
    let g = luminance(s.specular);
    if d + g <= 0.0 {
        return 0.5;
    }
    g / (d + g)
}

/// `eval_bsdf`'s result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfEval {
    /// f(wo, wi)·cos θi for the non-mirror part.
    pub f_cos: Vec3,
    /// The sampling pdf of wi (solid angle), lobe mixture.
    pub pdf: f32,
}

/// The value and the sampling pdf of the continuous lobes.
pub fn eval_bsdf(s: &Surface, n: Vec3, wo: Vec3, wi: Vec3) -> BsdfEval {
    let n_i = n.dot(wi);
    let n_o = n.dot(wo);
    if n_i <= 0.0 || n_o <= 0.0 {
        return BsdfEval {
            f_cos: Vec3::ZERO,
            pdf: 0.0,
        };
    }
    let h = (wi + wo).normalize();
    let n_h = n.dot(h).max(0.0);
    let d = ggx_d(n_h * n_h, n.cross(h).length_squared(), s.alpha);
    let spec = s.specular * d * smith_g1(n_i, s.alpha) * smith_g1(n_o, s.alpha) / (4.0 * n_o);
    let ps = specular_probability(s);
    let pdf = (1.0 - ps) * n_i * FRAC_1_PI + ps * d * n_h / (4.0 * wo.dot(h).max(1e-8));
    BsdfEval {
        f_cos: s.diffuse * FRAC_1_PI * n_i + spec,
        pdf,
    }
}

/// An orthonormal basis around `n` (Duff et al. 2017), columns t, b, n.
pub fn basis(n: Vec3) -> Mat3 {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
    Mat3::from_cols(t, bt, n)
}

/// WGSL's `reflect(e1, e2)`: e1 − 2 (e2·e1) e2.
fn reflect(e1: Vec3, e2: Vec3) -> Vec3 {
    e1 - 2.0 * e2.dot(e1) * e2
}

/// `sample_bsdf`'s result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    pub wi: Vec3,
    /// f·cos / pdf, or the mirror's 1.
    pub weight: Vec3,
    pub valid: bool,
    /// (1 − mirror)·pdf of wi under the continuous lobes; 0 for the mirror.
    pub pdf: f32,
}

/// A direction drawn from the BSDF with the four uniform numbers the shader
/// draws in this order: mirror or not, cos θ, φ, which lobe.
pub fn sample_bsdf(s: &Surface, n: Vec3, wo: Vec3, u: [f32; 4]) -> BsdfSample {
    let mirror = u[0] < s.mirror;
    let (u1, u2) = (u[1], u[2]);
    let specular = u[3] < specular_probability(s);
    // GGX's cos²θ = (1 − u) / (1 + (α² − 1) u) and sin²θ = α² u / (same),
    // the denominator summed as (1 − u) + α² u: both numerators then add
    // up to it and h stays unit length (1 + (α² − 1) u cancels for u near
    // 1). sin θ in closed form, not sqrt(1 − cos²θ), which loses its
    // digits where cos θ is near 1 (a narrow lobe).
    let a2 = s.alpha * s.alpha;
    let ggx = (1.0 - u1) + a2 * u1;
    let (cos_t, sin_t) = if specular {
        (((1.0 - u1) / ggx).sqrt(), (a2 * u1 / ggx).sqrt())
    } else {
        ((1.0 - u1).max(0.0).sqrt(), u1.sqrt())
    };
    let phi = 2.0 * PI * u2;
    let local = basis(n) * Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
    let wi = if specular { reflect(-wo, local) } else { local };
    let e = eval_bsdf(s, n, wo, wi);
    BsdfSample {
        wi: if mirror { reflect(-wo, n) } else { wi },
        weight: if mirror { Vec3::ONE } else { e.f_cos / e.pdf },
        valid: mirror || e.pdf > 0.0,
        pdf: if mirror {
            0.0
        } else {
            (1.0 - s.mirror) * e.pdf
        },
    }
}
