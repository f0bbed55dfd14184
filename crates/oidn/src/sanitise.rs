//! Inputs made safe for OIDN. The accumulation drops non-finite samples,
//! but a file merged from elsewhere, or a pixel whose sum overflowed, may
//! still hold NaN, ±Inf, negative or astronomically large values; OIDN's
//! HDR transfer function and its auto exposure (a log-average over the
//! image) are not defined for them, and one NaN would spread over the
//! network's receptive field.

/// The largest radiance passed on: far above any display's range (2⁶⁴
/// times middle grey would still be below it) yet small enough that
/// OIDN's sums over a 16384² image stay finite in f32.
pub const COLOUR_LIMIT: f32 = 1e8;

/// HDR colour: NaN and −Inf to 0, +Inf and anything above the limit to
/// the limit, negatives to 0 (radiance is never negative; a negative mean
/// is rounding or a bad file).
pub fn colour(c: [f32; 3]) -> [f32; 3] {
    c.map(|v| {
        if v.is_nan() {
            0.0
        } else {
            v.clamp(0.0, COLOUR_LIMIT)
        }
    })
}

/// Albedo, a reflectance: within [0, 1] (the trace's guide adds emission,
/// so a light reads 1, white), NaN to 0.
pub fn albedo(c: [f32; 3]) -> [f32; 3] {
    c.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
}

/// A normal's components within [−1, 1], NaN to 0. OIDN does not need it
/// normalised (a pixel's mean of several normals is shorter than 1).
pub fn normal(n: [f32; 3]) -> [f32; 3] {
    n.map(|v| if v.is_nan() { 0.0 } else { v.clamp(-1.0, 1.0) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_value_comes_out_finite_and_in_range() {
        let bad = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -3.0,
            1e30,
            f32::MAX,
        ];
        for &v in &bad {
            let c = colour([v; 3]);
            assert!(
                c.iter()
                    .all(|x| x.is_finite() && (0.0..=COLOUR_LIMIT).contains(x))
            );
            assert!(albedo([v; 3]).iter().all(|x| (0.0..=1.0).contains(x)));
            assert!(normal([v; 3]).iter().all(|x| (-1.0..=1.0).contains(x)));
        }
        assert_eq!(colour([0.25, 2.0, 1e5]), [0.25, 2.0, 1e5]);
        assert_eq!(normal([-0.5, 0.0, 0.5]), [-0.5, 0.0, 0.5]);
    }
}
