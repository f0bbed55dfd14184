//! CPU twin of `crates/core/src/mis.wgsl`: the weights that combine light sampling
//! and BSDF sampling of the same light (Veach 1997), guarded so that every
//! weight is finite and in [0, 1], and a pair sums to 1 wherever either
//! density is positive, whatever the densities: 0, subnormal, huge or
//! infinite (a delta, or a density that overflowed: a sphere light's
//! 1 / (2π (1 − cos θmax)) for a radius under ~3e-20 of its distance).

use crate::scene::Strategy;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/mis.wgsl");

/// The weight of a sample drawn with density `a` against the other
/// strategy's density `b` for the same direction. An infinite density
/// takes all the weight (half each if both are); otherwise both densities
/// are divided by the larger first, so neither `a + b` nor a square can
/// overflow (pbrt's guard) and tiny densities keep their ratio.
#[inline]
pub fn mis_heuristic(a: f32, b: f32, strategy: Strategy) -> f32 {
    let a_infinite = a > f32::MAX;
    let b_infinite = b > f32::MAX;
    if a_infinite || b_infinite {
        return match (a_infinite, b_infinite) {
            (true, true) => 0.5,
            (true, false) => 1.0,
            _ => 0.0,
        };
    }
    let m = a.max(b);
    if m <= 0.0 {
        return 0.0;
    }
    let (sa, sb) = (a / m, b / m);
    if strategy == Strategy::MisBalance {
        sa / (sa + sb)
    } else {
        sa * sa / (sa * sa + sb * sb)
    }
}

/// The weight of a light sample of density `light_pdf` whose direction the
/// BSDF samples with density `bsdf_pdf`.
#[inline]
pub fn light_sample_weight(light_pdf: f32, bsdf_pdf: f32, strategy: Strategy) -> f32 {
    match strategy {
        Strategy::Light => 1.0,
        Strategy::Bsdf | Strategy::Hemisphere => 0.0,
        _ => mis_heuristic(light_pdf, bsdf_pdf, strategy),
    }
}

/// The weight of light reached by a BSDF sample of density `bsdf_pdf`,
/// which light sampling finds with density `light_pdf` (0 where it cannot:
/// such light is always BSDF sampling's alone).
#[inline]
pub fn bsdf_sample_weight(bsdf_pdf: f32, light_pdf: f32, strategy: Strategy) -> f32 {
    if light_pdf <= 0.0 || strategy.directions_only() {
        return 1.0;
    }
    if strategy == Strategy::Light {
        return 0.0;
    }
    mis_heuristic(bsdf_pdf, light_pdf, strategy)
}
