// Display pass: exposure, tone mapping and (for non-sRGB targets) encoding,
// from the accumulation target onto the window or an offscreen image.

#import shaders/fullscreen.wgsl

struct DisplayUniform {
    // 2^exposure: the manual exposure, or with auto exposure the
    // compensation applied on top of the metered scale.
    exposure_scale: f32,
    tone_map: u32,          // 0 ACES, 1 Reinhard, 2 clamp, 3 1 - exp
    encode_srgb: u32,       // 1 when the target format does not encode
    auto_exposure: u32,     // 1: also scale by `metered.scale`, 2: by `metered.rms_scale`
    // Maps a target pixel to an accumulation texel: texel = (pixel - origin) * scale.
    origin: vec2f,
    scale: vec2f,
    // 1: paint the pixels that dropped a non-finite sample magenta.
    show_non_finite: u32,
    padding: u32,
}

// What the auto-exposure pass wrote (auto_exposure.wgsl; same layout).
struct Metered {
    log_average: f32,
    stops: f32,
    scale: f32,
    count: u32,
    rms: f32,
    rms_stops: f32,
    rms_scale: f32,
    padding: u32,
}

@group(0) @binding(0) var<uniform> display: DisplayUniform;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var<uniform> metered: Metered;
// The spread target: its alpha counts the pixel's dropped non-finite
// samples (trace.wgsl).
@group(0) @binding(3) var spread: texture_2d<f32>;

const MAGENTA: vec4f = vec4f(1.0, 0.0, 1.0, 1.0);

// Narkowicz's fit of the ACES filmic curve.
fn aces(x: vec3f) -> vec3f {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3f(0.0), vec3f(1.0));
}

fn srgb_encode(c: vec3f) -> vec3f {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3f(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3f(0.0031308));
}

fn tone_map(c: vec3f) -> vec3f {
    switch display.tone_map {
        case 0u: {
            return aces(c);
        }
        case 1u: {
            return c / (1.0 + c);
        }
        case 3u: {
            // Massal's exposure curve.
            return 1.0 - exp(-c);
        }
        default: {
            return clamp(c, vec3f(0.0), vec3f(1.0));
        }
    }
}

@fragment
fn fs_display(@builtin(position) position: vec4f) -> @location(0) vec4f {
    let size = vec2i(textureDimensions(radiance));
    let texel = clamp(vec2i(floor((position.xy - display.origin) * display.scale)), vec2i(0), size - 1);
    if display.show_non_finite != 0u && textureLoad(spread, texel, 0).a > 0.0 {
        return MAGENTA;
    }
    var metered_scale = 1.0;
    if display.auto_exposure == 1u {
        metered_scale = metered.scale;
    } else if display.auto_exposure == 2u {
        metered_scale = metered.rms_scale;
    }
    let scale = display.exposure_scale * metered_scale;
    let c = max(textureLoad(radiance, texel, 0).rgb * scale, vec3f(0.0));
    var mapped = tone_map(c);
    if display.encode_srgb != 0u {
        mapped = srgb_encode(mapped);
    }
    return vec4f(mapped, 1.0);
}
