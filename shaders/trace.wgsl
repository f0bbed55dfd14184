// The per-frame trace pass: a full-screen triangle whose fragment shader
// traces `samples_per_frame` jittered paths per pixel and folds them into the
// running mean held in the accumulation target.

@group(0) @binding(5) var previous: texture_2d<f32>;

fn camera_ray(pixel: vec2f) -> vec3f {
    let ndc = vec2f(pixel.x / frame.render_size.x * 2.0 - 1.0, 1.0 - pixel.y / frame.render_size.y * 2.0);
    let x = ndc.x * frame.tan_half_fov * frame.aspect;
    let y = ndc.y * frame.tan_half_fov;
    return normalize(frame.cam_forward + x * frame.cam_right + y * frame.cam_up);
}

#if POINT_LIGHT
fn point_light(hit: Hit, s: SurfacePoint, wo: vec3f) -> vec3f {
    let to_light = frame.light_pos - hit.p;
    let dist2 = dot(to_light, to_light);
    let wi = to_light * inverseSqrt(dist2);
    let f_cos = eval_bsdf(s, s.n, wo, wi).f_cos;
    if all(f_cos == vec3f(0.0)) {
        return vec3f(0.0);
    }
    let origin = offset_ray(hit.p, hit.n);
#if OPACITY
    let through = transmittance(origin, wi, length(frame.light_pos - origin));
#else
    let through = select(1.0, 0.0, occluded(origin, wi, length(frame.light_pos - origin)));
#endif
    return through * (1.0 - s.mirror) * f_cos * frame.light_power / dist2;
}
#endif

#if ENV_SAMPLING
// Light from the environment map by sampling it (next-event estimation),
// weighted against BSDF sampling's chance of the same direction by the
// power heuristic; the escape at the next bounce takes the other weight.
fn env_light(hit: Hit, s: SurfacePoint, wo: vec3f) -> vec3f {
    let sample = sample_env(rand(), rand());
    if sample.pdf <= 0.0 || dot(sample.wi, hit.n) <= 0.0 {
        return vec3f(0.0);
    }
    let e = eval_bsdf(s, s.n, wo, sample.wi);
    if all(e.f_cos == vec3f(0.0)) {
        return vec3f(0.0);
    }
    let origin = offset_ray(hit.p, hit.n);
#if OPACITY
    let through = transmittance(origin, sample.wi, NO_HIT);
#else
    let through = select(1.0, 0.0, occluded(origin, sample.wi, NO_HIT));
#endif
    let weight = power_heuristic(sample.pdf, (1.0 - s.mirror) * e.pdf);
    return through * (1.0 - s.mirror) * e.f_cos * environment(sample.wi) * weight / sample.pdf;
}
#endif

// The most surfaces a ray passes through (opacity < 1) before it counts as
// stopped: a bound, so that a stack of holes always ends.
const MAX_CROSSINGS: u32 = 16u;

#if OPACITY
// The fraction of light going from `o` along `d` that reaches distance
// `t_max` (NO_HIT: the environment) through the surfaces in between: each
// lets `1 - opacity` through, like a ray crossing it (no refraction, no
// tint). Distances are compared, never points far away, whose squared
// lengths would overflow.
fn transmittance(o: vec3f, d: vec3f, t_max: f32) -> f32 {
    var origin = o;
    var remaining = t_max;
    var through = 1.0;
    var crossings = 0u;
    loop {
        let h = intersect_scene(origin, d);
        if h.t >= remaining {
            break;
        }
        remaining -= h.t;
        through *= 1.0 - clamp(surface_opacity(h.material, h.texture_point, h.p, h.uv), 0.0, 1.0);
        origin = offset_ray(h.p, -h.n);
        crossings++;
        continuing {
            break if through <= 0.0 || crossings >= MAX_CROSSINGS;
        }
    }
    return select(through, 0.0, crossings >= MAX_CROSSINGS);
}
#endif

#if EMISSION || OPACITY
// With emitters or holes, the loop runs one pass past the last bounce: to
// add the emission of the surface the last bounce reached (as the
// environment is added when it escapes), and to let the path through that
// surface where it has a hole (crossing is not bouncing).
const FINAL_VERTEX_PASS: u32 = 1u;
#else
const FINAL_VERTEX_PASS: u32 = 0u;
#endif

