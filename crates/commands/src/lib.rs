//! The headless commands: each is a thin layer over the library.

pub mod accuracy_bench;
pub mod bake;
pub mod bvh_bench;
pub mod convergence_bench;
pub mod edit_bench;
pub mod farm;
pub mod interrupt;
pub mod markdown;
pub mod merge;
pub mod noise;
pub mod noise_figure;
pub mod parameters;
pub mod presets_bench;
pub mod references;
pub mod render;
pub mod tx;

use marbre_render::gpu::KernelChoice;

/// `--kernel`'s parser: the renderer's names, listed in `--help` (clap
/// lives in the command-line crates, not in marbre-render).
pub fn kernel_choice_parser() -> impl clap::builder::TypedValueParser<Value = KernelChoice> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(KernelChoice::NAMES)
        .map(|name| name.parse().expect("one of KernelChoice::NAMES"))
}

/// `--spp`'s parser: a whole number of samples from 1. The flag takes
/// negative numbers (`allow_negative_numbers`), so that `--spp -1` is
/// answered by this message rather than clap's "unexpected argument".
pub fn parse_spp(s: &str) -> Result<u32, String> {
    s.trim()
        .parse::<u32>()
        .ok()
        .filter(|&n| n >= 1)
        .ok_or_else(|| {
            format!("`{s}` is not a number of samples per pixel: give a whole number, 1 or more")
        })
}

/// `--target-error`'s parser: a positive relative error.
pub fn parse_target_error(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|e| e.is_finite() && *e > 0.0)
        .ok_or_else(|| {
            format!("`{s}` is not a target error: give a positive number, like 0.01 for 1 %")
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_and_zero_sample_counts_and_errors_are_refused_by_name() {
        assert_eq!(parse_spp("16"), Ok(16));
        for bad in ["-1", "0", "1.5", "x"] {
            assert!(
                parse_spp(bad).unwrap_err().contains("samples per pixel"),
                "{bad}"
            );
        }
        assert_eq!(parse_target_error("0.01"), Ok(0.01));
        for bad in ["-1", "0", "inf", "NaN"] {
            assert!(
                parse_target_error(bad).unwrap_err().contains("positive"),
                "{bad}"
            );
        }
    }
}
