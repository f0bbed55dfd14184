//! Latitude-longitude (equirectangular) environment maps, loaded on the CPU.
//!
//! [`load`] reads an OpenEXR (`.exr`, through the `exr` crate), Radiance
//! (`.hdr`), PNG or JPEG file (through `image`) into an [`EnvImage`]: linear
//! radiance, RGBA f32, row-major, row 0 at the top of the picture (the sky),
//! alpha always 1. The GPU copy is an `Rgba16Float` texture, built from
//! [`EnvImage::to_rgba16f`].
//!
//! Real-world maps are not clean: lossy compression leaves negative values,
//! and a sun can be brighter than a half float can hold. Every image is
//! therefore sanitised at load time (see [`EnvImage::sanitize`]): NaN, ±Inf
//! and negative values become 0 and values above [`F16_MAX`] are clamped to
//! it. Each kind of repair is reported as one human-readable line in
//! [`EnvLoad::notes`].
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
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use half::f16;
use thiserror::Error;

use crate::scene::LdrImages;

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/envmap.wgsl");

/// The largest finite half float. The GPU texture is `Rgba16Float`, so
/// anything brighter would become +Inf there.
pub const F16_MAX: f32 = 65504.0;

/// The extensions [`load`] understands (lower case, without the dot).
pub const SUPPORTED_EXTENSIONS: [&str; 8] =
    ["exr", "hdr", "png", "jpg", "jpeg", "ppm", "pgm", "pnm"];

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

/// How many channel values [`EnvImage::sanitize`] repaired, by kind. Only the
/// colour channels are counted; alpha is forced to 1.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SanitizeCounts {
    /// NaN values, set to 0.
    pub nan: usize,
    /// +Inf and -Inf values, set to 0.
    pub infinite: usize,
    /// Finite negative values, set to 0.
    pub negative: usize,
    /// Finite values above [`F16_MAX`], clamped to it.
    pub clamped: usize,
}

impl SanitizeCounts {
    /// Total number of repaired values.
    pub fn total(&self) -> usize {
        self.nan + self.infinite + self.negative + self.clamped
    }

    /// One line per non-zero kind, each starting with `file_name`, e.g.
    /// `"sky.exr: 1234 negative values set to 0"`.
    pub fn notes(&self, file_name: &str) -> Vec<String> {
        let mut notes = Vec::new();
        let mut push = |n: usize, what: &str| {
            if n > 0 {
                let s = if n == 1 { "" } else { "s" };
                notes.push(format!("{file_name}: {n} {}", what.replace("{s}", s)));
            }
        };
        push(self.nan, "NaN value{s} set to 0");
        push(self.infinite, "infinite value{s} set to 0");
        push(self.negative, "negative value{s} set to 0");
        push(
            self.clamped,
            "value{s} above 65504 (the half-float maximum) clamped to 65504",
        );
        notes
    }
}

/// Why an environment map could not be loaded. Every variant names the file.
#[derive(Debug, Error)]
pub enum EnvMapError {
    /// The file is missing or unreadable.
    #[error("environment map {}: cannot read the file: {cause}", .path.display())]
    Io {
        path: PathBuf,
        /// Not a `#[source]`: the message already says it, and a chain
        /// would print it twice.
        cause: std::io::Error,
    },
    /// The extension is not one [`load`] understands.
    #[error(
        "environment map {}: unsupported file type {}; supported: .exr, .hdr, .png, .jpg, .jpeg",
        .path.display(),
        if .extension.is_empty() { "(no extension)".to_string() } else { format!(".{}", .extension) }
    )]
    UnsupportedExtension { path: PathBuf, extension: String },
    /// The decoder rejected the file; `message` is the decoder's own.
    #[error("environment map {}: cannot decode {format}: {message}", .path.display())]
    Decode {
        path: PathBuf,
        format: &'static str,
        message: String,
    },
    /// An OpenEXR file whose compression the `exr` crate does not implement
    /// (HTJ2K), or DWAA/DWAB data it failed to decode (older `exr`
    /// versions could not read DWA at all).
    #[error(
        "environment map {}: cannot decode OpenEXR with {compression} compression: {message}; \
         {EXR_RESAVE_HINT}",
        .path.display()
    )]
    ExrCompression {
        path: PathBuf,
        compression: String,
        message: String,
    },
    /// The image has no texels.
    #[error("environment map {}: the image is empty ({width}x{height})", .path.display())]
    Empty {
        path: PathBuf,
        width: u32,
        height: u32,
    },
}

impl EnvMapError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            EnvMapError::Io { path, .. }
            | EnvMapError::UnsupportedExtension { path, .. }
            | EnvMapError::Decode { path, .. }
            | EnvMapError::ExrCompression { path, .. }
            | EnvMapError::Empty { path, .. } => path,
        }
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

    /// Makes every colour value finite, non-negative and at most
    /// [`F16_MAX`], and alpha 1: NaN, ±Inf and negative values become 0,
    /// larger values are clamped. Returns what was repaired.
    pub fn sanitize(&mut self) -> SanitizeCounts {
        let mut counts = SanitizeCounts::default();
        for px in &mut self.pixels {
            for c in &mut px[..3] {
                let v = *c;
                if v.is_nan() {
                    counts.nan += 1;
                    *c = 0.0;
                } else if v.is_infinite() {
                    counts.infinite += 1;
                    *c = 0.0;
                } else if v < 0.0 {
                    counts.negative += 1;
                    *c = 0.0;
                } else if v > F16_MAX {
                    counts.clamped += 1;
                    *c = F16_MAX;
                } else if v == 0.0 {
                    // Normalise -0.0 so the texture holds a plain zero.
                    *c = 0.0;
                }
            }
            px[3] = 1.0;
        }
        counts
    }

    /// The texels as half floats, RGBA interleaved, row 0 first: the data
    /// of an `Rgba16Float` texture of `width` x `height`. Values are expected
    /// to be sanitised (as [`load`] does); anything above [`F16_MAX`] would
    /// become +Inf.
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

