// Importance sampling of the lat-long environment; twin of
// env_sampling.rs. The distribution is a marginal CDF over rows
// (height + 1 values) then one CDF per row over its columns (width + 1
// values each), over the image's texel uv (row 0 at the top).

#import shaders/common.wgsl
#import crates/core/src/envmap.wgsl

@group(0) @binding(11) var<storage, read> env_distribution: array<f32>;

// The cell i of cdf[offset .. offset + count + 1] with cdf[i] <= x < cdf[i + 1]
// (by bisection; the trip count depends on `count` alone, the same for
// every lane) and where in it x falls, 0 to 1.
struct CdfSample {
    cell: u32,
    offset: f32,
}

fn sample_cdf(offset: u32, count: u32, x: f32) -> CdfSample {
    var lo = 0u;
    var hi = count;
    loop {
        if hi - lo <= 1u {
            break;
        }
        let mid = (lo + hi) / 2u;
        let below = env_distribution[offset + mid] <= x;
        lo = select(lo, mid, below);
        hi = select(mid, hi, below);
    }
    let a = env_distribution[offset + lo];
    let span = env_distribution[offset + lo + 1u] - a;
    let t = select(0.5, clamp((x - a) / span, 0.0, 1.0), span > 0.0);
    return CdfSample(lo, t);
}

// The density over texel uv at `t` (integrates to 1 over the unit square).
fn env_pdf_texel_uv(t: vec2f) -> f32 {
    let size = frame.env_distribution_size;
    let i = min(u32(t.x * f32(size.x)), size.x - 1u);
    let j = min(u32(t.y * f32(size.y)), size.y - 1u);
    let row = size.y + 1u + j * (size.x + 1u);
    let p_row = env_distribution[j + 1u] - env_distribution[j];
    let p_col = env_distribution[row + i + 1u] - env_distribution[row + i];
    return p_row * p_col * f32(size.x * size.y);
}

struct EnvSample {
    wi: vec3f,
    // Solid-angle density; 0 at the poles (the sample is then unusable).
    pdf: f32,
}

// A direction drawn in proportion to the map's luminance × sin θ.
fn sample_env(u1: f32, u2: f32) -> EnvSample {
    let size = frame.env_distribution_size;
    let row = sample_cdf(0u, size.y, u1);
    let column = sample_cdf(size.y + 1u + row.cell * (size.x + 1u), size.x, u2);
    let t = vec2f(
        (f32(column.cell) + column.offset) / f32(size.x),
        (f32(row.cell) + row.offset) / f32(size.y),
    );
    let u = t.x;
    let v = 1.0 - t.y;
    let phi = TWO_PI * u - PI;
    let sin_theta = sin(PI * v);
    let lookup = vec3f(sin_theta * sin(phi), -cos(PI * v), sin_theta * cos(phi));
    let wi = rotate_y(lookup, -frame.env_rotation);
    let pdf = select(0.0, env_pdf_texel_uv(t) / (2.0 * PI * PI * sin_theta), sin_theta > 0.0);
    return EnvSample(wi, pdf);
}

// The solid-angle density with which sample_env draws `d`.
fn env_pdf(d: vec3f) -> f32 {
    let uv = env_uv(rotate_y(d, frame.env_rotation));
    let sin_theta = sin(PI * uv.y);
    let t = vec2f(uv.x, 1.0 - uv.y);
    return select(0.0, env_pdf_texel_uv(t) / (2.0 * PI * PI * sin_theta), sin_theta > 0.0);
}

