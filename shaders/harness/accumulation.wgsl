// Compute harness: one pixel's accumulation over a long stream of frames,
// with the trace pass's own update (accumulation.wgsl), beside the two ways
// it replaces (an uncompensated running mean, a plain f32 sum), for the
// long-accumulation tests. A stream is run in chunks, one dispatch each,
// its state kept in `streams` between them: lavapipe ends a shader's loops
// after 65535 passes in all (llvmpipe's guard against hangs), which would
// silently stop a stream there.

#import crates/core/src/noise/hash.wgsl
#import shaders/accumulation.wgsl

struct AccumulationHarness {
    // The chunk: frames first_frame .. first_frame + frames.
    first_frame: u32,
    frames: u32,
    // Samples per frame: the weight of each frame.
    spp: u32,
    // 1.0, from a uniform (see compensated_mean_update).
    one: f32,
}

struct Stream {
    seed: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    // The compensated mean, its compensation, the uncompensated running
    // mean, the plain sum.
    values: vec4f,
}

@group(0) @binding(0) var<uniform> harness: AccumulationHarness;
@group(0) @binding(1) var<storage, read_write> streams: array<Stream>;

// An HDR pixel's frames: mostly 0.01, and one in ~1000 a firefly of 1000
// (a sun glint), decided by the top 24 bits of pcg3d, exactly as the CPU
// twin (`gpu::accumulation_harness::frame_value`) decides.
fn frame_value(seed: u32, frame_index: u32) -> f32 {
    let h = pcg3d(vec3u(seed, frame_index, 0u)).x >> 8u;
    return select(0.01, 1000.0, h < 16777u);
}

@compute @workgroup_size(64)
fn cs_accumulate(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= arrayLength(&streams) {
        return;
    }
    let seed = streams[i].seed;
    let v = streams[i].values;
    var compensated = CompensatedMean(vec3f(v.x), vec3f(v.y));
    var plain = v.z;
    var sum = v.w;
    let end = harness.first_frame + harness.frames;
    for (var f = harness.first_frame; f < end; f++) {
        let x = frame_value(seed, f);
        let w = frame_weight(f * harness.spp, harness.spp);
        compensated = compensated_mean_update(compensated.mean, compensated.compensation, vec3f(x), w, harness.one);
        plain = plain + (x - plain) * w;
        sum += x;
    }
    streams[i].values = vec4f(compensated.mean.x, compensated.compensation.x, plain, sum);
}
