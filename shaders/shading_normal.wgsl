// The shading normal the BSDF may use (Rust: texture::bump::
// facing_shading_normal). A bump can tilt the normal away from the viewer,
// so that the direction the light leaves by lies below its horizon: every
// BSDF value is then 0 there and the pixel turns black, and a normal that
// barely faces it (n·wo ≈ 0) divides by that cosine. Such a normal is bent
// towards the viewer, n + (FACING_MIN_COS - n·wo) wo normalised, the least
// change that leaves it facing the viewer at n·wo ≥ FACING_MIN_COS / √(1 +
// FACING_MIN_COS²), as renderers clamp shading normals that face away
// (pbrt-v4 and Mitsuba keep them on the geometric normal's side; Schüßler
// et al. 2017 discuss the energy this costs). Where even that is not
// usable (a non-finite input), the geometric normal `n_g` serves, which
// faces the viewer by construction (intersect_scene flips it).

const FACING_MIN_COS: f32 = 0.01;

fn facing_shading_normal(n_s: vec3f, n_g: vec3f, wo: vec3f) -> vec3f {
    let c = dot(n_s, wo);
    let bent = n_s + (FACING_MIN_COS - c) * wo;
    let len = length(bent);
    let usable = len > 0.0 && !is_non_finite(len);
    let clamped = select(n_g, bent / len, usable);
    return select(clamped, n_s, c >= FACING_MIN_COS);
}
