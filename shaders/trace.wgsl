// The per-frame trace pass: `samples_per_frame` jittered paths per pixel,
// folded into the running mean held in the accumulation target, and the
// spread of the frames' means folded into the second-moment target (what
// the error meter, shaders/error_meter.wgsl, estimates the image's error
// from). One body, `trace_pixel`, and two kernels that call it: `fs_trace`
// (a full-screen triangle, the targets as colour attachments) and
// `cs_trace` (a compute dispatch over a band of rows, the targets as
// storage textures). Which one runs faster depends on the adapter
// (gpu/kernel.rs); both give the same image.

#import shaders/common.wgsl
#import shaders/scene.wgsl
#import shaders/textures.wgsl
#import shaders/intersect.wgsl
#import shaders/random.wgsl
#import crates/core/src/bsdf.wgsl
#import shaders/surface.wgsl
#import shaders/env_lookup.wgsl
#import crates/core/src/mis.wgsl
#import crates/core/src/geometry/sphere.wgsl
#import crates/core/src/geometry/ray_offset.wgsl
#import shaders/fullscreen.wgsl
#import shaders/accumulation.wgsl
#import shaders/view.wgsl
#if POINT_LIGHT || AREA_LIGHT
#import crates/core/src/lights.wgsl
#endif
#if ENV_SAMPLING
#import crates/core/src/env_sampling.wgsl
#endif

@group(0) @binding(5) var previous: texture_2d<f32>;
@group(0) @binding(16) var previous_spread: texture_2d<f32>;
@group(0) @binding(18) var previous_compensation: texture_2d<f32>;

// Samples dropped for being NaN or infinite since the accumulation began
// (gpu/passes/non_finite.rs; cleared before its first frame). A correct renderer
// never adds to them: the tests and the Stats panel read them.
struct NonFiniteCounters {
    nan: atomic<u32>,
    infinite: atomic<u32>,
    pixels: atomic<u32>,
}
@group(0) @binding(17) var<storage, read_write> non_finite: NonFiniteCounters;

// What one frame leaves per pixel: the running mean of every sample so far,
// the running weighted second moment about it (Welford's update), and the
// mean's Kahan compensation (accumulation.wgsl).
struct Accumulated {
    @location(0) mean: vec4f,
    @location(1) spread: vec4f,
    @location(2) compensation: vec4f,
#if DENOISE_GUIDES
    @location(3) albedo: vec4f,
    @location(4) normal: vec4f,
#endif
}

#if DENOISE_GUIDES
// The denoiser's guides (gpu/passes/denoise.rs): the first hit's albedo (plus its
// emission) and shading normal, as the albedo and normal views record them
// (view_at_hit), averaged over the pixel's samples like the radiance.
@group(0) @binding(19) var previous_albedo: texture_2d<f32>;
@group(0) @binding(20) var previous_normal: texture_2d<f32>;
// What the current sample's camera ray met (0 where it escaped).
var<private> sample_albedo: vec3f;
var<private> sample_normal: vec3f;
#endif

struct CameraRay {
    origin: vec3f,
    d: vec3f,
}

// The camera ray through `pixel`, a position in the whole image (a crop's
// target pixel plus its origin): from the camera through the pixel, or
// for an orthographic camera along the view from the pixel's place on the
// camera's plane. CPU twin: CameraFrame::ray.
fn camera_ray(pixel: vec2f) -> CameraRay {
    let ndc = vec2f(pixel.x / frame.image_size.x * 2.0 - 1.0, 1.0 - pixel.y / frame.image_size.y * 2.0);
    if frame.ortho_half_height > 0.0 {
        let h = frame.ortho_half_height;
        let origin = frame.cam_pos + ndc.x * h * frame.aspect * frame.cam_right + ndc.y * h * frame.cam_up;
        return CameraRay(origin, frame.cam_forward);
    }
    let x = ndc.x * frame.tan_half_fov * frame.aspect;
    let y = ndc.y * frame.tan_half_fov;
    return CameraRay(frame.cam_pos, normalize(frame.cam_forward + x * frame.cam_right + y * frame.cam_up));
}

