//! Latitude-longitude (equirectangular) environment maps, loaded on the CPU.
//!
//! [`load`] reads a map through [`crate::image_decode`] (OpenEXR, Radiance
//! HDR, PNG, JPEG or PPM/PGM, sanitised there with a note per kind of
//! repair) into an [`EnvImage`]: linear radiance, RGBA f32, row-major, row
//! 0 at the top of the picture (the sky), alpha always 1. [`load_ldr`]
//! reads an 8- or 16-bit map as the scene's [`LdrImages`] says. The GPU
//! copy is an `Rgba16Float` texture, built from [`EnvImage::to_rgba16f`]
//! after [`EnvLoad::fit_within`] has shrunk the map to the GPU's largest
//! texture.
//!
//! # Mapping
//!
//! A direction `d` (unit length) is mapped to the lab's `(u, v)` by
//! [`direction_to_uv`]:
//!
//! ```text
//! u = (atan2(d.x, d.z) + π) / (2π)      +z → 0.5, +x → 0.75, -x → 0.25, -z → 0 or 1 (the seam)
//! v = acos(-d.y) / π                    straight down → 0, horizon → 0.5, straight up → 1
//! ```
//!
//! The lab's `v` grows upwards, but row 0 of an image file is its top (the
//! sky), so the texture coordinate that addresses the image is
//! `(u, 1 - v)`: [`uv_to_texel_uv`]. The shader must do the same two steps.

use std::borrow::Cow;
use std::path::Path;

use glam::{Vec2, Vec3};
use half::f16;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::image_decode::{self, DecodeError, DecodedImage, IntegerDecode};

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/envmap.wgsl");

/// A lat-long environment map in linear radiance.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvImage {
    pub width: u32,
    pub height: u32,
    /// Row-major, `width * height` texels, row 0 = top of the image (the sky,
    /// texel-space v = 0, lab v = 1). Linear RGB, alpha 1.
    pub pixels: Vec<[f32; 4]>,
}

/// The result of [`load`]: the sanitised image and one note per kind of
/// repair made to it (empty for a clean file).
#[derive(Debug, Clone)]
pub struct EnvLoad {
    pub image: EnvImage,
    pub notes: Vec<String>,
}

impl From<DecodedImage> for EnvLoad {
    /// The decoder's image as a map, with its notes.
    fn from(decoded: DecodedImage) -> EnvLoad {
        EnvLoad {
            image: EnvImage {
                width: decoded.width,
                height: decoded.height,
                pixels: decoded.pixels,
            },
            notes: decoded.notes,
        }
    }
}

/// Why an environment map could not be loaded: the decoder's error, which
/// names the file and the cause, its message prefixed with "environment
/// map" (an image texture's says "image texture" instead).
#[derive(Debug, Error)]
#[error("environment map {0}")]
pub struct EnvMapError(pub DecodeError);

impl EnvMapError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        self.0.path()
    }
}

impl EnvImage {
    /// A uniform map, for tests and as a stand-in when no file is loaded.
    pub fn constant(width: u32, height: u32, rgb: [f32; 3]) -> EnvImage {
        let texel = [rgb[0], rgb[1], rgb[2], 1.0];
        EnvImage {
            width,
            height,
            pixels: vec![texel; width as usize * height as usize],
        }
    }

    /// The texel at column `x`, row `y` (row 0 = top).
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// The texels as half floats, RGBA interleaved, row 0 first: the data
    /// of an `Rgba16Float` texture of `width` x `height`. Values are expected
    /// to be sanitised (as [`load`] does); anything above
    /// [`F16_MAX`](image_decode::F16_MAX) would become +Inf.
    pub fn to_rgba16f(&self) -> Vec<f16> {
        self.pixels
            .iter()
            .flat_map(|px| px.iter().map(|&c| f16::from_f32(c)))
            .collect()
    }

    /// The largest colour value (0 for an empty image).
    pub fn max_value(&self) -> f32 {
        self.pixels
            .iter()
            .flat_map(|px| px[..3].iter().copied())
            .fold(0.0, f32::max)
    }
}

