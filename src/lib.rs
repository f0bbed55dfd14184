//! marbre: an interactive ray tracer for procedural textures.

pub mod accel;
pub mod app;
pub mod atomic_write;
pub mod bsdf;
pub mod commands;
pub mod cubemap;
pub mod env_sampling;
pub mod envmap;
pub mod geometry;
pub mod gpu;
pub mod heap;
pub mod image_io;
pub mod lights;
pub mod mis;
pub mod noise;
pub mod obj_loader;
pub mod obj_syntax;
pub mod panel;
pub mod preset;
pub mod scene;
pub mod session;
#[cfg(test)]
mod test_dir;
pub mod texture;