/// How [`load_with`] turns the integer codes of an 8- or 16-bit PNG or JPEG
/// into floats. Float files (EXR, Radiance HDR) are linear either way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntegerDecode {
    /// Colour: the exact sRGB EOTF ([`srgb_to_linear`]) of code / max code.
    Srgb,
    /// Data such as roughness or height: code / max code, as it is.
    Linear,
}

impl IntegerDecode {
    fn code8(self, c: u8) -> f32 {
        match self {
            IntegerDecode::Srgb => SRGB8_TO_LINEAR[c as usize],
            IntegerDecode::Linear => f32::from(c) / 255.0,
        }
    }

    fn code16(self, c: u16) -> f32 {
        self.unit(f32::from(c) / 65535.0)
    }

    /// An integer code already scaled to [0, 1].
    fn unit(self, c: f32) -> f32 {
        match self {
            IntegerDecode::Srgb => srgb_to_linear(c),
            IntegerDecode::Linear => c,
        }
    }
}

/// Loads and sanitises a lat-long environment map. The format is chosen by
/// extension (case-insensitive): `.exr` (any compression the `exr` crate
/// reads; RGB(A) or luminance-only `Y`), `.hdr` (Radiance RGBE), `.png` and
/// `.jpg`/`.jpeg`. PNG and JPEG are taken as sRGB-encoded (8 or 16 bits) and
/// decoded to linear with the exact sRGB EOTF; grey images become RGB; alpha
/// is dropped.
pub fn load(path: &Path) -> Result<EnvLoad, EnvMapError> {
    load_with(path, IntegerDecode::Srgb)
}

/// [`load`], with the integer codes of PNG and JPEG files decoded as
/// `decode` says: image textures holding data rather than colour are read
/// with [`IntegerDecode::Linear`].
pub fn load_with(path: &Path, decode: IntegerDecode) -> Result<EnvLoad, EnvMapError> {
    // An unsupported type is refused before the file is read.
    supported_extension(path)?;
    let bytes = std::fs::read(path).map_err(|cause| EnvMapError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    decode_bytes(&bytes, path, decode)
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
    if matches!(supported_extension(path)?.as_str(), "exr" | "hdr") {
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

/// The lower-case extension of `path`, if [`load`] reads it.
fn supported_extension(path: &Path) -> Result<String, EnvMapError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if SUPPORTED_EXTENSIONS.contains(&extension.as_str()) {
        Ok(extension)
    } else {
        Err(EnvMapError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension,
        })
    }
}

/// [`load_with`] on the bytes of a file already read: `path` chooses the
/// format by its extension and names the file in messages. The fuzz target
/// and its regression tests decode through it without a file.
pub fn decode_bytes(
    bytes: &[u8],
    path: &Path,
    decode: IntegerDecode,
) -> Result<EnvLoad, EnvMapError> {
    let extension = supported_extension(path)?;
    let mut choice_note = None;
    let mut image = match extension.as_str() {
        "exr" => {
            let (image, note) = decode_exr(path, bytes)?;
            choice_note = note;
            image
        }
        "hdr" => decode_with_image(path, bytes, image::ImageFormat::Hdr, "Radiance HDR", decode)?,
        "png" => decode_with_image(path, bytes, image::ImageFormat::Png, "PNG", decode)?,
        // The texture report's IMAGE format (P2, P3 in text; P5, P6 binary).
        "ppm" | "pgm" | "pnm" => {
            check_pnm_samples(bytes).map_err(|message| EnvMapError::Decode {
                path: path.to_path_buf(),
                format: "PPM/PGM",
                message,
            })?;
            decode_with_image(path, bytes, image::ImageFormat::Pnm, "PPM/PGM", decode)?
        }
        _ => decode_with_image(path, bytes, image::ImageFormat::Jpeg, "JPEG", decode)?,
    };
    if image.width == 0 || image.height == 0 || image.pixels.is_empty() {
        return Err(EnvMapError::Empty {
            path: path.to_path_buf(),
            width: image.width,
            height: image.height,
        });
    }
    let counts = image.sanitize();
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    Ok(EnvLoad {
        image,
        notes: choice_note
            .into_iter()
            .chain(counts.notes(&file_name))
            .collect(),
    })
}

/// The most texels an image may declare: 2²⁷ (a 16384×8192 lat-long map),
/// 2 GiB as f32 RGBA. The size is checked from the file's header before
/// anything is allocated, so a hostile header cannot make the loader ask
/// for terabytes (the fuzzer's memory limit found the need).
pub const MAX_TEXELS: u64 = 16384 * 8192;

/// What to do about an OpenEXR file marbre's reader cannot decode.
pub const EXR_RESAVE_HINT: &str = "re-save it with ZIP or PIZ compression or none, \
     e.g. `oiiotool in.exr --compression zip -o out.exr`";

/// An error unless a `width` × `height` image is one marbre loads: not
/// empty, and at most [`MAX_TEXELS`].
fn check_size(
    path: &Path,
    format: &'static str,
    width: u64,
    height: u64,
) -> Result<(), EnvMapError> {
    if width == 0 || height == 0 {
        return Err(EnvMapError::Empty {
            path: path.to_path_buf(),
            width: width.min(u64::from(u32::MAX)) as u32,
            height: height.min(u64::from(u32::MAX)) as u32,
        });
    }
    if width.saturating_mul(height) > MAX_TEXELS {
        return Err(EnvMapError::Decode {
            path: path.to_path_buf(),
            format,
            message: format!(
                "the file declares {width}x{height} texels, more than the {MAX_TEXELS} \
                 (16384x8192) marbre loads"
            ),
        });
    }
    Ok(())
}

/// The channels of an OpenEXR file that hold the picture: red, green and
/// blue, or luminance alone.
enum ExrChannels {
    Rgb([exr::meta::attribute::Text; 3]),
    Grey(exr::meta::attribute::Text),
}

/// Which part of an OpenEXR file and which of its channels [`decode_exr`]
/// reads, and the note telling the user so when the file had a choice.
struct ExrChoice {
    part: usize,
    channels: ExrChannels,
    note: Option<String>,
}

/// Picks the picture in an OpenEXR file: the first part, and in it the
/// first layer (`R` before `diffuse.R`), that has red, green and blue
/// channels (names compared case-insensitively); failing that, the first
/// with luminance `Y`, read as grey. `None` when no part has either.
fn choose_exr_channels(headers: &[exr::meta::header::Header], file: &str) -> Option<ExrChoice> {
    // Per part, its layers in order of appearance: (prefix, channel names).
    let layers: Vec<Vec<(String, Vec<exr::meta::attribute::Text>)>> = headers
        .iter()
        .map(|header| {
            let mut layers: Vec<(String, Vec<exr::meta::attribute::Text>)> = Vec::new();
            for channel in &header.channels.list {
                let name = channel.name.to_string();
                let prefix = name.rfind('.').map_or("", |dot| &name[..dot]).to_string();
                match layers.iter_mut().find(|(p, _)| *p == prefix) {
                    Some((_, names)) => names.push(channel.name.clone()),
                    None => layers.push((prefix, vec![channel.name.clone()])),
                }
            }
            // The unnamed layer first: plain `R, G, B` are the picture.
            layers.sort_by_key(|(prefix, _)| !prefix.is_empty());
            layers
        })
        .collect();
    fn find<'a>(
        names: &'a [exr::meta::attribute::Text],
        base: &str,
    ) -> Option<&'a exr::meta::attribute::Text> {
        names.iter().find(|n| {
            let n = n.to_string();
            n.rsplit('.')
                .next()
                .unwrap_or("")
                .eq_ignore_ascii_case(base)
        })
    }
    let layer_count: usize = layers.iter().map(Vec::len).sum();
    let describe = |part: usize, prefix: &str| {
        let part_name = headers[part]
            .own_attributes
            .layer_name
            .as_ref()
            .map(|n| format!(" (`{n}`)"))
            .unwrap_or_default();
        let layer = if prefix.is_empty() {
            "the unnamed layer".to_string()
        } else {
            format!("layer `{prefix}`")
        };
        format!("{layer} of part {part}{part_name}")
    };
    let mut grey = None;
    for (part, part_layers) in layers.iter().enumerate() {
        for (prefix, names) in part_layers {
            let rgb = ["R", "G", "B"].map(|base| find(names, base));
            if let [Some(r), Some(g), Some(b)] = rgb {
                let exact = [r, g, b]
                    .iter()
                    .zip(["R", "G", "B"])
                    .all(|(n, base)| n.to_string().ends_with(base));
                let note = if layer_count > 1 {
                    Some(format!(
                        "{file}: read {} (channels {r}, {g}, {b}), one of the file's {layer_count} layers",
                        describe(part, prefix)
                    ))
                } else {
                    (!exact)
                        .then(|| format!("{file}: channels {r}, {g}, {b} read as red, green, blue"))
                };
                return Some(ExrChoice {
                    part,
                    channels: ExrChannels::Rgb([r.clone(), g.clone(), b.clone()]),
                    note,
                });
            }
            if grey.is_none()
                && let Some(y) = find(names, "Y")
            {
                let note = format!(
                    "{file}: luminance only: channel {y} of {} shown as grey",
                    describe(part, prefix)
                );
                grey = Some(ExrChoice {
                    part,
                    channels: ExrChannels::Grey(y.clone()),
                    note: Some(note),
                });
            }
        }
    }
    grey
}

