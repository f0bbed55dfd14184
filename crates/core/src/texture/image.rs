//! Image textures: pictures loaded from files, mip-mapped, packed into one
//! GPU atlas and sampled with nearest, bilinear or trilinear filtering and
//! repeat, clamp or mirror wrapping.
//!
//! # Convention
//!
//! Texture coordinates `(u, v)` have v up: `(0, 0)` is the bottom-left of
//! the picture, `(1, 1)` its top-right, while texel row 0 is its top (as in
//! the file). On a level of W×H texels, `(u, v)` lies at the continuous
//! texel coordinates `x = u·W`, `y = (1 − v)·H`; texel centres are at
//! `+0.5`.
//!
//! # Why filtering is done by hand
//!
//! The GPU holds every image of a scene in one `Rgba16Float` texture, the
//! [`ImageAtlas`], read with `textureLoad`; `crates/core/src/texture/image.wgsl`
//! wraps and filters by hand. A hardware sampler could do neither here:
//! wrapping in an atlas must stay inside one image's rectangle, and the
//! filter and wrap mode are per texture, while a sampler is per binding.
//! Doing it by hand also makes the GPU code the same operations as the CPU
//! reference in this module ([`MipImage::sample`], [`ImageAtlas::sample`]),
//! where a sampler's filtering weights are not specified to the bit; the
//! parity tests compare the two.
//!
//! # Why power-of-two sizes
//!
//! As pbrt-v3's `MIPMap` does, an image whose sides are not powers of two
//! is resampled on load to the nearest ones, so that every mip level is the
//! exact 2×2 box average of the level before, down to 1×1. The level count
//! and the atlas layout then follow from the level-0 size alone, which is
//! all the shader is told.
//!
//! Images are decoded and sanitised by [`crate::image_decode`], as
//! environment maps are; alpha is 1 (the decoder drops it).

use std::path::{Path, PathBuf};

use glam::{IVec2, UVec2, Vec2, Vec4};
use half::f16;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::image_decode::{self, DecodeError, IntegerDecode};

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/texture/image.wgsl");

/// The largest side of an image's level 0: larger images are resampled down
/// to it.
pub const MAX_IMAGE_SIDE: u32 = 1024;

/// How an image is filtered. The discriminant is the shader's `filter_mode`
/// ([`ImageFilter::id`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ImageFilter {
    /// The texel under the point, from level 0.
    Nearest = 0,
    /// The four texels around the point, from level 0.
    #[default]
    Bilinear = 1,
    /// Bilinear in the two mip levels around the level of detail, blended.
    Trilinear = 2,
}

impl ImageFilter {
    /// The shader's `filter_mode` argument.
    pub fn id(self) -> u32 {
        self as u32
    }
}

/// What an image shows outside `[0, 1]²`. The discriminant is the shader's
/// `wrap` ([`ImageWrap::id`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ImageWrap {
    /// Tiled.
    #[default]
    Repeat = 0,
    /// The edge texels, stretched outwards.
    Clamp = 1,
    /// Tiled, every other tile flipped, so tiles meet seamlessly.
    Mirror = 2,
}

impl ImageWrap {
    /// The shader's `wrap` argument.
    pub fn id(self) -> u32 {
        self as u32
    }

    /// Texel index `i` of a row or column of `n` texels, wrapped into
    /// `[0, n - 1]`. Mirror repeats `0 1 … n−1 n−1 … 1 0` (period 2n).
    fn index(self, i: i32, n: i32) -> i32 {
        match self {
            ImageWrap::Repeat => i.rem_euclid(n),
            ImageWrap::Clamp => i.clamp(0, n - 1),
            ImageWrap::Mirror => {
                let period = 2 * n;
                let m = i.rem_euclid(period);
                if m >= n { period - 1 - m } else { m }
            }
        }
    }
}

/// How the integer codes of an 8- or 16-bit image become values. Float
/// files (EXR, Radiance HDR) are linear either way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ColorSpace {
    /// Colour: decoded with the exact sRGB EOTF.
    #[default]
    Srgb,
    /// Data such as roughness or height: code / max code.
    Linear,
}

impl ColorSpace {
    fn integer_decode(self) -> IntegerDecode {
        match self {
            ColorSpace::Srgb => IntegerDecode::Srgb,
            ColorSpace::Linear => IntegerDecode::Linear,
        }
    }
}

/// Why an image texture could not be loaded. Every variant names the file.
#[derive(Debug, Error)]
pub enum ImageError {
    /// The file is missing or unreadable.
    #[error("image texture {}: cannot read the file: {cause}", .path.display())]
    Io {
        path: PathBuf,
        cause: std::io::Error,
    },
    /// The extension is not one [`load_image`] understands.
    #[error(
        "image texture {}: unsupported file type {}; supported: {}",
        .path.display(),
        if .extension.is_empty() { "(no extension)".to_string() } else { format!(".{}", .extension) },
        crate::image_decode::supported_list()
    )]
    UnsupportedExtension { path: PathBuf, extension: String },
    /// The decoder rejected the file; `message` says why.
    #[error("image texture {}: cannot decode {format}: {message}", .path.display())]
    Decode {
        path: PathBuf,
        format: &'static str,
        message: String,
    },
    /// The image has no texels.
    #[error("image texture {}: the image is empty ({width}x{height})", .path.display())]
    Empty {
        path: PathBuf,
        width: u32,
        height: u32,
    },
}