// Which side of the surface a direction `wi` leaves on: 1 along the
// geometric normal `n`, -1 against it (through the surface, where the
// diffuse transmission lobe sends it), 0 where `n` and the shading normal
// `s_n` disagree about the side (the direction would leak through the
// surface, or cross it unseen by the BSDF). Shadow and bounce rays are
// offset to that side.
fn leaving_side(wi: vec3f, n: vec3f, s_n: vec3f) -> f32 {
    let side = dot(wi, n);
    let reflected = select(0.0, 1.0, side > 0.0);
    let transmitted = select(0.0, -1.0, side < 0.0);
    return select(reflected, transmitted, dot(wi, s_n) < 0.0);
}

#if POINT_LIGHT || AREA_LIGHT
// Direct light from the light table: `frame.light_samples` points, each on
// a light chosen anew, their shadow rays through see-through surfaces,
// each weighted against BSDF sampling's chance of the same direction.
// Lights behind the surface reach it through its diffuse transmission.
fn direct_light(hit: Hit, s: SurfacePoint, wo: vec3f) -> vec3f {
    let count = frame.light_samples;
    var sum = vec3f(0.0);
    for (var k = 0u; k < count; k++) {
        let light = sample_light(hit.p, k);
        let side = leaving_side(light.wi, hit.n, s.n);
        if light.pdf > 0.0 && side != 0.0 {
            let e = eval_bsdf(s, s.n, wo, light.wi);
            var weight = 1.0;
            if !light.delta {
                weight = light_sample_weight(f32(count) * light.pdf, (1.0 - s.mirror) * e.pdf);
            }
            if weight > 0.0 && any(e.f_cos != vec3f(0.0)) {
                // Stop short of the sampled point, which lies on the light.
                let t_max = select(light.distance * (1.0 - 1e-4), light.distance, light.delta);
                let through = visibility(offset_ray(hit.p, side * hit.n), light.wi, t_max);
                sum += through * e.f_cos * light.radiance * (weight / light.pdf);
            }
        }
    }
    return (1.0 - s.mirror) * sum / f32(count);
}
#endif

#if ENV_SAMPLING
// Light from the environment map by sampling it (next-event estimation),
// weighted against BSDF sampling's chance of the same direction; the
// escape at the next bounce takes the other weight.
fn env_light(hit: Hit, s: SurfacePoint, wo: vec3f) -> vec3f {
    let sample = sample_env(rand(), rand());
    let side = leaving_side(sample.wi, hit.n, s.n);
    if sample.pdf <= 0.0 || side == 0.0 {
        return vec3f(0.0);
    }
    let e = eval_bsdf(s, s.n, wo, sample.wi);
    let weight = light_sample_weight(sample.pdf, (1.0 - s.mirror) * e.pdf);
    if weight <= 0.0 || all(e.f_cos == vec3f(0.0)) {
        return vec3f(0.0);
    }
    let through = visibility(offset_ray(hit.p, side * hit.n), sample.wi, NO_HIT);
    return through * (1.0 - s.mirror) * e.f_cos * environment(sample.wi) * weight / sample.pdf;
}
#endif

// The fraction of light that goes from `o` along `d` to distance `t_max`
// (NO_HIT: the environment), per channel.
fn visibility(o: vec3f, d: vec3f, t_max: f32) -> vec3f {
#if OPACITY
    return transmittance(o, d, t_max);
#else
    return select(vec3f(1.0), vec3f(0.0), occluded(o, d, t_max));
#endif
}

// The most surfaces a ray passes through (opacity < 1) before it counts as
// stopped: a bound, so that a stack of holes always ends.
const MAX_CROSSINGS: u32 = 16u;

