//! The bench's written results: `results.csv`, one row a point, for other
//! tools; `results.md`, a table and findings per knob with its plot, for
//! people.

use super::knob::Knob;
use super::measure::Point;
use super::scale::Scale;
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

pub const CSV_HEADER: &str =
    "knob,scene,variant,spp,ms_per_frame,seconds,rmse,relmse,mae,timer,adapter";

/// What the Markdown report says about the run as a whole.
pub struct RunInfo<'a> {
    pub adapter: &'a str,
    pub timer: &'a str,
    /// The trace kernel the sweeps used, in words.
    pub kernel: &'a str,
    pub scale: &'a Scale,
    pub quick: bool,
    /// Of the whole run, references included.
    pub seconds: f64,
    pub references_rendered: usize,
    pub references_cached: usize,
}

/// What the report says about one knob.
pub struct KnobReport<'a> {
    pub knob: Knob,
    pub points: Vec<&'a Point>,
    pub findings: Vec<String>,
    /// The plot's file name, beside the report.
    pub plot: String,
}

pub fn write_csv(path: &Path, points: &[Point], adapter: &str) -> Result<()> {
    let mut out = format!("{CSV_HEADER}\n");
    for p in points {
        let fields = [
            p.knob.id().to_string(),
            p.scene.clone(),
            p.variant.clone(),
            p.spp.to_string(),
            p.ms_per_frame.to_string(),
            p.seconds.to_string(),
            p.errors.rmse.to_string(),
            p.errors.relmse.to_string(),
            p.errors.mae.to_string(),
            p.timer.name().to_string(),
            adapter.to_string(),
        ];
        let row: Vec<String> = fields.iter().map(|f| csv_field(f)).collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    std::fs::write(path, out).with_context(|| format!("writing {}", path.display()))
}

/// `field` quoted as RFC 4180 wants where it holds a comma, a quote or a
/// line break (adapter names hold commas).
fn csv_field(field: &str) -> String {
    if field.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", field.replace('"', "\"\""))
    } else {
        field.to_string()
    }
}

pub fn write_markdown(path: &Path, run: &RunInfo, knobs: &[KnobReport]) -> Result<()> {
    let mut md = String::from("# marbre accuracy benchmark\n\n");
    let (w, h) = run.scale.size;
    let _ = writeln!(md, "* adapter: {}", run.adapter);
    let _ = writeln!(md, "* trace kernel: {}", run.kernel);
    let _ = writeln!(
        md,
        "* time per frame: {} (one sample per pixel a frame, every frame waited for; seconds are wall clock)",
        run.timer
    );
    let _ = writeln!(
        md,
        "* {} run: {w}×{h} pixels; samples per pixel 1 to {} (reference {}), other knobs at {} (references {} spp)",
        if run.quick { "quick" } else { "full" },
        run.scale.max_spp,
        run.scale.spp_reference,
        run.scale
            .variant_spp
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(", "),
        run.scale.reference_spp,
    );
    if knobs.iter().any(|k| k.knob == Knob::Denoise) {
        let (w, h) = run.scale.denoise_size;
        let _ = writeln!(
            md,
            "* the denoise knob: {w}×{h} pixels at {} spp (reference {})",
            run.scale
                .denoise_spp
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            run.scale.denoise_reference_spp,
        );
    }
    let _ = writeln!(
        md,
        "* the run took {:.0} s, with {} references rendered and {} read from the cache",
        run.seconds, run.references_rendered, run.references_cached
    );
    md.push_str("* errors on linear radiance against each variant's high-spp reference: RMSE, relMSE = mean of (x − ref)² / (ref² + 0.01), MAE\n");
    for knob in knobs {
        md.push_str(&knob_section(knob));
    }
    std::fs::write(path, md).with_context(|| format!("writing {}", path.display()))
}

fn knob_section(report: &KnobReport) -> String {
    let mut md = format!("\n## {}\n\n", report.knob.title());
    md.push_str("| scene | variant | spp | ms/frame | seconds | RMSE | relMSE | MAE |\n");
    md.push_str("|---|---|---:|---:|---:|---:|---:|---:|\n");
    for p in &report.points {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3} | {:.3} | {:.5} | {:.5} | {:.5} |",
            p.scene,
            p.variant,
            p.spp,
            p.ms_per_frame,
            p.seconds,
            p.errors.rmse,
            p.errors.relmse,
            p.errors.mae
        );
    }
    md.push('\n');
    for line in &report.findings {
        let _ = writeln!(md, "* {line}");
    }
    let _ = writeln!(
        md,
        "\n![{}: RMSE against time]({})",
        report.knob.title(),
        report.plot
    );
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_with_commas_or_quotes_are_quoted() {
        assert_eq!(csv_field("cornell"), "cornell");
        assert_eq!(
            csv_field("llvmpipe (LLVM 15, 256 bits)"),
            "\"llvmpipe (LLVM 15, 256 bits)\""
        );
        assert_eq!(csv_field("a \"b\""), "\"a \"\"b\"\"\"");
    }
}
