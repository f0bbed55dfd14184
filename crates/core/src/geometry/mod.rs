//! CPU twins of the scene-free ray geometry in `shaders/ray_geometry.wgsl`:
//! the sphere's distance and the robust ray offset, line for line, so that
//! tests can hold the f32 shader and its twin to double precision
//! (`tests/geometry_stability.rs`, through `gpu::geometry_harness`).

pub mod ray_offset;
pub mod sphere;

pub use ray_offset::offset_ray;
pub use sphere::{NO_HIT, sphere_distance};