#if OPACITY
// The light going from `o` along `d` that reaches distance `t_max`
// (NO_HIT: the environment) through the surfaces in between, per channel:
// each lets `1 - opacity` through, tinted by its transmission colour, like
// a ray crossing it (no refraction), so shadows take the colour of what
// casts them. Distances are compared, never points far away, whose
// squared lengths would overflow.
fn transmittance(o: vec3f, d: vec3f, t_max: f32) -> vec3f {
    var origin = o;
    var remaining = t_max;
    var through = vec3f(1.0);
    var crossings = 0u;
    loop {
        let h = intersect_scene(origin, d);
        if h.t >= remaining {
            break;
        }
        remaining -= h.t;
        through *= surface_transmittance(h.material, h.texture_point, h.p, h.uv);
        origin = offset_ray(h.p, -h.n);
        crossings++;
        continuing {
            break if all(through <= vec3f(0.0)) || crossings >= MAX_CROSSINGS;
        }
    }
    return select(through, vec3f(0.0), crossings >= MAX_CROSSINGS);
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
    let camera = camera_ray(pixel);
    var d = camera.d;
    var hit = intersect_scene(camera.origin, d);
    var throughput = vec3f(1.0);
    var radiance = vec3f(0.0);
    // Whether the path is still going: it ends by escaping or by absorption.
    var alive = true;
    var bounces = 0u;
    // Surfaces passed straight through (where opacity < 1).
    var crossings = 0u;
    // The ray cone's width where the current ray starts: it grows by the
    // pixel's spread per unit of distance, bounce after bounce (no
    // curvature term, so a mirror keeps it as the camera made it). A
    // perspective cone starts at a point; an orthographic one, whose rays
    // do not spread, as wide as a pixel on the camera's plane.
    var cone_width = 2.0 * frame.ortho_half_height / frame.image_size.y;
    // The continuous density of the last bounce's direction (0 for the
    // camera ray and mirror bounces): an escape or an emitter reached
    // weighs it against light sampling.
    var last_bsdf_pdf = 0.0;
    // Where the path last scattered: light sampling's density for the
    // emitter a bounce reaches is measured from there.
    var scatter_point = camera.origin;
#if DENOISE_GUIDES
    sample_albedo = vec3f(0.0);
    sample_normal = vec3f(0.0);
#endif
    if frame.view != VIEW_LIT && hit.t >= NO_HIT {
        return view_escaped();
    }
    if hit.t < NO_HIT && frame.max_bounces > 0u {
        loop {
            let width = cone_width + frame.pixel_spread * hit.t;
            cone_width = width;
            let s = surface_at(hit, width, d);
            // A view records the camera ray's first hit (the loop's first
            // pass), whatever its opacity, and ends the path there.
            if frame.view != VIEW_LIT {
                return view_at_hit(hit, s);
            }
#if DENOISE_GUIDES
            if bounces == 0u && crossings == 0u {
                // Emission joins the albedo: an emitter stands apart from
                // a surface of its colour, and its edge is not blurred.
                sample_albedo = s.diffuse + s.emission;
                sample_normal = 0.5 + 0.5 * s.n;
            }
#endif
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
                throughput *= s.transmission;
                origin = offset_ray(hit.p, -hit.n);
                crossings++;
            } else {
#if EMISSION
                // Triangles emit on their front side only; light sampling
                // found this emitter too, unless the bounce that reached
                // it was a delta.
                let emits = hit.front || hit.shape != SHAPE_TRIANGLE;
                var emission_weight = select(0.0, 1.0, emits);
#if AREA_LIGHT
                if emits && last_bsdf_pdf > 0.0 {
                    let light_pdf = f32(frame.light_samples) * emitter_pdf(hit, scatter_point);
                    emission_weight = bsdf_sample_weight(last_bsdf_pdf, light_pdf);
                }
#endif
                radiance += throughput * s.emission * emission_weight;
#endif
#if EMISSION || OPACITY
                if bounces >= frame.max_bounces {
                    alive = false;
                    break;
                }
#endif
#if POINT_LIGHT || AREA_LIGHT
                if frame.light_count > 0u {
                    radiance += throughput * direct_light(hit, s, wo);
                }
#endif
#if ENV_SAMPLING
                if frame.env_sampling != 0u && !directions_only(frame.strategy) {
                    radiance += throughput * env_light(hit, s, wo);
                }
#endif
                let bs = sample_bsdf(s, s.n, wo);
                let side = leaving_side(bs.wi, hit.n, s.n);
                if !bs.valid || side == 0.0 {
                    alive = false;
                    break;
                }
                throughput *= bs.weight;
                last_bsdf_pdf = bs.pdf;
                scatter_point = hit.p;
                d = bs.wi;
                origin = offset_ray(hit.p, side * hit.n);
                bounces++;
                // Russian roulette: past a few bounces a path goes on with
                // the chance of its throughput, and the survivors carry
                // the lost ones' share (unbiased).
                if frame.russian_roulette_from > 0u && bounces >= frame.russian_roulette_from {
                    let survive = min(max(throughput.x, max(throughput.y, throughput.z)), 1.0);
                    if rand() >= survive {
                        alive = false;
                        break;
                    }
                    throughput /= survive;
                }
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
            weight = bsdf_sample_weight(last_bsdf_pdf, env_pdf(d));
        }
#endif
        radiance += throughput * environment(d) * weight;
    }
    return radiance;
}

