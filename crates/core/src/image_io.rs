//! Writing rendered images, atomically.
//!
//! A render's output is checked before any rendering (`check_output`): its
//! folder must exist (a typo in a path is named rather than made into
//! folders, and a path through a file names the file), and a file must be
//! writable there (not a folder, not read-only, not on a read-only
//! filesystem).

use crate::atomic_write::{check_writable, write_atomic};
use anyhow::{Context, Result, bail};
use std::io::ErrorKind;
use std::path::Path;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Tone-mapped 8-bit sRGB.
    Png,
    /// Linear radiance, 32-bit float RGBA.
    Exr,
}

impl ImageFormat {
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ => bail!("{}: the output must end in .png or .exr", path.display()),
        }
    }
}

/// Fails unless a file can be written at `path`, naming the cause: the
/// path component that is a file, the topmost folder missing, or why the
/// file itself cannot be written. A bare name (the working folder) is
/// checked too: only its folders need no walk.
pub fn check_output(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        check_output_folders(path, dir)?;
    }
    check_writable(path).map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))
}

/// The folders `path` (in `dir`) needs: none of them a file, the topmost
/// missing one named.
fn check_output_folders(path: &Path, dir: &Path) -> Result<()> {
    let mut missing = None;
    for folder in dir.ancestors().take_while(|d| !d.as_os_str().is_empty()) {
        match std::fs::metadata(folder) {
            Ok(m) if m.is_dir() => break,
            Ok(_) => bail!(
                "cannot write {}: {} is a file, not a folder",
                path.display(),
                folder.display()
            ),
            // Not a directory: a component above is a file, found further up.
            Err(e) if matches!(e.kind(), ErrorKind::NotFound | ErrorKind::NotADirectory) => {
                missing = Some(folder);
            }
            Err(e) => bail!("cannot write {}: {}: {e}", path.display(), folder.display()),
        }
    }
    if let Some(folder) = missing {
        bail!(
            "cannot write {}: the folder {} does not exist",
            path.display(),
            folder.display()
        );
    }
    Ok(())
}

pub fn save_png(image: &image::RgbaImage, path: &Path) -> Result<()> {
    write_atomic(path, &encode_png(image)?)?;
    Ok(())
}

/// The PNG file of `image`.
pub fn encode_png(image: &image::RgbaImage) -> Result<Vec<u8>> {
    encode_png_with_text(image, None)
}

/// Writes [`encode_png_with_text`]'s file atomically.
pub fn save_png_with_text(
    image: &image::RgbaImage,
    text: Option<(&str, &str)>,
    path: &Path,
) -> Result<()> {
    write_atomic(path, &encode_png_with_text(image, text)?)?;
    Ok(())
}

/// The PNG file of `image` with one text chunk (keyword, text), such as a
/// render's record: an `iTXt` chunk, which holds any Unicode text (`tEXt`
/// holds Latin-1 only). Written by the png crate, which the image crate's
/// encoder wraps without a way to add chunks.
pub fn encode_png_with_text(
    image: &image::RgbaImage,
    text: Option<(&str, &str)>,
) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, image.width(), image.height());
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    // The image crate's defaults, so that a PNG without text is the bytes
    // it always was.
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Adaptive);
    if let Some((keyword, value)) = text {
        encoder.add_itxt_chunk(keyword.to_owned(), value.to_owned())?;
    }
    let mut writer = encoder.write_header()?;
    writer.write_image_data(image.as_raw())?;
    writer.finish()?;
    Ok(bytes)
}

