//! The image decoder every picture marbre reads goes through: a file's
//! bytes to linear RGBA f32 texels. Environment maps ([`crate::envmap`],
//! cube-map faces included) and image textures (`texture::image`) load
//! through it, and the fuzzer drives it on bytes without a file
//! ([`decode_bytes`]).
//!
//! It is apart from `envmap` because nothing here is about environment
//! maps: what a map does with its texels (the lat-long mapping, fitting the
//! GPU's largest texture, Massal's un-exposure) is `envmap`'s, and a texture
//! should not load through the environment's module.
//!
//! [`decode_file`] reads an OpenEXR (`.exr`, through the `exr` crate),
//! Radiance (`.hdr`), PNG, JPEG or PPM/PGM file (through `image`), the
//! format chosen by extension, into a [`DecodedImage`]: row-major, row 0 at
//! the top of the picture, alpha always 1. The integer codes of 8- and
//! 16-bit files become values as [`IntegerDecode`] says; float files are
//! linear.
//!
//! # Bounded and clean
//!
//! A file's declared size is checked from its header before its texels are
//! allocated ([`MAX_TEXELS`]), and the `exr` crate's panics on malformed
//! files are caught: a hostile file gives an error, not an abort.
//!
//! Real-world files are not clean either: lossy compression leaves negative
//! values, and a sun can be brighter than a half float can hold, while every
//! GPU copy of an image is `Rgba16Float`. Every image is therefore sanitised
//! as it is decoded (see [`DecodedImage::sanitize`]): NaN, ±Inf and negative
//! values become 0 and values above [`F16_MAX`] are clamped to it. Each kind
//! of repair is reported as one human-readable line in
//! [`DecodedImage::notes`].
//!
//! A [`DecodeError`] names the file but not what it was for: the loaders
//! above say that ("environment map …", "image texture …").

use std::io::Cursor;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// The largest finite half float. The GPU texture is `Rgba16Float`, so
/// anything brighter would become +Inf there.
pub const F16_MAX: f32 = 65504.0;

/// The extensions the decoder understands (lower case, without the dot).
pub const SUPPORTED_EXTENSIONS: [&str; 8] =
    ["exr", "hdr", "png", "jpg", "jpeg", "ppm", "pgm", "pnm"];

/// The most texels an image may declare: 2²⁷ (a 16384×8192 lat-long map),
/// 2 GiB as f32 RGBA. The size is checked from the file's header before
/// anything is allocated, so a hostile header cannot make the loader ask
/// for terabytes (the fuzzer's memory limit found the need).
pub const MAX_TEXELS: u64 = 16384 * 8192;

/// What to do about an OpenEXR file marbre's reader cannot decode.
pub const EXR_RESAVE_HINT: &str = "re-save it with ZIP or PIZ compression or none, \
     e.g. `oiiotool in.exr --compression zip -o out.exr`";

/// A picture as [`decode_file`] and [`decode_bytes`] return it: linear RGBA
/// f32, alpha 1, every colour value finite, non-negative and at most
/// [`F16_MAX`].
#[derive(Debug, Clone)]
pub struct DecodedImage {
    pub width: u32,
    pub height: u32,
    /// Row-major, `width * height` texels, row 0 = top of the picture (as
    /// in the file).
    pub pixels: Vec<[f32; 4]>,
    /// One line per choice or kind of repair the decoder made, each
    /// starting with the file's name (empty for a clean file): which layer
    /// of an OpenEXR file was read, how many values were sanitised.
    pub notes: Vec<String>,
}

impl DecodedImage {
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
}

/// How many channel values [`DecodedImage::sanitize`] repaired, by kind.
/// Only the colour channels are counted; alpha is forced to 1.
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

