//! How far an image is from its reference, three ways: RMSE (what most
//! papers plot), relMSE (the same with dark pixels weighed up, so a dim
//! corner counts as much as a bright wall) and the mean absolute error
//! (less swayed by a few fireflies). All on linear radiance, over every
//! pixel and the three colour channels.

/// The offset in relMSE's denominator, `(x − ref)² / (ref² + ε)`: it keeps
/// black reference pixels from dividing by zero (the value pbrt and the
/// denoising literature use).
pub const RELMSE_EPSILON: f64 = 0.01;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorMetrics {
    pub rmse: f64,
    pub relmse: f64,
    pub mae: f64,
}

impl ErrorMetrics {
    /// The errors of `image` against `reference`, pixel for pixel (the
    /// alpha channel is ignored).
    pub fn between(image: &[[f32; 4]], reference: &[[f32; 4]]) -> Self {
        assert_eq!(image.len(), reference.len(), "images of different sizes");
        let (mut squared, mut relative, mut absolute) = (0.0, 0.0, 0.0);
        for (pixel, truth) in image.iter().zip(reference) {
            for c in 0..3 {
                let (x, r) = (f64::from(pixel[c]), f64::from(truth[c]));
                let d = x - r;
                squared += d * d;
                relative += d * d / (r * r + RELMSE_EPSILON);
                absolute += d.abs();
            }
        }
        let n = (3 * image.len().max(1)) as f64;
        Self {
            rmse: (squared / n).sqrt(),
            relmse: relative / n,
            mae: absolute / n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: f32) -> [f32; 4] {
        [v, v, v, 1.0]
    }

    #[test]
    fn an_image_equal_to_its_reference_has_no_error() {
        let image = [grey(0.3), [1.0, 2.0, 3.0, 1.0]];
        let e = ErrorMetrics::between(&image, &image);
        assert_eq!((e.rmse, e.relmse, e.mae), (0.0, 0.0, 0.0));
    }

    /// Two pixels off by +0.3 and −0.1 in every channel, against a
    /// reference of 0.5 and 0: RMSE √((0.09 + 0.01) / 2), relMSE the mean
    /// of 0.09 / 0.26 and 0.01 / 0.01, MAE (0.3 + 0.1) / 2.
    #[test]
    fn the_metrics_match_their_closed_forms() {
        let image = [grey(0.8), grey(-0.1)];
        let reference = [grey(0.5), grey(0.0)];
        let e = ErrorMetrics::between(&image, &reference);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
        assert!(close(e.rmse, (0.1f64 / 2.0).sqrt()), "{e:?}");
        assert!(close(e.relmse, (0.09 / 0.26 + 1.0) / 2.0), "{e:?}");
        assert!(close(e.mae, 0.2), "{e:?}");
    }

    /// One channel off by 1 of the three: the mean is over channels too.
    #[test]
    fn the_mean_is_over_channels_and_ignores_alpha() {
        let image = [[1.0, 0.0, 0.0, 7.0]];
        let reference = [[0.0, 0.0, 0.0, 0.0]];
        let e = ErrorMetrics::between(&image, &reference);
        assert!((e.rmse - (1.0f64 / 3.0).sqrt()).abs() < 1e-9);
        assert!((e.mae - 1.0 / 3.0).abs() < 1e-9);
        assert!((e.relmse - 100.0 / 3.0).abs() < 1e-6);
    }
}
