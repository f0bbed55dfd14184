// Combining two estimators of the same light (light sampling and BSDF
// sampling) by multiple importance sampling (Veach 1997). `frame.strategy`
// (Rust: scene::Strategy) picks one estimator alone or a heuristic; each
// weight pair sums to one wherever both estimators can produce a sample,
// so every setting is unbiased.

const STRATEGY_LIGHT: u32 = 0u;
const STRATEGY_BSDF: u32 = 1u;
const STRATEGY_MIS_BALANCE: u32 = 2u;

// The weight of a sample drawn with density `a` against the other
// strategy's density `b` for the same direction, under the chosen
// heuristic. Guarded as pbrt's power heuristic is: an infinite density (a
// delta) takes all the weight, and none is NaN when both are 0.
fn mis_heuristic(a: f32, b: f32) -> f32 {
    if a >= 3.0e38 {
        return 1.0;
    }
    if frame.strategy == STRATEGY_MIS_BALANCE {
        return select(0.0, a / (a + b), a + b > 0.0);
    }
    // Squares of densities above ~1e19 overflow: scale both first.
    let m = max(a, b);
    let sa = select(0.0, a / m, m > 0.0);
    let sb = select(0.0, b / m, m > 0.0);
    return select(0.0, sa * sa / (sa * sa + sb * sb), m > 0.0);
}

// The weight of a light sample of density `light_pdf` whose direction the
// BSDF samples with density `bsdf_pdf`.
fn light_sample_weight(light_pdf: f32, bsdf_pdf: f32) -> f32 {
    if frame.strategy == STRATEGY_LIGHT {
        return 1.0;
    }
    if frame.strategy == STRATEGY_BSDF {
        return 0.0;
    }
    return mis_heuristic(light_pdf, bsdf_pdf);
}

// The weight of light reached by a BSDF sample of density `bsdf_pdf`, which
// light sampling finds with density `light_pdf` (0 where it cannot: such
// light is always BSDF sampling's alone).
fn bsdf_sample_weight(bsdf_pdf: f32, light_pdf: f32) -> f32 {
    if light_pdf <= 0.0 || frame.strategy == STRATEGY_BSDF {
        return 1.0;
    }
    if frame.strategy == STRATEGY_LIGHT {
        return 0.0;
    }
    return mis_heuristic(bsdf_pdf, light_pdf);
}
