// The ray-sphere distance; twin of sphere.rs. Shared by the trace pass
// (intersect.wgsl, lights.wgsl) and the geometry harness, which holds it to
// its CPU twin and to double precision.

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
