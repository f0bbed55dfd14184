// Compute pass of `marbre bake`: a material property at surface points the
// CPU gives (marbre_core::bake), evaluated by the scene's generated texture
// code (gpu::texture_codegen, appended to this module) as the trace pass
// shades a hit (surface.wgsl's surface_at), before its clamping and with no
// footprint: each texel is a point sample.

#import shaders/common.wgsl
#import shaders/scene.wgsl
#import shaders/textures.wgsl
#import crates/core/src/geometry/sphere.wgsl
#import shaders/intersect.wgsl

struct BakeSettings {
    count: u32,
    property: u32, // gpu::bake::property_id
    _pad0: u32,
    _pad1: u32,
}

// One texel's surface point: object point, material, world point, (u, v).
struct BakeTexel {
    p: vec3f,
    material: u32,
    pw: vec3f,
    _pad0: u32,
    uv: vec2f,
    _pad1: vec2f,
}

// Past the trace pass's bindings (0-16), which the texture code reads.
@group(0) @binding(17) var<uniform> bake: BakeSettings;
@group(0) @binding(18) var<storage, read> bake_texels: array<BakeTexel>;
@group(0) @binding(19) var<storage, read_write> bake_values: array<vec4f>;

@compute @workgroup_size(64)
fn cs_bake(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= bake.count {
        return;
    }
    let t = bake_texels[i];
    let fp = Footprint(vec2f(0.0), 0.0, vec3f(0.0));
#if NOISE
    let signals = material_signals(t.material, t.p, t.pw, 0.0);
#else
    let signals = vec4f(0.0);
#endif
    let s = surface_textures(t.material, t.p, t.pw, t.uv, fp, signals);
    var v: vec3f;
    switch bake.property {
        case 0u: {
            v = s.diffuse;
        }
        case 1u: {
            v = s.specular;
        }
        case 2u: {
            v = vec3f(s.roughness);
        }
        case 3u: {
            v = vec3f(surface_height(t.material, t.p, t.pw, t.uv, fp, signals));
        }
        case 4u: {
            v = vec3f(s.opacity);
        }
        default: {
            v = s.emission;
        }
    }
    bake_values[i] = vec4f(v, 1.0);
}
