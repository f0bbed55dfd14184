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