/// Every part of an OpenEXR file and its channels, for a message.
fn exr_channel_list(headers: &[exr::meta::header::Header]) -> String {
    headers
        .iter()
        .enumerate()
        .map(|(i, h)| {
            let names: Vec<String> = h.channels.list.iter().map(|c| c.name.to_string()).collect();
            format!(
                "part {i}: {}",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The picture of an OpenEXR file ([`choose_exr_channels`]), and a note if
/// it was chosen among others. The `exr` crate's panics on malformed files
/// are caught and reported as a decode error.
fn decode_exr(path: &Path, bytes: &[u8]) -> Result<(EnvImage, Option<String>), EnvMapError> {
    let decode_error = |message: String| EnvMapError::Decode {
        path: path.to_path_buf(),
        format: "OpenEXR",
        message,
    };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
            .map_err(|e| exr_error(path, None, e))?;
        let file = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.display().to_string());
        let Some(choice) = choose_exr_channels(&meta.headers, &file) else {
            return Err(decode_error(format!(
                "no part has R, G, B or Y channels (found {}); \
                 marbre reads a colour (R, G, B) or luminance (Y) image",
                exr_channel_list(&meta.headers)
            )));
        };
        let header = &meta.headers[choice.part];
        let size = header.layer_size;
        check_size(path, "OpenEXR", size.width() as u64, size.height() as u64)?;
        let image = read_exr_channels(bytes, &choice.channels)
            .map_err(|e| exr_error(path, Some(header.compression), e))?;
        Ok((image, choice.note))
    }))
    .unwrap_or_else(|_| {
        Err(decode_error(
            "the OpenEXR reader failed on this file (a malformed file it does not check)".into(),
        ))
    })
}