impl From<DecodeError> for ImageError {
    fn from(error: DecodeError) -> ImageError {
        match error {
            DecodeError::Io { path, cause } => ImageError::Io { path, cause },
            DecodeError::UnsupportedExtension { path, extension } => {
                ImageError::UnsupportedExtension { path, extension }
            }
            DecodeError::Decode {
                path,
                format,
                message,
            } => ImageError::Decode {
                path,
                format,
                message,
            },
            DecodeError::ExrCompression {
                path,
                compression,
                message,
            } => ImageError::Decode {
                path,
                format: "OpenEXR",
                message: format!(
                    "{compression} compression: {message}; {}",
                    image_decode::EXR_RESAVE_HINT
                ),
            },
            DecodeError::Empty {
                path,
                width,
                height,
            } => ImageError::Empty {
                path,
                width,
                height,
            },
        }
    }
}

/// One mip level: linear RGBA, row-major, row 0 = top of the picture.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageLevel {
    pub width: u32,
    pub height: u32,
    /// `width * height` texels.
    pub texels: Vec<[f32; 4]>,
}

impl ImageLevel {
    /// The texel at column `x`, row `y` (row 0 = top).
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        self.texels[y as usize * self.width as usize + x as usize]
    }

    /// This level resampled to `width` × `height` with a tent filter one
    /// output texel wide (at least one input texel), separably. Its weights
    /// are never negative, so it cannot ring below zero on high-dynamic-range
    /// images (and unlike `image::imageops::resize` it does not clamp floats
    /// to [0, 1]).
    fn resized(&self, width: u32, height: u32) -> ImageLevel {
        let columns = tent_taps(self.width, width);
        let rows = tent_taps(self.height, height);
        let wide: Vec<Vec4> = (0..self.height)
            .flat_map(|y| {
                columns.iter().map(move |taps| {
                    taps.iter()
                        .map(|&(x, w)| Vec4::from(self.texel(x, y)) * w)
                        .sum()
                })
            })
            .collect();
        let texels = rows
            .iter()
            .flat_map(|taps| {
                let wide = &wide;
                (0..width).map(move |x| {
                    let texel: Vec4 = taps
                        .iter()
                        .map(|&(y, w)| wide[(y * width + x) as usize] * w)
                        .sum();
                    texel.to_array()
                })
            })
            .collect();
        ImageLevel {
            width,
            height,
            texels,
        }
    }

    /// The next mip level: each texel the box average of the 2×2 texels
    /// above it, or of 2×1 or 1×2 once a side is 1. Sides must be powers of
    /// two.
    fn halved(&self) -> ImageLevel {
        let width = (self.width / 2).max(1);
        let height = (self.height / 2).max(1);
        let step = UVec2::new(self.width / width, self.height / height);
        let weight = 1.0 / (step.x * step.y) as f32;
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| {
                let sum: Vec4 = (0..step.y)
                    .flat_map(|dy| (0..step.x).map(move |dx| (dx, dy)))
                    .map(|(dx, dy)| Vec4::from(self.texel(x * step.x + dx, y * step.y + dy)))
                    .sum();
                (sum * weight).to_array()
            })
            .collect();
        ImageLevel {
            width,
            height,
            texels,
        }
    }
}

/// For each of `to` output texels along one axis, the input texels of a
/// tent filter over `from` texels and their weights, summing to 1.
fn tent_taps(from: u32, to: u32) -> Vec<Vec<(u32, f32)>> {
    let scale = from as f32 / to as f32;
    let radius = scale.max(1.0);
    (0..to)
        .map(|i| {
            let centre = (i as f32 + 0.5) * scale;
            let first = (centre - radius).floor().max(0.0) as u32;
            let end = ((centre + radius).ceil() as u32).min(from);
            let taps: Vec<(u32, f32)> = (first..end)
                .map(|j| (j, 1.0 - (j as f32 + 0.5 - centre).abs() / radius))
                .filter(|&(_, w)| w > 0.0)
                .collect();
            let total: f32 = taps.iter().map(|&(_, w)| w).sum();
            taps.into_iter().map(|(j, w)| (j, w / total)).collect()
        })
        .collect()
}

/// The power of two nearest to `side` (the larger on a tie), at most
/// [`MAX_IMAGE_SIDE`].
pub fn power_of_two_side(side: u32) -> u32 {
    if side >= MAX_IMAGE_SIDE {
        return MAX_IMAGE_SIDE;
    }
    let above = side.next_power_of_two();
    let below = if above == side { side } else { above / 2 };
    if side - below < above - side {
        below
    } else {
        above
    }
}

/// An image and its mip chain: level 0 has power-of-two sides of at most
/// [`MAX_IMAGE_SIDE`], each next level is half as large, the last is 1×1.
#[derive(Debug, Clone, PartialEq)]
pub struct MipImage {
    levels: Vec<ImageLevel>,
}

impl MipImage {
    /// Builds the chain of `image`, resampled first to
    /// [`power_of_two_side`]s unless its sides already are those.
    ///
    /// # Panics
    /// If `image.texels` does not hold `width * height` texels, or a side is 0.
    pub fn new(image: ImageLevel) -> MipImage {
        assert!(image.width > 0 && image.height > 0, "empty image");
        assert_eq!(
            image.texels.len(),
            image.width as usize * image.height as usize
        );
        let width = power_of_two_side(image.width);
        let height = power_of_two_side(image.height);
        let level0 = if (width, height) == (image.width, image.height) {
            image
        } else {
            image.resized(width, height)
        };
        let mut levels = vec![level0];
        while let Some(last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            let next = last.halved();
            levels.push(next);
        }
        MipImage { levels }
    }

    /// The levels, level 0 first.
    pub fn levels(&self) -> &[ImageLevel] {
        &self.levels
    }

    /// Level 0's width and height.
    pub fn size(&self) -> UVec2 {
        UVec2::new(self.levels[0].width, self.levels[0].height)
    }

