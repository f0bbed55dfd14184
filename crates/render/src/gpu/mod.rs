//! Everything that talks to wgpu: device creation, shader assembly and
//! specialisation, the progressive renderer, auto exposure, and (in
//! `harness/`) the compute passes that run shader functions for tests and
//! tools.

pub mod accumulation;
pub mod async_readback;
pub mod auto_exposure;
pub mod bake;
pub mod context;
pub mod denoise;
pub mod error_meter;
pub mod features;
pub mod geometry_buffers;
pub mod harness;
pub mod kernel;
pub mod mesh_buffers;
pub mod metering_grid;
pub mod non_finite;
pub mod pass_timer;
pub mod pipeline_build;
pub mod pipelines;
pub mod preprocess;
pub mod readback;
pub mod renderer;
pub mod scene_gpu;
pub mod shader_source;
pub mod swatch;
pub mod testing;
pub mod texture_codegen;
pub mod texture_params;
pub mod trace_bands;
pub mod trace_pass;
#[cfg(test)]
pub(crate) mod twin_layout;

pub use context::GpuContext;
pub use features::{Feature, FeatureSet};
pub use kernel::{Kernel, KernelChoice};
pub use non_finite::NonFiniteCounts;
pub use renderer::{DisplayTarget, Renderer, TraceWork, Viewport};
pub use trace_bands::TraceBudget;
pub use trace_pass::PassTimestamps;
