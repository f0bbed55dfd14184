//! How much tracing the viewer asks for each frame, so that one frame's GPU
//! work stays near a budget (12 ms by default) whatever a round costs: the
//! panel and the display are drawn every frame, and the image advances a
//! band of rows at a time on a slow adapter (lavapipe traces the Cornell
//! box at about 1 s a round) or by several rounds a frame on a fast one.
//!
//! The cost per pixel is learnt from the trace pass's measured time (GPU
//! timestamps, else the frame's wall time) and the pixels it traced, and
//! smoothed; the budget in pixels follows from it.

use marbre_render::gpu::TraceBudget;

/// The default budget of trace time per frame: about 12 ms leaves room for
/// the display and the panel within a 60 Hz frame on a GPU, and keeps a
/// CPU adapter's frame rate near 30 fps.
pub const DEFAULT_BUDGET_MS: f32 = 12.0;

/// The pixels the first frames trace, before any cost is known: a small
/// band on any adapter (a 1280-wide image's 25 rows).
const FIRST_PIXELS: u64 = 32 * 1024;

/// Weight of the newest measurement in the smoothed cost.
const SMOOTHING: f64 = 0.3;

/// A frame may grow the budget at most this much over what it traced: a
/// measurement of a tiny band (dominated by fixed costs) must not open
/// the door to a frame many times too long.
const MAX_GROWTH: f64 = 4.0;

/// The longest a frame that is not shown traces, in targets: a shown
/// frame on lavapipe lasts about twice the target (the trace, then the
/// display and the panel), which this leaves room for.
const MAX_UNSHOWN_STRETCH: f32 = 3.0;

/// `--frame-budget-ms`: milliseconds, zero or more.
pub fn parse_budget_ms(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|ms| ms.is_finite() && *ms >= 0.0)
        .ok_or_else(|| format!("`{s}` is not a number of milliseconds, 0 or more"))
}

#[derive(Debug, Clone)]
pub struct FrameBudget {
    /// Target trace time per frame; 0: whole rounds, as before budgets.
    target_ms: f32,
    /// Smoothed nanoseconds per traced pixel.
    ns_per_pixel: Option<f64>,
    /// Pixels of the last measured frame: caps the next budget's growth.
    last_pixels: u64,
}

impl FrameBudget {
    pub fn new(target_ms: f32) -> Self {
        Self {
            target_ms: if target_ms.is_finite() {
                target_ms.max(0.0)
            } else {
                0.0
            },
            ns_per_pixel: None,
            last_pixels: FIRST_PIXELS,
        }
    }

    /// What the next frame may trace.
    pub fn budget(&self) -> TraceBudget {
        self.budget_of(self.target_ms)
    }

    /// What a frame that is not shown (`app/present_schedule.rs`) may
    /// trace: as long as a shown frame lasts (`shown_frame_ms`), and at
    /// least the budget. Input that arrives meanwhile then waits no longer
    /// than it would for a shown frame to end, while the trace gets
    /// larger bands: each band costs a fixed time besides its pixels
    /// (on lavapipe about 2–3 ms: 3.5 samples/s at a 12 ms budget against
    /// 4.1 at 24 ms on the default preset).
    /// A shown frame that took long once (F12 finishing a round and
    /// OIDN, a reload) must not stretch the bands after it: the budget
    /// stays within [`MAX_UNSHOWN_STRETCH`] times the target.
    pub fn unshown_budget(&self, shown_frame_ms: f32) -> TraceBudget {
        let longest = MAX_UNSHOWN_STRETCH * self.target_ms;
        if shown_frame_ms.is_nan() {
            return self.budget();
        }
        self.budget_of(shown_frame_ms.clamp(self.target_ms, longest))
    }

    fn budget_of(&self, ms: f32) -> TraceBudget {
        if self.target_ms == 0.0 {
            return TraceBudget::Round;
        }
        let pixels = match self.ns_per_pixel {
            None => FIRST_PIXELS,
            Some(ns) => {
                let fit = f64::from(ms) * 1e6 / ns.max(1e-6);
                fit.min(self.last_pixels as f64 * MAX_GROWTH) as u64
            }
        };
        TraceBudget::Pixels(pixels.max(1))
    }

