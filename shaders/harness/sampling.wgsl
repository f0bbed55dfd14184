// Runs the sampling functions the trace pass uses (bsdf.wgsl,
// env_sampling.wgsl, env_lookup.wgsl, mis.wgsl) on inputs given from the
// CPU, so tests can feed the shader's own samples and densities to the
// chi² test and compare them with the CPU twins (sampling.rs).

#import shaders/common.wgsl
#import crates/core/src/noise/hash.wgsl
#import shaders/random.wgsl
#import crates/core/src/envmap.wgsl
#import crates/core/src/bsdf.wgsl
#import shaders/env_lookup.wgsl
#import crates/core/src/mis.wgsl
#import crates/core/src/env_sampling.wgsl

// The fields of the trace pass's Frame these files read, then the
// harness's own: what to run and the surface the BSDF modes use.
struct SamplingFrame {
    env_constant: vec3f,
    env_intensity: f32,
    env_distribution_size: vec2u,
    env_rotation: f32,
    env_kind: u32,
    strategy: u32,
    mode: u32,
    count: u32,
    alpha: f32,
    diffuse: vec3f,
    mirror: f32,
    specular: vec3f,
    uniform_diffuse: u32,
    normal: vec3f,
    wo: vec3f,
    diffuse_transmission: vec3f,
}

@group(0) @binding(0) var<uniform> frame: SamplingFrame;
@group(0) @binding(1) var<storage, read> inputs: array<vec4f>;
// Two vec4 per input.
@group(0) @binding(2) var<storage, read_write> outputs: array<vec4f>;

const MODE_ENV_SAMPLE: u32 = 0u;
const MODE_ENV_PDF: u32 = 1u;
const MODE_ENV_RADIANCE: u32 = 2u;
const MODE_BSDF_SAMPLE: u32 = 3u;
const MODE_BSDF_EVAL: u32 = 4u;
const MODE_MIS: u32 = 5u;

fn harness_surface() -> SurfacePoint {
    var s: SurfacePoint;
    s.n = frame.normal;
    s.diffuse = frame.diffuse;
    s.specular = frame.specular;
    s.alpha = frame.alpha;
    s.mirror = frame.mirror;
    s.opacity = 1.0;
    s.transmission = vec3f(0.0);
    s.emission = vec3f(0.0);
    s.uniform_diffuse = frame.uniform_diffuse != 0u;
    s.diffuse_transmission = frame.diffuse_transmission;
    return s;
}

@compute @workgroup_size(64)
fn cs_evaluate(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= frame.count {
        return;
    }
    let x = inputs[i];
    var first = vec4f(0.0);
    var second = vec4f(0.0);
    switch frame.mode {
        case MODE_ENV_SAMPLE: {
            let e = sample_env(x.x, x.y);
            first = vec4f(e.wi, e.pdf);
        }
        case MODE_ENV_PDF: {
            first = vec4f(env_pdf(x.xyz), env_uv(rotate_y(x.xyz, frame.env_rotation)), 0.0);
        }
        case MODE_ENV_RADIANCE: {
            first = vec4f(environment(x.xyz), 0.0);
        }
        case MODE_BSDF_SAMPLE: {
            let b = sample_bsdf_with(harness_surface(), frame.normal, frame.wo, x);
            first = vec4f(b.wi, b.pdf);
            second = vec4f(b.weight, select(0.0, 1.0, b.valid));
        }
        case MODE_BSDF_EVAL: {
            let e = eval_bsdf(harness_surface(), frame.normal, frame.wo, x.xyz);
            first = vec4f(e.f_cos, e.pdf);
        }
        case MODE_MIS: {
            first = vec4f(
                mis_heuristic(x.x, x.y),
                mis_heuristic(x.y, x.x),
                light_sample_weight(x.x, x.y),
                bsdf_sample_weight(x.y, x.x),
            );
        }
        default: {}
    }
    outputs[2u * i] = first;
    outputs[2u * i + 1u] = second;
}
