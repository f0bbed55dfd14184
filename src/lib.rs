//! marbre: an interactive ray tracer for procedural textures.

pub mod noise;
pub mod scene;
pub mod atomic_write;
pub mod preset;
pub mod gpu;
pub mod panel;
pub mod envmap;
pub mod app;
pub mod commands;
pub mod image_io;