// The work of one pixel in one frame: its samples, the firefly clamp, the
// non-finite samples dropped and counted, the compensated mean and the
// spread. Both kernels call it; `frame` must be set first.
fn trace_pixel(pixel: vec2u) -> Accumulated {
    let spp = frame.samples_per_frame;
    // Seeds and rays follow the pixel of the whole image: a crop traces
    // what the whole render traces there.
    let image_pixel = pixel + frame.crop_origin;
    var sum = vec3f(0.0);
    var dropped = 0u;
#if DENOISE_GUIDES
    var albedo_sum = vec3f(0.0);
    var normal_sum = vec3f(0.0);
#endif
#if CPU_SAMPLES
    // The CPU kernel traced this pixel's samples (cpu_kernel/mod.rs): their
    // mean, the guides' means and the dropped samples' counts, in three
    // layers of the band's rows.
    let at = vec2u(pixel.x, pixel.y - frame.band_start);
    let traced = textureLoad(cpu_samples, at, 0, 0);
    let guide_albedo = textureLoad(cpu_samples, at, 1, 0);
    sum = traced.xyz;
    let nan_samples = u32(traced.w);
    let infinite_samples = u32(guide_albedo.w);
    dropped = nan_samples + infinite_samples;
    if nan_samples > 0u {
        atomicAdd(&non_finite.nan, nan_samples);
    }
    if infinite_samples > 0u {
        atomicAdd(&non_finite.infinite, infinite_samples);
    }
#if DENOISE_GUIDES
    albedo_sum = guide_albedo.xyz;
    normal_sum = textureLoad(cpu_samples, at, 2, 0).xyz;
#endif
#else
    for (var k = 0u; k < spp; k++) {
        rng_seed(image_pixel, (frame.accumulated + k) * 0x9E3779B9u + frame.frame_index);
        let jitter = vec2f(rand(), rand());
        var l = trace_path(vec2f(image_pixel) + jitter);
#if DENOISE_GUIDES
        albedo_sum += sample_albedo / f32(spp);
        normal_sum += sample_normal / f32(spp);
#endif
        // The optional firefly clamp (biased; off by default).
        let brightest = max(l.x, max(l.y, l.z));
        if frame.sample_clamp > 0.0 && brightest > frame.sample_clamp && frame.view == VIEW_LIT {
            l *= frame.sample_clamp / brightest;
        }
        // A non-finite sample never reaches the accumulation target: it is
        // dropped and counted. Dividing each sample before adding keeps the
        // sum of finite samples finite too (spp samples near f32::MAX).
        if any_non_finite(l) {
            dropped++;
            if any_nan(l) {
                atomicAdd(&non_finite.nan, 1u);
            } else {
                atomicAdd(&non_finite.infinite, 1u);
            }
        } else {
            sum += l / f32(spp);
        }
    }
#endif
    let x = sum;
    // The first frame ignores what the targets held before (a resize or a
    // reset leaves stale texels, which must not leak in, even as NaN * 0).
    let first = frame.accumulated == 0u;
    let prev = select(textureLoad(previous, pixel, 0).xyz, vec3f(0.0), first);
    let prev_spread_texel = select(textureLoad(previous_spread, pixel, 0), vec4f(0.0), first);
    let prev_spread = prev_spread_texel.xyz;
    let prev_compensation = select(textureLoad(previous_compensation, pixel, 0).xyz, vec3f(0.0), first);
    // A compensated running mean: its rounding error does not grow with the
    // frame count.
    let w = frame_weight(frame.accumulated, spp);
    let updated = compensated_mean_update(prev, prev_compensation, x, w, frame.opaque_one);
    let mean = updated.mean;
    // Weighted Welford (West 1979), kept divided by the weight like the
    // mean: spread = Σ spp_i (x_i - mean)² / Σ spp_i over the frames' means
    // x_i. With F frames of equal spp, E[spread] = (F - 1)/F · σ²/spp, so the
    // variance of the pixel's mean is estimated by spread / (F - 1)
    // (gpu::error_meter).
    // Squares of radiances above ~1e19 overflow: the spread saturates at
    // the largest float instead of becoming infinite.
    let spread = min(prev_spread + ((x - prev) * (x - mean) - prev_spread) * w, vec3f(F32_MAX));
    // The spread's alpha counts this pixel's dropped samples (the magenta
    // debug view paints where it is not zero).
    let prev_dropped = prev_spread_texel.w;
    if dropped > 0u && prev_dropped == 0.0 {
        atomicAdd(&non_finite.pixels, 1u);
    }
    var out: Accumulated;
    out.mean = vec4f(mean, 1.0);
    out.spread = vec4f(spread, prev_dropped + f32(dropped));
    out.compensation = vec4f(updated.compensation, 0.0);
#if DENOISE_GUIDES
    // Plain running means: a guide needs no more than a few bits.
    let prev_albedo = select(textureLoad(previous_albedo, pixel, 0).xyz, vec3f(0.0), first);
    let prev_normal = select(textureLoad(previous_normal, pixel, 0).xyz, vec3f(0.0), first);
    out.albedo = vec4f(prev_albedo + (albedo_sum - prev_albedo) * w, 1.0);
    out.normal = vec4f(prev_normal + (normal_sum - prev_normal) * w, 1.0);
#endif
    return out;
}

