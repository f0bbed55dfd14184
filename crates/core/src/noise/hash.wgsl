// Lattice hashes; twins of hash.rs.

// pcg3d (Jarzynski & Olano, 2020). Integer-only, so bit-exact on every GPU.
fn pcg3d(v_in: vec3u) -> vec3u {
    var v = v_in * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v = v ^ (v >> vec3u(16u));
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return v;
}

// Top 24 bits to [-1, 1): exact in f32, so CPU and GPU agree to the bit.
fn unit_signed(h: vec3u) -> vec3f {
    return vec3f(h >> vec3u(8u)) * (2.0 / 16777216.0) - 1.0;
}

fn gradient_pcg(cell: vec3i) -> vec3f {
    return unit_signed(pcg3d(bitcast<vec3u>(cell)));
}

#if HASH_SIN
// The lab's hash. Only as accurate as the GPU's sin, which WGSL bounds on
// [-π, π] alone; the 43758 factor magnifies any error.
fn gradient_sin(cell: vec3f) -> vec3f {
    let p = vec3f(
        dot(cell, vec3f(127.1, 311.7, 74.7)),
        dot(cell, vec3f(269.5, 183.3, 246.1)),
        dot(cell, vec3f(113.5, 271.9, 124.6)),
    );
    return -1.0 + 2.0 * fract(sin(p) * 43758.5453123);
}
#endif

#if NOISE_EVOLVE
// pcg4d (Jarzynski & Olano, 2020): the evolving noise's 4D corners.
fn pcg4d(v_in: vec4u) -> vec4u {
    var v = v_in * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v = v ^ (v >> vec4u(16u));
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

fn gradient4_pcg(cell: vec4i) -> vec4f {
    return vec4f(pcg4d(bitcast<vec4u>(cell)) >> vec4u(8u)) * (2.0 / 16777216.0) - 1.0;
}

// A corner's lattice w wrapped modulo `period` cells while looping (0: no
// period); the non-negative remainder, as hash.rs's wrap_w.
fn wrap_w(cell_w: i32, period: u32) -> i32 {
    if period == 0u {
        return cell_w;
    }
    let p = i32(period);
    let r = cell_w % p;
    return select(r, r + p, r < 0);
}

#if HASH_SIN
// The lab's hash in 4D (hash.rs's gradient4_sin).
fn gradient4_sin(cell: vec4f) -> vec4f {
    let p = vec4f(
        dot(cell, vec4f(127.1, 311.7, 74.7, 201.3)),
        dot(cell, vec4f(269.5, 183.3, 246.1, 97.9)),
        dot(cell, vec4f(113.5, 271.9, 124.6, 157.1)),
        dot(cell, vec4f(191.3, 61.7, 233.9, 151.3)),
    );
    return -1.0 + 2.0 * fract(sin(p) * 43758.5453123);
}
#endif
#endif
