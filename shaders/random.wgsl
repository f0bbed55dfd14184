// Per-sample random numbers: a PCG state seeded by pcg3d of (pixel, sample).

#import crates/core/src/noise/hash.wgsl

var<private> rng_state: u32;

fn rng_seed(pixel: vec2u, sample_index: u32) {
    rng_state = pcg3d(vec3u(pixel, sample_index)).x;
}

fn rand() -> f32 {
    rng_state = rng_state * 747796405u + 2891336453u;
    var w = ((rng_state >> ((rng_state >> 28u) + 4u)) ^ rng_state) * 277803737u;
    w = (w >> 22u) ^ w;
    return f32(w >> 8u) * (1.0 / 16777216.0);
}
