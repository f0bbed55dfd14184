//! Whether memory stayed bounded: each series (RSS, GPU bytes, GPU
//! resources) against its baseline at the end of the warm-up.
//!
//! The baseline is taken over the second half of the warm-up, once the
//! first frames' one-off allocations (pipelines, the font atlas, the
//! allocator's first blocks) are made. What the check looks at is the end
//! of the run, its last quarter: a leak grows until the last frame, while
//! what a preset load, a shader build or a device loss takes for a moment
//! is given back.
//!
//! - RSS compares medians: the level held for at least half the frames.
//!   On lavapipe, compiling a heavy shader variant holds 150 MiB more for
//!   a few hundred frames (a 10,000-frame soak: median 204 -> 214 MiB,
//!   peaks to 415 MiB that fell back), which is work, not growth; a leak,
//!   steady or settled, moves the median.
//! - GPU bytes compare maxima (the allocator's blocks do not come and go
//!   with builds: a leak that has settled still shows).
//! - The resource count compares its smallest value with the baseline's
//!   largest (objects of a shader build in flight come and go, and a count
//!   that never drops back is exactly what a leak of one object per frame
//!   or per edit looks like).

/// How far a series may rise above its baseline: the larger of an
/// absolute amount and a fraction of the baseline.
#[derive(Debug, Clone, Copy)]
pub struct Allowance {
    pub absolute: f64,
    pub fraction: f64,
}

impl Allowance {
    fn limit(&self, baseline: f64) -> f64 {
        baseline + self.absolute.max(self.fraction * baseline)
    }
}

const MIB: f64 = 1024.0 * 1024.0;

/// Preset loads legitimately change sizes by a few MiB (textures, meshes,
/// the environment map); a real leak grows without end.
pub const RSS_ALLOWANCE: Allowance = Allowance {
    absolute: 64.0 * MIB,
    fraction: 0.25,
};
pub const GPU_BYTES_ALLOWANCE: Allowance = Allowance {
    absolute: 32.0 * MIB,
    fraction: 0.25,
};
/// Presets differ by a handful of objects (an image texture and its view,
/// a mesh's buffers).
pub const RESOURCE_ALLOWANCE: Allowance = Allowance {
    absolute: 32.0,
    fraction: 0.10,
};

/// Which value of the last quarter is held to the limit, and against
/// which baseline (see the module comment).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    /// The last quarter's median against the baseline window's median.
    Median,
    /// The last quarter's largest value against the baseline's largest.
    Max,
    /// The last quarter's smallest value against the baseline's largest.
    Min,
}

/// The median of `values` (the upper one of an even count); None if empty.
fn median(mut values: Vec<f64>) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied()
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    Bytes,
    Count,
}

impl Unit {
    fn show(self, v: f64) -> String {
        match self {
            Unit::Bytes => format!("{:.1} MiB", v / MIB),
            Unit::Count => format!("{v:.0}"),
        }
    }
}

/// One series to judge.
pub struct Metric {
    pub name: &'static str,
    pub unit: Unit,
    pub allowance: Allowance,
    pub rule: Rule,
}

/// A series judged: its report line, and why it failed if it did.
#[derive(Debug)]
pub struct Judged {
    pub line: String,
    pub failure: Option<String>,
}

/// Judges `points` (frame, value), in frame order, the frames before
/// `warm_up` being the warm-up.
pub fn judge(metric: &Metric, points: &[(u64, u64)], warm_up: u64) -> Judged {
    let name = metric.name;
    let (Some(&(first_frame, _)), Some(&(last_frame, _))) = (points.first(), points.last()) else {
        return Judged {
            line: format!("{name}: not reported by this platform or backend"),
            failure: None,
        };
    };
    let after: Vec<(u64, f64)> = points
        .iter()
        .filter(|(f, _)| *f >= warm_up)
        .map(|&(f, v)| (f, v as f64))
        .collect();
    if after.is_empty() {
        let why = format!(
            "{name}: no sample after the warm-up (frames {first_frame}..={last_frame} sampled, warm-up {warm_up}): the run was too short to judge"
        );
        return Judged {
            line: why.clone(),
            failure: Some(why),
        };
    }
    let window_start = warm_up / 2;
    let window: Vec<f64> = points
        .iter()
        .filter(|(f, _)| (window_start..warm_up).contains(f))
        .map(|&(_, v)| v as f64)
        .collect();
    let baseline = match metric.rule {
        Rule::Median => median(window),
        Rule::Max | Rule::Min => window.into_iter().reduce(f64::max),
    }
    // No warm-up sample (a warm-up of 0): the first sample after it.
    .unwrap_or(after[0].1);
    let tail_start = warm_up + (last_frame.saturating_sub(warm_up) * 3) / 4;
    let tail: Vec<f64> = after
        .iter()
        .filter(|(f, _)| *f >= tail_start)
        .map(|p| p.1)
        .collect();
    let (judged, what) = match metric.rule {
        Rule::Median => (median(tail), "last-quarter median"),
        Rule::Max => (tail.into_iter().reduce(f64::max), "last-quarter max"),
        Rule::Min => (tail.into_iter().reduce(f64::min), "last-quarter min"),
    };
    // The last sample is always in the tail, so it is never empty.
    let judged = judged.unwrap_or(after[after.len() - 1].1);
    let max = after.iter().map(|p| p.1).fold(baseline, f64::max);
    let last = after[after.len() - 1].1;
    let limit = metric.allowance.limit(baseline);
    let show = |v| metric.unit.show(v);
    let line = format!(
        "{name}: baseline {}, {what} {} (limit {}), max {}, final {}, slope {}{} per 1000 frames",
        show(baseline),
        show(judged),
        show(limit),
        show(max),
        show(last),
        if slope(&after) < 0.0 { "-" } else { "+" },
        show(slope(&after).abs() * 1000.0),
    );
    let failure = (judged > limit).then(|| {
        format!(
            "{name} grew: {what} {} exceeds the warm-up baseline {} by more than {} (limit {})",
            show(judged),
            show(baseline),
            show(limit - baseline),
            show(limit)
        )
    });
    Judged { line, failure }
}

