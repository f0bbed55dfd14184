// The shading normal the BSDF may use (Rust: texture::bump::
// facing_shading_normal). A bump can tilt the normal away from the viewer,
// so that the direction the light leaves by lies below its horizon: every
// BSDF value is then 0 there and the pixel turns black, and a normal that
// barely faces it (n·wo ≈ 0) divides by that cosine. Such a normal is bent
// towards the viewer, n + (c_min - n·wo) wo normalised, the least change
// that leaves it facing the viewer at n·wo = c_min / √(1 + c_min² - (n·wo)²),
// where c_min = min(FACING_MIN_COS, n_g·wo): never asking more than the
// geometric normal `n_g` (which faces the viewer, intersect_scene flips it)
// gives, so an unbumped normal seen at a grazing angle is left as it is.
// Renderers likewise keep shading normals on the viewer's side (pbrt-v4,
// Mitsuba; Schüßler et al. 2017 discuss the energy this costs). Where even
// the bent normal is unusable (a non-finite input), `n_g` serves.

#import shaders/common.wgsl

const FACING_MIN_COS: f32 = 0.01;

fn facing_shading_normal(n_s: vec3f, n_g: vec3f, wo: vec3f) -> vec3f {
    let c = dot(n_s, wo);
    let c_min = min(FACING_MIN_COS, dot(n_g, wo));
    let bent = n_s + (c_min - c) * wo;
    let len = length(bent);
    let usable = len > 0.0 && !is_non_finite(len);
    let clamped = select(n_g, bent / len, usable);
    return select(clamped, n_s, c >= c_min);
}
