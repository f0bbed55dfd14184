// The lab's gradient noise; twin of gradient.rs.

#import crates/core/src/noise/hash.wgsl

fn corner_gradient(cell: vec3i, hash: u32) -> vec3f {
#if HASH_SIN
    if hash == 1u {
        return gradient_sin(vec3f(cell));
    }
#endif
    // hash 2: pcg3d of the cell modulo 256, a lattice that repeats
    // (noise::rebase); `& 255` is the non-negative remainder, as on the CPU.
    return gradient_pcg(select(cell, cell & vec3i(255), hash == 2u));
}

fn gradient_noise(p: vec3f, hash: u32) -> f32 {
    let i = floor(p);
    let f = p - i;
    let c = vec3i(i);
    let u = f * f * (3.0 - 2.0 * f);
    let v000 = dot(corner_gradient(c + vec3i(0, 0, 0), hash), f - vec3f(0.0, 0.0, 0.0));
    let v100 = dot(corner_gradient(c + vec3i(1, 0, 0), hash), f - vec3f(1.0, 0.0, 0.0));
    let v010 = dot(corner_gradient(c + vec3i(0, 1, 0), hash), f - vec3f(0.0, 1.0, 0.0));
    let v110 = dot(corner_gradient(c + vec3i(1, 1, 0), hash), f - vec3f(1.0, 1.0, 0.0));
    let v001 = dot(corner_gradient(c + vec3i(0, 0, 1), hash), f - vec3f(0.0, 0.0, 1.0));
    let v101 = dot(corner_gradient(c + vec3i(1, 0, 1), hash), f - vec3f(1.0, 0.0, 1.0));
    let v011 = dot(corner_gradient(c + vec3i(0, 1, 1), hash), f - vec3f(0.0, 1.0, 1.0));
    let v111 = dot(corner_gradient(c + vec3i(1, 1, 1), hash), f - vec3f(1.0, 1.0, 1.0));
    let x00 = v000 + (v100 - v000) * u.x;
    let x10 = v010 + (v110 - v010) * u.x;
    let x01 = v001 + (v101 - v001) * u.x;
    let x11 = v011 + (v111 - v011) * u.x;
    let y0 = x00 + (x10 - x00) * u.y;
    let y1 = x01 + (x11 - x01) * u.y;
    return y0 + (y1 - y0) * u.z;
}

#if NOISE_EVOLVE
fn corner_gradient4(cell: vec4i, hash: u32) -> vec4f {
#if HASH_SIN
    if hash == 1u {
        return gradient4_sin(vec4f(cell));
    }
#endif
    return gradient4_pcg(select(cell, cell & vec4i(255), hash == 2u));
}

// Corner c + d's contribution at the offset f: its lattice w wrapped by the
// loop's period first.
fn gradient_corner4(c: vec4i, d: vec4i, f: vec4f, hash: u32, period: u32) -> f32 {
    let q = c + d;
    let g = corner_gradient4(vec4i(q.xyz, wrap_w(q.w, period)), hash);
    return dot(g, f - vec4f(d));
}

// The cube of corners at w offset dw, interpolated along x, y, z.
fn gradient_cube4(c: vec4i, dw: i32, f: vec4f, u: vec4f, hash: u32, period: u32) -> f32 {
    let v000 = gradient_corner4(c, vec4i(0, 0, 0, dw), f, hash, period);
    let v100 = gradient_corner4(c, vec4i(1, 0, 0, dw), f, hash, period);
    let v010 = gradient_corner4(c, vec4i(0, 1, 0, dw), f, hash, period);
    let v110 = gradient_corner4(c, vec4i(1, 1, 0, dw), f, hash, period);
    let v001 = gradient_corner4(c, vec4i(0, 0, 1, dw), f, hash, period);
    let v101 = gradient_corner4(c, vec4i(1, 0, 1, dw), f, hash, period);
    let v011 = gradient_corner4(c, vec4i(0, 1, 1, dw), f, hash, period);
    let v111 = gradient_corner4(c, vec4i(1, 1, 1, dw), f, hash, period);
    let x00 = v000 + (v100 - v000) * u.x;
    let x10 = v010 + (v110 - v010) * u.x;
    let x01 = v001 + (v101 - v001) * u.x;
    let x11 = v011 + (v111 - v011) * u.x;
    let y0 = x00 + (x10 - x00) * u.y;
    let y1 = x01 + (x11 - x01) * u.y;
    return y0 + (y1 - y0) * u.z;
}

// The 4D gradient noise of evolving signals (gradient.rs's gradient_noise4),
// periodic in w every `period` cells when it is not 0.
fn gradient_noise4(p: vec3f, w: f32, hash: u32, period: u32) -> f32 {
    let q = vec4f(p, w);
    let i = floor(q);
    let f = q - i;
    let c = vec4i(i);
    let u = f * f * (3.0 - 2.0 * f);
    let lo = gradient_cube4(c, 0, f, u, hash, period);
    let hi = gradient_cube4(c, 1, f, u, hash, period);
    return lo + (hi - lo) * u.w;
}
#endif
