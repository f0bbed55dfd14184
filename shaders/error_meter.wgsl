// The error meter: how far the accumulated image probably is from the
// converged one, estimated from the image alone. The trace pass keeps, per
// pixel, the running mean and the spread of its frames' means (trace.wgsl);
// spread / (F - 1) estimates the variance of the pixel's mean after F
// frames. One workgroup sums, over a grid of texels (metering_grid.wgsl),
// that spread per channel, and the spread relative to mean² + 0.01 (the
// relMSE of the benchmarks); the CPU divides by F - 1 and the texel count
// (error_meter.rs, which also holds the CPU twin).

#import shaders/common.wgsl
#import shaders/metering_grid.wgsl

const REL_EPSILON: f32 = 0.01;

struct ErrorParams {
    grid: MeteringGrid,
    // What was accumulated when the pass was recorded (frames, samples,
    // seconds, which accumulation), passed through to the result so that a
    // late readback knows what it measured.
    frames: u32,
    samples: u32,
    seconds: f32,
    generation: u32,
}

struct ErrorSums {
    spread: f32,
    relative_spread: f32,
    // Channels that counted: three per texel whose mean and spread are finite.
    channels: u32,
    frames: u32,
    samples: u32,
    seconds: f32,
    generation: u32,
}

@group(0) @binding(0) var<uniform> params: ErrorParams;
@group(0) @binding(1) var mean_texture: texture_2d<f32>;
@group(0) @binding(2) var spread_texture: texture_2d<f32>;
@group(0) @binding(3) var<storage, read_write> sums: ErrorSums;

var<workgroup> spread_sums: array<f32, WORKGROUP>;
var<workgroup> relative_sums: array<f32, WORKGROUP>;
var<workgroup> channel_counts: array<u32, WORKGROUP>;

@compute @workgroup_size(256)
fn cs_error(@builtin(local_invocation_index) t: u32) {
    let n = params.grid.grid.x * params.grid.grid.y;
    var spread = 0.0;
    var relative = 0.0;
    var channels = 0u;
    for (var k = t; k < n; k += WORKGROUP) {
        let texel = grid_cell_texel(k, params.grid);
        let m = textureLoad(mean_texture, texel, 0).rgb;
        let s = textureLoad(spread_texture, texel, 0).rgb;
        // A non-finite texel is left out rather than poisoning the sums.
        if any_non_finite(m) || any_non_finite(s) {
            continue;
        }
        for (var c = 0u; c < 3u; c++) {
            // Rounding can leave a spread a hair below zero.
            let v = max(s[c], 0.0);
            let r = v / (m[c] * m[c] + REL_EPSILON);
            spread += v;
            relative += r;
            channels += 1u;
        }
    }
    spread_sums[t] = spread;
    relative_sums[t] = relative;
    channel_counts[t] = channels;
    workgroupBarrier();
    for (var stride = WORKGROUP / 2u; stride > 0u; stride /= 2u) {
        if t < stride {
            spread_sums[t] += spread_sums[t + stride];
            relative_sums[t] += relative_sums[t + stride];
            channel_counts[t] += channel_counts[t + stride];
        }
        workgroupBarrier();
    }
    if t == 0u {
        sums = ErrorSums(spread_sums[0], relative_sums[0], channel_counts[0], params.frames, params.samples, params.seconds, params.generation);
    }
}
