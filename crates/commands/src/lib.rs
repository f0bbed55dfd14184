//! The headless commands: each is a thin layer over the library.

pub mod accuracy_bench;
pub mod bake;
pub mod bvh_bench;
pub mod convergence_bench;
pub mod edit_bench;
pub mod interrupt;
pub mod noise;
pub mod noise_figure;
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
