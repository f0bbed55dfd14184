//! marbre: an interactive ray tracer for procedural textures.

pub mod noise;
pub mod scene;
pub mod atomic_write;
pub mod preset;