/// The size of a `width` × `height` image shrunk, keeping its aspect ratio,
/// until no side exceeds `max_side` (at least 1): the image's own size when
/// it already fits.
pub fn fitted_size(width: u32, height: u32, max_side: u32) -> (u32, u32) {
    let max_side = max_side.max(1);
    if width <= max_side && height <= max_side {
        return (width, height);
    }
    let scale = f64::from(max_side) / f64::from(width.max(height));
    let side = |s: u32| ((f64::from(s) * scale).round() as u32).clamp(1, max_side);
    (side(width), side(height))
}

/// For each of `to` output texels along one axis, the input texels among
/// `from` (`to ≤ from`) that its footprint covers and their weights, the
/// covered fraction of each (summing to 1).
fn box_taps(from: u32, to: u32) -> Vec<Vec<(u32, f32)>> {
    let scale = f64::from(from) / f64::from(to);
    (0..to)
        .map(|i| {
            let start = f64::from(i) * scale;
            let end = f64::from(i + 1) * scale;
            let first = start.floor() as u32;
            let last = (end.ceil() as u32).min(from);
            (first..last)
                .map(|j| {
                    let overlap = end.min(f64::from(j + 1)) - start.max(f64::from(j));
                    (j, (overlap / scale) as f32)
                })
                .filter(|&(_, w)| w > 0.0)
                .collect()
        })
        .collect()
}

/// `image` downscaled by [`EnvImage::downscaled`] so that no side exceeds
/// `max_side`, or `image` itself when it fits.
pub fn fit_within(image: &EnvImage, max_side: u32) -> Cow<'_, EnvImage> {
    let (width, height) = fitted_size(image.width, image.height, max_side);
    if (width, height) == (image.width, image.height) {
        Cow::Borrowed(image)
    } else {
        Cow::Owned(image.downscaled(width, height))
    }
}

impl EnvImage {
    /// This image box-filtered down to `width` × `height` (neither larger
    /// than now, neither 0): each output texel is the area-weighted average
    /// of the input texels its footprint covers, so the mean radiance is
    /// kept and no value leaves the range of its inputs.
    pub fn downscaled(&self, width: u32, height: u32) -> EnvImage {
        let columns = box_taps(self.width, width);
        let rows = box_taps(self.height, height);
        let wide: Vec<[f32; 4]> = (0..self.height)
            .flat_map(|y| {
                columns
                    .iter()
                    .map(move |taps| weighted_sum(taps.iter().map(|&(x, w)| (self.texel(x, y), w))))
            })
            .collect();
        let pixels = rows
            .iter()
            .flat_map(|taps| {
                let wide = &wide;
                (0..width).map(move |x| {
                    weighted_sum(
                        taps.iter()
                            .map(|&(y, w)| (wide[y as usize * width as usize + x as usize], w)),
                    )
                })
            })
            .collect();
        EnvImage {
            width,
            height,
            pixels,
        }
    }
}

fn weighted_sum(taps: impl Iterator<Item = ([f32; 4], f32)>) -> [f32; 4] {
    let mut sum = [0.0f32; 4];
    for (texel, w) in taps {
        for (s, t) in sum.iter_mut().zip(texel) {
            *s += t * w;
        }
    }
    sum
}

impl EnvLoad {
    /// Shrinks the image to fit a texture of at most `max_side` texels a
    /// side (the GPU's `max_texture_dimension_2d`), with a note naming
    /// `what` (the file) when it had to.
    pub fn fit_within(mut self, max_side: u32, what: &str) -> EnvLoad {
        let (width, height) = (self.image.width, self.image.height);
        if let Cow::Owned(smaller) = fit_within(&self.image, max_side) {
            self.notes.push(format!(
                "{what} is {width}×{height}, larger than this GPU's max texture side {max_side}: \
                 downscaled to {}×{} (area average, mean radiance kept)",
                smaller.width, smaller.height
            ));
            self.image = smaller;
        }
        self
    }
}

/// A uniform map; same as [`EnvImage::constant`].
pub fn constant(width: u32, height: u32, rgb: [f32; 3]) -> EnvImage {
    EnvImage::constant(width, height, rgb)
}