    /// Takes in a frame's trace time and the pixels it traced.
    pub fn observe(&mut self, ms: f32, pixels: u64) {
        if pixels == 0 || !ms.is_finite() || ms <= 0.0 {
            return;
        }
        let ns = f64::from(ms) * 1e6 / pixels as f64;
        self.ns_per_pixel = Some(match self.ns_per_pixel {
            None => ns,
            Some(old) => old + SMOOTHING * (ns - old),
        });
        self.last_pixels = pixels;
    }

    /// The learnt milliseconds a whole round of `pixels` costs.
    pub fn round_ms(&self, pixels: u64) -> Option<f32> {
        self.ns_per_pixel
            .map(|ns| (ns * pixels as f64 / 1e6) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixels(budget: &FrameBudget) -> u64 {
        match budget.budget() {
            TraceBudget::Pixels(p) => p,
            TraceBudget::Round => panic!("a budget in pixels"),
        }
    }

    /// A zero budget asks for whole rounds: the behaviour before budgets.
    #[test]
    fn no_budget_traces_whole_rounds() {
        assert_eq!(FrameBudget::new(0.0).budget(), TraceBudget::Round);
        assert_eq!(FrameBudget::new(f32::NAN).budget(), TraceBudget::Round);
    }

    /// An adapter whose trace costs a fixed time per pixel: after the
    /// first frame (whose cost is unknown: 164 ms at 5 µs a pixel), the
    /// frames' traced time settles at the target, from below, without
    /// overshooting by more than the smoothing allows.
    #[test]
    fn the_traced_time_settles_at_the_target() {
        for ns_per_pixel in [2.0, 40.0, 5000.0] {
            let mut budget = FrameBudget::new(12.0);
            let mut ms = 0.0;
            for frame in 0..40 {
                let p = pixels(&budget);
                ms = (p as f64 * ns_per_pixel / 1e6) as f32;
                assert!(
                    frame == 0 || ms < 12.0 * 1.01 || p == 1,
                    "{ms} ms at {ns_per_pixel} ns/pixel"
                );
                budget.observe(ms, p);
            }
            assert!(
                (ms - 12.0).abs() < 0.12,
                "{ms} ms at {ns_per_pixel} ns/pixel"
            );
        }
    }

    /// A fast adapter's budget grows by at most the growth cap a frame
    /// (from a first band timed at fixed-cost scale), never in one jump.
    #[test]
    fn the_budget_grows_gradually() {
        let mut budget = FrameBudget::new(12.0);
        let first = pixels(&budget);
        budget.observe(0.01, first);
        assert_eq!(pixels(&budget), (first as f64 * MAX_GROWTH) as u64);
    }

    /// A frame that is not shown traces for as long as a shown frame
    /// lasts, never less than the budget, and whole rounds stay whole.
    #[test]
    fn unshown_frames_trace_as_long_as_a_shown_frame() {
        let mut budget = FrameBudget::new(12.0);
        budget.observe(12.0, 12_000);
        assert_eq!(pixels(&budget), 12_000);
        assert_eq!(budget.unshown_budget(26.0), TraceBudget::Pixels(26_000));
        assert_eq!(budget.unshown_budget(5.0), TraceBudget::Pixels(12_000));
        assert_eq!(budget.unshown_budget(f32::NAN), TraceBudget::Pixels(12_000));
        // A 3 s screenshot frame does not make the next bands 3 s long.
        assert_eq!(budget.unshown_budget(3000.0), TraceBudget::Pixels(36_000));
        assert_eq!(
            FrameBudget::new(0.0).unshown_budget(26.0),
            TraceBudget::Round
        );
    }

    #[test]
    fn a_budget_is_a_finite_number_of_milliseconds() {
        assert_eq!(parse_budget_ms("12"), Ok(12.0));
        assert_eq!(parse_budget_ms("0"), Ok(0.0));
        for bad in ["-5", "abc", "inf", "NaN", ""] {
            let why = parse_budget_ms(bad).unwrap_err();
            assert!(why.contains("milliseconds"), "{bad}: {why}");
        }
    }

    /// Unusable measurements (nothing traced, a zero or non-finite time)
    /// leave the estimate alone.
    #[test]
    fn unusable_measurements_are_ignored() {
        let mut budget = FrameBudget::new(12.0);
        budget.observe(5.0, 0);
        budget.observe(f32::INFINITY, 100);
        budget.observe(0.0, 100);
        assert_eq!(pixels(&budget), FIRST_PIXELS);
        assert_eq!(budget.round_ms(1000), None);
        budget.observe(1.0, 1000);
        assert_eq!(budget.round_ms(2000), Some(2.0));
    }
}
