// The ray geometry that needs no scene: the sphere's distance and the
// robust ray offset. Shared by the trace pass (intersect.wgsl, lights.wgsl)
// and the geometry harness, which holds them to their CPU twins
// (src/geometry/) and to double precision.

const NO_HIT: f32 = 3.0e38;

// Smallest positive root of |o + t d - c| = r, d unit length, or NO_HIT.
// Haines et al. (Ray Tracing Gems ch. 7): the discriminant is computed from
// the perpendicular distance, which keeps precision for small spheres far
// away, and the roots by the stable quadratic (no cancellation).
fn sphere_distance(o: vec3f, d: vec3f, center: vec3f, radius: f32) -> f32 {
    let f = o - center;
    let b = -dot(f, d);
    let perp = f + b * d;
    let r2 = radius * radius;
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

// offset_ray's constants (Rust: geometry::ray_offset): below OFFSET_ORIGIN
// a coordinate moves by OFFSET_FLOAT_SCALE (1/65536) times the normal,
// elsewhere by OFFSET_INT_SCALE times the normal in units in its last place.
const OFFSET_ORIGIN: f32 = 0.03125;
const OFFSET_FLOAT_SCALE: f32 = 1.52587890625e-5;
const OFFSET_INT_SCALE: f32 = 256.0;

// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection"
// (Ray Tracing Gems ch. 6): move the origin off the surface by a number of
// ULPs proportional to its magnitude, so it works at every scene scale. `n`
// points to the side the new ray leaves on.
fn offset_ray(p: vec3f, n: vec3f) -> vec3f {
    let origin = OFFSET_ORIGIN;
    let float_scale = OFFSET_FLOAT_SCALE;
    let of_i = vec3i(OFFSET_INT_SCALE * n);
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