/// How the 8- and 16-bit images of a map (PNG, JPEG, PPM/PGM) become
/// radiance: the scene's `Environment::ldr_images`, read by [`load_ldr`].
/// Float files (EXR, HDR) are radiance already either way. It is not an
/// [`IntegerDecode`]: un-exposing is applied to the decoded, sanitised
/// values of integer files only, with its own note.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum LdrImages {
    /// The codes are sRGB: decoded exactly to linear values in [0, 1].
    #[default]
    Srgb,
    /// Massal's tutorial (annex II): the image was stored after his
    /// exposure curve `1 − exp(−x)`, so each channel `c` (code / max) is
    /// taken to the power 2.2, then un-exposed by `−ln(1.001 − c)`: white
    /// comes back as ln(1000) ≈ 6.9, bright enough to light a scene.
    Exposed,
}

/// Loads a lat-long environment map: any file [`image_decode::decode_file`]
/// reads, PNG, JPEG and PPM/PGM taken as sRGB-encoded (8 or 16 bits) and
/// decoded to linear with the exact sRGB EOTF, sanitised.
pub fn load(path: &Path) -> Result<EnvLoad, EnvMapError> {
    load_with(path, IntegerDecode::Srgb)
}

/// [`load`], with the integer codes of PNG, JPEG and PPM/PGM files decoded
/// as `decode` says.
fn load_with(path: &Path, decode: IntegerDecode) -> Result<EnvLoad, EnvMapError> {
    image_decode::decode_file(path, decode)
        .map(EnvLoad::from)
        .map_err(EnvMapError)
}

/// [`load`], with the 8- and 16-bit codes read as `ldr` says: for
/// [`LdrImages::Exposed`], Massal's `−ln(1.001 − c^2.2)` of each channel
/// `c` = code / max, with a note; a float file (EXR, HDR) is left as it
/// is, with a note saying so.
pub fn load_ldr(path: &Path, ldr: LdrImages) -> Result<EnvLoad, EnvMapError> {
    if ldr == LdrImages::Srgb {
        return load(path);
    }
    let mut loaded = load_with(path, IntegerDecode::Linear)?;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let extension = image_decode::supported_extension(path).map_err(EnvMapError)?;
    if matches!(extension.as_str(), "exr" | "hdr") {
        loaded.notes.push(format!(
            "{name}: a float image is radiance already; not un-exposed"
        ));
        return Ok(loaded);
    }
    for texel in &mut loaded.image.pixels {
        for c in &mut texel[..3] {
            *c = unexpose(*c);
        }
    }
    loaded.notes.push(format!(
        "{name}: un-exposed as Massal's LDR maps (−ln(1.001 − c^2.2))"
    ));
    Ok(loaded)
}

/// Massal's inverse of his exposure curve for a stored channel `c` in
/// [0, 1]: `−ln(1.001 − c^2.2)`, in f64 so that white's 1.001 − 1 keeps
/// its digits.
pub fn unexpose(c: f32) -> f32 {
    (-(1.001 - f64::from(c).powf(2.2)).ln()) as f32
}

/// The lab's lat-long mapping of a unit direction:
/// `u = (atan2(d.x, d.z) + π) / (2π)`, `v = acos(-d.y) / π`.
///
/// `u` is 0.5 towards +z, 0.75 towards +x, 0.25 towards -x, and 0 or 1
/// towards -z (the seam, where `u` wraps; texture sampling must repeat in u).
/// `v` is 0 looking straight down and 1 straight up. It is computed as
/// `atan2(|d.xz|, -d.y) / π`, equal to the lab's `acos(-d.y) / π` for a
/// unit vector but exact near the poles, where `acos` of a y that rounds
/// in steps of 6e-8 loses digits of θ (0.5 % of it at θ = 0.003, and with
/// it the environment pdf's 1 / sin θ); it also needs no clamp for a
/// slightly non-unit vector. At the poles (`d.x == 0 && d.z == 0`, where
/// the azimuth is undefined) `u` is 0.5. The result is finite for every
/// finite `d`.
///
/// Note that `v` grows upwards while image rows grow downwards: use
/// [`uv_to_texel_uv`] to address an [`EnvImage`] or its texture.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    use std::f32::consts::PI;
    let u = if d.x == 0.0 && d.z == 0.0 {
        0.5
    } else {
        (d.x.atan2(d.z) + PI) / (2.0 * PI)
    };
    let v = Vec2::new(d.x, d.z).length().atan2(-d.y) / PI;
    Vec2::new(u, v)
}

