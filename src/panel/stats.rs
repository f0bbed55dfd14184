//! The Stats section: what the app measured, shown as is, with the
//! counters of dropped non-finite samples.

use super::Stats;
use egui::{Color32, Ui};
use marbre_render::denoiser::DenoiseReport;
use marbre_render::gpu::NonFiniteCounts;

/// The live figures for the first line of the panel (the Preset
/// section's header, which stays where the panel starts): frames per
/// second and samples per pixel so far.
pub(super) fn headline(stats: &Stats) -> String {
    let building = if stats.building {
        " · building shader…"
    } else {
        ""
    };
    format!("{:.1} fps · {} spp{building}", stats.fps, stats.samples)
}

pub(super) fn stats_ui(ui: &mut Ui, stats: &Stats) {
    ui.label(format!("{} lights", stats.lights)).on_hover_text(
        "Entries of the light table: the point light, emissive spheres and triangles",
    );
    if stats.triangles > 0 {
        ui.label(format!(
            "{} triangles, {} BVH nodes (built in {:.1} ms)",
            stats.triangles, stats.bvh_nodes, stats.bvh_build_ms
        ))
        .on_hover_text("The meshes' triangles and their bounding volume hierarchy (binned SAH)");
    }
    let clock = if stats.ms_is_gpu { "GPU" } else { "CPU" };
    ui.label(format!(
        "{:.2} ms per sample round ({clock})",
        stats.ms_per_frame
    ))
    .on_hover_text(
        "The trace's cost of one round (samples per frame for every pixel), from its measured \
         time per pixel. GPU: timestamp queries around the passes; CPU: wall time per frame",
    );
    ui.label(format!("{} samples accumulated", stats.samples));
    if stats.round_progress > 0.0 {
        ui.add(
            egui::ProgressBar::new(stats.round_progress)
                .text("next round")
                .desired_height(12.0),
        )
        .on_hover_text(
            "A round costs more than a frame's trace budget: it is traced a band of rows per \
             frame, and shown once complete",
        );
    }
    ui.label(format!(
        "trace kernel: {} ({})",
        stats.kernel, stats.kernel_reason
    ));
    non_finite_ui(ui, &stats.non_finite);
    if let Some(report) = &stats.denoise {
        denoise_ui(ui, report);
    }
    let (w, h) = stats.resolution;
    ui.label(format!("{w} × {h}"));
    ui.label(format!("{} ({})", stats.adapter, stats.backend));
    let features = if stats.features.is_empty() {
        "none".to_owned()
    } else {
        stats.features.join(", ")
    };
    ui.label(format!("shader features: {features}"))
        .on_hover_text("What the current scene compiled into the shader");
    ui.label(format!(
        "trace shader: {:.1} KiB of WGSL",
        stats.shader_bytes as f32 / 1024.0
    ))
    .on_hover_text("The assembled trace module: the files its features need, plus the code generated from the texture trees");
    if stats.building {
        ui.label("building a new shader… (the old one renders meanwhile)");
    } else if let Some(ms) = stats.last_build_ms {
        ui.label(format!("last shader build: {ms:.0} ms"))
            .on_hover_text(
                "From the structural edit to the new pipeline, built off the render thread",
            );
    }
}

/// The NaN and Inf counters: red as soon as one sample was dropped, since a
/// correct renderer never produces one.
/// Which denoiser runs, on which device, and its last time: two short
/// lines, as the panel's width clips a long one.
fn denoise_ui(ui: &mut Ui, report: &DenoiseReport) {
    ui.label(format!("denoiser: {}", report.running.describe()))
        .on_hover_text(
            "OIDN filters a copy of the accumulation off the render thread: the image shown \
             is the last one filtered (at 1, 2, 4, 8… rounds and when the image settles), or \
             the raw one before the first",
        );
    if let Some((took, samples)) = report.last {
        ui.label(format!(
            "last denoise: {:.0} ms, at {samples} spp",
            took.as_secs_f64() * 1e3
        ));
    }
}

fn non_finite_ui(ui: &mut Ui, counts: &NonFiniteCounts) {
    let text = format!(
        "non-finite samples: {} NaN, {} Inf ({} pixels)",
        counts.nan, counts.infinite, counts.pixels
    );
    let label = if counts.is_zero() {
        ui.label(text)
    } else {
        ui.colored_label(Color32::from_rgb(230, 60, 60), text)
    };
    label.on_hover_text(
        "Samples the accumulation dropped since the image restarted because they were NaN or \
         infinite; \"show non-finite pixels\" (Render) paints where they fell",
    );
}
