//! The Quality section: how converged the image is and what it costs. A
//! live plot of the estimated error since the last change, the time left to
//! a target error, the GPU time of each pass, and the cost of each shader
//! feature, which the user can compile out to see the difference.

use super::PanelAction;
use egui::{Checkbox, DragValue, Grid, Ui};
use egui_plot::{HLine, Line, Plot, PlotPoints};
use marbre_render::gpu::Feature;
use marbre_render::gpu::error_meter::ErrorEstimate;
use std::collections::BTreeSet;

/// What the user asks of convergence: kept by the panel, not the scene, so
/// changing it never restarts the accumulation.
#[derive(Debug, Clone, PartialEq)]
pub struct QualityControls {
    /// The relative error (√relMSE) the user aims at.
    pub target_error: f64,
    /// Stop tracing once the estimate is at the target: the image stays,
    /// the GPU rests.
    pub stop_at_target: bool,
    /// Save a screenshot (PNG and EXR) the moment the target is reached.
    pub screenshot_at_target: bool,
    /// The strip folded to its header line (the estimate alone), leaving
    /// the image its height.
    pub folded: bool,
}

impl Default for QualityControls {
    fn default() -> Self {
        Self {
            target_error: 0.02,
            stop_at_target: false,
            screenshot_at_target: false,
            folded: false,
        }
    }
}

/// What the app measured for the Quality section.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QualityStats {
    /// (seconds since the last change, estimated relative error).
    pub points: Vec<[f64; 2]>,
    pub latest: Option<ErrorEstimate>,
    /// Tracing is paused: the target is reached and the user asked to stop.
    pub paused_at_target: bool,
    /// GPU ms of each pass of a frame (`None`: not run or not measured);
    /// empty without timestamp queries.
    pub passes: Vec<(&'static str, Option<f32>)>,
    /// The features the scene's shader is specialised for.
    pub scene_features: Vec<Feature>,
    /// Those the user compiled out.
    pub disabled: BTreeSet<Feature>,
    /// Trace ms per frame with every feature in, and with each alone out.
    pub with_all_ms: Option<f32>,
    pub without_ms: Vec<Option<f32>>,
}

/// The header line, which folds the strip and holds convergence (the
/// estimate, the target, the time left, what to do at the target), so
/// that the folded strip keeps all but the figures; then three columns:
/// the error plot, the time of each pass, the cost of each feature.
pub fn quality_ui(
    ui: &mut Ui,
    controls: &mut QualityControls,
    stats: &QualityStats,
    actions: &mut Vec<PanelAction>,
) {
    ui.horizontal_wrapped(|ui| {
        // egui's own fold arrow (its fonts lack the arrow characters).
        let size = egui::vec2(ui.spacing().icon_width, ui.spacing().interact_size.y);
        let (_, arrow) = ui.allocate_exact_size(size, egui::Sense::click());
        let openness = if controls.folded { 0.0 } else { 1.0 };
        egui::collapsing_header::paint_default_icon(ui, openness, &arrow);
        let title = ui.add(
            egui::Label::new(egui::RichText::new("Quality").strong()).sense(egui::Sense::click()),
        );
        if (arrow | title)
            .on_hover_text(if controls.folded {
                "Show the convergence plot, the pass times and the feature costs"
            } else {
                "Fold the strip to this line, leaving the image its height"
            })
            .clicked()
        {
            controls.folded = !controls.folded;
        }
        convergence_ui(ui, controls, stats);
    });
    if controls.folded {
        return;
    }
    ui.columns(3, |columns| {
        error_plot(&mut columns[0], controls.target_error, &stats.points);
        passes_ui(&mut columns[1], stats);
        egui::ScrollArea::vertical()
            .id_salt("feature costs")
            .show(&mut columns[2], |ui| feature_costs_ui(ui, stats, actions));
    });
}

/// The estimate, the target and the time left to it, and what to do on
/// reaching it, along one wrapped line.
fn convergence_ui(ui: &mut Ui, controls: &mut QualityControls, stats: &QualityStats) {
    match stats.latest {
        Some(e) => {
            ui.label(format!(
                "estimated error {:.2} % relative (RMSE {:.4}) at {} spp, {:.1} s",
                100.0 * e.relative,
                e.rmse,
                e.samples,
                e.seconds
            ))
            .on_hover_text(
                "From the spread of each pixel's frames (variance of the mean): \
                 √mean(σ²/(mean² + 0.01)). It cannot see bias, and misses \
                 fireflies no frame has met yet.",
            );
        }
        None => {
            ui.label("estimated error: after two frames");
        }
    }
    ui.label("· target");
    let mut percent = 100.0 * controls.target_error;
    if ui
        .add(
            DragValue::new(&mut percent)
                .range(0.05..=50.0)
                .speed(0.05)
                .suffix(" %"),
        )
        .on_hover_text(
            "The relative error to aim at, 0.05 to 50 %: half the error takes about four \
             times as long",
        )
        .changed()
    {
        controls.target_error = percent / 100.0;
    }
    if let Some(e) = stats.latest {
        let left = e.seconds_to(controls.target_error);
        if left == 0.0 {
            ui.label("reached");
        } else {
            ui.label(format!("about {} left", human_seconds(left)))
                .on_hover_text("Monte Carlo error falls as 1/√time.");
        }
    }
    ui.label("· at the target:");
    ui.add(Checkbox::new(&mut controls.stop_at_target, "stop"))
        .on_hover_text(
            "Stop tracing at the target: the image stays and the GPU rests; any change \
             starts again",
        );
    ui.add(Checkbox::new(
        &mut controls.screenshot_at_target,
        "screenshot",
    ))
    .on_hover_text(
        "Save a PNG and an EXR into screenshots/ when the target is reached, once each \
             time the image restarts",
    );
    if stats.paused_at_target {
        ui.label("· paused: target reached (any change starts again)");
    }
}

