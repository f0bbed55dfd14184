// Ray-scene intersection. Rays start on robustly offset origins (see
// offset_ray in geometry/ray_offset.wgsl), so t > 0 is the only lower
// bound needed.

#import shaders/common.wgsl
#import shaders/scene.wgsl
#import crates/core/src/geometry/sphere.wgsl
#import crates/core/src/texture/mapping.wgsl

struct Hit {
    t: f32,
    p: vec3f,
    n: vec3f,            // geometric normal, facing the ray's origin side
    texture_point: vec3f,
    // The primitive's 2D texture coordinates: lat-long on a sphere, the
    // ground's frame (world (x, z) without one) on the ground. Only computed where a 2D pattern reads them.
    uv: vec2f,
#if TANGENTS
    // ∂p/∂u and ∂p/∂v: how the surface moves with its (u, v), for bumps
    // and footprints.
    dp_du: vec3f,
    dp_dv: vec3f,
#endif
    material: u32,
    // Which primitive: its kind (SHAPE_*) and index among its kind.
    shape: u32,
    index: u32,
    // Whether the ray arrived on the side the primitive faces (its
    // outside, or a triangle's counter-clockwise side): emitters emit there.
    front: bool,
}

const SHAPE_SPHERE: u32 = 0u;
const SHAPE_CYLINDER: u32 = 1u;
const SHAPE_POLYGON: u32 = 2u;
const SHAPE_GROUND: u32 = 3u;
const SHAPE_TRIANGLE: u32 = 4u;

// The sphere's distance (geometry/sphere.wgsl) read from the uniform array.
fn intersect_sphere(o: vec3f, d: vec3f, s: Sphere) -> f32 {
    return sphere_distance(o, d, s.center, s.radius);
}

#if CYLINDER
// Where a ray meets a cylinder: the distance, and which part (0 the side,
// 1 the bottom cap, 2 the top), or NO_HIT. The side solves the quadratic in
// the xz plane with the same stable form as the sphere.
struct CylinderHit {
    t: f32,
    part: u32,
}

fn intersect_cylinder(o: vec3f, d: vec3f, c: Cylinder) -> CylinderHit {
    let f = o - c.base;
    var best = CylinderHit(NO_HIT, 0u);
    let a = dot(d.xz, d.xz);
    if a > 0.0 {
        let b = -dot(f.xz, d.xz) / a;
        let perp = f.xz + b * d.xz;
        let disc = (c.radius * c.radius - dot(perp, perp)) / a;
        if disc >= 0.0 {
            let root = sqrt(disc);
            for (var k = 0u; k < 2u; k++) {
                let t = select(b + root, b - root, k == 0u);
                let y = f.y + t * d.y;
                if t > 0.0 && t < best.t && y >= 0.0 && y <= c.height {
                    best = CylinderHit(t, 0u);
                }
            }
        }
    }
    if d.y != 0.0 {
        for (var k = 0u; k < 2u; k++) {
            let y = select(c.height, 0.0, k == 0u);
            let t = (y - f.y) / d.y;
            let q = f.xz + t * d.xz;
            if t > 0.0 && t < best.t && dot(q, q) <= c.radius * c.radius {
                best = CylinderHit(t, 1u + k);
            }
        }
    }
    return best;
}
#endif

#if POLYGON
// Distance along the ray to convex polygon `index`, or NO_HIT: the plane,
// then the point on the inner side of every edge. Fields are read from the
// uniform array in place (copying the struct and indexing the copy by a
// loop counter made llvmpipe spill it: 5× the frame), and every edge is
// tested without an early exit (the loop's trip count is the same for all
// lanes).
fn intersect_polygon(o: vec3f, d: vec3f, index: u32) -> f32 {
    let normal = polygons[index].normal;
    let denominator = dot(d, normal);
    let t = dot(polygons[index].vertices[0].xyz - o, normal) / denominator;
    let p = o + t * d;
    let n = min(polygons[index].vertex_count, MAX_POLYGON_VERTICES);
    var inside = denominator != 0.0 && t > 0.0;
    var a = polygons[index].vertices[n - 1u].xyz;
    for (var i = 0u; i < n; i++) {
        let b = polygons[index].vertices[i].xyz;
        inside = inside && dot(cross(b - a, p - a), normal) >= 0.0;
        a = b;
    }
    return select(NO_HIT, t, inside);
}
#endif