    /// The filtered value at `uv` (v up); `lod` is the mip level for
    /// [`ImageFilter::Trilinear`] (fractional, clamped to the chain; should
    /// be finite), ignored by the other filters.
    pub fn sample(&self, uv: Vec2, filter: ImageFilter, wrap: ImageWrap, lod: f32) -> Vec4 {
        let chain = Chain {
            size: self.size().as_ivec2(),
            fetch: |k: i32, t: IVec2| {
                Vec4::from(self.levels[k as usize].texel(t.x as u32, t.y as u32))
            },
        };
        chain.sample(uv, filter, wrap, lod)
    }
}

/// The number of levels of a chain whose level 0 is `size` (powers of two).
fn level_count(size: IVec2) -> i32 {
    size.x.max(size.y).ilog2() as i32 + 1
}

/// The size of level `k`: each side halved `k` times, at least 1.
fn level_size(size: IVec2, k: i32) -> IVec2 {
    (size >> k).max(IVec2::ONE)
}

/// Where level `k` of a chain whose level 0 is `size` starts in the atlas,
/// relative to level 0's top-left. Levels 1, 2, … stack downwards in one
/// column right of level 0; level j ≥ 1 is `max(1, H >> j)` rows tall, so
/// level k starts `H − (H >> (k−1))` rows down while the levels above it
/// are at least one row tall, plus one row per level beyond the one where
/// the height reached 1 (images wider than tall: an 8×1 image has its
/// levels 1, 2, 3 in rows 0, 1, 2).
fn level_origin(size: IVec2, k: i32) -> IVec2 {
    if k == 0 {
        return IVec2::ZERO;
    }
    let halvings = (k - 1).min(size.y.trailing_zeros() as i32);
    IVec2::new(size.x, size.y - (size.y >> halvings) + (k - 1 - halvings))
}

/// The atlas area one image takes: level 0, and its other levels in a
/// column `max(1, W/2)` wide to the right, as tall as level 0 or, for
/// images much wider than tall, as the column of levels.
fn footprint(size: IVec2) -> UVec2 {
    let last = level_count(size) - 1;
    let column_bottom = level_origin(size, last).y + level_size(size, last).y;
    UVec2::new(
        (size.x + (size.x / 2).max(1)) as u32,
        size.y.max(column_bottom) as u32,
    )
}

/// A mip chain as sampling sees it: level 0's size and a way to read texel
/// `(x, y)` of level `k`. The same code samples a [`MipImage`] and an
/// image in the [`ImageAtlas`]; it is `crates/core/src/texture/image.wgsl`
/// operation for operation.
struct Chain<F: Fn(i32, IVec2) -> Vec4> {
    size: IVec2,
    fetch: F,
}

impl<F: Fn(i32, IVec2) -> Vec4> Chain<F> {
    fn sample(&self, uv: Vec2, filter: ImageFilter, wrap: ImageWrap, lod: f32) -> Vec4 {
        match filter {
            ImageFilter::Nearest => self.nearest(uv, wrap),
            ImageFilter::Bilinear => self.bilinear(0, uv, wrap),
            ImageFilter::Trilinear => {
                let last = level_count(self.size) - 1;
                let l = lod.clamp(0.0, last as f32);
                let base = l.floor();
                let k = base as i32;
                let t = l - base;
                let fine = self.bilinear(k, uv, wrap);
                let coarse = self.bilinear((k + 1).min(last), uv, wrap);
                fine * (1.0 - t) + coarse * t
            }
        }
    }

    fn nearest(&self, uv: Vec2, wrap: ImageWrap) -> Vec4 {
        let i = texel_coords(uv, self.size).floor().as_ivec2();
        let x = wrap.index(i.x, self.size.x);
        let y = wrap.index(i.y, self.size.y);
        (self.fetch)(0, IVec2::new(x, y))
    }

    fn bilinear(&self, k: i32, uv: Vec2, wrap: ImageWrap) -> Vec4 {
        let size = level_size(self.size, k);
        let p = texel_coords(uv, size) - 0.5;
        let base = p.floor();
        let f = p - base;
        let i = base.as_ivec2();
        // Wrapping like the shader's i32 addition at the far end of the range.
        let x0 = wrap.index(i.x, size.x);
        let x1 = wrap.index(i.x.wrapping_add(1), size.x);
        let y0 = wrap.index(i.y, size.y);
        let y1 = wrap.index(i.y.wrapping_add(1), size.y);
        let texel = |x: i32, y: i32| (self.fetch)(k, IVec2::new(x, y));
        let upper = texel(x0, y0) * (1.0 - f.x) + texel(x1, y0) * f.x;
        let lower = texel(x0, y1) * (1.0 - f.x) + texel(x1, y1) * f.x;
        upper * (1.0 - f.y) + lower * f.y
    }
}

/// The continuous texel coordinates of `uv` on a level of `size` texels.
fn texel_coords(uv: Vec2, size: IVec2) -> Vec2 {
    Vec2::new(uv.x, 1.0 - uv.y) * size.as_vec2()
}

/// The result of [`load_image`]: the mip-mapped image and one note per
/// repair or resample made to it (empty for a clean power-of-two file).
#[derive(Debug, Clone)]
pub struct ImageLoad {
    pub image: MipImage,
    pub notes: Vec<String>,
}