/// The text chunks of a PNG file (`tEXt`, `zTXt` and `iTXt`), by keyword:
/// where a render's record is. Only the chunks before the pixels are read.
pub fn read_png_text(path: &Path) -> Result<std::collections::BTreeMap<String, String>> {
    let bytes = crate::capped_read::read_capped(path, crate::capped_read::IMAGE)
        .with_context(|| format!("reading {}", path.display()))?;
    let reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .map_err(|e| anyhow::anyhow!("{}: not a readable PNG file ({e})", path.display()))?;
    let info = reader.info();
    let mut text = std::collections::BTreeMap::new();
    for chunk in &info.uncompressed_latin1_text {
        text.insert(chunk.keyword.clone(), chunk.text.clone());
    }
    for chunk in &info.compressed_latin1_text {
        if let Ok(value) = chunk.get_text() {
            text.insert(chunk.keyword.clone(), value);
        }
    }
    for chunk in &info.utf8_text {
        if let Ok(value) = chunk.get_text() {
            text.insert(chunk.keyword.clone(), value);
        }
    }
    Ok(text)
}

/// Writes [`encode_exr`]'s file atomically.
pub fn save_exr(
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    text: Option<(&str, &str)>,
    path: &Path,
) -> Result<()> {
    write_atomic(path, &encode_exr(width, height, pixels, text)?)?;
    Ok(())
}

/// An extra layer of an EXR file beside its picture: a name and three
/// channels (`variance.R`, `.G`, `.B`), in a fixed order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LayerName {
    pub name: &'static str,
    pub channels: [&'static str; 3],
}

/// Each pixel's estimated variance of its mean (`render --moments`), so
/// that a merge of such files still knows its error.
pub const VARIANCE: LayerName = LayerName {
    name: "variance",
    channels: ["R", "G", "B"],
};
/// The first hit's albedo plus emission, averaged over the pixel's samples
/// (`render --guides`): a denoiser's guide, as Blender's and OIDN's.
pub const ALBEDO: LayerName = LayerName {
    name: "albedo",
    channels: ["R", "G", "B"],
};
/// The first hit's shading normal, averaged over the pixel's samples
/// (`render --guides`; not renormalised: a mean, as the other layers).
pub const NORMAL: LayerName = LayerName {
    name: "normal",
    channels: ["X", "Y", "Z"],
};

/// Writes [`encode_exr_layers`]'s file atomically.
pub fn save_exr_layers(
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    layers: &[(LayerName, &[[f32; 3]])],
    text: Option<(&str, &str)>,
    path: &Path,
) -> Result<()> {
    write_atomic(
        path,
        &encode_exr_layers(width, height, pixels, layers, text)?,
    )?;
    Ok(())
}

/// [`encode_exr`]'s file with more layers beside the picture (`R`, `G`, `B`,
/// `A`), each of three channels `name.channel`: readers that want the
/// picture read the unnamed layer, as compositors do. Without layers, the
/// bytes [`encode_exr`] writes.
pub fn encode_exr_layers(
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    layers: &[(LayerName, &[[f32; 3]])],
    text: Option<(&str, &str)>,
) -> Result<Vec<u8>> {
    use exr::prelude::*;
    if layers.is_empty() {
        return encode_exr(width, height, pixels, text);
    }
    let (w, h) = (width as usize, height as usize);
    let channel = |name: String, values: Vec<f32>| {
        AnyChannel::new(Text::new_or_panic(name), FlatSamples::F32(values))
    };
    let mut list = SmallVec::new();
    for (c, name) in ["R", "G", "B", "A"].iter().enumerate() {
        list.push(channel(
            (*name).to_owned(),
            pixels.iter().map(|p| p[c]).collect(),
        ));
    }
    for (layer, values) in layers {
        for (c, name) in layer.channels.iter().enumerate() {
            list.push(channel(
                format!("{}.{name}", layer.name),
                values.iter().map(|v| v[c]).collect(),
            ));
        }
    }
    let encoding = Encoding {
        line_order: LineOrder::Increasing,
        ..Encoding::FAST_LOSSLESS
    };
    let mut layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(list),
    );
    if let Some((name, value)) = text {
        let values: Vec<(String, &[f32])> = layer
            .channel_data
            .list
            .iter()
            .filter_map(|c| match &c.sample_data {
                FlatSamples::F32(v) => Some((c.name.to_string(), &v[..])),
                _ => None,
            })
            .collect();
        let named: Vec<(&str, &[f32])> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let (name, value) = header_text(name, value, &named);
        layer
            .attributes
            .other
            .insert(name, exr::meta::attribute::AttributeValue::Text(value));
    }
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer).write().to_buffered(&mut bytes)?;
    Ok(bytes.into_inner())
}

