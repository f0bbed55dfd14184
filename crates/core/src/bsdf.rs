//! CPU twin of `crates/core/src/bsdf.wgsl`: Lambert plus GGX (Smith, separable)
//! with an optional perfect mirror and a diffuse transmission lobe (N3D's
//! TD: Lambert on the other side of the surface), its value and sampling density
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
    /// Sample the diffuse lobe uniformly over the hemisphere (pdf 1 / 2π)
    /// instead of by cosine (`Strategy::Hemisphere`); the value is the same.
    pub uniform_diffuse: bool,
    /// The diffuse transmission TD: f = TD/π between directions on
    /// opposite sides of the surface.
    pub diffuse_transmission: Vec3,
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
#[inline]
pub fn ggx_d(cos2: f32, sin2: f32, a: f32) -> f32 {
    let a2 = a * a;
    let k = sin2 + cos2 * a2;
    a2 / (PI * k * k)
}

/// Smith's masking G1 for GGX at cos θ = `n_v`.
#[inline]
pub fn smith_g1(n_v: f32, a: f32) -> f32 {
    let a2 = a * a;
    2.0 * n_v / (n_v + (a2 + (1.0 - a2) * n_v * n_v).sqrt())
}

/// The chances of sampling each continuous lobe, by albedo: (GGX,
/// transmission); the diffuse lobe takes the rest. A black surface splits
/// evenly between GGX and diffuse, as before transmission existed, so an
/// opaque surface keeps its samples.
#[inline]
pub fn lobe_probabilities(s: &Surface) -> (f32, f32) {
    let d = luminance(s.diffuse);
    let g = luminance(s.specular);
    let t = luminance(s.diffuse_transmission);
    let sum = d + g + t;
    if sum <= 0.0 {
        return (0.5, 0.0);
    }
    (g / sum, t / sum)
}

/// The density of the uniform hemisphere: 1 / 2π per steradian.
pub const UNIFORM_HEMISPHERE_PDF: f32 = 0.5 * FRAC_1_PI;

/// The diffuse lobe's sampling density at cos θi = `n_i` > 0: by cosine,
/// or uniform over the hemisphere.
#[inline]
pub fn diffuse_pdf(n_i: f32, uniform: bool) -> f32 {
    if uniform {
        UNIFORM_HEMISPHERE_PDF
    } else {
        n_i * FRAC_1_PI
    }
}

/// `eval_bsdf`'s result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfEval {
    /// f(wo, wi)·cos θi for the non-mirror part.
    pub f_cos: Vec3,
    /// The sampling pdf of wi (solid angle), lobe mixture.
    pub pdf: f32,
}

/// The value and the sampling pdf of the continuous lobes. `n` faces `wo`;
/// `wi` on its side meets the reflecting lobes, `wi` across it the
/// transmission lobe alone.
#[inline]
pub fn eval_bsdf(s: &Surface, n: Vec3, wo: Vec3, wi: Vec3) -> BsdfEval {
    let n_i = n.dot(wi);
    let n_o = n.dot(wo);
    if n_i == 0.0 || n_o <= 0.0 {
        return BsdfEval {
            f_cos: Vec3::ZERO,
            pdf: 0.0,
        };
    }
    let (ps, pt) = lobe_probabilities(s);
    if n_i < 0.0 {
        return BsdfEval {
            f_cos: s.diffuse_transmission * FRAC_1_PI * -n_i,
            pdf: pt * diffuse_pdf(-n_i, s.uniform_diffuse),
        };
    }
    if s.specular == Vec3::ZERO && ps == 0.0 {
        // No GGX lobe (a black specular on a surface that is not black
        // all over, which samples GGX half the time): its value and
        // density are exact zeros, so leaving them out changes no bit,
        // and skips the costliest part of a diffuse surface's evaluation
        // (the CPU kernel's hottest BSDF call).
        return BsdfEval {
            f_cos: s.diffuse * FRAC_1_PI * n_i,
            pdf: (1.0 - pt) * diffuse_pdf(n_i, s.uniform_diffuse),
        };
    }
    let h = (wi + wo).normalize();
    let n_h = n.dot(h).max(0.0);
    let d = ggx_d(n_h * n_h, n.cross(h).length_squared(), s.alpha);
    let spec = s.specular * d * smith_g1(n_i, s.alpha) * smith_g1(n_o, s.alpha) / (4.0 * n_o);
    let pdf = (1.0 - ps - pt) * diffuse_pdf(n_i, s.uniform_diffuse)
        + ps * d * n_h / (4.0 * wo.dot(h).max(1e-8));
    BsdfEval {
        f_cos: s.diffuse * FRAC_1_PI * n_i + spec,
        pdf,
    }
}