#if CPU_SAMPLES
// What the CPU kernel traced for the band this pass folds in (the fragment
// kernel's group 1; the compute kernel's outputs are never in the same
// module).
@group(1) @binding(5) var cpu_samples: texture_2d_array<f32>;
#endif

@fragment
fn fs_trace(@builtin(position) position: vec4f) -> Accumulated {
    frame = frame_slots[frame_slot()];
    return trace_pixel(vec2u(position.xy));
}

// The compute kernel's outputs: the same targets the fragment kernel
// writes as colour attachments (locations 0, 1 and 2, and the guides' 3 and
// 4).
@group(1) @binding(0) var out_mean: texture_storage_2d<rgba32float, write>;
@group(1) @binding(1) var out_spread: texture_storage_2d<rgba32float, write>;
@group(1) @binding(2) var out_compensation: texture_storage_2d<rgba32float, write>;
#if DENOISE_GUIDES
@group(1) @binding(3) var out_albedo: texture_storage_2d<rgba32float, write>;
@group(1) @binding(4) var out_normal: texture_storage_2d<rgba32float, write>;
#endif

// The compute kernel's workgroup: 16 x 8 pixels (128 invocations, four
// 32-wide SIMD groups on a GPU). On lavapipe it was 2-5 % faster than 8x8 on
// the default, tiles and Cornell presets, and never slower; 16x16 and 32x4
// lost on some (docs/PERFORMANCE.md). Rust: gpu::kernel::WORKGROUP.

// One invocation per pixel of the band of rows starting at
// `frame.band_start`; the dispatch rounds up to whole workgroups, so the
// invocations past the traced region do nothing.
@compute @workgroup_size(16, 8)
fn cs_trace(@builtin(global_invocation_id) id: vec3u) {
    frame = frame_slots[frame_slot()];
    let pixel = vec2u(id.x, id.y + frame.band_start);
    if pixel.x >= u32(frame.render_size.x) || pixel.y >= frame.band_end {
        return;
    }
    let out = trace_pixel(pixel);
    textureStore(out_mean, pixel, out.mean);
    textureStore(out_spread, pixel, out.spread);
    textureStore(out_compensation, pixel, out.compensation);
#if DENOISE_GUIDES
    textureStore(out_albedo, pixel, out.albedo);
    textureStore(out_normal, pixel, out.normal);
#endif
}
