// Compute harness: runs the ray geometry (geometry/sphere.wgsl,
// geometry/ray_offset.wgsl) and the shading-normal fallback
// (texture/bump.wgsl) on given inputs, for the stability tests
// (crates/render/tests/gpu/geometry_stability.rs) against the CPU twins in
// crates/core/src/geometry/ and texture::bump.
//
// Each query reads QUERY_POINTS consecutive points and writes its answer
// over the first one or two of its own slots:
//   mode 0, sphere distance: origin, direction, centre, (radius, _, _)
//           → x = t (NO_HIT for a miss)
//   mode 1, offset_ray: point, normal → xyz = the offset point
//   mode 2, shading normal: n, ∂p/∂u, ∂p/∂v, (∂h/∂u, ∂h/∂v, _), wo
//           → xyz = the shading normal; the next slot the bumped normal
//             before the facing fallback

#import crates/core/src/texture/shading.wgsl
#import crates/core/src/geometry/sphere.wgsl
#import crates/core/src/geometry/ray_offset.wgsl
#import crates/core/src/texture/bump.wgsl

const QUERY_POINTS: u32 = 5u;

struct GeometryHarness {
    mode: u32,
    count: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> harness: GeometryHarness;
@group(0) @binding(1) var<storage, read> points: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> results: array<vec4f>;

@compute @workgroup_size(64)
fn cs_evaluate(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= harness.count {
        return;
    }
    let k = i * QUERY_POINTS;
    let a = points[k].xyz;
    let b = points[k + 1u].xyz;
    let c = points[k + 2u].xyz;
    let e = points[k + 3u].xyz;
    let f = points[k + 4u].xyz;
    switch harness.mode {
        case 0u: {
            results[k] = vec4f(sphere_distance(a, b, c, e.x), 0.0, 0.0, 0.0);
        }
        case 1u: {
            results[k] = vec4f(offset_ray(a, b), 0.0);
        }
        default: {
            let tilted = bumped_normal(a, b, c, e.x, e.y);
            results[k] = vec4f(facing_shading_normal(tilted, a, f), 0.0);
            results[k + 1u] = vec4f(tilted, 0.0);
        }
    }
}
