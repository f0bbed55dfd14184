// Procedural textures. The texture trees themselves are generated per scene
// (gpu::texture_codegen, appended to this module as `surface_textures`);
// this file holds what they share.
//
// The fractal sums, the expensive part, are evaluated once per hit as the
// material's noise signals (deduplicated on the CPU), outside any pattern
// code. SIMD hardware runs every branch some lane takes under a mask
// (lavapipe runs every branch, taken or not), so a sum written inside each
// pattern would be paid for by every pattern in the scene.

#import shaders/scene.wgsl
#import shaders/intersect.wgsl
#import crates/core/src/noise/fractal.wgsl
#import crates/core/src/texture/mapping.wgsl
#import crates/core/src/texture/patterns.wgsl
#if IMAGE
#import crates/core/src/texture/image.wgsl
#endif

// The generated code's result for one hit.
struct SurfaceTextures {
    diffuse: vec3f,
    specular: vec3f,
    roughness: f32,
    mirror: f32,
    opacity: f32,
    transmission: vec3f,
    emission: vec3f,
    diffuse_transmission: vec3f,
}

// The render switches (Rust: gpu::renderer::RenderSwitches), as override
// constants: toggling one makes a new pipeline from the same module, and the
// driver folds the branch it does not take away.
override filter_checkers: bool = true;
override clamp_octaves: bool = true;

// How much of the surface a sample stands for: the ray cone's footprint on
// the surface, its extent in (u, v) along each axis (`uv`), along each 3D
// axis (`axes`, for box filters) and its long axis (`p`, for noise: never
// too little blur). Zero without the FOOTPRINT feature: textures are then
// point sampled.
struct Footprint {
    uv: vec2f,
    p: f32,
    axes: vec3f,
}

// A cone `width` wide meeting the surface along `d` covers an ellipse: `w`
// across the plane of incidence and `w / cos θ` along it, in the tangent
// plane. Its extent along a unit direction e is w·sqrt(e⊥² + (e·m)²/cos²θ)
// with m the ellipse's long axis and e⊥ the part of e in the plane across
// it. Along the tangents (∂p/∂u, ∂p/∂v), divided by how far the surface
// moves per unit of u and of v, that is the footprint in (u, v).
fn hit_footprint(hit: Hit, width: f32, d: vec3f) -> Footprint {
#if FOOTPRINT
    let cos_theta = max(abs(dot(d, hit.n)), 1e-4);
    let along = d - dot(d, hit.n) * hit.n;
    let along_len = length(along);
    let m = select(vec3f(0.0), along / along_len, along_len > 0.0);
    let across = cross(hit.n, m);
    let per_uv = vec2f(length(hit.dp_du), length(hit.dp_dv));
    let m_uv = vec2f(dot(hit.dp_du, m), dot(hit.dp_dv, m));
    let a_uv = vec2f(dot(hit.dp_du, across), dot(hit.dp_dv, across));
    let extent_uv = width * sqrt(a_uv * a_uv + m_uv * m_uv / (cos_theta * cos_theta));
    let uv = select(vec2f(0.0), extent_uv / (per_uv * per_uv), per_uv > vec2f(0.0));
    // The world axes' components along m and across it.
    let axes = width * sqrt(across * across + m * m / (cos_theta * cos_theta));
    return Footprint(uv, width / cos_theta, axes);
#else
    return Footprint(vec2f(0.0), 0.0, vec3f(0.0));
#endif
}

#if NOISE
// The material's signals, ordered by kind on the CPU: gradient noise ones
// first, then Perlin ones from `first_perlin` on. Each kind's loop holds only
// its own noise, so a hit pays for Perlin octaves only where some lane reads
// a Perlin signal.
fn material_signals(material: u32, p: vec3f, pw: vec3f, width: f32) -> vec4f {
    var values = vec4f(0.0);
    let count = min(materials[material].signal_count, MAX_SIGNALS);
    let first_perlin = min(materials[material].first_perlin, count);
#if NOISE_GRADIENT
    for (var k = 0u; k < first_perlin; k++) {
        let n = signal_params(material, k, width);
        values[k] = fractal_sum_gradient(signal_point(material, k, p, pw), n) + dropped_mean(material, k, n);
    }
#endif
#if NOISE_PERLIN
    for (var k = first_perlin; k < count; k++) {
        let n = signal_params(material, k, width);
        values[k] = fractal_sum_perlin(signal_point(material, k, p, pw), n) + dropped_mean(material, k, n);
    }
#endif
    return values;
}

// Signal k's noise, its octaves clamped to what a footprint `width` wide
// resolves if `clamp_octaves` (twin of noise::footprint_octaves).
fn signal_params(material: u32, k: u32, width: f32) -> NoiseParams {
    var n = materials[material].signals[k];
#if FOOTPRINT
    if clamp_octaves {
        n.octaves = footprint_octaves(n, width * n.footprint_scale);
    }
#endif
    return n;
}

// What signal k's octaves dropped by `signal_params` (leaving `kept`'s)
// add on average.
fn dropped_mean(material: u32, k: u32, kept: NoiseParams) -> f32 {
#if FOOTPRINT
    return dropped_octaves_mean(materials[material].signals[k], kept.octaves);
#else
    return 0.0;
#endif
}

// Where signal k of a material is taken: its mapping of the object point p
// or of the world point pw.
fn signal_point(material: u32, k: u32, p: vec3f, pw: vec3f) -> vec3f {
    let q = select(p, pw, (materials[material].signals[k].flags & NOISE_WORLD) != 0u);
    return affine_rows(
        q,
        materials[material].signal_rows[3u * k],
        materials[material].signal_rows[3u * k + 1u],
        materials[material].signal_rows[3u * k + 2u],
    );
}
#endif
