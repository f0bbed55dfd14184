// Compute harness for the texture library: evaluates one pattern of
// texture/patterns.wgsl or one mapping of texture/mapping.wgsl at a list
// of points, for the GPU parity tests.
// 2D patterns read uv from the point's x and y.

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
        case 17u: {
            r.x = filtered_checker_3d(p, a.xyz, b.xyz);
        }
        case 16u: {
            r = image_sample(a, p.xy, u32(b.x), u32(b.y), p.z);
        }
        case 0u: {
            let cell = checker_2d(p.xy, a.xy, a.z);
            r = vec4f(cell.select, cell.local, 0.0);
        }
        case 1u: {
            r.x = checker_3d(p, a.xyz);
        }
        case 2u: {
            r.x = filtered_checker_2d(p.xy, a.xy, a.z, b.xy);
        }
        case 3u: {
            let cell = brick(p.xy, a.xy, a.z, a.w);
            r = vec4f(cell.select, cell.local, 0.0);
        }
        case 4u: {
            let t = tile(p.xy, a.x, a.y, a.z);
            r = vec4f(t.select, t.height_gradient, tile_height(p.xy, a.x, a.y));
        }
        case 5u: {
            r.x = cutout(p.xy, harness.sides, a.x);
        }
        case 6u: {
            r.x = wood(p, a.xyz, a.w, b.x, harness.noise);
        }
        case 7u: {
            r.x = marble_veins(p, a.xyz, a.w, b.x, harness.noise);
        }
        case 18u: {
            r.x = massal_marble(p, a.x, turbulence(p, harness.noise));
        }
        case 8u: {
            r = vec4f(waves_gradient(p.xy, a.x, a.y, b.xy), waves(p.xy, a.x, b.xy), 0.0);
        }
        case 9u: {
            r = vec4f(bumped_normal(p, a.xyz, b.xyz, c.x, c.y), 0.0);
        }
        case 10u: {
            r = vec4f(ramp(harness.stops, harness.sides, p.x), 0.0);
        }
        case 11u: {
            r = vec4f(sphere_uv(p), 0.0, 0.0);
        }
        case 12u: {
            r = vec4f(cylinder_uv(p, a.x), 0.0, 0.0);
        }
        case 13u: {
            r = vec4f(plane_uv(p, a.xyz, b.xyz, c.xyz), 0.0, 0.0);
        }
        case 14u: {
            let s = harness.stops;
            r = vec4f(triangle_uv(p, s[0].xyz, s[1].xyz, s[2].xyz, s[3].xy, s[4].xy, s[5].xy), 0.0, 0.0);
        }
        default: {
            let linear = mat3x3f(a.xyz, b.xyz, c.xyz);
            r = vec4f(to_texture_space(p, linear, vec3f(a.w, b.w, c.w)), 0.0);
        }
    }
    results[i] = r;
}
