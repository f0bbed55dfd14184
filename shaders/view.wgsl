// The views of the first surface a camera ray meets (Rust: scene::View):
// what a sample records instead of radiance when `frame.view` is not
// VIEW_LIT. The Monte Carlo lab's exercises 1 (hit mask) and 2 (a colour
// per triangle), then the normal, albedo and depth of the hit. Each is a
// value in [0, 1] averaged over the pixel's jittered samples like the
// radiance, and shown unexposed and clamped (RenderSettings::shown_display).

#import shaders/scene.wgsl
#import shaders/intersect.wgsl

const VIEW_LIT: u32 = 0u;
const VIEW_HIT_MASK: u32 = 1u;
const VIEW_PRIMITIVE: u32 = 2u;
const VIEW_NORMAL: u32 = 3u;
const VIEW_ALBEDO: u32 = 4u;
const VIEW_DEPTH: u32 = 5u;

// A flat colour for primitive `index` of kind `shape` (SHAPE_*): its hash,
// each channel in [0.15, 1] so none is black like the background.
fn primitive_colour(shape: u32, index: u32) -> vec3f {
    let h = pcg3d(vec3u(shape, index, 0x2545F491u)) >> vec3u(8u);
    return 0.15 + 0.85 * vec3f(h) * (1.0 / 16777216.0);
}

// The view's value where the camera ray meets `hit`, whose surface is `s`.
fn view_at_hit(hit: Hit, s: SurfacePoint) -> vec3f {
    switch frame.view {
        case VIEW_PRIMITIVE: {
            return primitive_colour(hit.shape, hit.index);
        }
        case VIEW_NORMAL: {
            return 0.5 + 0.5 * s.n;
        }
        case VIEW_ALBEDO: {
            return s.diffuse;
        }
        case VIEW_DEPTH: {
            return vec3f(hit.t / (hit.t + frame.depth_scale));
        }
        default: {
            return vec3f(1.0);
        }
    }
}

// The view's value where the camera ray escapes: black, but for depth,
// where an escape is infinitely far (1).
fn view_escaped() -> vec3f {
    return select(vec3f(0.0), vec3f(1.0), frame.view == VIEW_DEPTH);
}