/// The least-squares slope of value over frame (0 for fewer than two
/// distinct frames).
fn slope(points: &[(u64, f64)]) -> f64 {
    let n = points.len() as f64;
    let mean_x = points.iter().map(|p| p.0 as f64).sum::<f64>() / n;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for &(x, y) in points {
        let dx = x as f64 - mean_x;
        sxy += dx * (y - mean_y);
        sxx += dx * dx;
    }
    if sxx > 0.0 { sxy / sxx } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RSS: Metric = Metric {
        name: "RSS",
        unit: Unit::Bytes,
        allowance: RSS_ALLOWANCE,
        rule: Rule::Median,
    };
    const GPU_BYTES: Metric = Metric {
        name: "GPU allocated",
        unit: Unit::Bytes,
        allowance: GPU_BYTES_ALLOWANCE,
        rule: Rule::Max,
    };
    const RESOURCES: Metric = Metric {
        name: "GPU resources",
        unit: Unit::Count,
        allowance: RESOURCE_ALLOWANCE,
        rule: Rule::Min,
    };

    #[test]
    fn slope_of_a_line_is_its_gradient() {
        let points: Vec<(u64, f64)> = (0..100).map(|f| (f, 3.0 + 0.5 * f as f64)).collect();
        assert!((slope(&points) - 0.5).abs() < 1e-9);
        assert_eq!(slope(&[(4, 1.0)]), 0.0);
    }

    /// A transient peak mid-run (a device loss: everything recreated while
    /// the old objects are still alive) that falls back passes; the same
    /// level held to the end fails.
    #[test]
    fn a_transient_peak_passes_and_a_held_one_fails() {
        let base = 300 << 20;
        let spike = |held: bool| -> Vec<(u64, u64)> {
            (0..1000)
                .map(|f| {
                    let high = (500..520).contains(&f) || (held && f >= 500);
                    (f, if high { base * 2 } else { base })
                })
                .collect()
        };
        for metric in [&RSS, &GPU_BYTES] {
            let transient = judge(metric, &spike(false), 200);
            assert!(transient.failure.is_none(), "{transient:?}");
            let held = judge(metric, &spike(true), 200);
            assert!(held.failure.is_some(), "{held:?}");
        }
    }

    /// RSS: peaks in the last quarter (frames 799 to 999 of 1000 after a
    /// 200-frame warm-up) that cover less than half of it pass, a level held over more
    /// than half fails; GPU bytes fail on any peak held there.
    #[test]
    fn rss_is_judged_on_the_level_held_for_half_the_last_quarter() {
        let base = 300u64 << 20;
        let peaks = |high_frames: u64| -> Vec<(u64, u64)> {
            (0..1000)
                .map(|f| {
                    let high = f >= 1000 - high_frames;
                    (f, if high { base * 2 } else { base })
                })
                .collect()
        };
        assert!(judge(&RSS, &peaks(80), 200).failure.is_none());
        let held = judge(&RSS, &peaks(120), 200);
        let why = held.failure.expect("held over most of the last quarter");
        assert!(why.contains("last-quarter median"), "{why}");
        assert!(judge(&GPU_BYTES, &peaks(80), 200).failure.is_some());
    }

    #[test]
    fn median_takes_the_middle_value() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(median(Vec::new()), None);
    }

    /// Objects of a shader build in flight come and go; one object per
    /// frame never leaves.
    #[test]
    fn resource_count_fails_only_when_its_floor_rises() {
        let noisy: Vec<(u64, u64)> = (0..400)
            .map(|f| (f, 200 + (f % 10 == 0) as u64 * 60))
            .collect();
        assert!(judge(&RESOURCES, &noisy, 100).failure.is_none());
        let leak: Vec<(u64, u64)> = (0..400).map(|f| (f, 200 + f)).collect();
        let judged = judge(&RESOURCES, &leak, 100);
        let why = judged.failure.expect("a leak of one object per frame");
        assert!(why.starts_with("GPU resources grew"), "{why}");
    }

    #[test]
    fn a_missing_series_is_reported_not_failed() {
        let judged = judge(&RSS, &[], 100);
        assert!(judged.failure.is_none());
        assert!(judged.line.contains("not reported"), "{}", judged.line);
    }

    #[test]
    fn a_run_that_ends_within_the_warm_up_fails() {
        let points: Vec<(u64, u64)> = (0..50).map(|f| (f, 1 << 30)).collect();
        let judged = judge(&RSS, &points, 100);
        assert!(
            judged
                .failure
                .unwrap()
                .contains("no sample after the warm-up")
        );
    }
}
