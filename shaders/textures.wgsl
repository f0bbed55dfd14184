// Procedural textures. The texture trees themselves are generated per scene
// (gpu::texture_codegen, appended to this module as `surface_textures`);
// this file holds what they share.
//
// The fractal sums, the expensive part, are evaluated once per hit as the
// material's noise signals (deduplicated on the CPU), outside any pattern
// code. SIMD hardware runs every branch some lane takes under a mask
// (lavapipe runs every branch, taken or not), so a sum written inside each
// pattern would be paid for by every pattern in the scene.

// The generated code's result for one hit.
struct SurfaceTextures {
    diffuse: vec3f,
    specular: vec3f,
    roughness: f32,
    mirror: f32,
    opacity: f32,
    emission: vec3f,
}

#if NOISE
// The material's signals, ordered by kind on the CPU: gradient noise ones
// first, then Perlin ones from `first_perlin` on. Each kind's loop holds only
// its own noise, so a hit pays for Perlin octaves only where some lane reads
// a Perlin signal.
fn material_signals(material: u32, p: vec3f, pw: vec3f) -> vec4f {
    var values = vec4f(0.0);
    let count = min(materials[material].signal_count, MAX_SIGNALS);
    let first_perlin = min(materials[material].first_perlin, count);
#if NOISE_GRADIENT
    for (var k = 0u; k < first_perlin; k++) {
        values[k] = fractal_sum_gradient(signal_point(material, k, p, pw), materials[material].signals[k]);
    }
#endif
#if NOISE_PERLIN
    for (var k = first_perlin; k < count; k++) {
        values[k] = fractal_sum_perlin(signal_point(material, k, p, pw), materials[material].signals[k]);
    }
#endif
    return values;
}

// Where signal k of a material is taken: its mapping of the object point p
// or of the world point pw.
fn signal_point(material: u32, k: u32, p: vec3f, pw: vec3f) -> vec3f {
    let q = select(p, pw, materials[material].signals[k].world != 0u);
    return affine_rows(
        q,
        materials[material].signal_rows[3u * k],
        materials[material].signal_rows[3u * k + 1u],
        materials[material].signal_rows[3u * k + 2u],
    );
}
#endif
