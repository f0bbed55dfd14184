//! `marbre bench --quick`, run once into a scratch folder: every knob's
//! rows in the CSV with finite, non-negative numbers, a valid plot per
//! knob, and on the samples-per-pixel knob the rate Monte Carlo promises,
//! error ∝ spp^-1/2.

use marbre_commands::accuracy_bench::{self, AccuracyBenchArgs, CSV_HEADER, Knob, log_log_slope};
use marbre_render::gpu::testing::gpu_or_skip;
use std::path::{Path, PathBuf};

/// A scratch folder, removed when the test passes (kept to look at when it
/// fails).
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("marbre-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// The fields of one CSV line, with RFC 4180 quoting undone.
fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            _ => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

#[test]
fn csv_fields_undo_quoting() {
    assert_eq!(
        csv_fields(r#"a,"b, c","d ""e""",7"#),
        ["a", "b, c", "d \"e\"", "7"]
    );
}

/// The CSV's rows, each a map from column to field.
fn read_rows(csv: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().expect("a header line");
    assert_eq!(header, CSV_HEADER);
    let columns = csv_fields(header);
    lines
        .map(|line| {
            let fields = csv_fields(line);
            assert_eq!(fields.len(), columns.len(), "row {line}");
            columns.iter().cloned().zip(fields).collect()
        })
        .collect()
}

#[test]
fn the_quick_bench_covers_every_knob_and_finds_the_monte_carlo_rate() {
    let Some(ctx) = gpu_or_skip("the_quick_bench_covers_every_knob_and_finds_the_monte_carlo_rate")
    else {
        return;
    };
    let scratch = Scratch::new("accuracy-bench");
    let out = scratch.0.join("out");
    let args = AccuracyBenchArgs {
        quick: true,
        knobs: Vec::new(),
        out: out.clone(),
        cache: scratch.0.join("references"),
        root: PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")),
        kernel: marbre_render::gpu::KernelChoice::Fragment,
    };
    let results = accuracy_bench::run_on(&ctx, &args, false).unwrap();
    // An empty cache: every reference rendered, and kept for the next run;
    // two are read back within the run: the esplanade's, which environment
    // sampling and the firefly clamp both measure against, and the default
    // preset's, which the shader and denoise knobs both measure against.
    assert_eq!(results.references_cached, 2);
    let kept = std::fs::read_dir(&args.cache).unwrap().count();
    assert!(results.references_rendered >= Knob::ALL.len());
    assert_eq!(kept, results.references_rendered);

    let rows = read_rows(&out.join("results.csv"));
    assert_eq!(rows.len(), results.points.len());
    for knob in Knob::ALL {
        let of_knob: Vec<_> = rows.iter().filter(|r| r["knob"] == knob.id()).collect();
        let variants: std::collections::HashSet<_> =
            of_knob.iter().map(|r| &r["variant"]).collect();
        assert!(!of_knob.is_empty(), "no rows for {}", knob.id());
        assert!(
            knob == Knob::Spp || variants.len() >= 2,
            "{}: one variant only",
            knob.id()
        );
    }
    for row in &rows {
        for column in ["spp", "ms_per_frame", "seconds", "rmse", "relmse", "mae"] {
            let value: f64 = row[column].parse().unwrap();
            assert!(
                value.is_finite() && value >= 0.0,
                "{column} = {value} in {row:?}"
            );
        }
        assert!(row["seconds"].parse::<f64>().unwrap() > 0.0, "{row:?}");
        assert!(["gpu-timestamps", "wall-clock"].contains(&row["timer"].as_str()));
        assert_eq!(row["adapter"], ctx.describe());
    }

    let report = std::fs::read_to_string(out.join("results.md")).unwrap();
    for knob in Knob::ALL {
        let plot = out.join(format!("{}.png", knob.id()));
        let image = image::open(&plot).unwrap_or_else(|e| panic!("{}: {e}", plot.display()));
        assert!(image.width() >= 400 && image.height() >= 300);
        assert!(report.contains(&format!("## {}", knob.title())));
        assert!(report.contains(&format!("({}.png)", knob.id())));
    }
    assert!(report.contains(&ctx.describe()));

    // The quick reference has 16 times the last count's samples: its own
    // variance adds 1/16 to the last point's, which flattens the slope by
    // under 0.02.
    let spp: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r["knob"] == "spp")
        .map(|r| (r["spp"].parse().unwrap(), r["rmse"].parse().unwrap()))
        .collect();
    assert!(spp.len() >= 5, "{spp:?}");
    let slope = log_log_slope(&spp).unwrap();
    assert!((slope + 0.5).abs() <= 0.15, "RMSE ∝ spp^{slope}: {spp:?}");
}
