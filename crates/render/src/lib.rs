//! marbre's renderer as a library: the WGSL shaders specialised per scene,
//! the GPU passes (trace, accumulation, metering, display, readback) and the
//! sessions that turn a preset into a ready renderer. No window, no UI.

pub mod bake_file;
pub mod cpu_display;
pub mod cpu_kernel;
pub mod denoiser;
pub mod final_render;
pub mod frame_sequence;
pub mod gpu;
pub mod session;
pub mod worker;
