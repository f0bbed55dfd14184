//! marbre's model and CPU reference: the scene, presets, noise, textures,
//! images and OBJ loading, the acceleration structure, lights, BSDF, MIS and
//! sampling. No GPU: every function here is what the shaders must match.

pub mod aa_scenes;
pub mod accel;
pub mod animated_image;
pub mod animation;
pub mod atomic_write;
pub mod bake;
pub mod bsdf;
pub mod capped_read;
pub mod child_process;
pub mod cubemap;
pub mod env_sampling;
pub mod envmap;
pub mod geometry;
pub mod image_decode;
pub mod image_io;
pub mod lexical_path;
pub mod lights;
pub mod merge;
pub mod mis;
pub mod noise;
pub mod obj_loader;
pub mod obj_scene;
pub mod obj_syntax;
pub mod page_files;
pub mod preset;
pub mod render_record;
pub mod scene;
pub mod shown;
pub mod texture;
pub mod tile;
pub mod tx;
pub mod tx_preview;
pub mod viewer_files;
pub mod wgsl;

/// The repository's root, where the shipped presets, images and env maps
/// that unit tests read live.
#[cfg(test)]
const REPO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
