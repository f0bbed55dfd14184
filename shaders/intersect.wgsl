// Ray-scene intersection. Rays start on robustly offset origins (see
// offset_ray), so t > 0 is the only lower bound needed.

struct Hit {
    t: f32,
    p: vec3f,
    n: vec3f,            // geometric normal, facing the ray's origin side
    texture_point: vec3f,
    // The primitive's 2D texture coordinates: lat-long on a sphere, world
    // (x, z) on the ground. Only computed where a 2D pattern reads them.
    uv: vec2f,
#if BUMP
    // ∂p/∂u and ∂p/∂v: how the surface moves with its (u, v), for bumps.
    dp_du: vec3f,
    dp_dv: vec3f,
#endif
    material: u32,
}

const NO_HIT: f32 = 3.0e38;

// Smallest positive root of |o + t d - c| = r, d unit length, or NO_HIT.
// Haines et al. (Ray Tracing Gems ch. 7): the discriminant is computed from
// the perpendicular distance, which keeps precision for small spheres far
// away, and the roots by the stable quadratic (no cancellation).
fn intersect_sphere(o: vec3f, d: vec3f, s: Sphere) -> f32 {
    let f = o - s.center;
    let b = -dot(f, d);
    let perp = f + b * d;
    let r2 = s.radius * s.radius;
    let disc = r2 - dot(perp, perp);
    if disc < 0.0 {
        return NO_HIT;
    }
    let q = b + select(-1.0, 1.0, b >= 0.0) * sqrt(disc);
    if q == 0.0 {
        return NO_HIT;
    }
    let c = dot(f, f) - r2;
    let t0 = c / q;
    let t1 = q;
    let near = min(t0, t1);
    let far = max(t0, t1);
    if near > 0.0 {
        return near;
    }
    if far > 0.0 {
        return far;
    }
    return NO_HIT;
}

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
#if BUMP
        // Lat-long about +y: u turns around the axis (2π r per unit), v
        // climbs from pole to pole (π r per unit). Zero at the poles, where
        // bumped_normal keeps the plain normal.
        let ring = length(dir.xz);
        hit.dp_du = TWO_PI * s.radius * vec3f(dir.z, 0.0, -dir.x);
        let climb = vec3f(-dir.y * dir.x / ring, ring, -dir.y * dir.z / ring);
        hit.dp_dv = select(vec3f(0.0), PI * s.radius * climb, ring > 0.0);
#endif
        hit.material = index;
    }
#if GROUND
    if frame.has_ground != 0u && d.y != 0.0 {
        let t = (frame.ground_height - o.y) / d.y;
        if t > 0.0 && t < hit.t {
            hit.t = t;
            hit.p = vec3f(o.x + t * d.x, frame.ground_height, o.z + t * d.z);
            hit.n = vec3f(0.0, 1.0, 0.0);
            hit.texture_point = vec3f(hit.p.x, 0.0, hit.p.z);
            hit.uv = vec2f(hit.p.x, hit.p.z);
#if BUMP
            hit.dp_du = vec3f(1.0, 0.0, 0.0);
            hit.dp_dv = vec3f(0.0, 0.0, 1.0);
#endif
            hit.material = frame.sphere_count;
        }
    }
#endif
    if hit.t < NO_HIT && dot(hit.n, d) > 0.0 {
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
#if GROUND
    if frame.has_ground != 0u && d.y != 0.0 {
        let t = (frame.ground_height - o.y) / d.y;
        if t > 0.0 && t < t_max {
            return true;
        }
    }
#endif
    return false;
}

// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection"
// (Ray Tracing Gems ch. 6): move the origin off the surface by a number of
// ULPs proportional to its magnitude, so it works at every scene scale. `n`
// points to the side the new ray leaves on.
fn offset_ray(p: vec3f, n: vec3f) -> vec3f {
    let origin = 1.0 / 32.0;
    let float_scale = 1.0 / 65536.0;
    let int_scale = 256.0;
    let of_i = vec3i(int_scale * n);
    let p_i = vec3f(
        bitcast<f32>(bitcast<i32>(p.x) + select(of_i.x, -of_i.x, p.x < 0.0)),
        bitcast<f32>(bitcast<i32>(p.y) + select(of_i.y, -of_i.y, p.y < 0.0)),
        bitcast<f32>(bitcast<i32>(p.z) + select(of_i.z, -of_i.z, p.z < 0.0)),
    );
    return vec3f(
        select(p_i.x, p.x + float_scale * n.x, abs(p.x) < origin),
        select(p_i.y, p.y + float_scale * n.y, abs(p.y) < origin),
        select(p_i.z, p.z + float_scale * n.z, abs(p.z) < origin),
    );
}