/// An orthonormal basis around `n` (Duff et al. 2017), columns t, b, n.
#[inline]
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
/// draws in this order: mirror or not, cos θ, φ, which lobe (GGX below its
/// chance, then transmission, then diffuse).
#[inline]
pub fn sample_bsdf(s: &Surface, n: Vec3, wo: Vec3, u: [f32; 4]) -> BsdfSample {
    let mirror = u[0] < s.mirror;
    let (u1, u2) = (u[1], u[2]);
    let (ps, pt) = lobe_probabilities(s);
    let specular = u[3] < ps;
    // The transmission lobe is the diffuse one mirrored through the plane.
    let transmit = !specular && u[3] < ps + pt;
    // GGX's cos²θ = (1 − u) / (1 + (α² − 1) u) and sin²θ = α² u / (same),
    // the denominator summed as (1 − u) + α² u: both numerators then add
    // up to it and h stays unit length (1 + (α² − 1) u cancels for u near
    // 1). sin θ in closed form, not sqrt(1 − cos²θ), which loses its
    // digits where cos θ is near 1 (a narrow lobe).
    let a2 = s.alpha * s.alpha;
    let ggx = (1.0 - u1) + a2 * u1;
    // The uniform hemisphere's cos θ = 1 − u, sin²θ = u (2 − u).
    let (cos_t, sin_t) = if specular {
        (((1.0 - u1) / ggx).sqrt(), (a2 * u1 / ggx).sqrt())
    } else if s.uniform_diffuse {
        (1.0 - u1, (u1 * (2.0 - u1)).max(0.0).sqrt())
    } else {
        ((1.0 - u1).max(0.0).sqrt(), u1.sqrt())
    };
    let phi = 2.0 * PI * u2;
    let side = if transmit { -1.0 } else { 1.0 };
    let local = basis(n) * Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), side * cos_t);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn lambert(albedo: f32, uniform_diffuse: bool) -> Surface {
        Surface {
            diffuse: Vec3::splat(albedo),
            specular: Vec3::ZERO,
            alpha: 1.0,
            mirror: 0.0,
            uniform_diffuse,
            diffuse_transmission: Vec3::ZERO,
        }
    }

    /// Stratified uniform numbers: an n × n grid of cells, jittered by a
    /// fixed LCG, for (cos θ, φ); the lobe and mirror numbers at 0.5.
    fn stratified(n: u32) -> impl Iterator<Item = [f32; 4]> {
        let mut state = 12345u32;
        let mut next = move || {
            state = state.wrapping_mul(1664525).wrapping_add(1013904223);
            (state >> 8) as f32 / 16777216.0
        };
        (0..n * n).map(move |k| {
            let (i, j) = (k % n, k / n);
            [
                0.5,
                (i as f32 + next()) / n as f32,
                (j as f32 + next()) / n as f32,
                0.5,
            ]
        })
    }

    /// The uniform hemisphere's pdf is 1 / 2π over the whole hemisphere:
    /// its integral (midpoint rule in cos θ and φ, where dω = d(cos θ) dφ)
    /// is 1, and the cosine lobe's too.
    #[test]
    fn the_uniform_hemisphere_pdf_integrates_to_one() {
        let n = Vec3::new(0.3, 0.9, 0.2).normalize();
        let frame = basis(n);
        let wo = n;
        for uniform in [true, false] {
            let s = lambert(0.5, uniform);
            let steps = 200;
            let mut total = 0.0f64;
            for i in 0..steps {
                let cos_t = (i as f32 + 0.5) / steps as f32;
                let sin_t = (1.0 - cos_t * cos_t).sqrt();
                for j in 0..steps {
                    let phi = 2.0 * PI * (j as f32 + 0.5) / steps as f32;
                    let wi = frame * Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
                    let cell = (1.0 / steps as f64) * (2.0 * std::f64::consts::PI / steps as f64);
                    total += f64::from(eval_bsdf(&s, n, wo, wi).pdf) * cell;
                }
            }
            assert!(
                (total - 1.0).abs() < 1e-4,
                "uniform {uniform}: ∫ pdf = {total}"
            );
        }
    }

    /// Each uniform sample has pdf 1 / 2π, cos θ uniform in [0, 1] (mean
    /// 1/2, not the cosine lobe's 2/3) and weight f cos / pdf = 2ρ cos θ.
    #[test]
    fn uniform_samples_have_the_hemisphere_density_and_weight() {
        let n = Vec3::Y;
        let s = lambert(0.6, true);
        let mut mean_cos = 0.0f64;
        let count = 64 * 64;
        for u in stratified(64) {
            let b = sample_bsdf(&s, n, n, u);
            let cos_t = b.wi.dot(n);
            assert!(b.valid && cos_t >= 0.0);
            assert!(
                (b.pdf - UNIFORM_HEMISPHERE_PDF).abs() < 1e-7,
                "pdf {}",
                b.pdf
            );
            assert!((b.weight.x - 1.2 * cos_t).abs() < 1e-5, "{b:?}");
            mean_cos += f64::from(cos_t) / f64::from(count);
        }
        assert!((mean_cos - 0.5).abs() < 1e-3, "mean cos θ {mean_cos}");
    }

    /// The lab's Q4 in closed form: estimating a Lambert surface's
    /// reflectance ∫ f cos dω = ρ under uniform light, cosine sampling's
    /// weight is ρ exactly (no variance), the uniform hemisphere's 2ρ cos θ,
    /// of mean ρ and variance ρ² (4 E[cos²θ] − 1) = ρ²/3.
    #[test]
    fn uniform_sampling_has_the_closed_form_variance_on_lambert() {
        let rho = 0.6f64;
        let n = Vec3::Y;
        let moments = |uniform: bool| {
            let s = lambert(rho as f32, uniform);
            let weights: Vec<f64> = stratified(64)
                .map(|u| f64::from(sample_bsdf(&s, n, n, u).weight.x))
                .collect();
            let mean = weights.iter().sum::<f64>() / weights.len() as f64;
            let var =
                weights.iter().map(|w| (w - mean).powi(2)).sum::<f64>() / weights.len() as f64;
            (mean, var)
        };
        let (cos_mean, cos_var) = moments(false);
        let (uni_mean, uni_var) = moments(true);
        assert!(
            (cos_mean - rho).abs() < 1e-5 && cos_var < 1e-10,
            "{cos_mean} {cos_var}"
        );
        assert!((uni_mean - rho).abs() < 1e-3, "uniform mean {uni_mean}");
        let expected = rho * rho / 3.0;
        assert!(
            (uni_var - expected).abs() < 0.01 * expected,
            "variance {uni_var}, expected {expected}"
        );
    }

    /// A surface of Lambert `diffuse`, diffuse transmission `td` and no
    /// specular (whose albedo has no closed form).
    fn translucent(diffuse: Vec3, td: Vec3) -> Surface {
        Surface {
            diffuse,
            specular: Vec3::ZERO,
            alpha: Surface::alpha_for(0.5),
            mirror: 0.0,
            diffuse_transmission: td,
            uniform_diffuse: false,
        }
    }

    /// The sphere of directions in `n × n` cells equal in solid angle
    /// (uniform in cos θ about +z and in φ): each cell's centre and its
    /// solid angle.
    fn sphere_cells(n: usize) -> impl Iterator<Item = (Vec3, f32)> {
        let d_omega = 4.0 * PI / (n * n) as f32;
        (0..n * n).map(move |k| {
            let cos_t = -1.0 + 2.0 * ((k / n) as f32 + 0.5) / n as f32;
            let phi = 2.0 * PI * ((k % n) as f32 + 0.5) / n as f32;
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            (
                Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t),
                d_omega,
            )
        })
    }

    /// Over the whole sphere, f·|cos| integrates to diffuse + TD (the
    /// reflected and the transmitted albedo) and the sampling pdf to 1,
    /// at normal and oblique incidence; the transmitted half alone to TD.
    #[test]
    fn diffuse_and_transmission_integrate_to_their_albedos() {
        let s = translucent(Vec3::new(0.2, 0.3, 0.1), Vec3::new(0.5, 0.1, 0.4));
        for wo in [Vec3::Z, Vec3::new(0.8, 0.0, 0.6)] {
            let (mut albedo, mut through, mut pdf) = (Vec3::ZERO, Vec3::ZERO, 0.0);
            for (wi, d_omega) in sphere_cells(400) {
                let e = eval_bsdf(&s, Vec3::Z, wo, wi);
                albedo += e.f_cos * d_omega;
                if wi.z < 0.0 {
                    through += e.f_cos * d_omega;
                }
                pdf += e.pdf * d_omega;
            }
            let expected = s.diffuse + s.diffuse_transmission;
            assert!(
                (albedo - expected).abs().max_element() < 1e-4,
                "{albedo} vs {expected}"
            );
            assert!(
                (through - s.diffuse_transmission).abs().max_element() < 1e-4,
                "{through}"
            );
            assert!((pdf - 1.0).abs() < 1e-4, "∫ pdf = {pdf}");
        }
    }

    /// Sampling: the transmission lobe is chosen with the chance of its
    /// share of the albedo and its directions lie across the surface; with
    /// grey lobes chosen by albedo every sample weighs exactly diffuse +
    /// TD, and each sample's pdf is the one `eval_bsdf` gives it.
    #[test]
    fn sampling_picks_the_transmission_lobe_by_its_albedo() {
        let s = translucent(Vec3::splat(0.2), Vec3::splat(0.6));
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let mut state = 0x853c_49e6_748f_ea9b_u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let n = 200_000;
        let mut across = 0usize;
        for _ in 0..n {
            let b = sample_bsdf(
                &s,
                Vec3::Z,
                wo,
                [uniform(), uniform(), uniform(), uniform()],
            );
            if !b.valid {
                continue;
            }
            let e = eval_bsdf(&s, Vec3::Z, wo, b.wi);
            assert!((b.pdf - e.pdf).abs() <= 1e-5 * e.pdf, "{b:?} vs {e:?}");
            across += usize::from(b.wi.z < 0.0);
            assert!(
                (b.weight - Vec3::splat(0.8)).abs().max_element() < 1e-5,
                "{b:?}"
            );
        }
        let share = across as f64 / n as f64;
        assert!(
            (share - 0.75).abs() < 0.005,
            "transmitted share {share}, expected 0.75"
        );
    }

    /// Without TD nothing crosses: a direction across the surface has no
    /// value and no density, so opaque surfaces are unchanged.
    #[test]
    fn without_transmission_nothing_crosses() {
        let s = translucent(Vec3::splat(0.8), Vec3::ZERO);
        let e = eval_bsdf(&s, Vec3::Z, Vec3::Z, Vec3::new(0.0, 0.6, -0.8));
        assert_eq!((e.f_cos, e.pdf), (Vec3::ZERO, 0.0));
        assert_eq!(lobe_probabilities(&s), (0.0, 0.0));
    }
}