// SIMD lanes run every piece of code some lane needs, and lavapipe runs
// every branch and at least one pass of every loop. So each expensive site
// appears once: one intersection before the loop and one at the end of each
// bounce, the shading once per bounce, the environment once after the loop.
// The loop tests whether to go on at its end (a do-while): a test at the top
// would cost one more pass, under an empty mask, after the last bounce
// (measured: 11 % of the default preset's frame).
fn trace_path(pixel: vec2f) -> vec3f {
    var d = camera_ray(pixel);
    var hit = intersect_scene(frame.cam_pos, d);
    var throughput = vec3f(1.0);
    var radiance = vec3f(0.0);
    // Whether the path is still going: it ends by escaping or by absorption.
    var alive = true;
    var bounces = 0u;
    // Surfaces passed straight through (where opacity < 1).
    var crossings = 0u;
    // The ray cone's width where the current ray starts: it grows by the
    // pixel's spread per unit of distance, bounce after bounce (no
    // curvature term, so a mirror keeps it as the camera made it).
    var cone_width = 0.0;
    // The continuous density of the last bounce's direction (0 for the
    // camera ray and mirror bounces): an escape weighs it against env
    // sampling.
    var last_bsdf_pdf = 0.0;
    if hit.t < NO_HIT && frame.max_bounces > 0u {
        loop {
            let width = cone_width + frame.pixel_spread * hit.t;
            cone_width = width;
            let s = surface_at(hit, width, d);
            let wo = -d;
#if OPACITY
            // Draws only where the surface has holes, so an opaque scene
            // keeps its random sequence whether or not this is compiled in.
            let crossing = s.opacity < 1.0 && rand() >= s.opacity;
#else
            let crossing = false;
#endif
            var origin: vec3f;
            if crossing {
                origin = offset_ray(hit.p, -hit.n);
                crossings++;
            } else {
#if EMISSION
                radiance += throughput * s.emission;
#endif
#if EMISSION || OPACITY
                if bounces >= frame.max_bounces {
                    alive = false;
                    break;
                }
#endif
#if POINT_LIGHT
                radiance += throughput * point_light(hit, s, wo);
#endif
#if ENV_SAMPLING
                if frame.env_sampling != 0u {
                    radiance += throughput * env_light(hit, s, wo);
                }
#endif
                let bs = sample_bsdf(s, s.n, wo);
                if !bs.valid || dot(bs.wi, hit.n) <= 0.0 {
                    alive = false;
                    break;
                }
                throughput *= bs.weight;
                last_bsdf_pdf = bs.pdf;
                d = bs.wi;
                origin = offset_ray(hit.p, hit.n);
                bounces++;
            }
            hit = intersect_scene(origin, d);
            continuing {
                break if bounces >= frame.max_bounces + FINAL_VERTEX_PASS || hit.t >= NO_HIT || crossings >= MAX_CROSSINGS;
            }
        }
    }
    // A path that escaped sees the environment; the camera sees it only if
    // the background is visible. One that ran out of bounces on a surface
    // gets nothing more.
    let escaped = alive && hit.t >= NO_HIT && crossings < MAX_CROSSINGS;
    if escaped && (bounces > 0u || frame.background_visible != 0u) {
        var weight = 1.0;
#if ENV_SAMPLING
        if frame.env_sampling != 0u && last_bsdf_pdf > 0.0 {
            weight = power_heuristic(last_bsdf_pdf, env_pdf(d));
        }
#endif
        radiance += throughput * environment(d) * weight;
    }
    return radiance;
}

@fragment
fn fs_trace(@builtin(position) position: vec4f) -> @location(0) vec4f {
    let pixel = vec2u(position.xy);
    let spp = frame.samples_per_frame;
    var sum = vec3f(0.0);
    for (var k = 0u; k < spp; k++) {
        rng_seed(pixel, (frame.accumulated + k) * 0x9E3779B9u + frame.frame_index);
        let jitter = vec2f(rand(), rand());
        let l = trace_path(vec2f(pixel) + jitter);
        // A non-finite sample never reaches the accumulation target.
        if !any_non_finite(l) {
            sum += l;
        }
    }
    let mean = sum / f32(spp);
    let n = f32(frame.accumulated);
    let prev = textureLoad(previous, pixel, 0).xyz;
    // A running mean: its rounding error does not grow with the frame count.
    let blended = prev + (mean - prev) * (f32(spp) / (n + f32(spp)));
    return vec4f(blended, 1.0);
}
