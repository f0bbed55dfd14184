//! The previews of a new accumulation, as Blender's viewport refines: while
//! the first round does not fit in a frame's budget, the image is traced
//! first at the largest scale that fits, then at twice that scale, and so
//! on up to [`LAST_SCALE`] of the render size, each a whole image shown
//! when complete (traced in bands over frames, as a round is), and then
//! the full round. Each step costs a quarter of the next, so the ladder
//! adds at most about a third of a round before the full image, and the
//! image reads at a useful resolution within a few frames instead of
//! staying at the first, coarse scale for the whole first round (issue 31:
//! 10 px blocks for about 3 s on lavapipe after an edit).

use super::trace_bands::{self, TraceBudget};
use std::ops::Range;

/// The largest preview scale: a preview at twice this would cost as much
/// as the full round.
pub const LAST_SCALE: f32 = 0.5;

/// Where a new accumulation's previews stand.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Previews {
    /// The scale of the preview on show, if any.
    pub shown: Option<f32>,
    /// The scale of the preview being traced in bands, if any.
    pub under_way: Option<f32>,
    /// No more previews: full rounds are traced.
    pub done: bool,
}

/// The scale of the preview after one at `shown`: twice it, up to
/// [`LAST_SCALE`] and `cap` (the interactive scale); `None` ends the
/// ladder.
pub fn next_scale(shown: f32, cap: f32) -> Option<f32> {
    let next = 2.0 * shown;
    (next <= LAST_SCALE.min(cap)).then_some(next)
}

/// One pass of a call: a band of `rows` of a region of `size`, and the
/// scale of the preview it traces, if it traces one.
#[derive(Debug, Clone, PartialEq)]
pub struct Pass {
    pub size: (u32, u32),
    pub rows: Range<u32>,
    pub preview: Option<f32>,
}

/// The passes of one call and where the previews stand after them.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    pub passes: Vec<Pass>,
    pub previews: Previews,
}

/// `size` scaled by `scale`, at least one pixel a side.
pub fn scaled(size: (u32, u32), scale: f32) -> (u32, u32) {
    let s = |v: u32| ((v as f32 * scale).ceil() as u32).clamp(1, v.max(1));
    (s(size.0), s(size.1))
}

/// The passes of a call with `budget` at the render size `full`: the
/// previews due (the first traced whole, the later ones in bands of the
/// budget), then the full round's bands with what the budget has left
/// ([`trace_bands::plan`]). `next_row`: the first untraced row of the
/// round or preview under way. A whole-round budget traces no preview.
pub fn plan(
    full: (u32, u32),
    next_row: u32,
    budget: TraceBudget,
    previews: Previews,
    cap: f32,
) -> Plan {
    let TraceBudget::Pixels(pixels) = budget else {
        // A preview under way is dropped: its next row is a row of the
        // preview, and the round traces all of its own (the rows above
        // would show what the targets held before).
        let next_row = if previews.under_way.is_some() {
            0
        } else {
            next_row
        };
        let rows = trace_bands::plan(full.0, full.1, next_row, budget);
        return Plan {
            passes: full_passes(full, rows),
            previews: Previews {
                under_way: None,
                done: true,
                ..previews
            },
        };
    };
    let round = u64::from(full.0) * u64::from(full.1);
    let mut state = previews;
    let mut left = pixels;
    let mut row = next_row;
    let mut passes = Vec::new();
    while !state.done && left > 0 {
        let (scale, whole) = match (state.under_way, state.shown) {
            (Some(scale), _) => (scale, false),
            (None, Some(shown)) => match next_scale(shown, cap) {
                Some(scale) => (scale, false),
                None => {
                    state.done = true;
                    break;
                }
            },
            (None, None) => {
                let fits = (left as f64 / round as f64).sqrt() as f32;
                if fits >= 1.0 {
                    state.done = true;
                    break;
                }
                (fits.min(cap), true)
            }
        };
        let size = scaled(full, scale);
        let end = if whole {
            size.1
        } else {
            let rows = (left / u64::from(size.0)).max(1);
            (u64::from(row) + rows).min(u64::from(size.1)) as u32
        };
        passes.push(Pass {
            size,
            rows: row..end,
            preview: Some(scale),
        });
        left = left.saturating_sub(u64::from(size.0) * u64::from(end - row));
        if end == size.1 {
            state.shown = Some(scale);
            state.under_way = None;
            state.done = next_scale(scale, cap).is_none();
            row = 0;
        } else {
            state.under_way = Some(scale);
            row = end;
        }
    }
    if state.done {
        // At least a row, as the bands always trace: the round starts in
        // the call whose preview was the last.
        let rows = trace_bands::plan(full.0, full.1, row, TraceBudget::Pixels(left));
        passes.extend(full_passes(full, rows));
    }
    Plan {
        passes,
        previews: state,
    }
}

