// Combining two estimators of the same light (light sampling and BSDF
// sampling) by multiple importance sampling (Veach 1997). `frame.strategy`
// (Rust: scene::Strategy) picks one estimator alone or a heuristic; each
// weight pair sums to one wherever both estimators can produce a sample,
// so every setting is unbiased.

#import shaders/common.wgsl

const STRATEGY_LIGHT: u32 = 0u;
const STRATEGY_BSDF: u32 = 1u;
const STRATEGY_MIS_BALANCE: u32 = 2u;
// BSDF sampling alone, its diffuse lobe uniform over the hemisphere
// (bsdf.wgsl's uniform_diffuse).
const STRATEGY_HEMISPHERE: u32 = 4u;

// Whether direction sampling alone finds the light (Rust:
// Strategy::directions_only).
fn directions_only(strategy: u32) -> bool {
    return strategy == STRATEGY_BSDF || strategy == STRATEGY_HEMISPHERE;
}

// The weight of a sample drawn with density `a` against the other
// strategy's density `b` for the same direction, under the chosen
// heuristic; twin of mis.rs. Finite and in [0, 1] for any densities,
// and a pair sums to 1 wherever either is positive. An infinite density
// (above F32_MAX: a delta, or one that overflowed) takes all the weight,
// half each if both are. Otherwise both are divided by the larger first,
// so neither a + b nor a square overflows (pbrt's guard) and tiny
// densities keep their ratio.
fn mis_heuristic(a: f32, b: f32) -> f32 {
    let a_infinite = a > F32_MAX;
    let b_infinite = b > F32_MAX;
    if a_infinite || b_infinite {
        return select(select(0.0, 1.0, a_infinite), 0.5, a_infinite && b_infinite);
    }
    let m = max(a, b);
    if m <= 0.0 {
        return 0.0;
    }
    let sa = a / m;
    let sb = b / m;
    if frame.strategy == STRATEGY_MIS_BALANCE {
        return sa / (sa + sb);
    }
    return sa * sa / (sa * sa + sb * sb);
}

// The weight of a light sample of density `light_pdf` whose direction the
// BSDF samples with density `bsdf_pdf`.
fn light_sample_weight(light_pdf: f32, bsdf_pdf: f32) -> f32 {
    if frame.strategy == STRATEGY_LIGHT {
        return 1.0;
    }
    if directions_only(frame.strategy) {
        return 0.0;
    }
    return mis_heuristic(light_pdf, bsdf_pdf);
}

// The weight of light reached by a BSDF sample of density `bsdf_pdf`, which
// light sampling finds with density `light_pdf` (0 where it cannot: such
// light is always BSDF sampling's alone).
fn bsdf_sample_weight(bsdf_pdf: f32, light_pdf: f32) -> f32 {
    if light_pdf <= 0.0 || directions_only(frame.strategy) {
        return 1.0;
    }
    if frame.strategy == STRATEGY_LIGHT {
        return 0.0;
    }
    return mis_heuristic(bsdf_pdf, light_pdf);
}
