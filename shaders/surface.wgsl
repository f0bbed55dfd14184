// The material at a hit: its textures evaluated, clamped to what the BSDF
// (bsdf.wgsl) accepts.

#import crates/core/src/bsdf.wgsl
#import crates/core/src/mis.wgsl
#import shaders/scene.wgsl
#import shaders/intersect.wgsl
#import shaders/textures.wgsl
#if BUMP
#import shaders/bump_mapping.wgsl
#endif

// The surface at a hit reached by a ray cone `width` wide, along `d`.
fn surface_at(hit: Hit, width: f32, d: vec3f) -> SurfacePoint {
    let p = hit.texture_point;
    let fp = hit_footprint(hit, width, d);
#if NOISE
    let signals = material_signals(hit.material, p, hit.p, fp.p);
#else
    let signals = vec4f(0.0);
#endif
    let textures = surface_textures(hit.material, p, hit.p, hit.uv, fp, signals);
    var s: SurfacePoint;
    // Math steps can leave [0, 1]: reflectances stay within it, so no
    // bounce ever adds energy.
    s.diffuse = clamp(textures.diffuse, vec3f(0.0), vec3f(1.0));
    s.specular = clamp(textures.specular, vec3f(0.0), vec3f(1.0));
    let r = clamp(textures.roughness, 0.0, 1.0);
    s.alpha = max(r * r, 1e-3);
    s.mirror = clamp(textures.mirror, 0.0, 1.0);
    s.opacity = clamp(textures.opacity, 0.0, 1.0);
    s.transmission = clamp(textures.transmission, vec3f(0.0), vec3f(1.0));
    s.emission = max(textures.emission, vec3f(0.0));
    s.uniform_diffuse = frame.strategy == STRATEGY_HEMISPHERE;
    s.diffuse_transmission = clamp(textures.diffuse_transmission, vec3f(0.0), vec3f(1.0));
#if BUMP
    s.n = bumped_shading_normal(hit, fp, signals, -d);
#else
    s.n = hit.n;
#endif
    return s;
}
