// How a pixel folds one frame into what it accumulated: the trace pass
// (trace.wgsl) applies it, and the accumulation harness
// (harness/accumulation.wgsl) runs the same code for 1e5 frames and more.

// The weight of a frame of `spp` samples after `accumulated` samples: the
// running mean moves by (x - mean) times this.
fn frame_weight(accumulated: u32, spp: u32) -> f32 {
    return f32(spp) / (f32(accumulated) + f32(spp));
}

// A running mean and the low-order bits its updates lost.
struct CompensatedMean {
    mean: vec3f,
    compensation: vec3f,
}

// The running mean's update, Kahan-compensated (Kahan 1965): late in an
// accumulation (x - mean) * w falls below the mean's rounding step, and an
// uncompensated f32 mean drifts by ~√n ulps, systematically where samples
// are skewed (an HDR pixel: 1e-3 relative after 1e6 frames). The
// compensation carries what each addition rounded off into the next one,
// so the error stays a few ulps whatever the frame count.
//
// `one` must be 1.0 read from a uniform. Drivers may simplify floating
// point algebraically (Mesa rewrites (a + b) - a to b unless told not to,
// and WGSL cannot tell it), which cancels the compensation to zero; a
// product by a value the compiler cannot see hides t's origin from it.
fn compensated_mean_update(mean: vec3f, compensation: vec3f, x: vec3f, w: f32, one: f32) -> CompensatedMean {
    let y = (x - mean) * w - compensation;
    let t = (mean + y) * one;
    return CompensatedMean(t, (t - mean) - y);
}