fn full_passes(full: (u32, u32), rows: Vec<Range<u32>>) -> Vec<Pass> {
    rows.into_iter()
        .map(|rows| Pass {
            size: full,
            rows,
            preview: None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const FULL: (u32, u32) = (900, 500);
    const ROUND: u64 = 900 * 500;

    /// Runs calls of `budget` pixels from a fresh accumulation until the
    /// first full round completes; each preview shown, in order, and the
    /// pixels traced.
    fn ladder(budget: u64, cap: f32) -> (Vec<(u32, u32)>, u64) {
        let (mut previews, mut row, mut shown, mut traced) = (Previews::default(), 0, vec![], 0);
        for _ in 0..10_000 {
            let plan = plan(FULL, row, TraceBudget::Pixels(budget), previews, cap);
            for pass in &plan.passes {
                traced += u64::from(pass.size.0) * u64::from(pass.rows.end - pass.rows.start);
                row = if pass.rows.end == pass.size.1 {
                    0
                } else {
                    pass.rows.end
                };
                if pass.rows.end == pass.size.1 {
                    match pass.preview {
                        Some(_) => shown.push(pass.size),
                        None => return (shown, traced),
                    }
                }
            }
            previews = plan.previews;
        }
        panic!("no full round after 10 000 calls; shown {shown:?}");
    }

    /// A budget of a hundredth of a round: a tenth-scale preview at once,
    /// then a fifth, then two fifths, then the full round; the previews
    /// cost less than a third of a round more.
    #[test]
    fn previews_double_in_scale_up_to_half_then_the_round_follows() {
        let (shown, traced) = ladder(ROUND / 100, 1.0);
        assert_eq!(shown, [(90, 50), (180, 100), (360, 200)]);
        assert!(traced > ROUND && traced < ROUND + ROUND / 3, "{traced}");
    }

    /// The first preview is drawn whole in the first call, whatever the
    /// rounding of its size.
    #[test]
    fn the_first_preview_shows_after_one_call() {
        for budget in [1_000, 4_321, ROUND / 7, ROUND / 2] {
            let plan = plan(
                FULL,
                0,
                TraceBudget::Pixels(budget),
                Previews::default(),
                1.0,
            );
            let first = &plan.passes[0];
            assert_eq!(first.rows, 0..first.size.1, "{budget}");
            assert!(first.preview.is_some());
            assert_eq!(plan.previews.shown, first.preview, "{budget}");
        }
    }

    /// A round that fits in the budget needs no preview, nor does a
    /// whole-round budget; the interactive scale caps the ladder.
    #[test]
    fn no_preview_where_the_round_fits_and_the_cap_holds() {
        let fits = plan(
            FULL,
            0,
            TraceBudget::Pixels(ROUND),
            Previews::default(),
            1.0,
        );
        assert!(fits.passes.iter().all(|p| p.preview.is_none()));
        assert!(fits.previews.done);
        let whole = plan(FULL, 0, TraceBudget::Round, Previews::default(), 1.0);
        assert_eq!(whole.passes.len(), 1);
        assert_eq!(whole.passes[0].rows, 0..FULL.1);
        let (shown, _) = ladder(ROUND / 100, 0.25);
        assert_eq!(shown, [(90, 50), (180, 100)]);
    }

    /// A whole round asked while a preview is traced in bands starts at
    /// the round's first row, not at the preview's next one; a round under
    /// way (no preview) goes on where it stopped.
    #[test]
    fn a_whole_round_during_a_preview_starts_at_the_first_row() {
        let under_way = Previews {
            shown: Some(0.1),
            under_way: Some(0.2),
            done: false,
        };
        let whole = plan(FULL, 40, TraceBudget::Round, under_way, 1.0);
        assert_eq!(whole.passes.len(), 1);
        assert_eq!(whole.passes[0].rows, 0..FULL.1);
        assert_eq!(whole.passes[0].preview, None);
        assert_eq!(whole.previews.under_way, None);
        assert!(whole.previews.done);
        let round = Previews {
            done: true,
            ..Previews::default()
        };
        let rest = plan(FULL, 40, TraceBudget::Round, round, 1.0);
        assert_eq!(rest.passes[0].rows, 40..FULL.1);
    }

    /// A quarter-round budget: one preview at half scale, and the round
    /// starts in the same call (at least a row of it).
    #[test]
    fn a_last_preview_hands_the_rest_of_the_budget_to_the_round() {
        let plan = plan(
            FULL,
            0,
            TraceBudget::Pixels(ROUND / 4),
            Previews::default(),
            1.0,
        );
        assert_eq!(plan.passes[0].size, (450, 250));
        assert!(plan.previews.done);
        assert_eq!(plan.passes.len(), 2, "{plan:?}");
        assert_eq!(plan.passes[1].size, FULL);
        assert_eq!(plan.passes[1].rows, 0..1);
        let next = super::plan(
            FULL,
            0,
            TraceBudget::Pixels(ROUND / 2),
            Previews::default(),
            1.0,
        );
        assert_eq!(next.passes[0].size, scaled(FULL, 0.5f32.sqrt()));
        assert_eq!(next.passes[1].size, FULL);
    }
}
