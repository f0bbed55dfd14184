// Perlin's improved noise (2002); twin of perlin.rs.

#if NOISE_EVOLVE
#import crates/core/src/noise/hash.wgsl
#endif
// The permutation table, 512 entries (p[256 + i] = p[i]), packed four to a
// vec4 as uniform arrays require. A uniform buffer: lavapipe reads it far
// faster than a storage buffer when lanes differ in index, and a dynamically
// indexed `const` array would be copied into every invocation.

@group(0) @binding(6) var<uniform> perm_table: array<vec4u, 128>;

fn perm(i: u32) -> u32 {
    return perm_table[i >> 2u][i & 3u];
}

fn perlin_fade(t: vec3f) -> vec3f {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

// Perlin's gradient table, or with `massal` the one of Massal's tutorial
// (twin of perlin.rs's Gradients): they differ at h = 13 and 14.
fn perlin_grad(hash: u32, x: f32, y: f32, z: f32, massal: bool) -> f32 {
    let h = hash & 15u;
    let twelve = massal && (h == 12u || h == 13u);
    let u = select(y, x, h < 8u || twelve);
    let v = select(select(z, x, !massal && (h == 12u || h == 14u)), y, h < 4u || twelve);
    return select(-u, u, (h & 1u) == 0u) + select(-v, v, (h & 2u) == 0u);
}

fn perlin_noise(p_in: vec3f, massal: bool) -> f32 {
    let fl = floor(p_in);
    let xi = u32(i32(fl.x) & 255);
    let yi = u32(i32(fl.y) & 255);
    let zi = u32(i32(fl.z) & 255);
    let p = p_in - fl;
    let f = perlin_fade(p);
    let a = perm(xi) + yi;
    let aa = perm(a) + zi;
    let ab = perm(a + 1u) + zi;
    let b = perm(xi + 1u) + yi;
    let ba = perm(b) + zi;
    let bb = perm(b + 1u) + zi;
    let x = p.x;
    let y = p.y;
    let z = p.z;
    let l0 = mix(perlin_grad(perm(aa), x, y, z, massal), perlin_grad(perm(ba), x - 1.0, y, z, massal), f.x);
    let l1 = mix(perlin_grad(perm(ab), x, y - 1.0, z, massal), perlin_grad(perm(bb), x - 1.0, y - 1.0, z, massal), f.x);
    let l2 = mix(perlin_grad(perm(aa + 1u), x, y, z - 1.0, massal), perlin_grad(perm(ba + 1u), x - 1.0, y, z - 1.0, massal), f.x);
    let l3 = mix(perlin_grad(perm(ab + 1u), x, y - 1.0, z - 1.0, massal), perlin_grad(perm(bb + 1u), x - 1.0, y - 1.0, z - 1.0, massal), f.x);
    return mix(mix(l0, l1, f.y), mix(l2, l3, f.y), f.z);
}

#if NOISE_EVOLVE
// Blender's 4D gradients (perlin.rs's grad4): the 32 edges of the
// hypercube. Massal's table has no 4D form; both Perlin kinds use this.
fn perlin_grad4(hash: u32, x: f32, y: f32, z: f32, w: f32) -> f32 {
    let h = hash & 31u;
    let u = select(y, x, h < 24u);
    let v = select(z, y, h < 16u);
    let s = select(w, z, h < 8u);
    return select(-u, u, (h & 1u) == 0u) + select(-v, v, (h & 2u) == 0u) + select(-s, s, (h & 4u) == 0u);
}

// The permutation applied a fourth time: corner (x, y, z, w)'s hash.
fn perlin_hash4(x: u32, y: u32, z: u32, w: u32) -> u32 {
    return perm(perm(perm(perm(x) + y) + z) + w);
}

// The cube of corners at lattice w `wi`, offset `wf` in w, interpolated
// along x, y, z.
fn perlin_cube4(i: vec3u, p: vec3f, f: vec3f, wi: u32, wf: f32) -> f32 {
    let x = p.x;
    let y = p.y;
    let z = p.z;
    let l0 = mix(perlin_grad4(perlin_hash4(i.x, i.y, i.z, wi), x, y, z, wf), perlin_grad4(perlin_hash4(i.x + 1u, i.y, i.z, wi), x - 1.0, y, z, wf), f.x);
    let l1 = mix(perlin_grad4(perlin_hash4(i.x, i.y + 1u, i.z, wi), x, y - 1.0, z, wf), perlin_grad4(perlin_hash4(i.x + 1u, i.y + 1u, i.z, wi), x - 1.0, y - 1.0, z, wf), f.x);
    let l2 = mix(perlin_grad4(perlin_hash4(i.x, i.y, i.z + 1u, wi), x, y, z - 1.0, wf), perlin_grad4(perlin_hash4(i.x + 1u, i.y, i.z + 1u, wi), x - 1.0, y, z - 1.0, wf), f.x);
    let l3 = mix(perlin_grad4(perlin_hash4(i.x, i.y + 1u, i.z + 1u, wi), x, y - 1.0, z - 1.0, wf), perlin_grad4(perlin_hash4(i.x + 1u, i.y + 1u, i.z + 1u, wi), x - 1.0, y - 1.0, z - 1.0, wf), f.x);
    return mix(mix(l0, l1, f.y), mix(l2, l3, f.y), f.z);
}

// Perlin's improved noise in 4D (perlin.rs's improved_noise4), periodic in
// w every `period` cells when it is not 0.
fn perlin_noise4(p_in: vec3f, w_in: f32, period: u32) -> f32 {
    let fl = floor(p_in);
    let i = vec3u(vec3i(fl) & vec3i(255));
    let wl = floor(w_in);
    let cw = i32(wl);
    let w0 = u32(wrap_w(cw, period) & 255);
    let w1 = u32(wrap_w(cw + 1, period) & 255);
    let p = p_in - fl;
    let wf = w_in - wl;
    let f = perlin_fade(p);
    let fw = wf * wf * wf * (wf * (wf * 6.0 - 15.0) + 10.0);
    return mix(perlin_cube4(i, p, f, w0, wf), perlin_cube4(i, p, f, w1, wf - 1.0), fw);
}
#endif
