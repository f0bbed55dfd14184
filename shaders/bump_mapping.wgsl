// Bump mapping: the material's height texture (generated `surface_height`)
// tilts the shading normal. Its gradient over (u, v) comes from central
// differences, one step of 1e-3 in uv, moving the 3D texture point along
// ∂p/∂u and ∂p/∂v with it. A height that reads noise (generated
// BUMP_READS_NOISE) needs the fractal-sum signals at each offset point too;
// otherwise the hit's own signals serve, and the four extra sums are
// compiled out.

#import shaders/scene.wgsl
#import shaders/intersect.wgsl
#import shaders/textures.wgsl
#import crates/core/src/texture/shading.wgsl
#import crates/core/src/texture/bump.wgsl

const BUMP_STEP: f32 = 1e-3;

fn height_at(hit: Hit, fp: Footprint, signals: vec4f, du: f32, dv: f32) -> f32 {
    let offset = du * hit.dp_du + dv * hit.dp_dv;
    let p = hit.texture_point + offset;
    let pw = hit.p + offset;
    var offset_signals = signals;
#if NOISE
    if BUMP_READS_NOISE {
        offset_signals = material_signals(hit.material, p, pw, fp.p);
    }
#endif
    return surface_height(hit.material, p, pw, hit.uv + vec2f(du, dv), fp, offset_signals);
}

// The bumped normal, kept facing the viewer `wo` (texture/bump.wgsl).
fn bumped_shading_normal(hit: Hit, fp: Footprint, signals: vec4f, wo: vec3f) -> vec3f {
    let height = materials[hit.material].bump_height;
    let dh_du = height_at(hit, fp, signals, BUMP_STEP, 0.0) - height_at(hit, fp, signals, -BUMP_STEP, 0.0);
    let dh_dv = height_at(hit, fp, signals, 0.0, BUMP_STEP) - height_at(hit, fp, signals, 0.0, -BUMP_STEP);
    let scale = height / (2.0 * BUMP_STEP);
    let tilted = bumped_normal(hit.n, hit.dp_du, hit.dp_dv, scale * dh_du, scale * dh_dv);
    return facing_shading_normal(tilted, hit.n, wo);
}
