// The lab's latitude-longitude mapping; twin of envmap.rs.
// u = (atan2(x, z) + π) / 2π, v = acos(-y) / π: v = 0 looks straight down.
// v is taken as atan2(|xz|, -y) / π, the same angle, because acos of a y
// near ±1 (which rounds in steps of 6e-8) loses θ's digits at the poles.

#import shaders/common.wgsl

fn env_uv(d: vec3f) -> vec2f {
    // atan2(0, 0) is undefined: at the poles every u is the same texel row.
    var u = 0.5;
    if d.x != 0.0 || d.z != 0.0 {
        u = (atan2(d.x, d.z) + PI) / TWO_PI;
    }
    let v = atan2(length(d.xz), -d.y) / PI;
    return vec2f(u, v);
}

// Turns a direction about +y by `-angle`, so a positive rotation turns the map.
fn rotate_y(d: vec3f, angle: f32) -> vec3f {
    let c = cos(angle);
    let s = sin(angle);
    return vec3f(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}