fn intersect_scene(o: vec3f, d: vec3f) -> Hit {
    var hit: Hit;
    hit.t = NO_HIT;
    var index = 0u;
    for (var i = 0u; i < frame.sphere_count; i++) {
        let t = intersect_sphere(o, d, spheres[i]);
        if t < hit.t {
            hit.t = t;
            index = i;
        }
    }
    if hit.t < NO_HIT {
        let s = spheres[index];
        // Re-project onto the sphere: o + t d carries the error of t.
        let dir = normalize(o + hit.t * d - s.center);
        hit.p = s.center + dir * s.radius;
        hit.n = dir;
        hit.texture_point = hit.p - s.center;
#if TEXTURE_UV
        hit.uv = sphere_uv(dir);
#endif
#if TANGENTS
        // Lat-long about +y: u turns around the axis (2π r per unit), v
        // climbs from pole to pole (π r per unit). Zero at the poles, where
        // bumped_normal keeps the plain normal.
        let ring = length(dir.xz);
        hit.dp_du = TWO_PI * s.radius * vec3f(dir.z, 0.0, -dir.x);
        let climb = vec3f(-dir.y * dir.x / ring, ring, -dir.y * dir.z / ring);
        hit.dp_dv = select(vec3f(0.0), PI * s.radius * climb, ring > 0.0);
#endif
        hit.material = index;
        hit.shape = SHAPE_SPHERE;
        hit.index = index;
    }
#if CYLINDER
    for (var i = 0u; i < frame.cylinder_count; i++) {
        let c = cylinders[i];
        let ch = intersect_cylinder(o, d, c);
        if ch.t < hit.t {
            hit.t = ch.t;
            hit.p = o + ch.t * d;
            let local = hit.p - c.base;
            hit.texture_point = local;
            let ring = local.xz / c.radius;
            if ch.part == 0u {
                hit.n = normalize(vec3f(ring.x, 0.0, ring.y));
#if TEXTURE_UV
                hit.uv = cylinder_uv(local, c.height);
#endif
#if TANGENTS
                hit.dp_du = TWO_PI * c.radius * vec3f(hit.n.z, 0.0, -hit.n.x);
                hit.dp_dv = vec3f(0.0, c.height, 0.0);
#endif
            } else {
                // The caps: the disc onto the unit square.
                hit.n = vec3f(0.0, select(-1.0, 1.0, ch.part == 2u), 0.0);
#if TEXTURE_UV
                hit.uv = 0.5 + 0.5 * ring;
#endif
#if TANGENTS
                hit.dp_du = vec3f(2.0 * c.radius, 0.0, 0.0);
                hit.dp_dv = vec3f(0.0, 0.0, 2.0 * c.radius);
#endif
            }
            hit.material = frame.sphere_count + i;
            hit.shape = SHAPE_CYLINDER;
            hit.index = i;
        }
    }
#endif
#if POLYGON
    for (var i = 0u; i < frame.polygon_count; i++) {
        let t = intersect_polygon(o, d, i);
        if t < hit.t {
            let normal = polygons[i].normal;
            hit.t = t;
            // On the plane exactly, whatever the rounding of t.
            let q = o + t * d;
            hit.p = q - dot(q - polygons[i].vertices[0].xyz, normal) * normal;
            hit.n = normal;
            hit.texture_point = hit.p;
#if TEXTURE_UV
            hit.uv = plane_uv(hit.p, polygons[i].uv_origin, polygons[i].uv_u, polygons[i].uv_v);
#endif
#if TANGENTS
            hit.dp_du = polygons[i].uv_u;
            hit.dp_dv = polygons[i].uv_v;
#endif
            hit.material = frame.sphere_count + frame.cylinder_count + i;
            hit.shape = SHAPE_POLYGON;
            hit.index = i;
        }
    }
#endif
#if GROUND
    if frame.has_ground != 0u && d.y != 0.0 {
        let t = (frame.ground_height - o.y) / d.y;
        if t > 0.0 && t < hit.t {
            hit.t = t;
            hit.p = vec3f(o.x + t * d.x, frame.ground_height, o.z + t * d.z);
            hit.n = vec3f(0.0, 1.0, 0.0);
            hit.texture_point = vec3f(hit.p.x, 0.0, hit.p.z);
            hit.uv = plane_uv(hit.p, frame.ground_uv_origin, frame.ground_uv_u, frame.ground_uv_v);
#if TANGENTS
            hit.dp_du = frame.ground_uv_u;
            hit.dp_dv = frame.ground_uv_v;
#endif
            hit.material = frame.sphere_count + frame.cylinder_count + frame.polygon_count;
            hit.shape = SHAPE_GROUND;
            hit.index = 0u;
        }
    }
#endif
#if MESH
    let m = slab_ray_intersect(o, d, hit.t);
    if m.t < hit.t {
        let tri = mesh_triangles[m.triangle];
        let a = mesh_attributes[m.triangle];
        let e1 = tri.v1.xyz - tri.v0.xyz;
        let e2 = tri.v2.xyz - tri.v0.xyz;
        hit.t = m.t;
        // From the barycentrics: on the triangle's plane whatever the
        // rounding of t.
        hit.p = tri.v0.xyz + m.b1 * e1 + m.b2 * e2;
        hit.n = normalize(cross(e1, e2));
        hit.texture_point = hit.p;
        let b0 = 1.0 - m.b1 - m.b2;
        hit.uv = b0 * a.uv01.xy + m.b1 * a.uv01.zw + m.b2 * a.uv2;
#if TANGENTS
        // Solve p = p0 + Δu ∂p/∂u + Δv ∂p/∂v over the two edges (pbrt);
        // degenerate (u, v) get the edges themselves.
        let du1 = a.uv01.zw - a.uv01.xy;
        let du2 = a.uv2 - a.uv01.xy;
        let det = du1.x * du2.y - du1.y * du2.x;
        let ok = abs(det) > 1e-12;
        let inv = select(0.0, 1.0 / det, ok);
        hit.dp_du = select(e1, (du2.y * e1 - du1.y * e2) * inv, ok);
        hit.dp_dv = select(e2, (du1.x * e2 - du2.x * e1) * inv, ok);
#endif
        hit.material = a.material;
        hit.shape = SHAPE_TRIANGLE;
        hit.index = m.triangle;
    }
#endif
    hit.front = dot(hit.n, d) <= 0.0;
    if hit.t < NO_HIT && !hit.front {
        hit.n = -hit.n;
    }
    return hit;
}

// Whether anything lies along o + t d for 0 < t < t_max.
fn occluded(o: vec3f, d: vec3f, t_max: f32) -> bool {
    for (var i = 0u; i < frame.sphere_count; i++) {
        if intersect_sphere(o, d, spheres[i]) < t_max {
            return true;
        }
    }
#if CYLINDER
    for (var i = 0u; i < frame.cylinder_count; i++) {
        if intersect_cylinder(o, d, cylinders[i]).t < t_max {
            return true;
        }
    }
#endif
#if POLYGON
    for (var i = 0u; i < frame.polygon_count; i++) {
        if intersect_polygon(o, d, i) < t_max {
            return true;
        }
    }
#endif
#if GROUND
    if frame.has_ground != 0u && d.y != 0.0 {
        let t = (frame.ground_height - o.y) / d.y;
        if t > 0.0 && t < t_max {
            return true;
        }
    }
#endif
#if MESH
    if slab_ray_occluded(o, d, t_max) {
        return true;
    }
#endif
    return false;
}