/// Why a file could not be decoded. Every variant names the file; the
/// loaders above add what it was for ([`crate::envmap::EnvMapError`],
/// [`crate::texture::image::ImageError`]).
#[derive(Debug, Error)]
pub enum DecodeError {
    /// The file is missing or unreadable.
    #[error("{}: cannot read the file: {cause}", .path.display())]
    Io {
        path: PathBuf,
        /// Not a `#[source]`: the message already says it, and a chain
        /// would print it twice.
        cause: std::io::Error,
    },
    /// The extension is not one of [`SUPPORTED_EXTENSIONS`].
    #[error(
        "{}: unsupported file type {}; supported: {}",
        .path.display(),
        if .extension.is_empty() { "(no extension)".to_string() } else { format!(".{}", .extension) },
        supported_list()
    )]
    UnsupportedExtension { path: PathBuf, extension: String },
    /// The decoder rejected the file; `message` is the decoder's own.
    #[error("{}: cannot decode {format}: {message}", .path.display())]
    Decode {
        path: PathBuf,
        format: &'static str,
        message: String,
    },
    /// An OpenEXR file whose compression the `exr` crate does not implement
    /// (HTJ2K), or DWAA/DWAB data it failed to decode (older `exr`
    /// versions could not read DWA at all).
    #[error(
        "{}: cannot decode OpenEXR with {compression} compression: {message}; \
         {EXR_RESAVE_HINT}",
        .path.display()
    )]
    ExrCompression {
        path: PathBuf,
        compression: String,
        message: String,
    },
    /// The image has no texels.
    #[error("{}: the image is empty ({width}x{height})", .path.display())]
    Empty {
        path: PathBuf,
        width: u32,
        height: u32,
    },
}

impl DecodeError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            DecodeError::Io { path, .. }
            | DecodeError::UnsupportedExtension { path, .. }
            | DecodeError::Decode { path, .. }
            | DecodeError::ExrCompression { path, .. }
            | DecodeError::Empty { path, .. } => path,
        }
    }
}

/// How the decoder turns the integer codes of an 8- or 16-bit PNG or JPEG
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

/// Reads and decodes the image file at `path`. The format is chosen by
/// extension (case-insensitive): `.exr` (any compression the `exr` crate
/// reads; RGB(A) or luminance-only `Y`), `.hdr` (Radiance RGBE), `.png`,
/// `.jpg`/`.jpeg` and `.ppm`/`.pgm`/`.pnm`. The integer codes of PNG, JPEG
/// and PPM/PGM files (8 or 16 bits) are decoded as `decode` says; grey
/// images become RGB; alpha is dropped.
pub fn decode_file(path: &Path, decode: IntegerDecode) -> Result<DecodedImage, DecodeError> {
    // An unsupported type is refused before the file is read.
    supported_extension(path)?;
    let bytes =
        crate::capped_read::read_capped(path, crate::capped_read::IMAGE).map_err(|cause| {
            DecodeError::Io {
                path: path.to_path_buf(),
                cause,
            }
        })?;
    decode_bytes(&bytes, path, decode)
}

/// [`SUPPORTED_EXTENSIONS`] as messages list them: `.exr, .hdr, …`.
pub fn supported_list() -> String {
    SUPPORTED_EXTENSIONS.map(|e| format!(".{e}")).join(", ")
}

/// The lower-case extension of `path`, if it is one of
/// [`SUPPORTED_EXTENSIONS`].
pub fn supported_extension(path: &Path) -> Result<String, DecodeError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if SUPPORTED_EXTENSIONS.contains(&extension.as_str()) {
        Ok(extension)
    } else {
        Err(DecodeError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension,
        })
    }
}