/// Reads `channels` of the first part that has them, as linear RGBA.
fn read_exr_channels(bytes: &[u8], channels: &ExrChannels) -> exr::error::Result<EnvImage> {
    use exr::prelude::*;

    let storage = |resolution: Vec2<usize>| {
        (
            resolution.width(),
            vec![[0.0f32, 0.0, 0.0, 1.0]; resolution.width() * resolution.height()],
        )
    };
    let to_image = |size: Vec2<usize>, pixels: Vec<[f32; 4]>| EnvImage {
        width: size.width() as u32,
        height: size.height() as u32,
        pixels,
    };
    match channels {
        ExrChannels::Rgb([r, g, b]) => {
            let image = read()
                .no_deep_data()
                .largest_resolution_level()
                .specific_channels()
                .required(r.clone())
                .required(g.clone())
                .required(b.clone())
                .collect_pixels(
                    |resolution, _| storage(resolution),
                    |(w, px): &mut (usize, Vec<[f32; 4]>),
                     pos: Vec2<usize>,
                     (r, g, b): (f32, f32, f32)| {
                        px[pos.y() * *w + pos.x()] = [r, g, b, 1.0];
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(Cursor::new(bytes))?;
            Ok(to_image(
                image.layer_data.size,
                image.layer_data.channel_data.pixels.1,
            ))
        }
        ExrChannels::Grey(y) => {
            let image = read()
                .no_deep_data()
                .largest_resolution_level()
                .specific_channels()
                .required(y.clone())
                .collect_pixels(
                    |resolution, _| storage(resolution),
                    |(w, px): &mut (usize, Vec<[f32; 4]>), pos: Vec2<usize>, (y,): (f32,)| {
                        px[pos.y() * *w + pos.x()] = [y, y, y, 1.0];
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(Cursor::new(bytes))?;
            Ok(to_image(
                image.layer_data.size,
                image.layer_data.channel_data.pixels.1,
            ))
        }
    }
}

/// Turns an `exr` failure into an [`EnvMapError`]. A file whose
/// `compression` the `exr` crate does not implement (HTJ2K), or whose DWAA
/// or DWAB data it failed on, gets [`EnvMapError::ExrCompression`], which
/// says what to do.
fn exr_error(
    path: &Path,
    compression: Option<exr::compression::Compression>,
    err: exr::error::Error,
) -> EnvMapError {
    use exr::compression::Compression;

    let message = decode_message(&match &err {
        exr::error::Error::Aborted => "reading was aborted".to_string(),
        exr::error::Error::NotSupported(m) => format!("not supported: {m}"),
        exr::error::Error::Invalid(m) => format!("invalid file: {m}"),
        exr::error::Error::Io(e) => format!("I/O error: {e}"),
    });
    let named = match compression {
        Some(Compression::DWAA(_)) => Some(("DWAA", message.clone())),
        Some(Compression::DWAB(_)) => Some(("DWAB", message.clone())),
        Some(Compression::HTJ2K32 | Compression::HTJ2K256) => Some((
            "HTJ2K",
            "marbre's OpenEXR reader (the `exr` crate) does not support it".to_string(),
        )),
        _ => None,
    };
    match named {
        Some((compression, message)) => EnvMapError::ExrCompression {
            path: path.to_path_buf(),
            compression: compression.to_string(),
            message,
        },
        None => EnvMapError::Decode {
            path: path.to_path_buf(),
            format: "OpenEXR",
            message,
        },
    }
}

fn decode_with_image(
    path: &Path,
    bytes: &[u8],
    format: image::ImageFormat,
    format_name: &'static str,
    decode: IntegerDecode,
) -> Result<EnvImage, EnvMapError> {
    use image::DynamicImage as D;

    let decode_err = |message: String| EnvMapError::Decode {
        path: path.to_path_buf(),
        format: format_name,
        message,
    };
    let reader = || {
        let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format);
        // The default 512 MiB cap rejects 16k maps; stay bounded but roomier.
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(4 << 30);
        reader.limits(limits);
        reader
    };
    // The header first: an empty or absurdly large image is refused before
    // its pixels are allocated.
    if let Some((width, height)) = declared_png_size(bytes).filter(|&(w, h)| w == 0 || h == 0) {
        return Err(EnvMapError::Empty {
            path: path.to_path_buf(),
            width,
            height,
        });
    }
    let (width, height) = reader()
        .into_dimensions()
        .map_err(|e| decode_err(decode_message(&e.to_string())))?;
    check_size(path, format_name, width.into(), height.into())?;
    let decoded = reader()
        .decode()
        .map_err(|e| decode_err(decode_message(&e.to_string())))?;
    let (width, height) = (decoded.width(), decoded.height());

    let pixels: Vec<[f32; 4]> = match &decoded {
        // Radiance HDR (and any other float source) is already linear.
        D::ImageRgb32F(img) => img.pixels().map(|p| [p[0], p[1], p[2], 1.0]).collect(),
        D::ImageRgba32F(img) => img.pixels().map(|p| [p[0], p[1], p[2], 1.0]).collect(),
        D::ImageLuma8(img) => img.pixels().map(|p| grey(decode.code8(p[0]))).collect(),
        D::ImageLumaA8(img) => img.pixels().map(|p| grey(decode.code8(p[0]))).collect(),
        D::ImageRgb8(img) => img
            .pixels()
            .map(|p| rgb8(decode, p[0], p[1], p[2]))
            .collect(),
        D::ImageRgba8(img) => img
            .pixels()
            .map(|p| rgb8(decode, p[0], p[1], p[2]))
            .collect(),
        D::ImageLuma16(img) => img.pixels().map(|p| grey(decode.code16(p[0]))).collect(),
        D::ImageLumaA16(img) => img.pixels().map(|p| grey(decode.code16(p[0]))).collect(),
        D::ImageRgb16(img) => img
            .pixels()
            .map(|p| rgb16(decode, p[0], p[1], p[2]))
            .collect(),
        D::ImageRgba16(img) => img
            .pixels()
            .map(|p| rgb16(decode, p[0], p[1], p[2]))
            .collect(),
        other => {
            // A layout this code does not know yet (DynamicImage is
            // non-exhaustive): an integer image is decoded, a float one linear.
            let rgb = other.to_rgb32f();
            let color = other.color();
            let linear = color.bytes_per_pixel() / color.channel_count().max(1) >= 4;
            rgb.pixels()
                .map(|p| {
                    if linear {
                        [p[0], p[1], p[2], 1.0]
                    } else {
                        [decode.unit(p[0]), decode.unit(p[1]), decode.unit(p[2]), 1.0]
                    }
                })
                .collect()
        }
    };
    if pixels.len() != width as usize * height as usize {
        return Err(decode_err(format!(
            "decoder returned {} texels for {width}x{height}",
            pixels.len()
        )));
    }
    Ok(EnvImage {
        width,
        height,
        pixels,
    })
}

/// A decoder's reason, saying "truncated" where it means that the file
/// ends early: the decoders' own words for it vary ("unexpected end of
/// file", "not enough bytes", "failed to fill whole buffer", "reference to
/// missing bytes").
fn decode_message(message: &str) -> String {
    let message = message.trim();
    let lower = message.to_ascii_lowercase();
    let cut_short = [
        "unexpected end",
        "unexpectedeof",
        "eof",
        "not enough bytes",
        "missing bytes",
        "fill whole buffer",
    ]
    .iter()
    .any(|w| lower.contains(w));
    if cut_short && !lower.contains("truncated") {
        format!("the file is truncated ({message})")
    } else {
        message.to_string()
    }
}

/// An error if a PGM or PPM file (P2, P3, P5, P6) holds a sample above its
/// maxval, which the `image` decoder would clamp without a word: such a
/// file was written wrong, and its picture is not the one meant. Other
/// files, and headers the decoder will refuse itself, pass.
fn check_pnm_samples(bytes: &[u8]) -> Result<(), String> {
    let mut at = 0;
    // The header: magic, width, height, maxval, each after white space or
    // `#` comments, then one white-space byte before binary samples.
    let mut token = || -> Option<&[u8]> {
        loop {
            while bytes.get(at).is_some_and(u8::is_ascii_whitespace) {
                at += 1;
            }
            if bytes.get(at) != Some(&b'#') {
                break;
            }
            while bytes.get(at).is_some_and(|&b| b != b'\n') {
                at += 1;
            }
        }
        let start = at;
        while bytes.get(at).is_some_and(|b| !b.is_ascii_whitespace()) {
            at += 1;
        }
        (at > start).then(|| &bytes[start..at])
    };
    let magic = token();
    let number = |t: Option<&[u8]>| std::str::from_utf8(t?).ok()?.parse::<u64>().ok();
    let text = match magic {
        Some(b"P2" | b"P3") => true,
        Some(b"P5" | b"P6") => false,
        _ => return Ok(()),
    };
    let (Some(_), Some(_), Some(maxval)) = (number(token()), number(token()), number(token()))
    else {
        return Ok(());
    };
    let above = |index: usize, value: u64| {
        format!("sample {index} is {value}, above the file's maxval {maxval}")
    };
    if text {
        let mut index = 0;
        while let Some(t) = token() {
            match number(Some(t)) {
                Some(v) if v > maxval => return Err(above(index, v)),
                _ => index += 1,
            }
        }
    } else if maxval < 255 {
        let samples = bytes.get(at + 1..).unwrap_or_default();
        if let Some((index, &v)) = samples
            .iter()
            .enumerate()
            .find(|&(_, &v)| u64::from(v) > maxval)
        {
            return Err(above(index, v.into()));
        }
    } else if maxval > 255 && maxval < 65535 {
        let samples = bytes.get(at + 1..).unwrap_or_default();
        let values = samples
            .chunks_exact(2)
            .map(|b| u64::from(u16::from_be_bytes([b[0], b[1]])));
        if let Some((index, v)) = values.enumerate().find(|&(_, v)| v > maxval) {
            return Err(above(index, v));
        }
    }
    Ok(())
}

/// The size a PNG file's header declares, if it is a PNG file with a
/// header: the `png` crate refuses a zero side as "invalid dimensions",
/// which does not say that the image is empty.
fn declared_png_size(bytes: &[u8]) -> Option<(u32, u32)> {
    let header = bytes.get(..24)?;
    if !header.starts_with(b"\x89PNG\r\n\x1a\n") || &header[12..16] != b"IHDR" {
        return None;
    }
    let side = |at: usize| {
        u32::from_be_bytes([header[at], header[at + 1], header[at + 2], header[at + 3]])
    };
    Some((side(16), side(20)))
}

fn grey(v: f32) -> [f32; 4] {
    [v, v, v, 1.0]
}

fn rgb8(decode: IntegerDecode, r: u8, g: u8, b: u8) -> [f32; 4] {
    [decode.code8(r), decode.code8(g), decode.code8(b), 1.0]
}

fn rgb16(decode: IntegerDecode, r: u16, g: u16, b: u16) -> [f32; 4] {
    [decode.code16(r), decode.code16(g), decode.code16(b), 1.0]
}

/// The exact sRGB EOTF (IEC 61966-2-1): encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    let c = f64::from(c);
    let l = if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    };
    l as f32
}

/// [`srgb_to_linear`] of `i / 255` for every 8-bit code.
static SRGB8_TO_LINEAR: std::sync::LazyLock<[f32; 256]> =
    std::sync::LazyLock::new(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)));

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
    use std::f32::consts::PI;

    /// A map shipped in `envmaps/`, else the shared copy; `None` if neither.
    fn shipped_map(name: &str) -> Option<PathBuf> {
        let root = Path::new(crate::REPO);
        [
            root.join("envmaps").join(name),
            root.join("../shared/envmaps").join(name),
        ]
        .into_iter()
        .find(|p| p.is_file())
    }

    fn assert_clean(image: &EnvImage) {
        assert_eq!(image.pixels.len(), (image.width * image.height) as usize);
        for px in &image.pixels {
            for &c in &px[..3] {
                assert!((0.0..=F16_MAX).contains(&c), "bad value {c}");
            }
            assert_eq!(px[3], 1.0);
        }
    }

    fn close(a: f32, b: f32, tol: f32) -> bool {
        (a - b).abs() <= tol
    }

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
    fn sanitize_counts_each_kind() {
        let mut img = EnvImage {
            width: 3,
            height: 1,
            pixels: vec![
                [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.5],
                [-1.0, -0.0, 70000.0, 1.0],
                [F16_MAX, 1.0, 1e30, f32::NAN],
            ],
        };
        let counts = img.sanitize();
        assert_eq!(
            counts,
            SanitizeCounts {
                nan: 1,
                infinite: 2,
                negative: 1,
                clamped: 2
            }
        );
        assert_eq!(counts.total(), 6);
        assert_clean(&img);
        assert_eq!(img.pixels[1], [0.0, 0.0, F16_MAX, 1.0]);
        assert!(img.pixels[1][1].is_sign_positive());
        assert_eq!(img.pixels[2], [F16_MAX, 1.0, F16_MAX, 1.0]);
        let notes = counts.notes("x.exr");
        assert_eq!(
            notes,
            vec![
                "x.exr: 1 NaN value set to 0",
                "x.exr: 2 infinite values set to 0",
                "x.exr: 1 negative value set to 0",
                "x.exr: 2 values above 65504 (the half-float maximum) clamped to 65504",
            ]
        );
        assert!(SanitizeCounts::default().notes("x.exr").is_empty());
    }

    #[test]
    fn exr_with_bad_values_is_sanitised_and_reported() {
        let dir = tempfile::Builder::new()
            .prefix("bad-exr")
            .tempdir()
            .unwrap();
        let path = dir.path().join("bad.exr");
        // 4x2: row 0 holds the bad values, row 1 is clean.
        let (w, h) = (4usize, 2usize);
        let texel = move |x: usize, y: usize| -> (f32, f32, f32, f32) {
            match (x, y) {
                (0, 0) => (f32::NAN, f32::NAN, 1.0, 1.0),
                (1, 0) => (f32::INFINITY, f32::NEG_INFINITY, 2.0, 1.0),
                (2, 0) => (-0.25, -3894.0, -1e-6, 1.0),
                (3, 0) => (1e6, 70000.0, 29856.0, 1.0),
                _ => (x as f32, y as f32, 0.5, 0.25),
            }
        };
        exr::prelude::write_rgba_file(&path, w, h, texel).unwrap();

        let loaded = load(&path).unwrap();
        let img = &loaded.image;
        assert_eq!((img.width, img.height), (4, 2));
        assert_clean(img);
        assert_eq!(img.texel(0, 0), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(img.texel(1, 0), [0.0, 0.0, 2.0, 1.0]);
        assert_eq!(img.texel(2, 0), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(img.texel(3, 0), [F16_MAX, F16_MAX, 29856.0, 1.0]);
        // Row 1 of the file is row 1 of the image, alpha forced to 1.
        assert_eq!(img.texel(3, 1), [3.0, 1.0, 0.5, 1.0]);
        assert_eq!(
            loaded.notes,
            vec![
                "bad.exr: 2 NaN values set to 0",
                "bad.exr: 2 infinite values set to 0",
                "bad.exr: 3 negative values set to 0",
                "bad.exr: 2 values above 65504 (the half-float maximum) clamped to 65504",
            ]
        );
    }

    #[test]
    fn clean_exr_has_no_notes_and_luminance_exr_becomes_grey() {
        use exr::prelude::*;
        let dir = tempfile::Builder::new()
            .prefix("grey-exr")
            .tempdir()
            .unwrap();

        let rgb = dir.path().join("clean.exr");
        write_rgb_file(&rgb, 2, 2, |x, y| (x as f32, y as f32, 0.25f32)).unwrap();
        let loaded = load(&rgb).unwrap();
        assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
        assert_eq!(loaded.image.texel(1, 0), [1.0, 0.0, 0.25, 1.0]);

        let y_only = dir.path().join("grey.exr");
        let channels = SpecificChannels::build()
            .with_channel("Y")
            .with_pixel_fn(|p: Vec2<usize>| (p.x() as f32 + 10.0 * p.y() as f32,));
        Image::from_channels((3, 2), channels)
            .write()
            .to_file(&y_only)
            .unwrap();
        let img = load(&y_only).unwrap().image;
        assert_eq!((img.width, img.height), (3, 2));
        assert_eq!(img.texel(2, 1), [12.0, 12.0, 12.0, 1.0]);
    }

    #[test]
    fn dwab_exr_decodes() {
        use exr::prelude::*;
        let dir = tempfile::Builder::new().prefix("dwab").tempdir().unwrap();
        let path = dir.path().join("dwab.exr");
        let (w, h) = (64usize, 32usize);
        let value = |x: usize, y: usize| 0.5 + (x as f32 / w as f32) + 2.0 * (y as f32 / h as f32);
        let layer = Layer::new(
            (w, h),
            LayerAttributes::named("main"),
            Encoding {
                compression: Compression::DWAB(None),
                blocks: Blocks::ScanLines,
                line_order: LineOrder::Increasing,
            },
            SpecificChannels::rgb(move |p: Vec2<usize>| {
                let v = f16::from_f32(value(p.x(), p.y()));
                (v, v, v)
            }),
        );
        Image::from_layer(layer).write().to_file(&path).unwrap();
        let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
        assert!(matches!(meta.headers[0].compression, Compression::DWAB(_)));

        let img = load(&path).unwrap().image;
        assert_eq!((img.width, img.height), (64, 32));
        // Lossy, but close to the smooth ramp.
        for (x, y) in [(0u32, 0u32), (63, 0), (0, 31), (40, 20)] {
            let got = img.texel(x, y)[1];
            let want = value(x as usize, y as usize);
            assert!(close(got, want, 0.05 * want), "({x},{y}): {got} vs {want}");
        }
    }

    #[test]
    fn png_is_srgb_decoded_and_grey_expands() {
        let dir = tempfile::Builder::new().prefix("png").tempdir().unwrap();
        let rgb = dir.path().join("rgb.png");
        let img = image::RgbImage::from_raw(2, 1, vec![0, 128, 255, 10, 200, 1]).unwrap();
        img.save_with_format(&rgb, image::ImageFormat::Png).unwrap();
        let loaded = load(&rgb).unwrap();
        assert!(loaded.notes.is_empty());
        let t = loaded.image.texel(0, 0);
        assert_eq!(t[0], 0.0);
        // ((128/255 + 0.055) / 1.055)^2.4
        assert!(close(t[1], 0.215_860_5, 1e-6), "{}", t[1]);
        assert_eq!(t[2], 1.0);
        assert_eq!(t[3], 1.0);
        // 10/255 is below the linear-segment threshold 0.04045: c / 12.92.
        let t = loaded.image.texel(1, 0);
        assert!(close(t[0], 10.0 / 255.0 / 12.92, 1e-7));
        assert!(close(t[1], srgb_to_linear(200.0 / 255.0), 1e-7));

        let grey = dir.path().join("grey.PNG");
        let g = image::GrayImage::from_raw(1, 2, vec![255, 64]).unwrap();
        g.save_with_format(&grey, image::ImageFormat::Png).unwrap();
        let img = load(&grey).unwrap().image;
        assert_eq!((img.width, img.height), (1, 2));
        assert_eq!(img.texel(0, 0), [1.0, 1.0, 1.0, 1.0]);
        let l = srgb_to_linear(64.0 / 255.0);
        assert_eq!(img.texel(0, 1), [l, l, l, 1.0]);

        let rgba16 = dir.path().join("rgba16.png");
        let im =
            image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(1, 1, vec![65535u16, 0, 32768, 0])
                .unwrap();
        im.save_with_format(&rgba16, image::ImageFormat::Png)
            .unwrap();
        let t = load(&rgba16).unwrap().image.texel(0, 0);
        assert_eq!(t[0], 1.0);
        assert_eq!(t[1], 0.0);
        assert!(close(t[2], srgb_to_linear(32768.0 / 65535.0), 1e-6));
        assert_eq!(t[3], 1.0, "alpha is dropped");
    }

    #[test]
    fn srgb_eotf_is_exact_at_known_points() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert_eq!(srgb_to_linear(1.0), 1.0);
        assert!(close(srgb_to_linear(0.04045), 0.04045 / 12.92, 1e-9));
        assert!(close(srgb_to_linear(0.5), 0.214_041_14, 1e-7));
        for i in 0..256 {
            assert_eq!(SRGB8_TO_LINEAR[i], srgb_to_linear(i as f32 / 255.0));
        }
    }

    #[test]
    fn hdr_and_jpeg_load() {
        let dir = tempfile::Builder::new()
            .prefix("hdr-jpg")
            .tempdir()
            .unwrap();
        let hdr = dir.path().join("sun.hdr");
        let img =
            image::Rgb32FImage::from_raw(2, 1, vec![100000.0, 1.0, 0.5, 0.0, 2.0, 4.0]).unwrap();
        image::DynamicImage::ImageRgb32F(img)
            .save_with_format(&hdr, image::ImageFormat::Hdr)
            .unwrap();
        let loaded = load(&hdr).unwrap();
        assert_clean(&loaded.image);
        assert_eq!(loaded.image.texel(0, 0)[0], F16_MAX);
        assert!(close(loaded.image.texel(1, 0)[2], 4.0, 0.05));
        assert_eq!(
            loaded.notes,
            vec!["sun.hdr: 1 value above 65504 (the half-float maximum) clamped to 65504"]
        );

        let jpg = dir.path().join("grey.jpeg");
        let g = image::GrayImage::from_pixel(8, 8, image::Luma([128]));
        g.save_with_format(&jpg, image::ImageFormat::Jpeg).unwrap();
        let img = load(&jpg).unwrap().image;
        assert_eq!((img.width, img.height), (8, 8));
        let t = img.texel(4, 4);
        assert!(close(t[0], 0.2159, 0.01), "{t:?}");
        assert_eq!(t[0], t[1]);
        assert_eq!(t[1], t[2]);
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
    fn missing_file_error_names_it() {
        let err = load(Path::new("/nonexistent/dir/nowhere-sky.exr")).unwrap_err();
        assert!(matches!(err, EnvMapError::Io { .. }), "{err:?}");
        let msg = err.to_string();
        assert!(msg.contains("nowhere-sky.exr"), "{msg}");
        assert!(msg.contains("cannot read"), "{msg}");
        assert_eq!(err.path(), Path::new("/nonexistent/dir/nowhere-sky.exr"));
    }

    #[test]
    fn unsupported_extension_error_lists_formats() {
        let dir = tempfile::Builder::new().prefix("ext").tempdir().unwrap();
        let path = dir.path().join("sky.tga");
        std::fs::write(&path, b"not an env map").unwrap();
        let err = load(&path).unwrap_err();
        assert!(matches!(err, EnvMapError::UnsupportedExtension { .. }));
        let msg = err.to_string();
        for needle in ["sky.tga", ".tga", ".exr", ".hdr", ".png", ".jpg", ".jpeg"] {
            assert!(msg.contains(needle), "{needle} not in {msg}");
        }
        let err = load(Path::new("noext")).unwrap_err();
        assert!(err.to_string().contains("noext"));
        assert!(err.to_string().contains("(no extension)"));
    }

    #[test]
    fn corrupt_files_error_names_them() {
        let dir = tempfile::Builder::new()
            .prefix("corrupt")
            .tempdir()
            .unwrap();
        let png = dir.path().join("broken.png");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\nthis is not a png").unwrap();
        let err = load(&png).unwrap_err();
        assert!(
            matches!(err, EnvMapError::Decode { format: "PNG", .. }),
            "{err:?}"
        );
        assert!(err.to_string().contains("broken.png"), "{err}");

        let exr = dir.path().join("garbage.exr");
        std::fs::write(&exr, b"garbage").unwrap();
        let err = load(&exr).unwrap_err();
        assert!(
            matches!(
                err,
                EnvMapError::Decode {
                    format: "OpenEXR",
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(err.to_string().contains("garbage.exr"), "{err}");
    }

    #[test]
    fn truncated_exr_error_names_the_file() {
        let Some(sky) = shipped_map("sky.exr") else {
            eprintln!("sky.exr not found; skipping");
            return;
        };
        let bytes = std::fs::read(&sky).unwrap();
        let dir = tempfile::Builder::new()
            .prefix("truncated")
            .tempdir()
            .unwrap();
        let path = dir.path().join("half-sky.exr");
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let err = load(&path).unwrap_err();
        let msg = err.to_string();
        eprintln!("{msg}");
        assert!(msg.contains("half-sky.exr"), "{msg}");
        assert!(matches!(err, EnvMapError::Decode { .. }), "{err:?}");
    }

    #[test]
    fn error_messages_for_empty_and_dwa() {
        let e = EnvMapError::Empty {
            path: "maps/empty.png".into(),
            width: 0,
            height: 4,
        };
        assert_eq!(
            e.to_string(),
            "environment map maps/empty.png: the image is empty (0x4)"
        );
        let e = EnvMapError::ExrCompression {
            path: "maps/dwa.exr".into(),
            compression: "DWAB".into(),
            message: "not supported: x".into(),
        };
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
        assert_clean(&loaded.image);
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
            assert_clean(&loaded.image);
            assert_eq!(loaded.notes, Vec::<String>::new(), "{name}");
        }
    }

    /// The texture report's IMAGE files: PPM and PGM in text (P3, P2) and
    /// binary (P6, P5), 8 and 16 bits, any maxval, read as sRGB codes.
    #[test]
    fn ppm_and_pgm_load_in_text_and_binary() {
        let dir = tempfile::Builder::new().prefix("pnm").tempdir().unwrap();
        let write = |name: &str, bytes: &[u8]| {
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).unwrap();
            path
        };
        let linear = |path: &Path| load_with(path, IntegerDecode::Linear).unwrap().image;
        // Two texels: red, then (0, 128/255, 255/255)·white in P3 text.
        let p3 = linear(&write(
            "a.ppm",
            b"P3\n# a comment\n2 1\n255\n255 0 0  0 128 255\n",
        ));
        assert_eq!((p3.width, p3.height), (2, 1));
        assert_eq!(p3.pixels[0], [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(p3.pixels[1], [0.0, 128.0 / 255.0, 1.0, 1.0]);
        let mut p6 = b"P6 2 1 255\n".to_vec();
        p6.extend([255, 0, 0, 0, 128, 255]);
        assert_eq!(linear(&write("b.ppm", &p6)).pixels, p3.pixels, "P6 = P3");
        let p2 = linear(&write("c.pgm", b"P2 1 2 15\n0\n15\n"));
        assert_eq!(p2.pixels, [[0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0]]);
        let p5 = linear(&write(
            "d.pgm",
            &[b"P5 2 1 65535\n".as_slice(), &[0x80, 0x00, 0xff, 0xff]].concat(),
        ));
        assert_eq!(p5.pixels[0][0], 32768.0 / 65535.0);
        assert_eq!(p5.pixels[1], [1.0, 1.0, 1.0, 1.0]);
        // sRGB codes by default, as for PNG: mid grey 188 is 0.5 linear.
        let srgb = load(&write("e.pgm", b"P2 1 1 255\n188\n")).unwrap().image;
        assert!(
            (srgb.pixels[0][0] - 0.5029).abs() < 1e-3,
            "{:?}",
            srgb.pixels[0]
        );
    }

    #[test]
    fn bad_ppm_files_give_errors_naming_the_file_and_the_cause() {
        let dir = tempfile::Builder::new()
            .prefix("bad-pnm")
            .tempdir()
            .unwrap();
        let error = |name: &str, bytes: &[u8]| {
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).unwrap();
            let message = load(&path).unwrap_err().to_string();
            assert!(message.contains(name), "{message}");
            message
        };
        let truncated = error("cut.ppm", b"P6 4 4 255\n\x01\x02\x03");
        assert!(truncated.contains("truncated"), "{truncated}");
        let oversized = error("huge.ppm", b"P6 100000 100000 255\n");
        assert!(oversized.contains("100000x100000"), "{oversized}");
        for (name, bytes) in [
            ("zero.pgm", b"P2 1 1 0\n0\n".as_slice()),
            ("wide.pgm", b"P2 1 1 70000\n0\n".as_slice()),
            ("over.pgm", b"P2 1 1 15\n16\n".as_slice()),
            ("over.ppm", b"P6 1 1 100\n\x00\x65\x00".as_slice()),
            ("magic.ppm", b"P9 1 1 255\n0 0 0\n".as_slice()),
        ] {
            let message = error(name, bytes);
            assert!(message.contains("PPM/PGM"), "{message}");
        }
        let over = error("above.pgm", b"P2 2 1 15\n# two samples\n3 16\n");
        assert!(
            over.contains("sample 1 is 16, above the file's maxval 15"),
            "{over}"
        );
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
