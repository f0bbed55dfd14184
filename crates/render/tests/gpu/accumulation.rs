//! Long accumulation: the trace pass's running mean (Kahan-compensated,
//! `shaders/accumulation.wgsl`) keeps its rounding error at a few ulps over
//! 1e5 and 1e6 frames, where an uncompensated running mean and a plain f32
//! sum drift. The streams are an HDR pixel's frames (mostly 0.01, one in
//! ~1000 a firefly of 1000), the hard case for rounding. Runs on the CPU
//! twin and, through a compute harness, on the GPU (skips loudly without
//! an adapter, see `marbre_render::gpu::testing`).

use marbre_render::gpu::harness::accumulation::{
    LongAccumulation, accumulate_on_cpu, exact_mean, frame_value, run,
};
use marbre_render::gpu::testing::gpu_or_skip;

/// f32's unit roundoff.
const U: f64 = f32::EPSILON as f64 / 2.0;

/// What rounding may cost the compensated mean of stream `seed`, relative
/// to the exact mean. Kahan's summation of the increments yᵢ = (xᵢ −
/// meanᵢ₋₁)·wᵢ errs by at most 2u·Σ|yᵢ| (Higham, Accuracy and Stability of
/// Numerical Algorithms, 2nd ed., §4.3, dropping O(nu²)). Each yᵢ itself
/// carries the relative error of its weight (a division: WGSL allows 2.5
/// ulps, 5u) plus a subtraction and a product (u each), which compensation
/// cannot recover: 7u. The compensation still pending at the end is at most
/// half an ulp of the mean (u). So the error is at most 9u·Σ|yᵢ| + u·mean,
/// with the yᵢ taken exactly here in f64.
fn compensated_bound(seed: u32, frames: u32) -> f64 {
    let (mut mean, mut increments) = (0.0f64, 0.0f64);
    for f in 0..frames {
        let y = (f64::from(frame_value(seed, f)) - mean) / f64::from(f + 1);
        mean += y;
        increments += y.abs();
    }
    9.0 * U * increments / mean + U
}

fn relative_error(got: f32, exact: f64) -> f64 {
    (f64::from(got) - exact).abs() / exact
}

/// The compensated mean stays within its bound; returns the worst relative
/// errors of (compensated, plain running mean, plain sum).
fn check(results: &[LongAccumulation], seeds: &[u32], frames: u32, what: &str) -> [f64; 3] {
    let mut worst = [0.0f64; 3];
    for (r, &seed) in results.iter().zip(seeds) {
        let exact = exact_mean(seed, frames);
        let errors = [r.compensated, r.plain, r.summed].map(|v| relative_error(v, exact));
        let bound = compensated_bound(seed, frames);
        assert!(
            errors[0] <= bound,
            "{what}, stream {seed}, {frames} frames: the compensated mean {} is {:.2e} from \
             the exact {exact}, beyond the rounding bound {bound:.2e}",
            r.compensated,
            errors[0]
        );
        for k in 0..3 {
            worst[k] = worst[k].max(errors[k]);
        }
    }
    println!(
        "{what}, {frames} frames: worst relative error: compensated {:.1e}, plain running mean \
         {:.1e}, f32 sum {:.1e}",
        worst[0], worst[1], worst[2]
    );
    worst
}

#[test]
fn the_compensated_mean_stays_within_its_rounding_bound_on_the_cpu_where_the_others_drift() {
    let seeds: Vec<u32> = (0..4).collect();
    let frames = 1_000_000;
    let results: Vec<LongAccumulation> = seeds
        .iter()
        .map(|&s| accumulate_on_cpu(s, frames, 1))
        .collect();
    let [compensated, plain, summed] = check(&results, &seeds, frames, "CPU");
    // The counter-cases: uncompensated, the same arithmetic drifts by
    // hundreds of times the compensated error.
    assert!(plain > 100.0 * compensated.max(U), "plain {plain:.1e}");
    assert!(summed > 100.0 * compensated.max(U), "summed {summed:.1e}");
}

#[test]
fn the_trace_pass_update_keeps_1e5_and_1e6_frames_exact_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("the_trace_pass_update_keeps_1e5_and_1e6_frames_exact_on_the_gpu")
    else {
        return;
    };
    let seeds: Vec<u32> = (0..64).collect();
    let short = run(&ctx, &seeds, 1_000, 1).unwrap();
    let long = run(&ctx, &seeds, 100_000, 1).unwrap();
    check(&short, &seeds, 1_000, "GPU");
    check(&long, &seeds, 100_000, "GPU");
    // 1e5 frames give the 1e3 frames' mean within Monte Carlo error: the
    // frames' standard deviation σ (in f64 over the long stream) over √1e3,
    // four times, summed over the 64 streams' worst case.
    for ((s, l), &seed) in short.iter().zip(&long).zip(&seeds) {
        let mean = exact_mean(seed, 100_000);
        let variance = (0..100_000)
            .map(|f| (f64::from(frame_value(seed, f)) - mean).powi(2))
            .sum::<f64>()
            / 100_000.0;
        let tolerance = 4.5 * (variance / 1_000.0).sqrt();
        assert!(
            (f64::from(s.compensated) - f64::from(l.compensated)).abs() < tolerance,
            "stream {seed}: {} after 1e3 frames, {} after 1e5 (tolerance {tolerance})",
            s.compensated,
            l.compensated
        );
    }
    // The counter-case on the GPU too: a million frames.
    let few: Vec<u32> = (0..4).collect();
    let million = run(&ctx, &few, 1_000_000, 1).unwrap();
    let [compensated, plain, summed] = check(&million, &few, 1_000_000, "GPU");
    assert!(plain > 100.0 * compensated.max(U), "plain {plain:.1e}");
    assert!(summed > 100.0 * compensated.max(U), "summed {summed:.1e}");
}