/// An EXR file's picture and layers as the file holds them: its first
/// valid part's channels, each by its full name (`R`, `variance.G`), the
/// values as written (no NaN replaced, nothing clamped: a merge averages
/// them as they are).
#[derive(Debug, Clone, PartialEq)]
pub struct ExrChannels {
    pub width: u32,
    pub height: u32,
    pub channels: Vec<(String, Vec<f32>)>,
}

impl ExrChannels {
    /// The values of the channel `name`, if the file has it.
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| &v[..])
    }

    /// The layer `layer` ([`encode_exr_layers`]), `None` where the file
    /// lacks one of its channels.
    pub fn layer(&self, layer: LayerName) -> Option<Vec<[f32; 3]>> {
        let [a, b, c] = layer
            .channels
            .map(|ch| self.channel(&format!("{}.{ch}", layer.name)));
        Some(
            a?.iter()
                .zip(b?)
                .zip(c?)
                .map(|((a, b), c)| [*a, *b, *c])
                .collect(),
        )
    }

    /// The channels by name, as [`crate::render_record::check_seal`] takes
    /// them.
    pub fn named(&self) -> Vec<(&str, &[f32])> {
        self.channels
            .iter()
            .map(|(n, v)| (n.as_str(), &v[..]))
            .collect()
    }
}

/// Every channel of an EXR file's first valid part ([`ExrChannels`]).
/// Its declared size is checked against [`crate::image_decode::MAX_TEXELS`]
/// and against what the file's bytes can hold
/// ([`crate::image_decode::check_exr_fits`]) before anything is
/// allocated, and the `exr` crate's panics on malformed files are caught.
pub fn read_exr_channels(path: &Path) -> Result<ExrChannels> {
    use exr::prelude::*;
    let bytes = crate::capped_read::read_capped(path, crate::capped_read::IMAGE)
        .with_context(|| format!("reading {}", path.display()))?;
    let unreadable = |e: &dyn std::fmt::Display| {
        anyhow::anyhow!(
            "{}: not a readable OpenEXR file ({})",
            path.display(),
            crate::image_decode::decode_message(&e.to_string())
        )
    };
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&bytes), false)
        .map_err(|e| unreadable(&e))?;
    for header in &meta.headers {
        let size = header.layer_size;
        let texels = (size.width() as u64).saturating_mul(size.height() as u64);
        if texels > crate::image_decode::MAX_TEXELS {
            bail!(
                "{}: the file declares {}x{} texels, more than the {} (16384x8192) marbre reads",
                path.display(),
                size.width(),
                size.height(),
                crate::image_decode::MAX_TEXELS
            );
        }
    }
    crate::image_decode::check_exr_fits(path, bytes.len(), &meta.headers)?;
    let image = std::panic::catch_unwind(|| {
        read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(&bytes))
    })
    .map_err(|_| unreadable(&"the OpenEXR reader failed on it"))?
    .map_err(|e| unreadable(&e))?;
    let size = image.layer_data.size;
    Ok(ExrChannels {
        width: size.width() as u32,
        height: size.height() as u32,
        channels: image
            .layer_data
            .channel_data
            .list
            .iter()
            .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
            .collect(),
    })
}

/// `s` as EXR text can hold it: its characters beyond Latin-1 written as
/// `?`.
fn latin1(s: &str) -> String {
    s.chars()
        .map(|c| if u32::from(c) < 256 { c } else { '?' })
        .collect()
}