/// Loads an image texture: PNG, JPEG (`.jpg`, `.jpeg`), Radiance HDR or
/// OpenEXR, by extension (case-insensitive). Integer images are decoded as
/// `space` says, float ones are linear; NaN, infinite and negative values
/// become 0 and values above the half-float maximum are clamped (each noted);
/// sides that are not powers of two are resampled (noted).
pub fn load_image(path: &Path, space: ColorSpace) -> Result<ImageLoad, ImageError> {
    let decoded = image_decode::decode_file(path, space.integer_decode())?;
    let (width, height) = (decoded.width, decoded.height);
    let image = MipImage::new(ImageLevel {
        width,
        height,
        texels: decoded.pixels,
    });
    let mut notes = decoded.notes;
    let size = image.size();
    if size != UVec2::new(width, height) {
        let file_name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.display().to_string());
        notes.push(format!(
            "{file_name}: {width}×{height} resampled to {}×{} for mipmapping",
            size.x, size.y
        ));
    }
    Ok(ImageLoad { image, notes })
}

/// Where one image lies in the [`ImageAtlas`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AtlasEntry {
    /// The top-left texel of level 0.
    pub x: u32,
    pub y: u32,
    /// Level 0's size, powers of two.
    pub width: u32,
    pub height: u32,
    /// The number of mip levels, `log2(max(width, height)) + 1`.
    pub levels: u32,
}

impl AtlasEntry {
    /// The shader's `rect`: `[x, y, width, height]`. The level count is not
    /// passed: every chain goes down to 1×1, so the shader derives it from
    /// the size, as it does each level's place (see `level_origin`).
    pub fn params(&self) -> [f32; 4] {
        [self.x, self.y, self.width, self.height].map(|v| v as f32)
    }
}

/// The images do not fit in a texture of the GPU's largest size.
#[derive(Debug, Error)]
#[error(
    "image textures: {images} images need a {width}×{height} atlas, \
     more than the GPU's largest texture ({max_side}×{max_side}); use fewer or smaller images"
)]
pub struct AtlasTooLarge {
    pub images: usize,
    pub width: u32,
    pub height: u32,
    pub max_side: u32,
}

/// Every image of a scene with its mip levels in one `Rgba16Float` texture,
/// as the shader reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageAtlas {
    pub width: u32,
    pub height: u32,
    /// Row-major, `width * height` texels, row 0 at the top; RGBA.
    pub texels: Vec<[f16; 4]>,
    /// One per packed image, in the order given to [`ImageAtlas::pack`].
    pub entries: Vec<AtlasEntry>,
}

impl ImageAtlas {
    /// Packs `images` on shelves (tallest first) no wider than `max_side`,
    /// the GPU's `max_texture_dimension_2d`. The atlas is as large as the
    /// shelves need; with no images it is one black texel.
    pub fn pack(images: &[&MipImage], max_side: u32) -> Result<ImageAtlas, AtlasTooLarge> {
        let sizes: Vec<UVec2> = images.iter().map(|image| image.size()).collect();
        let footprints: Vec<UVec2> = sizes.iter().map(|s| footprint(s.as_ivec2())).collect();
        let shelf_width = footprints.iter().map(|f| f.x).fold(max_side, u32::max);
        let mut order: Vec<usize> = (0..images.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(footprints[i].y));

        let mut origins = vec![UVec2::ZERO; images.len()];
        let mut cursor = UVec2::ZERO;
        let mut shelf_height = 0;
        let mut extent = UVec2::ONE;
        for i in order {
            let footprint = footprints[i];
            if cursor.x + footprint.x > shelf_width {
                cursor = UVec2::new(0, cursor.y + shelf_height);
                shelf_height = 0;
            }
            origins[i] = cursor;
            extent = extent.max(cursor + footprint);
            cursor.x += footprint.x;
            shelf_height = shelf_height.max(footprint.y);
        }
        if extent.x > max_side || extent.y > max_side {
            return Err(AtlasTooLarge {
                images: images.len(),
                width: extent.x,
                height: extent.y,
                max_side,
            });
        }

        let mut atlas = ImageAtlas {
            width: extent.x,
            height: extent.y,
            texels: vec![[f16::ZERO; 4]; (extent.x * extent.y) as usize],
            entries: Vec::with_capacity(images.len()),
        };
        for ((image, size), origin) in images.iter().zip(&sizes).zip(&origins) {
            atlas.copy_levels(image, *origin);
            atlas.entries.push(AtlasEntry {
                x: origin.x,
                y: origin.y,
                width: size.x,
                height: size.y,
                levels: image.levels().len() as u32,
            });
        }
        Ok(atlas)
    }

    fn copy_levels(&mut self, image: &MipImage, origin: UVec2) {
        let size = image.size().as_ivec2();
        for (k, level) in image.levels().iter().enumerate() {
            let start = origin + level_origin(size, k as i32).as_uvec2();
            for (row, texels) in level.texels.chunks(level.width as usize).enumerate() {
                let at = ((start.y + row as u32) * self.width + start.x) as usize;
                for (dst, src) in self.texels[at..at + texels.len()].iter_mut().zip(texels) {
                    *dst = src.map(f16::from_f32);
                }
            }
        }
    }

