//! The headless commands: each is a thin layer over the library.

pub mod accuracy_bench;
pub mod bake;
pub mod bvh_bench;
pub mod convergence_bench;
pub mod edit_bench;
pub mod noise;
pub mod noise_figure;
pub mod presets_bench;
pub mod references;
pub mod render;
pub mod tx;
