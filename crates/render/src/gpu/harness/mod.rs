//! Compute harnesses: each runs shader functions of the renderer on inputs
//! given from the CPU and reads the results back, so tests (and `marbre
//! noise`, `marbre bench-bvh`) hold the WGSL to its CPU twin. Each harness
//! is a Rust file beside its WGSL entry point; all of them build their
//! pipeline, upload their inputs and read back through `dispatch`.

pub mod accumulation;
pub mod bvh;
pub mod dispatch;
pub mod geometry;
pub mod noise;
pub mod points;
pub mod sampling;
pub mod texture;
