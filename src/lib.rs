//! marbre: an interactive ray tracer for procedural textures.

pub mod noise;