/// A header text attribute as a file holds it: in Latin-1, and a render's
/// record sealed with the file's `channels`
/// ([`crate::render_record::sealed`]), so that a merge finds a record
/// changed after the render.
fn header_text(
    name: &str,
    value: &str,
    channels: &[(&str, &[f32])],
) -> (exr::meta::attribute::Text, exr::meta::attribute::Text) {
    let mut value = latin1(value);
    if name == crate::render_record::RECORD_ATTRIBUTE {
        value = crate::render_record::sealed(&value, channels);
    }
    let text = exr::meta::attribute::Text::new_or_panic;
    (text(latin1(name)), text(value))
}

/// The text attributes of an EXR file's header (its first part's and
/// those shared by all parts), by name: where a render's record is
/// (`render_record`). Only the header is read.
pub fn read_exr_attributes(path: &Path) -> Result<std::collections::BTreeMap<String, String>> {
    use exr::meta::attribute::AttributeValue;
    let bytes = crate::capped_read::read_capped(path, crate::capped_read::IMAGE)
        .with_context(|| format!("reading {}", path.display()))?;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| anyhow::anyhow!("{}: not a readable OpenEXR file ({e})", path.display()))?;
    let mut attributes = std::collections::BTreeMap::new();
    if let Some(header) = meta.headers.first() {
        let all = header
            .shared_attributes
            .other
            .iter()
            .chain(&header.own_attributes.other);
        for (name, value) in all {
            if let AttributeValue::Text(text) = value {
                attributes.insert(name.to_string(), text.to_string());
            }
        }
    }
    Ok(attributes)
}

