// Auto exposure (Reinhard et al. 2002, "Photographic tone reproduction"):
// the log-average luminance L_avg = exp(mean(log(DELTA + L))) of the
// accumulated radiance, and the exposure that maps it to the middle grey
// KEY. One workgroup meters a grid of texels (metering_grid.wgsl) and
// reduces it in workgroup memory; the result stays in a buffer the display
// pass reads (`Metered` in tonemap.wgsl mirrors it). The same texels give
// Massal's RMS luminance sqrt(sum w_c mean(c^2)) and his scale
// -ln(0.6) / L_rms; the display picks one of the two.
// CPU twin: auto_exposure.rs.

#import shaders/common.wgsl
#import shaders/metering_grid.wgsl

const DELTA: f32 = 1e-4;
const KEY: f32 = 0.18;
const MAX_STOPS: f32 = 20.0;
const MASSAL_WEIGHTS: vec3f = vec3f(0.2126, 0.71516, 0.072169);
const MASSAL_TARGET: f32 = 0.6;
const MASSAL_MIN_RMS: f32 = 0.001;

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

@group(0) @binding(0) var<uniform> metering: MeteringGrid;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> metered: Metered;

var<workgroup> sums: array<f32, WORKGROUP>;
var<workgroup> squares: array<f32, WORKGROUP>;
var<workgroup> counts: array<u32, WORKGROUP>;

@compute @workgroup_size(256)
fn cs_meter(@builtin(local_invocation_index) t: u32) {
    let grid = metering.grid;
    let n = grid.x * grid.y;
    var sum = 0.0;
    var square = 0.0;
    var count = 0u;
    for (var k = t; k < n; k += WORKGROUP) {
        let c = textureLoad(radiance, grid_cell_texel(k, metering), 0).rgb;
        // NaN, ±Inf and negative texels (and a luminance that overflows) are
        // left out rather than poisoning the mean.
        let l = luminance(c);
        if !any_non_finite(c) && all(c >= vec3f(0.0)) && !is_non_finite(l) {
            sum += log(DELTA + l);
            square += dot(MASSAL_WEIGHTS, c * c);
            count += 1u;
        }
    }
    sums[t] = sum;
    squares[t] = square;
    counts[t] = count;
    workgroupBarrier();
    for (var stride = WORKGROUP / 2u; stride > 0u; stride /= 2u) {
        if t < stride {
            sums[t] += sums[t + stride];
            squares[t] += squares[t + stride];
            counts[t] += counts[t + stride];
        }
        workgroupBarrier();
    }
    if t == 0u {
        // Nothing metered reads as black: L_avg = DELTA.
        let mean = select(log(DELTA), sums[0] / f32(max(counts[0], 1u)), counts[0] > 0u);
        let log_average = exp(mean);
        let stops = clamp(log2(KEY / log_average), -MAX_STOPS, MAX_STOPS);
        // Massal's: nothing metered reads as black, and below his 0.001 he
        // keeps his default exposure (scale 1).
        let rms = sqrt(squares[0] / f32(max(counts[0], 1u)));
        var rms_stops = 0.0;
        if rms > MASSAL_MIN_RMS {
            rms_stops = clamp(log2(-log(MASSAL_TARGET) / rms), -MAX_STOPS, MAX_STOPS);
        }
        metered = Metered(log_average, stops, exp2(stops), counts[0], rms, rms_stops, exp2(rms_stops), 0u);
    }
}
