//! The texture library: the patterns of the course material as pure
//! functions of a point (uv in 2D, p in 3D) and their parameters, and the
//! mappings that give a surface point those coordinates.
//!
//! This is the CPU reference. `patterns.wgsl` (beside this file) mirrors
//! every pattern here operation for operation, and `shading.wgsl` the
//! shading helpers of `bump`, `waves` and `ramp`; the GPU parity tests run
//! them in a compute harness (`marbre_render::gpu::harness::texture`) and
//! compare. Composition (which
//! child texture a cell shows, what a blend weight mixes) is the texture
//! tree's business: a pattern only says where a point falls.

pub mod brick;
pub mod bump;
pub mod checker;
pub mod cutout;
pub mod diagonal;
pub mod image;
pub mod image_set;
pub mod mapping;
pub mod marble;
pub mod ramp;
pub mod waves;
pub mod wood;

pub use self::image::{
    AtlasEntry, AtlasTooLarge, ColorSpace, ImageAtlas, ImageError, ImageFilter, ImageLevel,
    ImageLoad, ImageWrap, MAX_IMAGE_SIDE, MipImage, load_image,
};
pub use brick::{TileSample, brick, brick_mortar_fraction, tile, tile_height};
pub use bump::bumped_normal;
pub use checker::{Cell, checker_2d, checker_3d, filtered_checker_2d, filtered_checker_3d};
pub use cutout::{cutout, cutout_area};
pub use diagonal::diagonal;
pub use image_set::{ImageSet, ImageSource};
pub use mapping::{TextureTransform, cylinder_uv, plane_uv, polygon_frame, sphere_uv, triangle_uv};
pub use marble::{marble_veins, massal_marble, massal_marble_stripes};
pub use ramp::{MAX_RAMP_STOPS, RampStop, luminance, ramp};
pub use waves::{waves, waves_gradient};
pub use wood::{default_axis, wood};

/// The patterns' shader code, the twin of this module's patterns.
pub const PATTERNS_WGSL: crate::wgsl::WgslFile =
    crate::wgsl_file!("crates/core/src/texture/patterns.wgsl");

/// The shading helpers' shader code (bump tilt, waves' gradient, ramps).
pub const SHADING_WGSL: crate::wgsl::WgslFile =
    crate::wgsl_file!("crates/core/src/texture/shading.wgsl");

/// The fraction of an n×n grid of cell centres over the unit square moved
/// to `origin` where `inside` holds: the area a pattern covers, for tests.
#[cfg(test)]
pub(crate) fn covered_fraction(
    n: usize,
    origin: glam::Vec2,
    inside: impl Fn(glam::Vec2) -> bool,
) -> f32 {
    let covered = (0..n * n)
        .filter(|k| {
            let cell = glam::Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
            inside(origin + cell / n as f32)
        })
        .count();
    covered as f32 / (n * n) as f32
}
