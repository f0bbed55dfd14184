// Compute harness for the texture library: evaluates one pattern of
// texture/patterns.wgsl or one mapping of texture/mapping.wgsl at a list
// of points, for the GPU parity tests.
// 2D patterns read uv from the point's x and y.

#import shaders/common.wgsl
#import crates/core/src/noise/fractal.wgsl
#import crates/core/src/texture/patterns.wgsl
#import crates/core/src/texture/shading.wgsl
#import crates/core/src/texture/mapping.wgsl
#import crates/core/src/texture/image.wgsl

// The functions the harness runs: `Mode` in texture.rs, value for value.
const MODE_CHECKER_2D: u32 = 0u;
const MODE_CHECKER_3D: u32 = 1u;
const MODE_FILTERED_CHECKER_2D: u32 = 2u;
const MODE_BRICK: u32 = 3u;
const MODE_TILE: u32 = 4u;
const MODE_CUTOUT: u32 = 5u;
const MODE_WOOD: u32 = 6u;
const MODE_MARBLE_VEINS: u32 = 7u;
const MODE_WAVES_GRADIENT: u32 = 8u;
const MODE_BUMP: u32 = 9u;
const MODE_RAMP: u32 = 10u;
const MODE_SPHERE_UV: u32 = 11u;
const MODE_CYLINDER_UV: u32 = 12u;
const MODE_PLANE_UV: u32 = 13u;
const MODE_TRIANGLE_UV: u32 = 14u;
const MODE_TRANSFORM: u32 = 15u;
const MODE_IMAGE: u32 = 16u;
const MODE_FILTERED_CHECKER_3D: u32 = 17u;
const MODE_MASSAL_MARBLE: u32 = 18u;

struct TextureHarness {
    noise: NoiseParams,
    mode: u32,
    count: u32,
    sides: u32,      // cutout sides, or ramp stop count
    _pad: u32,
    a: vec4f,
    b: vec4f,
    c: vec4f,
    stops: array<vec4f, 8>,
}

@group(0) @binding(0) var<uniform> harness: TextureHarness;
@group(0) @binding(1) var<storage, read> points: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> results: array<vec4f>;
@group(0) @binding(8) var image_atlas: texture_2d<f32>;

@compute @workgroup_size(64)
fn cs_evaluate(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= harness.count {
        return;
    }
    let p = points[i].xyz;
    let a = harness.a;
    let b = harness.b;
    let c = harness.c;
    var r = vec4f(0.0);
    switch harness.mode {
        case MODE_FILTERED_CHECKER_3D: {
            r.x = filtered_checker_3d(p, a.xyz, b.xyz);
        }
        case MODE_IMAGE: {
            r = image_sample(a, p.xy, u32(b.x), u32(b.y), p.z);
        }
        case MODE_CHECKER_2D: {
            let cell = checker_2d(p.xy, a.xy, a.z);
            r = vec4f(cell.select, cell.local, 0.0);
        }
        case MODE_CHECKER_3D: {
            r.x = checker_3d(p, a.xyz);
        }
        case MODE_FILTERED_CHECKER_2D: {
            r.x = filtered_checker_2d(p.xy, a.xy, a.z, b.xy);
        }
        case MODE_BRICK: {
            let cell = brick(p.xy, a.xy, a.z, a.w);
            r = vec4f(cell.select, cell.local, 0.0);
        }
        case MODE_TILE: {
            let t = tile(p.xy, a.x, a.y, a.z);
            r = vec4f(t.select, t.height_gradient, tile_height(p.xy, a.x, a.y));
        }
        case MODE_CUTOUT: {
            r.x = cutout(p.xy, harness.sides, a.x);
        }
        case MODE_WOOD: {
            r.x = wood(p, a.xyz, a.w, b.x, harness.noise);
        }
        case MODE_MARBLE_VEINS: {
            r.x = marble_veins(p, a.xyz, a.w, b.x, harness.noise);
        }
        case MODE_MASSAL_MARBLE: {
            r.x = massal_marble(p, a.x, turbulence(p, harness.noise));
        }
        case MODE_WAVES_GRADIENT: {
            r = vec4f(waves_gradient(p.xy, a.x, a.y, b.xy), waves(p.xy, a.x, b.xy), 0.0);
        }
        case MODE_BUMP: {
            r = vec4f(bumped_normal(p, a.xyz, b.xyz, c.x, c.y), 0.0);
        }
        case MODE_RAMP: {
            r = vec4f(ramp(harness.stops, harness.sides, p.x), 0.0);
        }
        case MODE_SPHERE_UV: {
            r = vec4f(sphere_uv(p), 0.0, 0.0);
        }
        case MODE_CYLINDER_UV: {
            r = vec4f(cylinder_uv(p, a.x), 0.0, 0.0);
        }
        case MODE_PLANE_UV: {
            r = vec4f(plane_uv(p, a.xyz, b.xyz, c.xyz), 0.0, 0.0);
        }
        case MODE_TRIANGLE_UV: {
            let s = harness.stops;
            r = vec4f(triangle_uv(p, s[0].xyz, s[1].xyz, s[2].xyz, s[3].xy, s[4].xy, s[5].xy), 0.0, 0.0);
        }
        case MODE_TRANSFORM, default: {
            let linear = mat3x3f(a.xyz, b.xyz, c.xyz);
            r = vec4f(to_texture_space(p, linear, vec3f(a.w, b.w, c.w)), 0.0);
        }
    }
    results[i] = r;
}
