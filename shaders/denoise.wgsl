// The denoiser: `cs_denoise_input` turns the accumulation into the filter's
// input, then each `cs_denoise` runs one iteration of the edge-avoiding à-trous wavelet filter (Dammertz,
// Sewtz, Hanika and Lensch 2010) with SVGF's luminance weight (Schied et al.
// 2017): a 5 x 5 B3-spline kernel whose taps lie `step` pixels apart
// (1, 2, 4, 8, 16 over five iterations), each tap weighed down where its
// albedo or shading normal differ from the centre's (Dammertz's
// exp(-|Δ|² / σ²)) or its luminance differs by more than the centre's
// noise explains (SVGF's exp(-|ΔL| / (σ_l √var + ε))). The colour's alpha
// carries the variance of its luminance, filtered with the squared weights
// so that the next iteration reads the variance of what this one made.
// CPU twin: crates/render/src/gpu/passes/denoise.rs (`iterate`).

#import shaders/common.wgsl

struct DenoiseParams {
    size: vec2u,
    step: u32,
    // Frames the accumulation averaged (cs_denoise_input).
    frames: u32,
    sigma_luminance: f32,
    sigma_normal: f32,
    sigma_albedo: f32,
    pad: f32,
}

@group(0) @binding(0) var<uniform> params: DenoiseParams;
@group(0) @binding(1) var colour_in: texture_2d<f32>;
@group(0) @binding(2) var albedo_guide: texture_2d<f32>;
@group(0) @binding(3) var normal_guide: texture_2d<f32>;
@group(0) @binding(4) var colour_out: texture_storage_2d<rgba32float, write>;
// The accumulation's spread of frame means (cs_denoise_input).
@group(0) @binding(5) var spread_in: texture_2d<f32>;

// Colours are clamped to ±1e18 and variances to [0, 1e30], so that no sum
// or square below overflows; guides to ±16 (they are reflectances and
// normals encoded in [0, 1]), so their squared distances stay finite.
const COLOUR_LIMIT: f32 = 1e18;
const VARIANCE_LIMIT: f32 = 1e30;
const GUIDE_LIMIT: f32 = 16.0;
// Keeps the luminance weight's scale above zero where a pixel has no noise.
const LUMINANCE_EPSILON: f32 = 1e-6;

// The B3 spline's weights at offsets 0, ±1, ±2.
fn b3(offset: i32) -> f32 {
    switch abs(offset) {
        case 0: {
            return 0.375;
        }
        case 1: {
            return 0.25;
        }
        default: {
            return 0.0625;
        }
    }
}

fn finite_or_zero(x: f32) -> f32 {
    return select(x, 0.0, is_non_finite(x));
}

fn clamped(v: vec3f, limit: f32) -> vec3f {
    let finite = vec3f(finite_or_zero(v.x), finite_or_zero(v.y), finite_or_zero(v.z));
    return clamp(finite, vec3f(-limit), vec3f(limit));
}

// The colour at `p` and its luminance variance, made safe to sum.
fn load_colour(p: vec2i) -> vec4f {
    let texel = textureLoad(colour_in, p, 0);
    let variance = clamp(finite_or_zero(texel.w), 0.0, VARIANCE_LIMIT);
    return vec4f(clamped(texel.xyz, COLOUR_LIMIT), variance);
}

fn load_guide(guide: texture_2d<f32>, p: vec2i) -> vec3f {
    return clamped(textureLoad(guide, p, 0).xyz, GUIDE_LIMIT);
}

fn inside(p: vec2i) -> bool {
    return all(p >= vec2i(0)) && all(p < vec2i(params.size));
}

// SVGF's 3 x 3 Gaussian of the variance around `p`: one pixel's estimate is
// itself noisy.
fn blurred_variance(p: vec2i) -> f32 {
    var sum = 0.0;
    var weight = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2i(dx, dy);
            if inside(q) {
                let w = select(0.5, 1.0, dx == 0) * select(0.5, 1.0, dy == 0);
                sum += w * load_colour(q).w;
                weight += w;
            }
        }
    }
    return sum / weight;
}

// Dammertz's edge-stopping weight of a guide: 1 where equal, falling as a
// Gaussian of the distance.
fn guide_weight(a: vec3f, b: vec3f, sigma: f32) -> f32 {
    let d = a - b;
    return exp(-dot(d, d) / (sigma * sigma));
}

// The filter's input from the accumulation's mean (colour_in) and spread:
// the mean with the variance of its luminance in alpha. With two frames or
// more, spread / (F - 1) per channel is the variance of the mean
// (gpu/passes/error_meter.rs), the channels taken as fully correlated, as a
// path's are; with one, the variance of the luminances of the 3 x 3
// neighbourhood, as SVGF does before it has a history.
@compute @workgroup_size(8, 8)
fn cs_denoise_input(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= params.size.x || id.y >= params.size.y {
        return;
    }
    let p = vec2i(id.xy);
    var variance: f32;
    if params.frames >= 2u {
        let spread = clamp(clamped(textureLoad(spread_in, p, 0).xyz, VARIANCE_LIMIT), vec3f(0.0), vec3f(VARIANCE_LIMIT));
        let l = luminance(sqrt(spread / f32(params.frames - 1u)));
        variance = l * l;
    } else {
        var sum = 0.0;
        var squares = 0.0;
        var n = 0.0;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let q = p + vec2i(dx, dy);
                if inside(q) {
                    let l = luminance(load_colour(q).xyz);
                    sum += l;
                    squares += l * l;
                    n += 1.0;
                }
            }
        }
        let mean = sum / n;
        variance = max(squares / n - mean * mean, 0.0);
    }
    textureStore(colour_out, p, vec4f(load_colour(p).xyz, variance));
}

@compute @workgroup_size(8, 8)
fn cs_denoise(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= params.size.x || id.y >= params.size.y {
        return;
    }
    let p = vec2i(id.xy);
    let centre = load_colour(p);
    let albedo_p = load_guide(albedo_guide, p);
    let normal_p = load_guide(normal_guide, p);
    let luminance_p = luminance(centre.xyz);
    let luminance_scale = params.sigma_luminance * sqrt(blurred_variance(p)) + LUMINANCE_EPSILON;
    let step = i32(params.step);
    var weight_sum = 0.0;
    // Sums of differences from the centre, not of colours: a constant
    // image stays exactly constant, whatever the weights' rounding.
    var difference_sum = vec3f(0.0);
    var variance_sum = 0.0;
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let q = p + vec2i(dx, dy) * step;
            if inside(q) {
                let colour = load_colour(q);
                let w_luminance = exp(-abs(luminance(colour.xyz) - luminance_p) / luminance_scale);
                let w_albedo = guide_weight(load_guide(albedo_guide, q), albedo_p, params.sigma_albedo);
                let w_normal = guide_weight(load_guide(normal_guide, q), normal_p, params.sigma_normal);
                let w = b3(dx) * b3(dy) * w_luminance * w_albedo * w_normal;
                weight_sum += w;
                difference_sum += w * (colour.xyz - centre.xyz);
                variance_sum += w * w * colour.w;
            }
        }
    }
    // The centre's own weight is b3(0)² > 0, so the sums never divide by 0.
    let filtered = centre.xyz + difference_sum / weight_sum;
    textureStore(colour_out, p, vec4f(filtered, variance_sum / (weight_sum * weight_sum)));
}
