//! How a trace call splits a sample round into bands of rows, so that one
//! frame's trace stays within a budget of pixels: a slow adapter advances
//! the image a band at a time while the window keeps drawing, a fast one
//! traces several whole rounds in one frame.
//!
//! A round is one sample (in fact `samples_per_frame`) for every pixel of
//! the traced region. Every band of a round reads the same accumulated
//! state and writes its own rows of the next, so a round traced in bands
//! gives exactly the image a whole pass gives (`crates/render/tests/gpu/kernels.rs`).
#![allow(
    clippy::single_range_in_vec_init,
    reason = "a list of bands of rows, which is often one band"
)]

use std::ops::Range;

/// The most passes one call records: a bound on the frame-uniform slots in
/// flight (`Renderer`'s ring) and on the command buffer's length.
pub const MAX_PASSES: usize = 32;

/// How much one trace call may trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TraceBudget {
    /// Finish the round under way (the whole of it if none is).
    Round,
    /// About this many pixels (at least one row, at most [`MAX_PASSES`]
    /// passes), continuing the round under way and starting the next ones.
    Pixels(u64),
}

/// The rows of each pass of one call, in order: the first continues the
/// round at `next_row`, each that ends at `height` completes a round.
pub fn plan(width: u32, height: u32, next_row: u32, budget: TraceBudget) -> Vec<Range<u32>> {
    let (width, height) = (width.max(1), height.max(1));
    let next_row = next_row.min(height - 1);
    let TraceBudget::Pixels(pixels) = budget else {
        return vec![next_row..height];
    };
    let mut rows_left = (pixels / u64::from(width)).max(1);
    let mut bands = Vec::new();
    let mut row = next_row;
    while rows_left > 0 && bands.len() < MAX_PASSES {
        let end = (u64::from(row) + rows_left).min(u64::from(height)) as u32;
        bands.push(row..end);
        rows_left -= u64::from(end - row);
        row = if end == height { 0 } else { end };
    }
    bands
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_round_budget_finishes_the_round_under_way() {
        assert_eq!(plan(640, 360, 0, TraceBudget::Round), [0..360]);
        assert_eq!(plan(640, 360, 100, TraceBudget::Round), [100..360]);
    }

    #[test]
    fn a_small_budget_traces_one_band_and_always_at_least_a_row() {
        assert_eq!(plan(100, 50, 0, TraceBudget::Pixels(1000)), [0..10]);
        assert_eq!(plan(100, 50, 45, TraceBudget::Pixels(1000)), [45..50, 0..5]);
        assert_eq!(plan(100, 50, 7, TraceBudget::Pixels(1)), [7..8]);
        assert_eq!(plan(100, 50, 7, TraceBudget::Pixels(0)), [7..8]);
    }

    #[test]
    fn a_large_budget_traces_whole_rounds_up_to_the_pass_limit() {
        assert_eq!(
            plan(10, 10, 0, TraceBudget::Pixels(250)),
            [0..10, 0..10, 0..5]
        );
        let many = plan(10, 10, 0, TraceBudget::Pixels(u64::MAX));
        assert_eq!(many.len(), MAX_PASSES);
        assert!(many.iter().all(|band| *band == (0..10)));
    }

    /// Whatever the budgets, the bands tile each round exactly once, in
    /// order: no row traced twice in a round, none skipped.
    #[test]
    fn bands_tile_every_round_exactly() {
        let (width, height) = (37, 23);
        let mut row = 0;
        let mut covered = vec![0u32; height as usize];
        let mut rounds = 0;
        for budget in [1u64, 5, 40, 37, 999, 3, 1234, 74, 10_000, 2] {
            for band in plan(width, height, row, TraceBudget::Pixels(budget)) {
                assert_eq!(band.start, row);
                for r in band.clone() {
                    covered[r as usize] += 1;
                }
                row = band.end;
                if row == height {
                    assert!(covered.iter().all(|&c| c == 1), "{covered:?}");
                    covered.fill(0);
                    rounds += 1;
                    row = 0;
                }
            }
        }
        assert!(rounds > 5);
    }
}
