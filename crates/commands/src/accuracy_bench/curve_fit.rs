//! Reading error-against-time curves: the slope of a log-log fit (Monte
//! Carlo error falls as time^-1/2, a slope of −0.5) and the time a curve
//! takes to reach a given error, which is how two variants are compared at
//! equal error rather than at equal samples.

/// The least-squares slope of ln y against ln x; `None` with fewer than two
/// distinct x or any value that is not positive.
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<f64> {
    if points.iter().any(|&(x, y)| !(x > 0.0 && y > 0.0)) {
        return None;
    }
    let logs: Vec<(f64, f64)> = points.iter().map(|&(x, y)| (x.ln(), y.ln())).collect();
    let n = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 1e-12).then(|| sxy / sxx)
}

/// When a curve of (time, error) points first gets down to an error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reach {
    /// Its first point is already there: it takes at most this time.
    AtMost(f64),
    /// Between two points, interpolated linearly in log time and log error.
    At(f64),
    /// Not within the points measured.
    Never,
}

/// Errors this close count as reached: two variants that make the same
/// image up to rounding (the specialised and uber shaders) tie.
const SAME_ERROR: f64 = 1e-3;

/// The time `curve` (points in any order) first reaches `target` error
/// (within [`SAME_ERROR`]).
pub fn time_to_reach(curve: &[(f64, f64)], target: f64) -> Reach {
    let reached = |error: f64| error <= target * (1.0 + SAME_ERROR);
    let mut points = curve.to_vec();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let Some(&(first_time, first_error)) = points.first() else {
        return Reach::Never;
    };
    if reached(first_error) {
        return Reach::AtMost(first_time);
    }
    for pair in points.windows(2) {
        let ((t0, e0), (t1, e1)) = (pair[0], pair[1]);
        if reached(e1) {
            let ln = |v: f64| v.max(f64::MIN_POSITIVE).ln();
            // A tie just above the target is reached at its point.
            let along = ((ln(target) - ln(e0)) / (ln(e1) - ln(e0))).min(1.0);
            return Reach::At((ln(t0) + along * (ln(t1) - ln(t0))).exp());
        }
    }
    Reach::Never
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn an_equal_error_up_to_rounding_is_reached() {
        let curve = [(1.0, 0.5), (4.0, 0.0927 * (1.0 + 1e-6))];
        assert_eq!(time_to_reach(&curve, 0.0927), Reach::At(4.0));
        assert_eq!(time_to_reach(&curve, 0.09), Reach::Never);
    }

    #[test]
    fn the_slope_of_a_power_law_is_its_exponent() {
        let inverse_sqrt: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 64.0, 1024.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 / x.sqrt()))
            .collect();
        assert!(close(log_log_slope(&inverse_sqrt).unwrap(), -0.5));
        let square = [(0.5, 0.25), (3.0, 9.0), (10.0, 100.0)];
        assert!(close(log_log_slope(&square).unwrap(), 2.0));
    }

    /// ln y = {0, 1, 1} at ln x = {0, 1, 2}: the least-squares line through
    /// them has slope 1/2 (not the 0 or 1 of either pair alone).
    #[test]
    fn the_slope_is_the_least_squares_fit_of_scattered_points() {
        let e = std::f64::consts::E;
        let points = [(1.0, 1.0), (e, e), (e * e, e)];
        assert!(close(log_log_slope(&points).unwrap(), 0.5));
    }

    #[test]
    fn no_slope_without_two_distinct_positive_points() {
        assert_eq!(log_log_slope(&[(2.0, 1.0)]), None);
        assert_eq!(log_log_slope(&[(2.0, 1.0), (2.0, 3.0)]), None);
        assert_eq!(log_log_slope(&[(1.0, 1.0), (2.0, 0.0)]), None);
    }

    /// Error 1, 1/2, 1/4 at times 1, 4, 16 (error ∝ time^-1/2): error
    /// 1/(2√2) lies halfway in the logs between 4 and 16, at time 8.
    #[test]
    fn the_time_to_an_error_interpolates_in_the_logs() {
        let curve = [(16.0, 0.25), (1.0, 1.0), (4.0, 0.5)];
        assert_eq!(time_to_reach(&curve, 0.5), Reach::At(4.0));
        match time_to_reach(&curve, 0.5 / 2f64.sqrt()) {
            Reach::At(t) => assert!(close(t, 8.0), "{t}"),
            other => panic!("{other:?}"),
        }
        assert_eq!(time_to_reach(&curve, 2.0), Reach::AtMost(1.0));
        assert_eq!(time_to_reach(&curve, 0.1), Reach::Never);
        assert_eq!(time_to_reach(&[], 0.1), Reach::Never);
    }
}
