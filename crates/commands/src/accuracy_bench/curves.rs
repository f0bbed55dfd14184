//! The points of one variant on one scene, in order of samples: one curve
//! of the plots and one subject of the findings.

use super::knob::Knob;
use super::measure::Point;

pub struct Curve<'a> {
    pub scene: &'a str,
    pub variant: &'a str,
    /// In the order measured: increasing samples per pixel.
    pub points: Vec<&'a Point>,
}

impl<'a> Curve<'a> {
    /// (seconds, RMSE) of every point.
    pub fn error_against_time(&self) -> Vec<(f64, f64)> {
        self.points
            .iter()
            .map(|p| (p.seconds, p.errors.rmse))
            .collect()
    }

    /// The point with the most samples.
    pub fn last(&self) -> &'a Point {
        self.points.last().expect("a curve has points")
    }

    pub fn at_spp(&self, spp: u32) -> Option<&'a Point> {
        self.points.iter().copied().find(|p| p.spp == spp)
    }
}

/// The curves of `knob`, in the order their first points were measured.
pub fn curves_of(points: &[Point], knob: Knob) -> Vec<Curve<'_>> {
    let mut curves: Vec<Curve> = Vec::new();
    for point in points.iter().filter(|p| p.knob == knob) {
        match curves
            .iter_mut()
            .find(|c| c.scene == point.scene && c.variant == point.variant)
        {
            Some(curve) => curve.points.push(point),
            None => curves.push(Curve {
                scene: &point.scene,
                variant: &point.variant,
                points: vec![point],
            }),
        }
    }
    curves
}
