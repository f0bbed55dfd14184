//! The findings in words, computed from the points: what a reader would
//! otherwise work out from the tables. Variants are compared at equal error
//! (the time each takes to reach the same RMSE), not at equal samples: a
//! variant that costs twice as much per sample must halve the variance to
//! break even.

use super::curve_fit::{Reach, log_log_slope, time_to_reach};
use super::curves::{Curve, curves_of};
use super::knob::Knob;
use super::measure::Point;

/// Variants whose errors are within this factor make the same image (the
/// specialised and uber shaders differ in the last bits of a float).
const TIE: f64 = 1.001;

/// A variant counts as having converged once its error at the most samples
/// is within this factor of the lowest.
const PLATEAU: f64 = 1.1;

/// Times within this factor of each other are "about the same": timings on
/// a shared machine drift by more.
const SAME_TIME: f64 = 1.05;

/// Seconds, or milliseconds below one second.
fn duration(seconds: f64) -> String {
    if seconds < 1.0 {
        format!("{:.0} ms", seconds * 1000.0)
    } else {
        format!("{seconds:.2} s")
    }
}

/// One-line findings about `knob`.
pub fn findings(knob: Knob, points: &[Point]) -> Vec<String> {
    let curves = curves_of(points, knob);
    match knob {
        Knob::Spp => curves.iter().filter_map(convergence_rate).collect(),
        Knob::Bounces | Knob::Octaves => ordered(&curves),
        Knob::Denoise => denoised(&curves),
        _ => {
            let mut scenes: Vec<&str> = curves.iter().map(|c| c.scene).collect();
            scenes.dedup();
            scenes
                .into_iter()
                .flat_map(|scene| {
                    let of_scene: Vec<&Curve> =
                        curves.iter().filter(|c| c.scene == scene).collect();
                    compared(&of_scene)
                })
                .collect()
        }
    }
}

/// For each scene, sample count and denoiser, the denoised image's RMSE
/// against the raw one's (the same accumulation, filtered) and what the
/// filter cost; then, for OIDN, the sample count at which raw reaches its
/// RMSE at 16 spp.
fn denoised(curves: &[Curve]) -> Vec<String> {
    let mut lines = Vec::new();
    for raw in curves.iter().filter(|c| c.variant == "raw") {
        let filtered = curves
            .iter()
            .filter(|c| c.scene == raw.scene && c.variant != "raw");
        for f in filtered {
            for point in &raw.points {
                let Some(d) = f.at_spp(point.spp) else {
                    continue;
                };
                lines.push(format!(
                    "{} at {} spp: RMSE {:.4} raw, {:.4} {} ({:.2}× raw), the filter {:.1} ms.",
                    raw.scene,
                    point.spp,
                    point.errors.rmse,
                    d.errors.rmse,
                    f.variant,
                    d.errors.rmse / point.errors.rmse,
                    d.filter_ms.unwrap_or(0.0),
                ));
            }
            if let Some(at16) = f.at_spp(16) {
                let matched = raw
                    .points
                    .iter()
                    .find(|p| p.errors.rmse <= at16.errors.rmse)
                    .map_or_else(
                        || "none of the raw counts measured".to_owned(),
                        |p| format!("raw at {} spp", p.spp),
                    );
                lines.push(format!(
                    "{}: {} at 16 spp (RMSE {:.4}) is reached by {matched}.",
                    raw.scene, f.variant, at16.errors.rmse
                ));
            }
        }
    }
    lines
}

/// The fitted exponents of RMSE against time and against samples.
fn convergence_rate(curve: &Curve) -> Option<String> {
    let against_time = log_log_slope(&curve.error_against_time())?;
    let against_spp = log_log_slope(
        &curve
            .points
            .iter()
            .map(|p| (f64::from(p.spp), p.errors.rmse))
            .collect::<Vec<_>>(),
    )?;
    let halving = if against_time < 0.0 {
        format!(
            "each halving of the error costs {:.1}× the time",
            2f64.powf(-1.0 / against_time)
        )
    } else {
        "the error does not fall with time".to_string()
    };
    Some(format!(
        "{}: RMSE ∝ time^{against_time:.2} and ∝ spp^{against_spp:.2}, fitted over {} renders of {} to {} spp (Monte Carlo predicts −0.5): {halving}.",
        curve.scene,
        curve.points.len(),
        curve.points[0].spp,
        curve.last().spp,
    ))
}

