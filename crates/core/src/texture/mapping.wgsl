// Texture coordinates of a surface point; twin of mapping.rs.
// Needs env_uv (envmap.wgsl): a sphere's (u, v) is the lab's lat-long
// mapping of the direction from its centre.

#import shaders/common.wgsl
#import crates/core/src/envmap.wgsl

fn sphere_uv(offset: vec3f) -> vec2f {
    let len2 = dot(offset, offset);
    let d = select(vec3f(0.0, -1.0, 0.0), offset * inverseSqrt(len2), len2 > 0.0);
    return env_uv(d);
}

fn cylinder_uv(offset: vec3f, height: f32) -> vec2f {
    var u = 0.5;
    if offset.x != 0.0 || offset.z != 0.0 {
        u = (atan2(offset.x, offset.z) + PI) / TWO_PI;
    }
    return vec2f(u, offset.y / height);
}

// Coordinates of p in the frame origin + u·u_axis + v·v_axis (axes possibly
// oblique), by the normal equations; degenerate axes give (0, 0).
fn plane_uv(p: vec3f, origin: vec3f, u_axis: vec3f, v_axis: vec3f) -> vec2f {
    let d = p - origin;
    let uu = dot(u_axis, u_axis);
    let uv = dot(u_axis, v_axis);
    let vv = dot(v_axis, v_axis);
    let det = uu * vv - uv * uv;
    let du = dot(u_axis, d);
    let dv = dot(v_axis, d);
    let solved = vec2f(du * vv - dv * uv, dv * uu - du * uv) / det;
    return select(vec2f(0.0), solved, det > 1e-12 * uu * vv);
}

fn triangle_uv(p: vec3f, v0: vec3f, v1: vec3f, v2: vec3f, uv0: vec2f, uv1: vec2f, uv2: vec2f) -> vec2f {
    let b = plane_uv(p, v0, v1 - v0, v2 - v0);
    return uv0 * (1.0 - b.x - b.y) + uv1 * b.x + uv2 * b.y;
}

// A 3D texture point: the affine map computed on the CPU
// (TextureTransform::to_texture), as its linear part and translation.
fn to_texture_space(p: vec3f, linear: mat3x3f, translation: vec3f) -> vec3f {
    return linear * p + translation;
}

// An affine map given as three rows: (dot(r0.xyz, p) + r0.w, …); Rust:
// TextureMapping::rows.
fn affine_rows(p: vec3f, r0: vec4f, r1: vec4f, r2: vec4f) -> vec3f {
    return vec3f(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
}
