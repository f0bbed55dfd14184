//! The GPU tests: one binary, as the wgpu examples do, so the renderer and
//! its dependencies are linked once. Each module runs the real WGSL (on
//! lavapipe in CI) against an independent expectation; `common` holds the
//! render helpers they share. Without an adapter each test skips loudly
//! (`MARBRE_REQUIRE_GPU=1` turns a skip into a failure).

/// The repository's root: the shipped presets, images and env maps.
const REPO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

mod accumulation;
mod bad_input;
mod bake;
mod bvh;
mod chi2;
mod common;
mod course_looks;
mod cpu_kernel;
mod cubemap;
mod denoise;
mod diffuse_transmission;
mod edit_path;
mod error_estimate;
mod exposure;
mod extreme_radiance;
mod geometry_stability;
mod gpu_parity;
mod integrators;
mod kernels;
mod light_points;
mod light_transport;
mod noise_stability;
mod non_finite;
mod offscreen;
mod oidn;
mod orthographic;
mod presets;
mod report_frames;
mod sampling_stability;
mod sampling_support;
mod swatch;
mod texture_graph;
mod texture_parity;
mod tx;
mod views;