/// The EXR file (32-bit float RGBA) of `pixels`, row 0 at the top: the
/// same pixels always give the same bytes.
///
/// `exr` compresses the blocks (64 × 64 tiles) on a thread pool, and with
/// its default line order, `Unspecified`, writes each one as soon as it is
/// compressed: the tiles' order in the file, and so the file's bytes,
/// varied from run to run with the threads' timing (often in debug builds,
/// where compression is slower), though the pixels were the same. An
/// increasing line order makes it write them in order.
///
/// `text`: one text attribute (name, value) for the header, such as a
/// render's record, its characters beyond Latin-1 (which EXR text cannot
/// hold) written as `?`. One: `exr` keeps a header's attributes in a
/// `HashMap`, whose order, and so the file's bytes, would vary from run
/// to run with two.
pub fn encode_exr(
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    text: Option<(&str, &str)>,
) -> Result<Vec<u8>> {
    use exr::prelude::*;
    let (w, h) = (width as usize, height as usize);
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let p = pixels[y * w + x];
        (p[0], p[1], p[2], p[3])
    });
    let encoding = Encoding {
        line_order: LineOrder::Increasing,
        ..Encoding::FAST_LOSSLESS
    };
    let mut image = Image::from_encoded_channels((w, h), encoding, channels);
    if let Some((name, value)) = text {
        let values: Vec<Vec<f32>> = (0..4)
            .map(|c| pixels.iter().map(|p| p[c]).collect())
            .collect();
        let named: Vec<(&str, &[f32])> = ["R", "G", "B", "A"]
            .into_iter()
            .zip(values.iter().map(Vec::as_slice))
            .collect();
        let (name, value) = header_text(name, value, &named);
        image
            .layer_data
            .attributes
            .other
            .insert(name, exr::meta::attribute::AttributeValue::Text(value));
    }
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut bytes)?;
    Ok(bytes.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A text attribute written in an EXR's header reads back by name;
    /// a character EXR text cannot hold is written as `?`; the same
    /// file is the same bytes.
    #[test]
    fn an_exr_text_attribute_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let text = Some(("marbre:note", "spp=16\nadapter=GPU ✓ é"));
        save_exr(2, 1, &[[0.5; 4]; 2], text, &path).unwrap();
        let read = read_exr_attributes(&path).unwrap();
        assert_eq!(
            read.get("marbre:note").map(String::as_str),
            Some("spp=16\nadapter=GPU ? é")
        );
        let bytes = std::fs::read(&path).unwrap();
        save_exr(2, 1, &[[0.5; 4]; 2], text, &path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), bytes);
    }

    /// Layers read back beside the picture, which still decodes as the
    /// file's RGBA; a layer the file lacks reads as none.
    #[test]
    fn exr_layers_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.exr");
        let pixels = [[0.5, 1.0, 2.0, 1.0], [3.0, 4.0, 5.0, 1.0]];
        let variance = [[0.01, 0.02, 0.03], [0.04, 0.05, 0.06]];
        let normal = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]];
        let layers = [(VARIANCE, &variance[..]), (NORMAL, &normal[..])];
        save_exr_layers(2, 1, &pixels, &layers, Some(("k", "v")), &path).unwrap();
        let read = read_exr_channels(&path).unwrap();
        assert_eq!(
            [VARIANCE, ALBEDO, NORMAL].map(|l| read.layer(l)),
            [Some(variance.to_vec()), None, Some(normal.to_vec())]
        );
        assert_eq!((read.width, read.height), (2, 1));
        let decoded =
            crate::image_decode::decode_file(&path, crate::image_decode::IntegerDecode::Linear)
                .unwrap();
        assert_eq!(decoded.pixels, pixels.to_vec());
        assert_eq!(read_exr_attributes(&path).unwrap()["k"], "v");
        let plain = dir.path().join("p.exr");
        save_exr(2, 1, &pixels, None, &plain).unwrap();
        assert_eq!(read_exr_channels(&plain).unwrap().layer(VARIANCE), None);
    }

    /// A render's record is written sealed with the file's channels, with
    /// layers or without: the file as written checks; its `spp` patched
    /// in place (the probe's edit) does not. Another text is kept as is.
    #[test]
    fn a_render_record_is_sealed_with_the_pixels() {
        use crate::render_record::{RECORD_ATTRIBUTE, check_seal};
        let dir = tempfile::tempdir().unwrap();
        let pixels = [[0.5, 1.0, 2.0, 1.0], [3.0, f32::INFINITY, 5.0, 1.0]];
        let variance = [[0.01, 0.02, 0.03], [0.04, 0.05, 0.06]];
        let record = Some((RECORD_ATTRIBUTE, "spp=4\nscene=x\n"));
        for layers in [&[][..], &[(VARIANCE, &variance[..])][..]] {
            let path = dir.path().join("r.exr");
            save_exr_layers(2, 1, &pixels, layers, record, &path).unwrap();
            let text = |path: &Path| read_exr_attributes(path).unwrap()[RECORD_ATTRIBUTE].clone();
            let read = read_exr_channels(&path).unwrap();
            assert!(text(&path).starts_with("spp=4\nscene=x\nseal="));
            assert_eq!(check_seal(&text(&path), &read.named()), Ok(true));
            let bytes = std::fs::read(&path).unwrap();
            let at = bytes.windows(5).position(|w| w == b"spp=4").unwrap();
            let mut edited = bytes.clone();
            edited[at + 4] = b'8';
            std::fs::write(&path, edited).unwrap();
            let read = read_exr_channels(&path).unwrap();
            assert!(check_seal(&text(&path), &read.named()).is_err());
        }
        let path = dir.path().join("k.exr");
        save_exr(2, 1, &pixels, Some(("k", "v")), &path).unwrap();
        assert_eq!(read_exr_attributes(&path).unwrap()["k"], "v");
    }

    /// The probe's lying header (a small file claiming 16384×8192) is
    /// refused by the merge's reader from its size, naming the file,
    /// before its channels are allocated (it cost 2.1 GB).
    #[test]
    fn an_exr_claiming_more_than_its_bytes_is_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lying.exr");
        let small =
            encode_exr_layers(2, 1, &[[1.0; 4]; 2], &[(VARIANCE, &[[0.0; 3]; 2])], None).unwrap();
        let lying = crate::image_decode::test_support::exr_claiming(&small, 16384, 8192);
        std::fs::write(&path, &lying).unwrap();
        let e = read_exr_channels(&path).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: ", path.display()))
                && e.contains("declares 16384x8192 texels")
                && e.contains(&format!("it is {} bytes", lying.len())),
            "{e}"
        );
    }

    /// A PNG's text chunk reads back by keyword, any character included,
    /// and the pixels are the image's.
    #[test]
    fn a_png_text_chunk_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let image = image::RgbaImage::from_raw(2, 1, vec![1, 2, 3, 255, 4, 5, 6, 128]).unwrap();
        save_png_with_text(
            &image,
            Some(("marbre:render", "spp=16\nadapter=GPU ✓")),
            &path,
        )
        .unwrap();
        let text = read_png_text(&path).unwrap();
        assert_eq!(
            text.get("marbre:render").map(String::as_str),
            Some("spp=16\nadapter=GPU ✓")
        );
        let decoded = image::open(&path).unwrap().to_rgba8();
        assert_eq!(decoded, image);
        let mut by_image = Vec::new();
        image
            .write_to(
                &mut std::io::Cursor::new(&mut by_image),
                image::ImageFormat::Png,
            )
            .unwrap();
        assert!(
            encode_png(&image).unwrap() == by_image,
            "no text: the image crate's bytes"
        );
    }

    /// Many tiles of different content, so that they take different times
    /// to compress: encoded again and again, the bytes never change, and
    /// the tiles are in the file in order.
    #[test]
    fn an_exr_is_the_same_bytes_every_time() {
        let (w, h) = (300u32, 200u32);
        let pixels: Vec<[f32; 4]> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                // Smooth on the left (long RLE runs), noisy on the right.
                let v = if x < 128 {
                    (y / 8) as f32
                } else {
                    (i.wrapping_mul(2_654_435_761) >> 20) as f32
                };
                [v, v * 0.5, 1.0 / (1.0 + v), 1.0]
            })
            .collect();
        let first = encode_exr(w, h, &pixels, None).unwrap();
        for _ in 0..10 {
            assert!(encode_exr(w, h, &pixels, None).unwrap() == first);
        }
        let meta =
            exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&first), false).unwrap();
        assert_eq!(
            meta.headers[0].line_order,
            exr::meta::attribute::LineOrder::Increasing
        );
        let decoded = crate::image_decode::decode_bytes(
            &first,
            Path::new("x.exr"),
            crate::image_decode::IntegerDecode::Linear,
        )
        .unwrap();
        assert!(decoded.pixels == pixels);
    }

    #[test]
    fn a_missing_folder_is_named_and_not_made() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("renders/today/x.png");
        assert_eq!(
            check_output(&out).unwrap_err().to_string(),
            format!(
                "cannot write {}: the folder {} does not exist",
                out.display(),
                dir.path().join("renders").display()
            )
        );
        assert!(!dir.path().join("renders").exists());
        std::fs::create_dir_all(dir.path().join("renders/today")).unwrap();
        check_output(&out).unwrap();
    }

    #[test]
    fn a_file_in_the_path_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("notes.txt");
        std::fs::write(&file, "not a folder").unwrap();
        for out in [file.join("x.png"), file.join("a/b/x.exr")] {
            assert_eq!(
                check_output(&out).unwrap_err().to_string(),
                format!(
                    "cannot write {}: {} is a file, not a folder",
                    out.display(),
                    file.display()
                )
            );
        }
    }

    /// An output that is a folder, or a read-only file, is refused before
    /// a render (which used to trace fully, then fail or replace it).
    #[test]
    fn a_folder_or_a_read_only_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("out.png");
        std::fs::create_dir(&folder).unwrap();
        assert_eq!(
            check_output(&folder).unwrap_err().to_string(),
            format!("cannot write {}: it is a folder", folder.display())
        );
        let kept = dir.path().join("kept.exr");
        crate::atomic_write::test_support::read_only_file(&kept, b"old");
        assert!(
            check_output(&kept)
                .unwrap_err()
                .to_string()
                .contains("read-only")
        );
    }

    #[test]
    fn a_bare_file_name_goes_in_the_current_folder() {
        check_output(Path::new("x.png")).unwrap();
    }
}