    /// The texels as an `Rgba16Float` texture's bytes, row 0 first
    /// (`width * 8` bytes a row).
    pub fn rgba16f_bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.texels)
    }

    /// Image `entry` sampled as the shader samples the atlas: the same
    /// operations as [`MipImage::sample`], on the atlas's half-float texels.
    pub fn sample(
        &self,
        entry: usize,
        uv: Vec2,
        filter: ImageFilter,
        wrap: ImageWrap,
        lod: f32,
    ) -> Vec4 {
        let e = &self.entries[entry];
        let origin = IVec2::new(e.x as i32, e.y as i32);
        let size = IVec2::new(e.width as i32, e.height as i32);
        let chain = Chain {
            size,
            fetch: |k: i32, t: IVec2| self.texel(origin + level_origin(size, k) + t),
        };
        chain.sample(uv, filter, wrap, lod)
    }

    fn texel(&self, at: IVec2) -> Vec4 {
        let texel = self.texels[(at.y as u32 * self.width + at.x as u32) as usize];
        Vec4::from(texel.map(f16::to_f32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic values in [0, 1) (a 64-bit LCG's top bits).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// A `width` × `height` level whose texel (x, y) is `[x, y, x + 10y, 1]`.
    fn indexed(width: u32, height: u32) -> ImageLevel {
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| [x as f32, y as f32, (x + 10 * y) as f32, 1.0]))
            .collect();
        ImageLevel {
            width,
            height,
            texels,
        }
    }

    /// A level of deterministic values in [0, 4).
    fn noisy(width: u32, height: u32, seed: u64) -> ImageLevel {
        let mut rng = Lcg(seed);
        let texels = (0..width * height)
            .map(|_| std::array::from_fn(|_| 4.0 * rng.next()))
            .collect();
        ImageLevel {
            width,
            height,
            texels,
        }
    }

    /// The uv of texel (x, y)'s centre on a level of `width` × `height`.
    fn centre(x: u32, y: u32, width: u32, height: u32) -> Vec2 {
        Vec2::new(
            (x as f32 + 0.5) / width as f32,
            1.0 - (y as f32 + 0.5) / height as f32,
        )
    }

    fn mean(level: &ImageLevel) -> Vec4 {
        let sum: Vec4 = level.texels.iter().map(|&t| Vec4::from(t)).sum();
        sum / level.texels.len() as f32
    }

    fn near(a: Vec4, b: Vec4, tolerance: f32) -> bool {
        (a - b).abs().max_element() <= tolerance
    }

    fn write_png(path: &Path, width: u32, height: u32, rgb: [u8; 3]) {
        image::RgbImage::from_pixel(width, height, image::Rgb(rgb))
            .save_with_format(path, image::ImageFormat::Png)
            .unwrap();
    }

    #[test]
    fn nearest_reads_exact_texels_with_v_up() {
        let image = MipImage::new(indexed(4, 2));
        for y in 0..2 {
            for x in 0..4 {
                let got = image.sample(
                    centre(x, y, 4, 2),
                    ImageFilter::Nearest,
                    ImageWrap::Clamp,
                    0.0,
                );
                assert_eq!(
                    got,
                    Vec4::from(indexed(4, 2).texel(x, y)),
                    "texel ({x}, {y})"
                );
            }
        }
        // v near 0 is the bottom row (row 1), v near 1 the top (row 0).
        let bottom_left = image.sample(
            Vec2::new(0.01, 0.01),
            ImageFilter::Nearest,
            ImageWrap::Repeat,
            0.0,
        );
        assert_eq!(bottom_left, Vec4::new(0.0, 1.0, 10.0, 1.0));
        let top_right = image.sample(
            Vec2::new(0.99, 0.99),
            ImageFilter::Nearest,
            ImageWrap::Repeat,
            0.0,
        );
        assert_eq!(top_right, Vec4::new(3.0, 0.0, 3.0, 1.0));
    }

    #[test]
    fn bilinear_is_the_mean_between_four_centres_and_the_texel_at_a_centre() {
        let level = noisy(4, 4, 7);
        let image = MipImage::new(level.clone());
        // Texel coordinates (2, 2): the corner shared by texels (1..=2, 1..=2).
        let corner = image.sample(
            Vec2::new(0.5, 0.5),
            ImageFilter::Bilinear,
            ImageWrap::Repeat,
            0.0,
        );
        let four = [(1, 1), (2, 1), (1, 2), (2, 2)].map(|(x, y)| Vec4::from(level.texel(x, y)));
        let expected = (four[0] + four[1] + four[2] + four[3]) / 4.0;
        assert!(near(corner, expected, 1e-6), "{corner} vs {expected}");
        for (x, y) in [(1, 2), (0, 0), (3, 3)] {
            let got = image.sample(
                centre(x, y, 4, 4),
                ImageFilter::Bilinear,
                ImageWrap::Clamp,
                0.0,
            );
            assert_eq!(got, Vec4::from(level.texel(x, y)), "texel ({x}, {y})");
        }
    }

    #[test]
    fn wrap_modes_repeat_clamp_and_mirror() {
        let image = MipImage::new(noisy(8, 4, 3));
        let at = |u: f32, filter, wrap| image.sample(Vec2::new(u, 0.4), filter, wrap, 0.0);
        let same = |a: Vec4, b: Vec4| assert!(near(a, b, 1e-5), "{a} vs {b}");
        for filter in [ImageFilter::Nearest, ImageFilter::Bilinear] {
            same(
                at(-0.25, filter, ImageWrap::Repeat),
                at(0.75, filter, ImageWrap::Repeat),
            );
            same(
                at(2.3125, filter, ImageWrap::Repeat),
                at(0.3125, filter, ImageWrap::Repeat),
            );
            same(
                at(-5.0, filter, ImageWrap::Clamp),
                at(0.0, filter, ImageWrap::Clamp),
            );
            same(
                at(7.0, filter, ImageWrap::Clamp),
                at(0.999, filter, ImageWrap::Clamp),
            );
            // Mirror reflects about u = 0 and u = 1; off texel boundaries
            // nearest agrees too (on one, floor picks the texel to the right).
            for u in [0.3, 0.17, 0.6] {
                same(
                    at(-u, filter, ImageWrap::Mirror),
                    at(u, filter, ImageWrap::Mirror),
                );
                same(
                    at(1.0 + u, filter, ImageWrap::Mirror),
                    at(1.0 - u, filter, ImageWrap::Mirror),
                );
            }
        }
        let clamp_edge = image.sample(
            Vec2::new(-5.0, 0.4),
            ImageFilter::Nearest,
            ImageWrap::Clamp,
            0.0,
        );
        assert_eq!(clamp_edge, Vec4::from(image.levels()[0].texel(0, 2)));
        let two = MipImage::new(indexed(2, 1));
        let mirrored = two.sample(
            Vec2::new(-0.25, 0.5),
            ImageFilter::Nearest,
            ImageWrap::Mirror,
            0.0,
        );
        assert_eq!(
            mirrored,
            two.sample(
                Vec2::new(0.25, 0.5),
                ImageFilter::Nearest,
                ImageWrap::Mirror,
                0.0
            )
        );
        assert_eq!(mirrored, Vec4::new(0.0, 0.0, 0.0, 1.0));
    }

    #[test]
    fn wrap_indices() {
        let mirror: Vec<i32> = (-5..9).map(|i| ImageWrap::Mirror.index(i, 3)).collect();
        assert_eq!(mirror, [1, 2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0, 1, 2]);
        let repeat: Vec<i32> = (-4..4).map(|i| ImageWrap::Repeat.index(i, 3)).collect();
        assert_eq!(repeat, [2, 0, 1, 2, 0, 1, 2, 0]);
        assert_eq!(ImageWrap::Clamp.index(-9, 3), 0);
        assert_eq!(ImageWrap::Clamp.index(9, 3), 2);
        for wrap in [ImageWrap::Repeat, ImageWrap::Clamp, ImageWrap::Mirror] {
            for i in [i32::MIN, i32::MAX] {
                assert!((0..5).contains(&wrap.index(i, 5)), "{wrap:?} {i}");
            }
        }
    }

    #[test]
    fn mip_levels_halve_down_to_one_texel_and_keep_the_mean() {
        let image = MipImage::new(noisy(16, 4, 11));
        let sizes: Vec<(u32, u32)> = image.levels().iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(16, 4), (8, 2), (4, 1), (2, 1), (1, 1)]);
        let level0 = mean(&image.levels()[0]);
        for (k, level) in image.levels().iter().enumerate() {
            assert!(
                near(mean(level), level0, 1e-5),
                "level {k}: {} vs {level0}",
                mean(level)
            );
        }
        // 2×2 box: the first texel of level 1 averages texels (0..2, 0..2).
        let l0 = &image.levels()[0];
        let box_mean = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .map(|(x, y)| Vec4::from(l0.texel(x, y)))
            .into_iter()
            .sum::<Vec4>()
            / 4.0;
        assert!(near(
            Vec4::from(image.levels()[1].texel(0, 0)),
            box_mean,
            1e-6
        ));
        // Narrow images halve along the long side only.
        let tall = MipImage::new(noisy(1, 8, 5));
        assert_eq!(tall.levels().len(), 4);
        let t = &tall.levels()[0];
        let pair = (Vec4::from(t.texel(0, 6)) + Vec4::from(t.texel(0, 7))) / 2.0;
        assert!(near(Vec4::from(tall.levels()[1].texel(0, 3)), pair, 1e-6));
    }

    #[test]
    fn trilinear_is_bilinear_on_a_level_at_integer_lod_and_blends_between() {
        let image = MipImage::new(noisy(16, 8, 21));
        let mut rng = Lcg(99);
        for _ in 0..200 {
            let uv = Vec2::new(3.0 * rng.next() - 1.0, 3.0 * rng.next() - 1.0);
            for wrap in [ImageWrap::Repeat, ImageWrap::Clamp, ImageWrap::Mirror] {
                for k in 0..image.levels().len() {
                    let alone = MipImage::new(image.levels()[k].clone());
                    let expected = alone.sample(uv, ImageFilter::Bilinear, wrap, 0.0);
                    let got = image.sample(uv, ImageFilter::Trilinear, wrap, k as f32);
                    assert_eq!(got, expected, "lod {k} at {uv}");
                }
                let half = image.sample(uv, ImageFilter::Trilinear, wrap, 0.5);
                let ends = (image.sample(uv, ImageFilter::Trilinear, wrap, 0.0)
                    + image.sample(uv, ImageFilter::Trilinear, wrap, 1.0))
                    / 2.0;
                assert!(near(half, ends, 1e-5), "{half} vs {ends}");
            }
        }
        // Beyond the chain the lod clamps: the 1×1 level is the mean.
        let far = image.sample(
            Vec2::new(0.3, 0.6),
            ImageFilter::Trilinear,
            ImageWrap::Repeat,
            50.0,
        );
        assert!(near(far, mean(&image.levels()[0]), 1e-5));
        let below = image.sample(
            Vec2::new(0.3, 0.6),
            ImageFilter::Trilinear,
            ImageWrap::Repeat,
            -3.0,
        );
        assert_eq!(
            below,
            image.sample(
                Vec2::new(0.3, 0.6),
                ImageFilter::Bilinear,
                ImageWrap::Repeat,
                0.0
            )
        );
    }

    #[test]
    fn srgb_decodes_with_the_exact_eotf_and_linear_keeps_codes() {
        let dir = tempfile::Builder::new().prefix("decode").tempdir().unwrap();
        let path = dir.path().join("grey188.png");
        write_png(&path, 2, 2, [188, 188, 188]);
        let srgb = load_image(&path, ColorSpace::Srgb).unwrap();
        let t = srgb.image.levels()[0].texel(1, 1);
        // ((188/255 + 0.055) / 1.055)^2.4
        assert!((t[0] - 0.502_886_5).abs() < 1e-6, "{t:?}");
        assert_eq!(t[3], 1.0);
        let linear = load_image(&path, ColorSpace::Linear).unwrap();
        assert_eq!(
            linear.image.levels()[0].texel(0, 0),
            [188.0 / 255.0, 188.0 / 255.0, 188.0 / 255.0, 1.0]
        );
    }

    #[test]
    fn power_of_two_sides() {
        let cases = [
            (1, 1),
            (2, 2),
            (3, 4),
            (5, 4),
            (6, 8),
            (200, 256),
            (300, 256),
            (700, 512),
            (1023, 1024),
            (1024, 1024),
            (5000, 1024),
        ];
        for (side, expected) in cases {
            assert_eq!(power_of_two_side(side), expected, "{side}");
        }
    }

    #[test]
    fn other_sizes_are_resampled_with_a_note_and_powers_of_two_kept() {
        let dir = tempfile::Builder::new()
            .prefix("resample")
            .tempdir()
            .unwrap();
        let odd = dir.path().join("odd.png");
        write_png(&odd, 300, 200, [200, 100, 50]);
        let loaded = load_image(&odd, ColorSpace::Srgb).unwrap();
        assert_eq!(loaded.image.size(), UVec2::new(256, 256));
        assert_eq!(loaded.image.levels().len(), 9);
        assert_eq!(
            loaded.notes,
            ["odd.png: 300×200 resampled to 256×256 for mipmapping"]
        );
        // The tent weights sum to 1: a flat image stays flat.
        let flat = Vec4::from(
            image_decode::decode_file(&odd, IntegerDecode::Srgb)
                .unwrap()
                .pixels[0],
        );
        for &t in &loaded.image.levels()[0].texels {
            assert!(near(Vec4::from(t), flat, 1e-6), "{t:?} vs {flat}");
        }
        // A resampled gradient keeps its direction and range.
        let ramp = ImageLevel {
            width: 6,
            height: 1,
            texels: (0..6).map(|x| [x as f32, 0.0, 0.0, 1.0]).collect(),
        };
        let resampled = MipImage::new(ramp);
        let red: Vec<f32> = resampled.levels()[0].texels.iter().map(|t| t[0]).collect();
        assert_eq!(red.len(), 8);
        assert!(
            red.windows(2).all(|w| w[0] <= w[1]) && red[0] >= 0.0 && red[7] <= 5.0,
            "{red:?}"
        );

        let even = dir.path().join("even.png");
        let pixels: Vec<u8> = (0..8 * 4 * 3).map(|i| (i * 37 % 256) as u8).collect();
        image::RgbImage::from_raw(8, 4, pixels)
            .unwrap()
            .save_with_format(&even, image::ImageFormat::Png)
            .unwrap();
        let loaded = load_image(&even, ColorSpace::Srgb).unwrap();
        assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
        assert_eq!(
            loaded.image.levels()[0].texels,
            image_decode::decode_file(&even, IntegerDecode::Srgb)
                .unwrap()
                .pixels
        );
    }

    /// Images of many shapes, 1-wide and 1-tall included.
    fn shapes() -> Vec<MipImage> {
        [
            (1, 1),
            (1, 8),
            (8, 1),
            (64, 1),
            (2, 64),
            (64, 2),
            (32, 32),
            (16, 4),
            (4, 16),
            (128, 64),
            (1, 2),
            (2, 1),
        ]
        .iter()
        .enumerate()
        .map(|(i, &(w, h))| MipImage::new(noisy(w, h, i as u64 + 1)))
        .collect()
    }

    #[test]
    fn atlas_levels_never_overlap_and_stay_inside() {
        let images = shapes();
        let refs: Vec<&MipImage> = images.iter().collect();
        for max_side in [256, 8192] {
            let atlas = ImageAtlas::pack(&refs, max_side).unwrap();
            assert!(atlas.width <= max_side && atlas.height <= max_side);
            assert_eq!(atlas.texels.len(), (atlas.width * atlas.height) as usize);
            let mut owner = vec![None; atlas.texels.len()];
            for (i, (entry, image)) in atlas.entries.iter().zip(&images).enumerate() {
                assert_eq!(
                    (entry.width, entry.height),
                    (image.size().x, image.size().y)
                );
                assert_eq!(entry.levels as usize, image.levels().len());
                let size = image.size().as_ivec2();
                let reach = footprint(size);
                for (k, level) in image.levels().iter().enumerate() {
                    let start = level_origin(size, k as i32).as_uvec2();
                    assert_eq!(
                        level_size(size, k as i32).as_uvec2(),
                        UVec2::new(level.width, level.height)
                    );
                    assert!(
                        start.x + level.width <= reach.x && start.y + level.height <= reach.y,
                        "image {i} level {k} outside its footprint"
                    );
                    for y in 0..level.height {
                        for x in 0..level.width {
                            let (ax, ay) = (entry.x + start.x + x, entry.y + start.y + y);
                            assert!(
                                ax < atlas.width && ay < atlas.height,
                                "image {i} level {k} outside the atlas"
                            );
                            let slot = &mut owner[(ay * atlas.width + ax) as usize];
                            assert_eq!(*slot, None, "image {i} level {k} overlaps {slot:?}");
                            *slot = Some((i, k));
                            let stored = atlas.texels[(ay * atlas.width + ax) as usize];
                            assert_eq!(stored, level.texel(x, y).map(f16::from_f32));
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn atlas_sampling_matches_the_images() {
        let images = shapes();
        let refs: Vec<&MipImage> = images.iter().collect();
        let atlas = ImageAtlas::pack(&refs, 512).unwrap();
        let filters = [
            ImageFilter::Nearest,
            ImageFilter::Bilinear,
            ImageFilter::Trilinear,
        ];
        let wraps = [ImageWrap::Repeat, ImageWrap::Clamp, ImageWrap::Mirror];
        let mut rng = Lcg(2024);
        for n in 0..10_000 {
            let i = n % images.len();
            let uv = Vec2::new(5.0 * rng.next() - 2.0, 5.0 * rng.next() - 2.0);
            let lod = 10.0 * rng.next() - 1.0;
            let filter = filters[n / images.len() % 3];
            let wrap = wraps[n / images.len() / 3 % 3];
            let expected = images[i].sample(uv, filter, wrap, lod);
            let got = atlas.sample(i, uv, filter, wrap, lod);
            let error =
                ((got - expected).abs() / expected.abs().max(Vec4::splat(1e-3))).max_element();
            assert!(
                error <= 1e-3,
                "image {i} {filter:?} {wrap:?} uv {uv} lod {lod}: {got} vs {expected}"
            );
        }
    }

    #[test]
    fn atlas_params_bytes_and_limits() {
        let empty = ImageAtlas::pack(&[], 8192).unwrap();
        assert_eq!((empty.width, empty.height, empty.entries.len()), (1, 1, 0));
        assert_eq!(empty.rgba16f_bytes(), [0u8; 8]);

        let big = MipImage::new(noisy(64, 64, 1));
        let small = MipImage::new(noisy(4, 2, 2));
        let atlas = ImageAtlas::pack(&[&small, &big], 8192).unwrap();
        // Tallest first: the 64×64 image starts the shelf, the 4×2 follows.
        assert_eq!(atlas.entries[1].params(), [0.0, 0.0, 64.0, 64.0]);
        assert_eq!(atlas.entries[0].params(), [96.0, 0.0, 4.0, 2.0]);
        assert_eq!((atlas.width, atlas.height), (96 + 6, 64));
        assert_eq!(
            atlas.rgba16f_bytes().len(),
            (atlas.width * atlas.height * 8) as usize
        );
        let first = f16::from_f32(big.levels()[0].texel(0, 0)[0]).to_ne_bytes();
        assert_eq!(atlas.rgba16f_bytes()[..2], first);

        let err = ImageAtlas::pack(&[&big, &big], 100).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("2 images need a 96×128 atlas") && message.contains("100×100"),
            "{message}"
        );
    }

    #[test]
    fn bad_files_give_errors_naming_them() {
        let dir = tempfile::Builder::new().prefix("bad").tempdir().unwrap();
        let whole = dir.path().join("whole.png");
        write_png(&whole, 32, 32, [10, 20, 30]);
        let bytes = std::fs::read(&whole).unwrap();
        let truncated = dir.path().join("truncated.png");
        std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
        let unsupported = dir.path().join("picture.tga");
        std::fs::write(&unsupported, b"not read").unwrap();
        let missing = dir.path().join("missing.jpg");
        for (path, name) in [
            (&truncated, "truncated.png"),
            (&unsupported, "picture.tga"),
            (&missing, "missing.jpg"),
        ] {
            let message = load_image(path, ColorSpace::Srgb).unwrap_err().to_string();
            assert!(
                message.contains(name) && message.starts_with("image texture "),
                "{message}"
            );
        }
        assert!(matches!(
            load_image(&truncated, ColorSpace::Srgb),
            Err(ImageError::Decode { format: "PNG", .. })
        ));
        assert!(matches!(
            load_image(&unsupported, ColorSpace::Srgb),
            Err(ImageError::UnsupportedExtension { .. })
        ));
        assert!(matches!(
            load_image(&missing, ColorSpace::Srgb),
            Err(ImageError::Io { .. })
        ));
    }

    #[test]
    fn shipped_uv_grid_loads_with_its_marker_bottom_left() {
        let path = Path::new(crate::REPO).join("presets/images/uv_grid.png");
        let loaded = load_image(&path, ColorSpace::Srgb).unwrap();
        assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
        assert_eq!(loaded.image.size(), UVec2::new(256, 256));
        assert_eq!(loaded.image.levels().len(), 9);
        let at = |u, v| {
            loaded
                .image
                .sample(Vec2::new(u, v), ImageFilter::Nearest, ImageWrap::Clamp, 0.0)
        };
        assert!(
            at(0.02, 0.02).truncate().min_element() > 0.95,
            "the white marker is at (0, 0)"
        );
        for corner in [at(0.98, 0.02), at(0.02, 0.98), at(0.98, 0.98)] {
            assert!(
                corner.truncate().min_element() < 0.9,
                "only (0, 0) is white: {corner}"
            );
        }
    }

    #[test]
    fn ids_match_the_shader_and_defaults() {
        let filters = [
            ImageFilter::Nearest,
            ImageFilter::Bilinear,
            ImageFilter::Trilinear,
        ];
        assert_eq!(filters.map(ImageFilter::id), [0, 1, 2]);
        let wraps = [ImageWrap::Repeat, ImageWrap::Clamp, ImageWrap::Mirror];
        assert_eq!(wraps.map(ImageWrap::id), [0, 1, 2]);
        assert_eq!(ImageFilter::default(), ImageFilter::Bilinear);
        assert_eq!(ImageWrap::default(), ImageWrap::Repeat);
        assert_eq!(ColorSpace::default(), ColorSpace::Srgb);
        assert_eq!(ron::to_string(&ImageWrap::Mirror).unwrap(), "Mirror");
        assert_eq!(
            ron::from_str::<ColorSpace>("Linear").unwrap(),
            ColorSpace::Linear
        );
    }

    #[test]
    fn wgsl_parses_and_validates() {
        let source = [
            "@group(0) @binding(8) var image_atlas: texture_2d<f32>;\n",
            WGSL.text,
            "@group(0) @binding(0) var<storage, read_write> samples: array<vec4f>;\n\
             @compute @workgroup_size(1)\n\
             fn main() {\n\
                 samples[0] = image_sample(vec4f(0.0, 0.0, 4.0, 2.0), vec2f(0.3, -0.7), 2u, 2u, 0.5);\n\
             }\n",
        ]
        .concat();
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    }
}
