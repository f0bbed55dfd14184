// Perlin's improved noise (2002); twin of perlin.rs.
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