/// Log error against log time: a Monte Carlo estimate falls on a line of
/// slope −½, drawn through the latest point for comparison.
fn error_plot(ui: &mut Ui, target: f64, points: &[[f64; 2]]) {
    let log: Vec<[f64; 2]> = points
        .iter()
        .filter(|p| p[0] > 0.0 && p[1] > 0.0)
        .map(|p| [p[0].log10(), p[1].log10()])
        .collect();
    let power_of_ten = |mark: egui_plot::GridMark, _: &std::ops::RangeInclusive<f64>| {
        axis_value(10f64.powf(mark.value))
    };
    // The key sits above the plot, not in it: the curve runs corner to
    // corner as the axes follow it, and a legend inside always hid part of it.
    let [estimate, slope_color, target_color] = PLOT_COLORS;
    ui.horizontal(|ui| {
        for (color, name) in [
            (estimate, "— estimate"),
            (slope_color, "— 1/√t"),
            (target_color, "— target"),
        ] {
            ui.colored_label(color, name);
        }
    });
    Plot::new("error against time")
        .height(ui.available_height().max(60.0))
        .x_axis_label("seconds (log)")
        .y_axis_label("relative error (log)")
        .x_axis_formatter(power_of_ten)
        .y_axis_formatter(power_of_ten)
        .allow_scroll(false)
        .show(ui, |plot| {
            if let (Some(first), Some(last)) = (log.first(), log.last()) {
                let slope = [first[0], last[0]].map(|x| [x, last[1] - 0.5 * (x - last[0])]);
                plot.line(Line::new("1/√t", PlotPoints::from(slope.to_vec())).color(slope_color));
            }
            plot.line(Line::new("estimate", PlotPoints::from(log)).color(estimate));
            plot.hline(HLine::new("target", target.log10()).color(target_color));
        });
}

/// The colours of the estimate, the 1/√t line and the target, which the
/// key above the plot names.
const PLOT_COLORS: [egui::Color32; 3] = [
    egui::Color32::from_rgb(100, 170, 255),
    egui::Color32::from_rgb(160, 160, 160),
    egui::Color32::from_rgb(230, 140, 60),
];

/// A tick label of a log axis: as few digits as its size needs.
fn axis_value(v: f64) -> String {
    if v >= 10.0 {
        format!("{v:.0}")
    } else if v >= 1.0 {
        format!("{v:.1}")
    } else {
        let digits = (-v.log10()).ceil() as usize + 1;
        format!("{v:.digits$}")
    }
}

fn human_seconds(s: f64) -> String {
    if s < 90.0 {
        format!("{s:.0} s")
    } else if s < 5400.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

fn passes_ui(ui: &mut Ui, stats: &QualityStats) {
    if stats.passes.is_empty() {
        ui.label("no GPU timestamps on this adapter: see the frame time in Stats");
        return;
    }
    ui.label("GPU time per frame, by pass");
    Grid::new("pass times").striped(true).show(ui, |ui| {
        for (label, ms) in &stats.passes {
            ui.label(*label);
            ui.label(ms.map_or("-".to_owned(), |ms| format!("{ms:.2} ms")));
            ui.end_row();
        }
    });
}

fn feature_costs_ui(ui: &mut Ui, stats: &QualityStats, actions: &mut Vec<PanelAction>) {
    ui.label("Feature cost: compile a feature out to time the trace pass without it")
        .on_hover_text(
            "The image is wrong without it (a texture or light missing): only the time counts. \
             A feature the scene's texture code calls cannot be compiled out.",
        );
    ui.label(match stats.with_all_ms {
        Some(ms) => format!("with every feature: {ms:.1} ms"),
        None => "with every feature: measuring…".to_owned(),
    });
    Grid::new("feature costs").striped(true).show(ui, |ui| {
        for (feature, without) in stats.scene_features.iter().zip(&stats.without_ms) {
            let mut compiled_in = !stats.disabled.contains(feature);
            if ui
                .checkbox(&mut compiled_in, format!("{feature:?}"))
                .on_hover_text(
                    "Ticked: compiled in. Untick to rebuild the shader without it and time the \
                     trace pass (the image is then wrong)",
                )
                .changed()
            {
                actions.push(PanelAction::ToggleFeature(*feature));
            }
            match (without, stats.with_all_ms) {
                (Some(without), Some(all)) => ui.label(format!(
                    "{without:.1} ms without ({:+.1} ms)",
                    without - all
                )),
                (Some(without), None) => ui.label(format!("{without:.1} ms without")),
                _ => ui.label(""),
            };
            ui.end_row();
        }
    });
}
