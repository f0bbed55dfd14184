// The texture library's shading helpers: normal perturbation by a height
// gradient, and colour ramps; twin of crates/core/src/texture/{waves,bump,ramp}.rs.

#import shaders/common.wgsl

fn waves_gradient(uv: vec2f, frequency: f32, amplitude: f32, direction: vec2f) -> vec2f {
    let phase = TWO_PI * frequency * dot(direction, uv);
    return amplitude * TWO_PI * frequency * cos(phase) * direction;
}

fn bump_along(dp: vec3f, dh: f32) -> vec3f {
    let len2 = dot(dp, dp);
    return select(vec3f(0.0), dp * (dh / len2), len2 > 0.0);
}

// Blinn's bump: the normal tilted by the height gradient over uv; a
// vanished (shorter than MIN_TILTED_LENGTH) or non-finite result (tested on
// the bits) falls back to the normal (Rust: texture::bump::bumped_normal).
const MIN_TILTED_LENGTH: f32 = 1e-3;

fn bumped_normal(n: vec3f, dp_du: vec3f, dp_dv: vec3f, dh_du: f32, dh_dv: f32) -> vec3f {
    let tilted = n - bump_along(dp_du, dh_du) - bump_along(dp_dv, dh_dv);
    let len = length(tilted);
    let usable = len >= MIN_TILTED_LENGTH && !is_non_finite(len);
    return select(n, tilted / len, usable);
}

// A colour ramp of `count` stops (position in w, colour in xyz), sorted.
const MAX_RAMP_STOPS: u32 = 8u;

fn ramp(stops: array<vec4f, 8>, count: u32, t: f32) -> vec3f {
    let n = min(count, MAX_RAMP_STOPS);
    if n == 0u {
        return vec3f(0.0);
    }
    var color = stops[0].xyz;
    for (var i = 1u; i < n; i++) {
        let a = stops[i - 1u];
        let b = stops[i];
        let span = b.w - a.w;
        let w = select(1.0, (t - a.w) / span, span > 0.0);
        color = select(color, mix(a.xyz, b.xyz, clamp(w, 0.0, 1.0)), t > a.w);
    }
    return color;
}
