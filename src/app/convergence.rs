//! The convergence of the image on screen, as the Quality panel shows it:
//! the error meter's estimates since the last change, and whether the
//! user's target error is reached.

use marbre_render::gpu::error_meter::ErrorEstimate;

/// At most this many points are kept; beyond, every other one is dropped,
/// so a long accumulation keeps its whole history at a coarser step.
const MAX_POINTS: usize = 1024;

#[derive(Debug, Clone, Default)]
pub struct Convergence {
    /// The accumulation the points belong to.
    generation: u32,
    /// (seconds since the accumulation started, estimated relative error),
    /// oldest first.
    points: Vec<[f64; 2]>,
    latest: Option<ErrorEstimate>,
    /// Whether the screenshot at target was taken for this accumulation.
    screenshot_taken: bool,
}

impl Convergence {
    /// Follows the renderer's accumulation (`generation` changes at every
    /// reset) and takes in a new estimate, if one arrived; an estimate of
    /// an earlier accumulation is dropped.
    pub fn observe(&mut self, generation: u32, estimate: Option<ErrorEstimate>) {
        if generation != self.generation {
            *self = Self {
                generation,
                ..Self::default()
            };
        }
        let Some(e) = estimate.filter(|e| e.generation == generation) else {
            return;
        };
        if self.points.len() >= MAX_POINTS {
            let kept = self.points.iter().step_by(2).copied().collect();
            self.points = kept;
        }
        self.points.push([e.seconds, e.relative]);
        self.latest = Some(e);
    }

    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    pub fn latest(&self) -> Option<ErrorEstimate> {
        self.latest
    }

    /// Whether the latest estimate is at or below `target`.
    pub fn reached(&self, target: f64) -> bool {
        self.latest.is_some_and(|e| e.relative <= target)
    }

    /// True once per accumulation, when `target` is first reached: the
    /// moment to save the screenshot the user asked for.
    pub fn take_screenshot_moment(&mut self, target: f64) -> bool {
        if self.screenshot_taken || !self.reached(target) {
            return false;
        }
        self.screenshot_taken = true;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(generation: u32, seconds: f64, relative: f64) -> ErrorEstimate {
        ErrorEstimate {
            rmse: relative,
            relative,
            frames: 2,
            samples: 2,
            seconds,
            generation,
        }
    }

    #[test]
    fn a_reset_starts_a_new_history_and_drops_late_estimates() {
        let mut c = Convergence::default();
        c.observe(0, Some(estimate(0, 1.0, 0.1)));
        c.observe(0, Some(estimate(0, 2.0, 0.07)));
        assert_eq!(c.points(), [[1.0, 0.1], [2.0, 0.07]]);
        c.observe(1, Some(estimate(0, 3.0, 0.05)));
        assert!(c.points().is_empty());
        assert_eq!(c.latest(), None);
        c.observe(1, Some(estimate(1, 0.5, 0.2)));
        assert_eq!(c.points(), [[0.5, 0.2]]);
    }

    #[test]
    fn the_screenshot_moment_comes_once_per_accumulation() {
        let mut c = Convergence::default();
        c.observe(0, Some(estimate(0, 1.0, 0.02)));
        assert!(!c.take_screenshot_moment(0.01));
        c.observe(0, Some(estimate(0, 4.0, 0.009)));
        assert!(c.reached(0.01));
        assert!(c.take_screenshot_moment(0.01));
        assert!(!c.take_screenshot_moment(0.01));
        c.observe(1, Some(estimate(1, 9.0, 0.005)));
        assert!(c.take_screenshot_moment(0.01));
    }

    #[test]
    fn a_long_history_is_thinned_not_cut() {
        let mut c = Convergence::default();
        for i in 0..3 * MAX_POINTS {
            c.observe(0, Some(estimate(0, i as f64, 1.0)));
        }
        assert!(c.points().len() <= MAX_POINTS);
        assert_eq!(c.points()[0][0], 0.0);
        assert_eq!(c.points().last().unwrap()[0], (3 * MAX_POINTS - 1) as f64);
    }
}
