// Compute harness: evaluates the same WGSL noise and mapping functions the
// renderer uses at a list of points, for `marbre noise` and the parity tests.

#import shaders/common.wgsl
#import crates/core/src/noise/fractal.wgsl
#import crates/core/src/envmap.wgsl

struct NoiseHarness {
    noise: NoiseParams,
    mode: u32,            // 0 noise, 1 fBm, 2 turbulence, 3 marble, 4 env_uv, 5 rotate_y, 6 ridged,
                          // 7 footprint octaves, 8 the 4D noise at the signal's w
    count: u32,
    param: f32,           // marble stripe frequency, or rotation in radians
    _pad: f32,
}

@group(0) @binding(0) var<uniform> harness: NoiseHarness;
@group(0) @binding(1) var<storage, read> points: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> results: array<vec4f>;

@compute @workgroup_size(64)
fn cs_evaluate(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= harness.count {
        return;
    }
    let p = points[i].xyz;
    let n = harness.noise;
    var r = vec4f(0.0);
    switch harness.mode {
        case 0u: {
            r.x = lattice_noise(p, n.kind, n.hash);
        }
        case 1u: {
            r.x = fbm(p, n);
        }
        case 2u: {
            r.x = turbulence(p, n);
        }
        case 3u: {
            r.x = marble(p, n, harness.param);
        }
        case 4u: {
            r = vec4f(env_uv(p), 0.0, 0.0);
        }
        case 6u: {
            r.x = ridged(p, n);
        }
        case 7u: {
            r.x = footprint_octaves(n, harness.param);
        }
#if NOISE_EVOLVE
        case 8u: {
            r.x = lattice_noise4(p, n.w, n.kind, n.hash, noise_w_period(n));
        }
#endif
        default: {
            r = vec4f(rotate_y(p, harness.param), 0.0);
        }
    }
    results[i] = r;
}
