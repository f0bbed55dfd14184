//! From a scene to a trace pipeline: which features it needs
//! (`features`), the WGSL table and its assembly (`shader_source`,
//! `preprocess`), the generated texture code and its parameter plan
//! (`texture_codegen`, `texture_params`), module creation and error
//! mapping (`pipelines`) and the builds off the render thread
//! (`pipeline_build`).

pub mod features;
pub mod pipeline_build;
pub mod pipelines;
pub mod preprocess;
pub mod shader_source;
pub mod texture_codegen;
pub mod texture_params;
