// The robust ray offset; twin of ray_offset.rs. Shared by the trace pass
// and the geometry harness, which holds it to its CPU twin.

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
