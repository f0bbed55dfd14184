//! Everything that talks to wgpu, in folders by job: `shader/` (from a
//! scene to a pipeline: features, WGSL assembly, generated texture code),
//! `passes/` (the trace pass, the meters, the denoiser, swatches and
//! bakes), `transfer/` (the scene's buffers, read-backs), `renderer/` (the
//! progressive renderer built from those parts), and `harness/` (compute
//! passes that run shader functions for tests and tools). Each module is
//! also re-exported here by name (`gpu::features`, `gpu::scene_gpu`…), the
//! paths callers and the tests use.

pub mod context;
pub mod harness;
pub mod kernel;
pub mod passes;
pub mod renderer;
pub mod shader;
pub mod testing;
pub mod transfer;
#[cfg(test)]
pub(crate) mod twin_layout;

pub use passes::{
    accumulation, auto_exposure, bake, denoise, error_meter, metering_grid, non_finite, pass_timer,
    preview_ladder, swatch, trace_bands, trace_pass,
};
pub use shader::{
    features, pipeline_build, pipelines, preprocess, shader_source, texture_codegen, texture_params,
};
pub use transfer::{async_readback, geometry_buffers, mesh_buffers, readback, scene_gpu};

pub use context::GpuContext;
pub use features::{Feature, FeatureSet};
pub use kernel::{Kernel, KernelChoice};
pub use non_finite::NonFiniteCounts;
pub use renderer::{DisplayTarget, Renderer, TraceWork, Viewport};
pub use trace_bands::TraceBudget;
pub use trace_pass::PassTimestamps;