/// For a knob whose variants are increasing values (bounces, octaves): from
/// which value on the error stops falling, and what the last costs per frame
/// against the first.
fn ordered(curves: &[Curve]) -> Vec<String> {
    let (Some(first), Some(last)) = (curves.first(), curves.last()) else {
        return Vec::new();
    };
    let spp = first.last().spp;
    let lowest = curves
        .iter()
        .map(|c| c.last().errors.rmse)
        .fold(f64::INFINITY, f64::min);
    let mut lines = vec![format!(
        "{}: at {spp} spp the RMSE goes from {:.4} ({}) to {:.4} ({}).",
        first.scene,
        first.last().errors.rmse,
        first.variant,
        last.last().errors.rmse,
        last.variant,
    )];
    if let Some(converged) = curves
        .iter()
        .find(|c| c.last().errors.rmse <= PLATEAU * lowest)
    {
        lines.push(format!(
            "{}: from {} on, the RMSE at {spp} spp is within {:.0} % of the lowest ({lowest:.4}); what more adds is below that much noise.",
            first.scene,
            converged.variant,
            (PLATEAU - 1.0) * 100.0,
        ));
    }
    lines.push(format!(
        "{}: a frame of {} costs {:.2}× one of {} ({:.2} against {:.2} ms).",
        first.scene,
        last.variant,
        last.last().ms_per_frame / first.last().ms_per_frame,
        first.variant,
        last.last().ms_per_frame,
        first.last().ms_per_frame,
    ));
    lines
}

/// For the variants of one scene: which is best with few samples and with
/// many, and how much time the best with many saves over each other one at
/// equal error.
fn compared(curves: &[&Curve]) -> Vec<String> {
    let Some(first) = curves.first() else {
        return Vec::new();
    };
    let (fewest, most) = (first.points[0].spp, first.last().spp);
    let (Some(low), Some(high)) = (lowest_at(curves, fewest), lowest_at(curves, most)) else {
        return Vec::new();
    };
    let names = |tied: &[(&Curve, &Point)]| {
        tied.iter()
            .map(|(c, _)| format!("{}'s", c.variant))
            .collect::<Vec<_>>()
            .join(" and ")
    };
    let mut lines = vec![format!(
        "{}: the lowest RMSE at {fewest} spp is {} ({:.4}), at {most} spp {} ({:.4}).",
        first.scene,
        names(&low),
        low[0].1.errors.rmse,
        names(&high),
        high[0].1.errors.rmse,
    )];
    // Of variants with equal error (the same image, as the specialised and
    // uber shaders make), the quicker one wins.
    let (best, _) = high
        .iter()
        .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
        .copied()
        .expect("lowest_at returns at least one");
    for other in curves.iter().filter(|c| c.variant != best.variant) {
        lines.push(equal_error(best, other, other.last()));
    }
    // A variant best with few samples but not with many (a filter: less
    // noise, some bias) is worth the time the winner needs to catch up.
    if let Some((early, at_fewest)) = low.first()
        && !high.iter().any(|(c, _)| c.variant == early.variant)
    {
        lines.push(equal_error(best, early, at_fewest));
    }
    lines
}

/// The curves with the lowest RMSE at `spp` (several if they tie), with
/// their point there.
fn lowest_at<'c, 'p>(
    curves: &[&'c Curve<'p>],
    spp: u32,
) -> Option<Vec<(&'c Curve<'p>, &'p Point)>> {
    let at: Vec<(&Curve, &Point)> = curves
        .iter()
        .filter_map(|&c| c.at_spp(spp).map(|p| (c, p)))
        .collect();
    let lowest = at
        .iter()
        .map(|(_, p)| p.errors.rmse)
        .fold(f64::INFINITY, f64::min);
    let tied: Vec<_> = at
        .into_iter()
        .filter(|(_, p)| p.errors.rmse <= lowest * TIE)
        .collect();
    (!tied.is_empty()).then_some(tied)
}