/// From the lab's `(u, v)` ([`direction_to_uv`], v = 1 up) to texture
/// coordinates of an [`EnvImage`] whose row 0 is the top of the picture (the
/// sky): `(u, 1 - v)`. So straight up reads row 0, straight down the last
/// row, the horizon the middle.
pub fn uv_to_texel_uv(uv: Vec2) -> Vec2 {
    Vec2::new(uv.x, 1.0 - uv.y)
}

/// Applies a map rotation of `degrees` about +y to a lookup direction: the
/// direction is rotated about +y by **-degrees**, so the map itself appears
/// turned by +degrees (right-handed, about +y: what was seen towards +z is
/// seen towards +x after +90°). Increasing the rotation turns the map.
pub fn rotate_y(d: Vec3, degrees: f32) -> Vec3 {
    let (s, c) = (-degrees.to_radians()).sin_cos();
    Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z)
}

/// The texel (column, row) of `image` nearest to direction `d`, with the
/// given map rotation: the CPU twin of the shader's lookup, for tests.
pub fn texel_for_direction(image: &EnvImage, d: Vec3, rotation_degrees: f32) -> (u32, u32) {
    let t = uv_to_texel_uv(direction_to_uv(rotate_y(d, rotation_degrees)));
    let x = ((t.x * image.width as f32).floor() as i64).rem_euclid(i64::from(image.width.max(1)));
    let y = ((t.y * image.height as f32).floor() as i64).clamp(0, i64::from(image.height) - 1);
    (x as u32, y.max(0) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image_decode::test_support::{assert_clean, close, shipped_map};
    use std::f32::consts::PI;

    /// Circular distance between two u values (u wraps at 1).
    fn u_dist(a: f32, b: f32) -> f32 {
        let d = (a - b).rem_euclid(1.0);
        d.min(1.0 - d)
    }

    #[test]
    fn fitted_sizes_keep_the_aspect_ratio_within_the_limit() {
        assert_eq!(fitted_size(16384, 8192, 8192), (8192, 4096));
        assert_eq!(fitted_size(8192, 4096, 8192), (8192, 4096));
        assert_eq!(fitted_size(1000, 3, 100), (100, 1));
        assert_eq!(fitted_size(30, 70, 7), (3, 7));
        assert_eq!(fitted_size(5, 5, 0), (1, 1));
    }

    /// Each output texel of a downscale is the mean of the input area it
    /// covers: integer ratios average whole blocks, other ratios weigh
    /// partly covered texels by their covered fraction; the image mean is
    /// kept either way.
    #[test]
    fn downscaling_averages_areas_and_keeps_the_mean() {
        let ramp = EnvImage {
            width: 4,
            height: 2,
            pixels: (0..8).map(|i| [i as f32, 1.0, 0.0, 1.0]).collect(),
        };
        let half = ramp.downscaled(2, 1);
        // Blocks {0, 1, 4, 5} and {2, 3, 6, 7}.
        assert_eq!(half.pixels, [[2.5, 1.0, 0.0, 1.0], [4.5, 1.0, 0.0, 1.0]]);
        // 3 → 2 columns: the middle texel is split half and half.
        let row = EnvImage {
            width: 3,
            height: 1,
            pixels: [3.0, 6.0, 9.0].map(|v| [v, v, v, 1.0]).to_vec(),
        };
        let two = row.downscaled(2, 1);
        assert!(close(two.pixels[0][0], (3.0 * 1.0 + 6.0 * 0.5) / 1.5, 1e-5));
        assert!(close(two.pixels[1][0], (6.0 * 0.5 + 9.0 * 1.0) / 1.5, 1e-5));
        let mean = |img: &EnvImage| {
            img.pixels.iter().map(|p| f64::from(p[0])).sum::<f64>() / img.pixels.len() as f64
        };
        let noisy = EnvImage {
            width: 37,
            height: 19,
            pixels: (0..37 * 19)
                .map(|i| {
                    let v = ((i * 7919) % 1000) as f32 / 10.0;
                    [v, v, v, 1.0]
                })
                .collect(),
        };
        for (w, h) in [(10, 5), (36, 18), (1, 1), (20, 19)] {
            let small = noisy.downscaled(w, h);
            assert_eq!((small.width, small.height), (w, h));
            assert_eq!(small.pixels.len(), (w * h) as usize);
            let (a, b) = (mean(&noisy), mean(&small));
            assert!((a - b).abs() < 1e-4 * a, "{w}x{h}: mean {b} vs {a}");
        }
    }

    #[test]
    fn an_oversize_load_is_fitted_with_a_note_and_a_fitting_one_kept() {
        let load = EnvLoad {
            image: EnvImage::constant(64, 32, [2.0, 1.0, 0.5]),
            notes: Vec::new(),
        };
        let fitted = load.clone().fit_within(16, "big.exr");
        assert_eq!((fitted.image.width, fitted.image.height), (16, 8));
        assert!(fitted.image.pixels.iter().all(|p| close(p[0], 2.0, 1e-6)));
        assert_eq!(
            fitted.notes,
            [
                "big.exr is 64×32, larger than this GPU's max texture side 16: \
              downscaled to 16×8 (area average, mean radiance kept)"
            ]
        );
        let kept = load.fit_within(64, "big.exr");
        assert_eq!((kept.image.width, kept.notes.len()), (64, 0));
    }

    #[test]
    fn known_directions() {
        let uv = direction_to_uv(Vec3::Z);
        assert!(close(uv.x, 0.5, 1e-6) && close(uv.y, 0.5, 1e-6), "{uv}");
        let uv = direction_to_uv(Vec3::X);
        assert!(close(uv.x, 0.75, 1e-6) && close(uv.y, 0.5, 1e-6), "{uv}");
        let uv = direction_to_uv(-Vec3::X);
        assert!(close(uv.x, 0.25, 1e-6), "{uv}");
        assert_eq!(direction_to_uv(-Vec3::Y).y, 0.0);
        assert!(close(direction_to_uv(Vec3::Y).y, 1.0, 1e-6));
        // 45° above the horizon towards +z.
        let uv = direction_to_uv(Vec3::new(0.0, 1.0, 1.0).normalize());
        assert!(close(uv.y, 0.75, 1e-6), "{uv}");
    }

    #[test]
    fn poles_give_finite_uv() {
        for d in [
            Vec3::Y,
            -Vec3::Y,
            Vec3::new(0.0, 1.000_001, 0.0),
            Vec3::new(0.0, -1.000_001, 0.0),
            Vec3::new(-0.0, 1.0, -0.0),
            Vec3::ZERO,
        ] {
            let uv = direction_to_uv(d);
            assert!(uv.is_finite(), "{d} -> {uv}");
            assert_eq!(uv.x, 0.5, "{d}");
            assert!((0.0..=1.0).contains(&uv.y));
        }
        assert_eq!(direction_to_uv(Vec3::new(0.0, 1.000_001, 0.0)).y, 1.0);
        assert_eq!(direction_to_uv(Vec3::new(0.0, -1.000_001, 0.0)).y, 0.0);
        // Nearly at the pole, still finite and v near 1.
        let uv = direction_to_uv(Vec3::new(1e-20, 1.0, 1e-20));
        assert!(uv.is_finite() && close(uv.y, 1.0, 1e-6));
    }

    #[test]
    fn seam_is_at_minus_z_and_u_is_continuous_mod_1() {
        let uv = direction_to_uv(-Vec3::Z);
        assert!(uv.x == 0.0 || uv.x == 1.0, "{uv}");
        let e = 1e-3f32;
        let left = direction_to_uv(Vec3::new(e.sin(), 0.0, -e.cos()));
        let right = direction_to_uv(Vec3::new(-e.sin(), 0.0, -e.cos()));
        assert!(left.x > 0.99 && right.x < 0.01, "{left} {right}");
        assert!(u_dist(left.x, right.x) < 2.0 * e / (2.0 * PI) + 1e-6);
        assert!(u_dist(left.x, uv.x) < 1e-3 && u_dist(right.x, uv.x) < 1e-3);
        // All the way round the horizon, and on a tilted circle: steps of
        // 1/720 turn move u by 1/720 modulo 1, never by a jump.
        for y in [0.0f32, 0.6, -0.9] {
            let r = (1.0 - y * y).sqrt();
            let dir = |i: i32| {
                let a = i as f32 * 2.0 * PI / 720.0;
                Vec3::new(r * a.sin(), y, r * a.cos())
            };
            for i in 0..720 {
                let a = direction_to_uv(dir(i)).x;
                let b = direction_to_uv(dir(i + 1)).x;
                assert!(
                    close(u_dist(a, b), 1.0 / 720.0, 1e-4),
                    "step {i} at y={y}: {a} -> {b}"
                );
            }
        }
    }

    #[test]
    fn texel_uv_flips_v_so_the_sky_is_row_0() {
        assert_eq!(uv_to_texel_uv(Vec2::new(0.3, 1.0)), Vec2::new(0.3, 0.0));
        assert_eq!(uv_to_texel_uv(Vec2::new(0.3, 0.0)), Vec2::new(0.3, 1.0));
        let img = EnvImage::constant(8, 4, [1.0; 3]);
        assert_eq!(texel_for_direction(&img, Vec3::Y, 0.0).1, 0);
        assert_eq!(texel_for_direction(&img, -Vec3::Y, 0.0).1, 3);
        assert_eq!(texel_for_direction(&img, Vec3::Z, 0.0), (4, 2));
        assert_eq!(texel_for_direction(&img, Vec3::X, 0.0).0, 6);
    }

    #[test]
    fn rotation_turns_the_map_about_plus_y() {
        let near = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        // The texel seen towards +z at rotation 0 is seen towards +x at 90°.
        assert!(near(rotate_y(Vec3::X, 90.0), Vec3::Z));
        assert!(near(rotate_y(Vec3::Z, 90.0), -Vec3::X));
        assert!(near(rotate_y(Vec3::Y, 37.0), Vec3::Y));
        let d = Vec3::new(0.3, -0.4, 0.5).normalize();
        assert!(near(rotate_y(d, 0.0), d));
        assert!(near(rotate_y(d, 360.0), d));
        assert!(close(rotate_y(d, 123.0).length(), 1.0, 1e-6));
        assert!(near(rotate_y(rotate_y(d, 40.0), -40.0), d));
        // Increasing rotation lowers u at a fixed view direction by
        // degrees / 360 (modulo 1).
        let u0 = direction_to_uv(rotate_y(Vec3::Z, 0.0)).x;
        let u90 = direction_to_uv(rotate_y(Vec3::Z, 90.0)).x;
        assert!(close(u_dist(u0 - 0.25, u90), 0.0, 1e-6), "{u0} {u90}");
        let img = EnvImage::constant(8, 4, [1.0; 3]);
        assert_eq!(texel_for_direction(&img, Vec3::X, 90.0).0, 4);
    }

    #[test]
    fn constant_and_rgba16f() {
        let img = constant(3, 2, [0.25, 1.5, 65504.0]);
        assert_eq!(img, EnvImage::constant(3, 2, [0.25, 1.5, 65504.0]));
        assert_eq!(img.pixels.len(), 6);
        let h = img.to_rgba16f();
        assert_eq!(h.len(), 3 * 2 * 4);
        assert_eq!(h[0], f16::from_f32(0.25));
        assert_eq!(h[1], f16::from_f32(1.5));
        assert_eq!(h[2], f16::MAX);
        assert_eq!(h[3], f16::ONE);
        assert!(h.iter().all(|v| v.is_finite()));
        assert_eq!(img.max_value(), 65504.0);
    }

    #[test]
    fn error_messages_for_empty_and_dwa() {
        let e = EnvMapError(DecodeError::Empty {
            path: "maps/empty.png".into(),
            width: 0,
            height: 4,
        });
        assert_eq!(
            e.to_string(),
            "environment map maps/empty.png: the image is empty (0x4)"
        );
        let e = EnvMapError(DecodeError::ExrCompression {
            path: "maps/dwa.exr".into(),
            compression: "DWAB".into(),
            message: "not supported: x".into(),
        });
        let msg = e.to_string();
        assert!(
            msg.contains("maps/dwa.exr") && msg.contains("DWAB"),
            "{msg}"
        );
        assert!(msg.contains("ZIP or PIZ"), "{msg}");
    }

    #[test]
    fn esplanade_is_finite_non_negative_with_its_sun() {
        let Some(path) = shipped_map("esplanade.exr") else {
            eprintln!("esplanade.exr not found; skipping");
            return;
        };
        let loaded = load(&path).unwrap();
        eprintln!("esplanade notes: {:?}", loaded.notes);
        assert_clean(
            &loaded.image.pixels,
            loaded.image.width,
            loaded.image.height,
        );
        assert_eq!((loaded.image.width, loaded.image.height), (512, 256));
        let max = loaded.image.max_value();
        assert!(max > 10000.0, "max {max}");
        let h = loaded.image.to_rgba16f();
        assert!(h.iter().all(|v| v.is_finite() && v.to_f32() >= 0.0));
    }

    /// The maps marbre ships load clean, with no note: their negative
    /// texels (left by the originals' lossy compression) were set to 0 in
    /// the files once, so the loader's notes speak of the user's own files
    /// only.
    #[test]
    fn shipped_maps_load_without_notes() {
        let root = Path::new(crate::REPO).join("envmaps");
        for name in [
            "sky.exr",
            "esplanade.exr",
            "studio.exr",
            "sunset.exr",
            "forest.exr",
            "cube/studio-cross.exr",
        ] {
            let loaded = load(&root.join(name)).unwrap();
            assert_clean(
                &loaded.image.pixels,
                loaded.image.width,
                loaded.image.height,
            );
            assert_eq!(loaded.notes, Vec::<String>::new(), "{name}");
        }
    }

    /// Massal's LDR maps: each channel c = code / 255 read back by
    /// −ln(1.001 − c^2.2) (his annex II), white as ln(1000); a float file
    /// stays as it is, with a note.
    #[test]
    fn exposed_ldr_maps_are_read_back_by_massals_formula() {
        let dir = tempfile::Builder::new()
            .prefix("exposed")
            .tempdir()
            .unwrap();
        let png = dir.path().join("sky.png");
        image::RgbImage::from_raw(2, 1, vec![0, 128, 255, 255, 255, 255])
            .unwrap()
            .save(&png)
            .unwrap();
        let loaded = load_ldr(&png, LdrImages::Exposed).unwrap();
        let massal = |code: f64| -(1.001 - (code / 255.0).powf(2.2)).ln();
        for (got, code) in loaded.image.pixels[0][..3].iter().zip([0.0, 128.0, 255.0]) {
            assert!(
                (f64::from(*got) - massal(code)).abs() < 1e-6,
                "{got} for {code}"
            );
        }
        assert!((loaded.image.pixels[1][0] - 1000f32.ln()).abs() < 1e-4);
        assert!(
            loaded.notes.iter().any(|n| n.contains("un-exposed")),
            "{:?}",
            loaded.notes
        );
        assert_eq!(
            load_ldr(&png, LdrImages::Srgb).unwrap().image,
            load(&png).unwrap().image
        );
        let exr = dir.path().join("sky.exr");
        exr::prelude::write_rgb_file(&exr, 1, 1, |_, _| (2.0f32, 0.5f32, 0.25f32)).unwrap();
        let float = load_ldr(&exr, LdrImages::Exposed).unwrap();
        assert_eq!(float.image.pixels[0], [2.0, 0.5, 0.25, 1.0]);
        assert!(float.notes.iter().any(|n| n.contains("not un-exposed")));
    }
}
