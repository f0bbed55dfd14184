// Constants and small helpers shared by every entry point.

const PI: f32 = 3.14159265358979;
const TWO_PI: f32 = 6.28318530717959;
const INV_PI: f32 = 0.318309886183791;
const F32_MAX: f32 = 0x1.fffffep+127f;

fn luminance(c: vec3f) -> f32 {
    return dot(c, vec3f(0.2126, 0.7152, 0.0722));
}

// True for NaN and ±Inf. Tested on the bit pattern: WGSL lets compilers assume
// finite maths, so `x != x` may be folded to false.
fn is_non_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) == 0x7f800000u;
}

fn any_non_finite(v: vec3f) -> bool {
    return is_non_finite(v.x) || is_non_finite(v.y) || is_non_finite(v.z);
}

// NaN only (an infinity has a zero mantissa).
fn is_nan(x: f32) -> bool {
    let bits = bitcast<u32>(x);
    return (bits & 0x7f800000u) == 0x7f800000u && (bits & 0x007fffffu) != 0u;
}

fn any_nan(v: vec3f) -> bool {
    return is_nan(v.x) || is_nan(v.y) || is_nan(v.z);
}
