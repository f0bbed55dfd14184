//! One PNG per knob: log RMSE against log seconds, a curve per variant.
//! On these axes Monte Carlo noise is a line of slope −1/2, a bias is a
//! floor the curve flattens onto, and the variant further down-left at
//! equal height is the cheaper way to that error. Nothing is both quick and
//! accurate, so the legend goes in the lower left corner.

use super::curves::Curve;
use super::knob::Knob;
use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

const SIZE: (u32, u32) = (900, 600);
const FONT: &str = "sans-serif";

/// The plots' text is drawn from a font compiled in (egui's Ubuntu
/// Light), so no system font is needed.
fn register_font() -> Result<()> {
    static REGISTER: Once = Once::new();
    let mut result = Ok(());
    REGISTER.call_once(|| {
        result = plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        )
        .map_err(|_| anyhow!("the plot font does not parse"));
    });
    result
}

/// Writes the plot of `knob`'s curves to `path`, captioned with the adapter.
pub fn plot(path: &Path, knob: Knob, curves: &[Curve], adapter: &str) -> Result<()> {
    register_font()?;
    let series: Vec<(String, Vec<(f64, f64)>)> = curves
        .iter()
        .map(|c| {
            let points = c
                .error_against_time()
                .into_iter()
                .filter(|&(t, e)| t > 0.0 && e > 0.0)
                .collect();
            (label(c, curves), points)
        })
        .collect();
    let all = || series.iter().flat_map(|(_, p)| p.iter().copied());
    // From just below the power of ten under the least value (plotters'
    // log axis puts grid lines and labels only from the first power of ten
    // in range, and rounding can put an exact one out), to a margin above
    // the greatest.
    let range = |values: Vec<f64>| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(0.0, f64::max);
        (0.99 * 10f64.powf((lo / 1.2).log10().floor()), hi * 1.5)
    };
    let (t0, t1) = range(all().map(|p| p.0).collect());
    let (e0, e1) = range(all().map(|p| p.1).collect());
    if !(t0.is_finite() && e0.is_finite() && t0 > 0.0 && e0 > 0.0) {
        return Err(anyhow!(
            "no positive time and error to plot for {}",
            knob.id()
        ));
    }
    let mut pixels = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("{}: RMSE against time ({adapter})", knob.title()),
                (FONT, 20),
            )
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d((t0..t1).log_scale(), (e0..e1).log_scale())?;
        chart
            .configure_mesh()
            .x_labels(12)
            .y_labels(12)
            .max_light_lines(4)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .x_desc("seconds (wall clock, log)")
            .y_desc("RMSE (log)")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()?;
        for (i, (name, points)) in series.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            chart
                .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?
                .label(name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(2))
                });
            chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerLeft)
            .draw()?;
        root.present()?;
    }
    let image = image::RgbImage::from_raw(SIZE.0, SIZE.1, pixels)
        .context("the plot's buffer has the wrong size")?;
    image
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// An axis label: 1, 2 and 5 times a power of ten, to two significant
/// digits (not the float steps of the log axis, 0.30000000000000004); the
/// other grid lines go unlabelled, or their labels would overlap.
fn tick(v: f64) -> String {
    let decade = v.log10().floor();
    let mantissa = v / 10f64.powf(decade);
    if ![1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-6) {
        return String::new();
    }
    let decimals = (1 - decade as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// The variant, with its scene where the knob is swept on several.
fn label(curve: &Curve, all: &[Curve]) -> String {
    if all.iter().all(|c| c.scene == curve.scene) {
        curve.variant.to_string()
    } else {
        format!("{}: {}", curve.scene, curve.variant)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_label_one_two_and_five_to_two_significant_digits() {
        assert_eq!(tick(0.20000000000000004), "0.20");
        assert_eq!(tick(0.005), "0.0050");
        assert_eq!(tick(0.010000000001), "0.010");
        assert_eq!(tick(2.0), "2.0");
        assert_eq!(tick(50.0), "50");
        assert_eq!(tick(0.30000000000000004), "");
        assert_eq!(tick(7000.0), "");
    }
}