/// [`decode_file`] on the bytes of a file already read: `path` chooses the
/// format by its extension and names the file in messages. The fuzz target
/// and its regression tests decode through it without a file.
pub fn decode_bytes(
    bytes: &[u8],
    path: &Path,
    decode: IntegerDecode,
) -> Result<DecodedImage, DecodeError> {
    let extension = supported_extension(path)?;
    let mut image = match extension.as_str() {
        "exr" => decode_exr(path, bytes)?,
        "hdr" => decode_with_image(path, bytes, image::ImageFormat::Hdr, "Radiance HDR", decode)?,
        "png" => decode_with_image(path, bytes, image::ImageFormat::Png, "PNG", decode)?,
        // The texture report's IMAGE format (P2, P3 in text; P5, P6 binary).
        "ppm" | "pgm" | "pnm" => {
            let bytes = &clean_pnm_header(bytes);
            check_pnm_samples(bytes).map_err(|message| DecodeError::Decode {
                path: path.to_path_buf(),
                format: "PPM/PGM",
                message,
            })?;
            decode_with_image(path, bytes, image::ImageFormat::Pnm, "PPM/PGM", decode)?
        }
        _ => decode_with_image(path, bytes, image::ImageFormat::Jpeg, "JPEG", decode)?,
    };
    if image.width == 0 || image.height == 0 || image.pixels.is_empty() {
        return Err(DecodeError::Empty {
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
    image.notes.extend(counts.notes(&file_name));
    Ok(image)
}

/// An error unless a `width` × `height` image is one marbre loads: not
/// empty, and at most [`MAX_TEXELS`].
fn check_size(
    path: &Path,
    format: &'static str,
    width: u64,
    height: u64,
) -> Result<(), DecodeError> {
    if width == 0 || height == 0 {
        return Err(DecodeError::Empty {
            path: path.to_path_buf(),
            width: width.min(u64::from(u32::MAX)) as u32,
            height: height.min(u64::from(u32::MAX)) as u32,
        });
    }
    if width.saturating_mul(height) > MAX_TEXELS {
        return Err(DecodeError::Decode {
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

/// Refuses an OpenEXR file whose headers declare more than its `file_len`
/// bytes can hold, before its texels are allocated: a 598-byte file
/// claiming 16384×8192 texels used to cost 2 GiB before the reader found
/// its chunks missing.
///
/// The least a file holds for its headers ([`exr_least_bytes`]) is a
/// bound, not an estimate: every chunk has its offset and its own header,
/// and no compression shrinks the texels further than its method can
/// (deflate's longest match, 258 bytes in 2 bits, is 1032:1). A file
/// within the bound may still be truncated further on; the reader finds
/// that, having allocated at most what the file's bytes could hold.
pub fn check_exr_fits(
    path: &Path,
    file_len: usize,
    headers: &[exr::meta::header::Header],
) -> Result<(), DecodeError> {
    let least: u64 = headers
        .iter()
        .map(exr_least_bytes)
        .fold(0, u64::saturating_add);
    if (file_len as u64) < least {
        let declared: Vec<String> = headers
            .iter()
            .map(|h| format!("{}x{}", h.layer_size.width(), h.layer_size.height()))
            .collect();
        return Err(DecodeError::Decode {
            path: path.to_path_buf(),
            format: "OpenEXR",
            message: format!(
                "the file declares {} texels with {}, which take {least} bytes at least, but \
                 it is {file_len} bytes: the file is truncated or its header is wrong",
                declared.join(" and "),
                headers
                    .first()
                    .map_or("no".into(), |h| h.compression.to_string())
            ),
        });
    }
    Ok(())
}

/// The fewest bytes a file holds for `header`'s part: 8 bytes of offset
/// table and a chunk header (8 bytes for lines, 20 for a tile) a chunk,
/// and its largest resolution's texels shrunk by its compression's
/// largest ratio ([`largest_ratio`]). Deep parts count their chunks only.
fn exr_least_bytes(header: &exr::meta::header::Header) -> u64 {
    use exr::meta::BlockDescription;
    let chunk_header: u64 = match header.blocks {
        BlockDescription::ScanLines => 8,
        BlockDescription::Tiles(_) => 20,
    };
    let chunks = (header.chunk_count as u64).saturating_mul(8 + chunk_header);
    if header.deep {
        return chunks;
    }
    let texel_bytes = header
        .channels
        .list
        .iter()
        .map(|c| {
            let size = c.subsampled_resolution(header.layer_size);
            (size.width() as u64)
                .saturating_mul(size.height() as u64)
                .saturating_mul(c.sample_type.bytes_per_sample() as u64)
        })
        .fold(0, u64::saturating_add);
    chunks.saturating_add(texel_bytes / largest_ratio(header.compression))
}

/// How many times smaller than its texels a compression can make them, at
/// most, rounded up: none 1; RLE 64 (127 bytes in 2); ZIP 1032 (deflate's
/// limit); PXR24 4/3 more (f32 to 24 bits, then deflate); B44 11 (a flat
/// 4×4 block of halves, 32 bytes, in 3); PIZ's Huffman runs (256 halves in
/// 10 bits, 410:1) under deflate's; DWA and HTJ2K, whose flat blocks keep
/// one value in 64 and deflate it, 64 × 1032.
fn largest_ratio(compression: exr::compression::Compression) -> u64 {
    use exr::compression::Compression as C;
    match compression {
        C::Uncompressed => 1,
        C::RLE => 64,
        C::ZIP1 | C::ZIP16 | C::PIZ => 1032,
        C::PXR24 => 1376,
        C::B44 | C::B44A => 11,
        C::DWAA(_) | C::DWAB(_) | C::HTJ2K32 | C::HTJ2K256 => 64 * 1032,
    }
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

/// The picture of an OpenEXR file ([`choose_exr_channels`]), with a note
/// if it was chosen among others. The `exr` crate's panics on malformed
/// files are caught and reported as a decode error.
fn decode_exr(path: &Path, bytes: &[u8]) -> Result<DecodedImage, DecodeError> {
    let decode_error = |message: String| DecodeError::Decode {
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
        check_exr_fits(path, bytes.len(), &meta.headers)?;
        let mut image = read_exr_channels(bytes, &choice.channels)
            .map_err(|e| exr_error(path, Some(header.compression), e))?;
        image.notes.extend(choice.note);
        Ok(image)
    }))
    .unwrap_or_else(|_| {
        Err(decode_error(
            "the OpenEXR reader failed on this file (a malformed file it does not check)".into(),
        ))
    })
}

/// Reads `channels` of the first part that has them, as linear RGBA.
fn read_exr_channels(bytes: &[u8], channels: &ExrChannels) -> exr::error::Result<DecodedImage> {
    use exr::prelude::*;

    let storage = |resolution: Vec2<usize>| {
        (
            resolution.width(),
            vec![[0.0f32, 0.0, 0.0, 1.0]; resolution.width() * resolution.height()],
        )
    };
    let to_image = |size: Vec2<usize>, pixels: Vec<[f32; 4]>| DecodedImage {
        width: size.width() as u32,
        height: size.height() as u32,
        pixels,
        notes: Vec::new(),
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

/// Turns an `exr` failure into a [`DecodeError`]. A file whose
/// `compression` the `exr` crate does not implement (HTJ2K), or whose DWAA
/// or DWAB data it failed on, gets [`DecodeError::ExrCompression`], which
/// says what to do.
fn exr_error(
    path: &Path,
    compression: Option<exr::compression::Compression>,
    err: exr::error::Error,
) -> DecodeError {
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
        Some((compression, message)) => DecodeError::ExrCompression {
            path: path.to_path_buf(),
            compression: compression.to_string(),
            message,
        },
        None => DecodeError::Decode {
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
) -> Result<DecodedImage, DecodeError> {
    use image::DynamicImage as D;

    let decode_err = |message: String| DecodeError::Decode {
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
        return Err(DecodeError::Empty {
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
    Ok(DecodedImage {
        width,
        height,
        pixels,
        notes: Vec::new(),
    })
}

/// A decoder's reason, saying "truncated" where it means that the file
/// ends early: the decoders' own words for it vary ("unexpected end of
/// file", "not enough bytes", "failed to fill whole buffer", "reference to
/// missing bytes").
pub(crate) fn decode_message(message: &str) -> String {
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

/// A netpbm file's tokens: runs of non-blank bytes, each ended by a blank
/// or a `#`, with `#` comments (to the end of the line) skipped.
struct NetpbmTokens<'b> {
    bytes: &'b [u8],
    at: usize,
}

impl<'b> NetpbmTokens<'b> {
    fn new(bytes: &'b [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    fn skip_comment(&mut self) {
        while self.bytes.get(self.at).is_some_and(|&b| b != b'\n') {
            self.at += 1;
        }
    }

    fn next_token(&mut self) -> Option<&'b [u8]> {
        loop {
            while self.bytes.get(self.at).is_some_and(u8::is_ascii_whitespace) {
                self.at += 1;
            }
            if self.bytes.get(self.at) != Some(&b'#') {
                break;
            }
            self.skip_comment();
        }
        let start = self.at;
        while self
            .bytes
            .get(self.at)
            .is_some_and(|&b| !b.is_ascii_whitespace() && b != b'#')
        {
            self.at += 1;
        }
        (self.at > start).then(|| &self.bytes[start..self.at])
    }

    fn number(&mut self) -> Option<u64> {
        std::str::from_utf8(self.next_token()?).ok()?.parse().ok()
    }

    /// The binary samples, once the header's last number is read: past a
    /// comment right after it, then the one white-space byte before them.
    fn samples(&mut self) -> &'b [u8] {
        if self.bytes.get(self.at) == Some(&b'#') {
            self.skip_comment();
        }
        self.bytes.get(self.at + 1..).unwrap_or_default()
    }
}

/// A netpbm file with its header rewritten plainly (`P6\nW H\nMAXVAL\n`,
/// then the samples as they were): the format lets a `#` comment start
/// anywhere in the header, right after a number too (`4#c`), which the
/// `image` decoder refuses. A header that does not parse is left as it
/// is, for the decoder to name what is wrong.
fn clean_pnm_header(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    let mut tokens = NetpbmTokens::new(bytes);
    let header = match tokens.next_token() {
        Some(magic @ (b"P2" | b"P3" | b"P5" | b"P6")) => {
            match (tokens.number(), tokens.number(), tokens.number()) {
                (Some(w), Some(h), Some(max)) => {
                    format!("{}\n{w} {h}\n{max}\n", String::from_utf8_lossy(magic))
                }
                _ => return bytes.into(),
            }
        }
        Some(magic @ (b"P1" | b"P4")) => match (tokens.number(), tokens.number()) {
            (Some(w), Some(h)) => format!("{}\n{w} {h}\n", String::from_utf8_lossy(magic)),
            _ => return bytes.into(),
        },
        _ => return bytes.into(),
    };
    [header.as_bytes(), tokens.samples()].concat().into()
}

/// An error if a PGM or PPM file (P2, P3, P5, P6) holds a sample above its
/// maxval, which the `image` decoder would clamp without a word: such a
/// file was written wrong, and its picture is not the one meant. Other
/// files, and headers the decoder will refuse itself, pass.
fn check_pnm_samples(bytes: &[u8]) -> Result<(), String> {
    // The header: magic, width, height, maxval, then the samples.
    let mut tokens = NetpbmTokens::new(bytes);
    let text = match tokens.next_token() {
        Some(b"P2" | b"P3") => true,
        Some(b"P5" | b"P6") => false,
        _ => return Ok(()),
    };
    let (Some(_), Some(_), Some(maxval)) = (tokens.number(), tokens.number(), tokens.number())
    else {
        return Ok(());
    };
    let above = |index: usize, value: u64| {
        format!("sample {index} is {value}, above the file's maxval {maxval}")
    };
    if text {
        let mut index = 0;
        while let Some(t) = tokens.next_token() {
            let value = std::str::from_utf8(t)
                .ok()
                .and_then(|t| t.parse::<u64>().ok());
            match value {
                Some(v) if v > maxval => return Err(above(index, v)),
                _ => index += 1,
            }
        }
    } else if maxval < 255 {
        let samples = tokens.samples();
        if let Some((index, &v)) = samples
            .iter()
            .enumerate()
            .find(|&(_, &v)| u64::from(v) > maxval)
        {
            return Err(above(index, v.into()));
        }
    } else if maxval > 255 && maxval < 65535 {
        let samples = tokens.samples();
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

/// What the decoder's and the env maps' tests share.
#[cfg(test)]
pub(crate) mod test_support {
    use super::F16_MAX;
    use std::path::{Path, PathBuf};

    /// A map shipped in `envmaps/`, else the shared copy; `None` if neither.
    pub(crate) fn shipped_map(name: &str) -> Option<PathBuf> {
        let root = Path::new(crate::REPO);
        [
            root.join("envmaps").join(name),
            root.join("../shared/envmaps").join(name),
        ]
        .into_iter()
        .find(|p| p.is_file())
    }

    /// `width × height` pixels, each finite, in [0, F16_MAX], alpha 1.
    pub(crate) fn assert_clean(pixels: &[[f32; 4]], width: u32, height: u32) {
        assert_eq!(pixels.len(), (width * height) as usize);
        for px in pixels {
            for &c in &px[..3] {
                assert!((0.0..=F16_MAX).contains(&c), "bad value {c}");
            }
            assert_eq!(px[3], 1.0);
        }
    }

    pub(crate) fn close(a: f32, b: f32, tol: f32) -> bool {
        (a - b).abs() <= tol
    }

    /// `exr`, a file of one part, with its data window patched to claim
    /// `width × height` texels, and its chunk count to match: the probe's
    /// lying header (598 bytes claiming 16384×8192), which the `exr` crate
    /// reads as valid up to its missing chunks.
    pub(crate) fn exr_claiming(exr: &[u8], width: i32, height: i32) -> Vec<u8> {
        let meta =
            exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(exr), false).unwrap();
        let header = &meta.headers[0];
        let size = exr::math::Vec2(width as usize, height as usize);
        let chunks = exr::meta::compute_chunk_count(header.compression, size, header.blocks) as i32;
        let mut lying = exr.to_vec();
        let mut patch = |name: &[u8], values: &[i32]| {
            let at = exr
                .windows(name.len())
                .position(|w| w == name)
                .expect("the `exr` crate writes both attributes")
                + name.len();
            let size = 4 * values.len() as i32;
            assert_eq!(exr[at..at + 4], size.to_le_bytes(), "{values:?}");
            for (k, v) in values.iter().enumerate() {
                let start = at + 4 + 4 * k;
                lying[start..start + 4].copy_from_slice(&v.to_le_bytes());
            }
        };
        patch(b"dataWindow\0box2i\0", &[0, 0, width - 1, height - 1]);
        patch(b"chunkCount\0int\0", &[chunks]);
        lying
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::test_support::{assert_clean, close, shipped_map};

    /// An image that is a device or a FIFO is refused by its file type,
    /// not read until memory runs out or waited on forever.
    #[test]
    fn a_device_or_fifo_image_is_refused() {
        use crate::capped_read::test_support::{make_fifo, within_10_s};
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.png");
        make_fifo(&fifo);
        let zero = dir.path().join("zero.exr");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        for path in [fifo, zero] {
            let error = within_10_s(move || {
                decode_file(&path, IntegerDecode::Srgb)
                    .unwrap_err()
                    .to_string()
            });
            assert!(error.contains("not a regular file"), "{error}");
        }
    }

    /// A small file claiming 16384×8192 texels, within [`MAX_TEXELS`], is
    /// refused from its size, naming the file and what it claims, before
    /// its texels are allocated (the probe's 598-byte file cost 2.1 GB);
    /// the file it was patched from still decodes.
    #[test]
    fn an_exr_claiming_more_than_its_bytes_hold_is_refused() {
        for compression in [
            exr::compression::Compression::Uncompressed,
            exr::compression::Compression::ZIP16,
            exr::compression::Compression::PIZ,
        ] {
            use exr::prelude::*;
            let channels = SpecificChannels::rgb(|_: Vec2<usize>| (0.5f32, 0.5f32, 0.5f32));
            let encoding = Encoding {
                compression,
                ..Encoding::FAST_LOSSLESS
            };
            let mut bytes = std::io::Cursor::new(Vec::new());
            Image::from_encoded_channels((4, 2), encoding, channels)
                .write()
                .to_buffered(&mut bytes)
                .unwrap();
            let small = bytes.into_inner();
            let path = Path::new("lying.exr");
            decode_bytes(&small, path, IntegerDecode::Linear).unwrap();
            let lying = test_support::exr_claiming(&small, 16384, 8192);
            assert!(lying.len() < 2000, "{}", lying.len());
            let e = decode_bytes(&lying, path, IntegerDecode::Linear)
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with("lying.exr: ")
                    && e.contains("declares 16384x8192 texels")
                    && e.contains(&format!("it is {} bytes", lying.len())),
                "{compression:?}: {e}"
            );
        }
    }

    /// The texel at column `x`, row `y` (row 0 = top).
    fn texel_at(image: &DecodedImage, x: u32, y: u32) -> [f32; 4] {
        image.pixels[y as usize * image.width as usize + x as usize]
    }

    #[test]
    fn sanitize_counts_each_kind() {
        let mut img = DecodedImage {
            width: 3,
            height: 1,
            pixels: vec![
                [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.5],
                [-1.0, -0.0, 70000.0, 1.0],
                [F16_MAX, 1.0, 1e30, f32::NAN],
            ],
            notes: Vec::new(),
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
        assert_clean(&img.pixels, img.width, img.height);
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

        let loaded = decode_file(&path, IntegerDecode::Srgb).unwrap();
        let img = &loaded;
        assert_eq!((img.width, img.height), (4, 2));
        assert_clean(&img.pixels, img.width, img.height);
        assert_eq!(texel_at(img, 0, 0), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(texel_at(img, 1, 0), [0.0, 0.0, 2.0, 1.0]);
        assert_eq!(texel_at(img, 2, 0), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(texel_at(img, 3, 0), [F16_MAX, F16_MAX, 29856.0, 1.0]);
        // Row 1 of the file is row 1 of the image, alpha forced to 1.
        assert_eq!(texel_at(img, 3, 1), [3.0, 1.0, 0.5, 1.0]);
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
        let loaded = decode_file(&rgb, IntegerDecode::Srgb).unwrap();
        assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
        assert_eq!(texel_at(&loaded, 1, 0), [1.0, 0.0, 0.25, 1.0]);

        let y_only = dir.path().join("grey.exr");
        let channels = SpecificChannels::build()
            .with_channel("Y")
            .with_pixel_fn(|p: Vec2<usize>| (p.x() as f32 + 10.0 * p.y() as f32,));
        Image::from_channels((3, 2), channels)
            .write()
            .to_file(&y_only)
            .unwrap();
        let img = decode_file(&y_only, IntegerDecode::Srgb).unwrap();
        assert_eq!((img.width, img.height), (3, 2));
        assert_eq!(texel_at(&img, 2, 1), [12.0, 12.0, 12.0, 1.0]);
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

        let img = decode_file(&path, IntegerDecode::Srgb).unwrap();
        assert_eq!((img.width, img.height), (64, 32));
        // Lossy, but close to the smooth ramp.
        for (x, y) in [(0u32, 0u32), (63, 0), (0, 31), (40, 20)] {
            let got = texel_at(&img, x, y)[1];
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
        let loaded = decode_file(&rgb, IntegerDecode::Srgb).unwrap();
        assert!(loaded.notes.is_empty());
        let t = texel_at(&loaded, 0, 0);
        assert_eq!(t[0], 0.0);
        // ((128/255 + 0.055) / 1.055)^2.4
        assert!(close(t[1], 0.215_860_5, 1e-6), "{}", t[1]);
        assert_eq!(t[2], 1.0);
        assert_eq!(t[3], 1.0);
        // 10/255 is below the linear-segment threshold 0.04045: c / 12.92.
        let t = texel_at(&loaded, 1, 0);
        assert!(close(t[0], 10.0 / 255.0 / 12.92, 1e-7));
        assert!(close(t[1], srgb_to_linear(200.0 / 255.0), 1e-7));

        let grey = dir.path().join("grey.PNG");
        let g = image::GrayImage::from_raw(1, 2, vec![255, 64]).unwrap();
        g.save_with_format(&grey, image::ImageFormat::Png).unwrap();
        let img = decode_file(&grey, IntegerDecode::Srgb).unwrap();
        assert_eq!((img.width, img.height), (1, 2));
        assert_eq!(texel_at(&img, 0, 0), [1.0, 1.0, 1.0, 1.0]);
        let l = srgb_to_linear(64.0 / 255.0);
        assert_eq!(texel_at(&img, 0, 1), [l, l, l, 1.0]);

        let rgba16 = dir.path().join("rgba16.png");
        let im =
            image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(1, 1, vec![65535u16, 0, 32768, 0])
                .unwrap();
        im.save_with_format(&rgba16, image::ImageFormat::Png)
            .unwrap();
        let t = texel_at(&decode_file(&rgba16, IntegerDecode::Srgb).unwrap(), 0, 0);
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
        let loaded = decode_file(&hdr, IntegerDecode::Srgb).unwrap();
        assert_clean(&loaded.pixels, loaded.width, loaded.height);
        assert_eq!(texel_at(&loaded, 0, 0)[0], F16_MAX);
        assert!(close(texel_at(&loaded, 1, 0)[2], 4.0, 0.05));
        assert_eq!(
            loaded.notes,
            vec!["sun.hdr: 1 value above 65504 (the half-float maximum) clamped to 65504"]
        );

        let jpg = dir.path().join("grey.jpeg");
        let g = image::GrayImage::from_pixel(8, 8, image::Luma([128]));
        g.save_with_format(&jpg, image::ImageFormat::Jpeg).unwrap();
        let img = decode_file(&jpg, IntegerDecode::Srgb).unwrap();
        assert_eq!((img.width, img.height), (8, 8));
        let t = texel_at(&img, 4, 4);
        assert!(close(t[0], 0.2159, 0.01), "{t:?}");
        assert_eq!(t[0], t[1]);
        assert_eq!(t[1], t[2]);
    }

    #[test]
    fn missing_file_error_names_it() {
        let err = decode_file(
            Path::new("/nonexistent/dir/nowhere-sky.exr"),
            IntegerDecode::Srgb,
        )
        .unwrap_err();
        assert!(matches!(err, DecodeError::Io { .. }), "{err:?}");
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
        let err = decode_file(&path, IntegerDecode::Srgb).unwrap_err();
        assert!(matches!(err, DecodeError::UnsupportedExtension { .. }));
        let msg = err.to_string();
        for needle in [
            "sky.tga", ".tga", ".exr", ".hdr", ".png", ".jpg", ".jpeg", ".ppm", ".pgm", ".pnm",
        ] {
            assert!(msg.contains(needle), "{needle} not in {msg}");
        }
        let err = decode_file(Path::new("noext"), IntegerDecode::Srgb).unwrap_err();
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
        let err = decode_file(&png, IntegerDecode::Srgb).unwrap_err();
        assert!(
            matches!(err, DecodeError::Decode { format: "PNG", .. }),
            "{err:?}"
        );
        assert!(err.to_string().contains("broken.png"), "{err}");

        let exr = dir.path().join("garbage.exr");
        std::fs::write(&exr, b"garbage").unwrap();
        let err = decode_file(&exr, IntegerDecode::Srgb).unwrap_err();
        assert!(
            matches!(
                err,
                DecodeError::Decode {
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
        let err = decode_file(&path, IntegerDecode::Srgb).unwrap_err();
        let msg = err.to_string();
        eprintln!("{msg}");
        assert!(msg.contains("half-sky.exr"), "{msg}");
        assert!(matches!(err, DecodeError::Decode { .. }), "{err:?}");
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
        let linear = |path: &Path| decode_file(path, IntegerDecode::Linear).unwrap();
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
        // A comment right after a number, which the format allows.
        let commented = linear(&write("f.pgm", b"P2\n1#c\n2 15#max\n0\n15\n"));
        assert_eq!(commented.pixels, p2.pixels);
        let mut binary = b"P5 2 1 255#c\n".to_vec();
        binary.extend([0, 255]);
        let binary = linear(&write("g.pgm", &binary));
        assert_eq!(binary.pixels, [[0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0]]);
        let srgb = decode_file(&write("e.pgm", b"P2 1 1 255\n188\n"), IntegerDecode::Srgb).unwrap();
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
            let message = decode_file(&path, IntegerDecode::Srgb)
                .unwrap_err()
                .to_string();
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
}