/// How long `fast` takes to reach the error of `slow` at `target` (one of
/// its points), against how long `slow` took there.
fn equal_error(fast: &Curve, slow: &Curve, target: &Point) -> String {
    let subject = format!(
        "{}: {} against the RMSE of {} at {} spp ({:.4}, {})",
        fast.scene,
        fast.variant,
        slow.variant,
        target.spp,
        target.errors.rmse,
        duration(target.seconds)
    );
    let ratio = |t: f64| {
        let r = target.seconds / t;
        if r >= SAME_TIME {
            format!("{r:.1}× less time")
        } else if r <= 1.0 / SAME_TIME {
            format!("{:.1}× more time", 1.0 / r)
        } else {
            "about the same time".to_string()
        }
    };
    match time_to_reach(&fast.error_against_time(), target.errors.rmse) {
        Reach::At(t) => format!("{subject}: reaches it in {}, {}.", duration(t), ratio(t)),
        Reach::AtMost(t) => format!(
            "{subject}: already below it at {} spp ({}), at least {}.",
            fast.points[0].spp,
            duration(t),
            ratio(t)
        ),
        Reach::Never => {
            let lowest = fast
                .points
                .iter()
                .map(|p| p.errors.rmse)
                .fold(f64::INFINITY, f64::min);
            format!("{subject}: never reaches it within the sweep (its lowest is {lowest:.4}).")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy_bench::error_metrics::ErrorMetrics;
    use crate::accuracy_bench::frame_timer::TimerKind;

    fn point(knob: Knob, variant: &str, spp: u32, seconds: f64, rmse: f64) -> Point {
        Point {
            knob,
            scene: "scene".into(),
            variant: variant.into(),
            spp,
            ms_per_frame: 1000.0 * seconds / f64::from(spp),
            seconds,
            errors: ErrorMetrics {
                rmse,
                relmse: rmse * rmse,
                mae: rmse,
            },
            timer: TimerKind::WallClock,
            filter_ms: None,
        }
    }

    /// The denoise knob compares each filter with raw at each sample
    /// count, and finds the raw count matching the filter at 16 spp.
    #[test]
    fn denoise_findings_compare_raw_and_filtered_at_equal_samples() {
        let mut points = vec![
            point(Knob::Denoise, "raw", 4, 1.0, 0.2),
            point(Knob::Denoise, "raw", 16, 4.0, 0.1),
            point(Knob::Denoise, "raw", 64, 16.0, 0.05),
            point(Knob::Denoise, "OIDN", 4, 1.5, 0.05),
            point(Knob::Denoise, "OIDN", 16, 4.5, 0.04),
        ];
        points[3].filter_ms = Some(12.0);
        points[4].filter_ms = Some(12.0);
        let lines = findings(Knob::Denoise, &points);
        assert_eq!(
            lines,
            [
                "scene at 4 spp: RMSE 0.2000 raw, 0.0500 OIDN (0.25× raw), the filter 12.0 ms.",
                "scene at 16 spp: RMSE 0.1000 raw, 0.0400 OIDN (0.40× raw), the filter 12.0 ms.",
                "scene: OIDN at 16 spp (RMSE 0.0400) is reached by none of the raw counts measured.",
            ]
        );
    }

    /// Error ∝ spp^-1/2 at 10 ms a sample: slope −0.5 against both, and
    /// halving the error takes four times the samples.
    #[test]
    fn the_spp_finding_reports_the_fitted_rate() {
        let points: Vec<Point> = [1, 2, 4, 8, 16]
            .iter()
            .map(|&n| {
                point(
                    Knob::Spp,
                    "path",
                    n,
                    0.01 * f64::from(n),
                    0.3 / f64::from(n).sqrt(),
                )
            })
            .collect();
        let lines = findings(Knob::Spp, &points);
        assert_eq!(lines.len(), 1);
        assert!(
            lines[0].contains("time^-0.50 and ∝ spp^-0.50"),
            "{}",
            lines[0]
        );
        assert!(lines[0].contains("costs 4.0× the time"), "{}", lines[0]);
    }

    /// `good` has half the error of `bad` at every count for the same time:
    /// it reaches bad's error at 16 spp (0.5) at 4 spp, in a quarter of
    /// the time.
    #[test]
    fn variants_are_compared_at_equal_error() {
        let mut points = Vec::new();
        for n in [1, 4, 16] {
            let t = f64::from(n);
            points.push(point(Knob::Strategy, "bad", n, t, 2.0 / t.sqrt()));
            points.push(point(Knob::Strategy, "good", n, t, 1.0 / t.sqrt()));
        }
        let lines = findings(Knob::Strategy, &points);
        assert_eq!(
            lines[0],
            "scene: the lowest RMSE at 1 spp is good's (1.0000), at 16 spp good's (0.2500)."
        );
        assert!(lines[1].starts_with("scene: good against the RMSE of bad at 16 spp (0.5000"));
        assert!(
            lines[1].ends_with("reaches it in 4.00 s, 4.0× less time."),
            "{}",
            lines[1]
        );
        assert_eq!(lines.len(), 2);
    }

    /// A filter with no noise but a bias of 0.3 wins at 1 spp; point
    /// sampling (error 1/√spp) wins at 64, and needs 4^(1 + ln 0.6 / ln 0.5)
    /// = 11.1 s to get down to the filter's 1-spp error.
    #[test]
    fn a_variant_best_only_with_few_samples_is_caught_up_with() {
        let mut points = Vec::new();
        for n in [1, 4, 16, 64] {
            let t = f64::from(n);
            points.push(point(Knob::Filtering, "filtered", n, t, 0.3));
            points.push(point(Knob::Filtering, "point", n, t, 1.0 / t.sqrt()));
        }
        let lines = findings(Knob::Filtering, &points);
        assert_eq!(lines.len(), 3, "{lines:?}");
        assert!(lines[0].contains("at 1 spp is filtered's (0.3000), at 64 spp point's (0.1250)"));
        assert!(
            lines[1].contains("RMSE of filtered at 64 spp"),
            "{}",
            lines[1]
        );
        assert!(lines[1].ends_with("5.8× less time."), "{}", lines[1]);
        assert!(
            lines[2].contains("RMSE of filtered at 1 spp (0.3000, 1.00 s)"),
            "{}",
            lines[2]
        );
        assert!(
            lines[2].ends_with("reaches it in 11.11 s, 11.1× more time."),
            "{}",
            lines[2]
        );
    }

    /// Two variants drawing the same image (the specialised and uber
    /// shaders) tie on error; the quicker one wins.
    #[test]
    fn of_tied_variants_the_quicker_wins() {
        let mut points = Vec::new();
        for n in [1, 4] {
            let t = f64::from(n);
            points.push(point(Knob::Shader, "slow", n, 3.0 * t, 1.0 / t.sqrt()));
            points.push(point(Knob::Shader, "fast", n, t, 1.0 / t.sqrt()));
        }
        let lines = findings(Knob::Shader, &points);
        assert!(
            lines[0].contains("at 1 spp is slow's and fast's"),
            "{}",
            lines[0]
        );
        assert!(
            lines[1].starts_with("scene: fast against the RMSE of slow"),
            "{}",
            lines[1]
        );
        assert!(lines[1].contains("3.0× less time"), "{}", lines[1]);
    }

    /// Bias that stops falling after 3 bounces: 0.5, 0.2, 0.105, 0.1.
    #[test]
    fn an_ordered_knob_reports_where_the_error_levels_off() {
        let points: Vec<Point> = [0.5, 0.2, 0.105, 0.1]
            .iter()
            .zip(1..)
            .map(|(&e, b)| point(Knob::Bounces, &format!("{b} bounces"), 64, f64::from(b), e))
            .collect();
        let lines = findings(Knob::Bounces, &points);
        assert!(
            lines[1].starts_with("scene: from 3 bounces on"),
            "{}",
            lines[1]
        );
        assert!(
            lines[2].contains("costs 4.00× one of 1 bounces"),
            "{}",
            lines[2]
        );
    }
}
