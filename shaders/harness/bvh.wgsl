// Compute harness: sends rays through the mesh functions of accel/traverse.wgsl, for
// the parity and watertightness tests and `marbre bench-bvh`.

#import crates/core/src/accel/traverse.wgsl

struct BvhHarnessUniform {
    count: u32,
    row_pitch: u32, // invocations per row of workgroups (dispatches past 65535 groups)
    _pad0: u32,
    _pad1: u32,
}

struct HarnessRay {
    origin: vec4f,    // w: t_max
    direction: vec4f, // w unused
}

@group(0) @binding(0) var<uniform> harness: BvhHarnessUniform;
@group(0) @binding(1) var<storage, read> rays: array<HarnessRay>;
// Closest: (t, triangle, b1, b2) as bits; occluded: x = 1 or 0.
@group(0) @binding(2) var<storage, read_write> results: array<vec4u>;
@group(0) @binding(3) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(4) var<storage, read> mesh_triangles: array<TriangleVerts>;

@compute @workgroup_size(64)
fn cs_closest(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * harness.row_pitch;
    if i >= harness.count {
        return;
    }
    let ray = rays[i];
    let h = slab_ray_intersect(ray.origin.xyz, ray.direction.xyz, ray.origin.w);
    results[i] = vec4u(bitcast<u32>(h.t), h.triangle, bitcast<u32>(h.b1), bitcast<u32>(h.b2));
}

@compute @workgroup_size(64)
fn cs_occluded(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * harness.row_pitch;
    if i >= harness.count {
        return;
    }
    let ray = rays[i];
    let hit = slab_ray_occluded(ray.origin.xyz, ray.direction.xyz, ray.origin.w);
    results[i] = vec4u(select(0u, 1u, hit), 0u, 0u, 0u);
}
