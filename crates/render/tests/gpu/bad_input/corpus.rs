//! Writes the binary files of the bad-input corpus, `tests/data/bad/`
//! (its README.md lists them). The text files (presets, OBJ, MTL) are
//! written by hand. Regenerate with
//! `cargo test --test bad_input -- --ignored regenerate_the_binary_corpus`.

use exr::prelude::*;
use std::path::Path;

/// The colour of the `diffuse` layer and of the `beauty` part: what the
/// loader must pick out of the multi-layer and multi-part files.
pub const PICKED: [f32; 3] = [0.25, 0.5, 0.75];
/// Every other channel of those files: what it must not pick.
pub const DECOY: f32 = 9.0;
/// The luminance of `luminance_only.exr`.
pub const LUMINANCE: f32 = 0.375;
/// The 16-bit code of `rgb16.png`: half of 65535, rounded up.
pub const CODE16: u16 = 32768;
/// The 8-bit code of `grey.png`.
pub const GREY8: u8 = 100;
/// The declared side of `huge_header.png` and `huge_header.exr`, far beyond
/// `image_decode::MAX_TEXELS`.
pub const HUGE_SIDE: u32 = 100_000;

pub fn write_all(bad: &Path) {
    write_images(&bad.join("images"));
    write_exr(&bad.join("exr"));
    write_envmaps(&bad.join("envmaps"));
}

/// Deterministic noise codes, so that the encoders cannot shrink the files
/// to nothing and a cut really loses pixels.
fn noise(n: usize) -> Vec<u8> {
    let mut state = 0x2545_f491_u32;
    (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 24) as u8
        })
        .collect()
}

fn write_images(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let rgb = image::RgbImage::from_raw(16, 16, noise(16 * 16 * 3)).unwrap();
    let mut png = Vec::new();
    rgb.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    std::fs::write(dir.join("truncated.png"), &png[..png.len() / 2]).unwrap();
    let mut jpg = Vec::new();
    rgb.write_to(
        &mut std::io::Cursor::new(&mut jpg),
        image::ImageFormat::Jpeg,
    )
    .unwrap();
    std::fs::write(dir.join("truncated.jpg"), &jpg[..jpg.len() / 2]).unwrap();

    std::fs::write(dir.join("empty_0x0.png"), png_with_header(0, 0)).unwrap();
    std::fs::write(
        dir.join("huge_header.png"),
        png_with_header(HUGE_SIDE, HUGE_SIDE),
    )
    .unwrap();

    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(2, 2, vec![CODE16; 2 * 2 * 3])
        .unwrap()
        .save_with_format(dir.join("rgb16.png"), image::ImageFormat::Png)
        .unwrap();
    image::GrayImage::from_pixel(2, 2, image::Luma([GREY8]))
        .save_with_format(dir.join("grey.png"), image::ImageFormat::Png)
        .unwrap();
}

/// A PNG whose header declares `width` × `height` RGB texels and whose data
/// is empty: what a broken writer or a hostile file leaves. The `image`
/// crate will not write such a file, so it is put together by hand.
fn png_with_header(width: u32, height: u32) -> Vec<u8> {
    let mut ihdr = Vec::new();
    ihdr.extend(width.to_be_bytes());
    ihdr.extend(height.to_be_bytes());
    // 8 bits, RGB, deflate, adaptive filtering, no interlace.
    ihdr.extend([8, 2, 0, 0, 0]);
    // A zlib stream of no bytes.
    let idat = [0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01];
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [(b"IHDR", &ihdr[..]), (b"IDAT", &idat[..]), (b"IEND", &[])] {
        png.extend((data.len() as u32).to_be_bytes());
        let start = png.len();
        png.extend(kind);
        png.extend(data);
        let crc = crc32(&png[start..]);
        png.extend(crc.to_be_bytes());
    }
    png
}

/// The CRC-32 of PNG chunks (ISO 3309, reflected, polynomial 0xEDB88320).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A one-part EXR of `width` × `height` f32 channels, each `(name, value)`
/// constant.
fn exr_layer(
    name: &str,
    width: usize,
    height: usize,
    compression: Compression,
    channels: &[(&str, f32)],
) -> Layer<AnyChannels<FlatSamples>> {
    let list = channels
        .iter()
        .map(|&(channel, value)| {
            AnyChannel::new(channel, FlatSamples::F32(vec![value; width * height]))
        })
        .collect();
    Layer::new(
        (width, height),
        LayerAttributes::named(name),
        Encoding {
            compression,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        AnyChannels::sort(list),
    )
}

fn write_layer(path: &Path, layer: Layer<AnyChannels<FlatSamples>>) {
    Image::from_layer(layer).write().to_file(path).unwrap();
}

/// Sets the value of the `compression` attribute of an EXR file.
fn set_compression(bytes: &mut [u8], code: u8) {
    // Name, type name, 4-byte size (1), then the value byte.
    let attribute = b"compression\0compression\0\x01\0\0\0";
    let at = bytes
        .windows(attribute.len())
        .position(|w| w == attribute)
        .expect("a compression attribute")
        + attribute.len();
    bytes[at] = code;
}

/// Sets the value of the `box2i` attribute `name` of an EXR file:
/// x min, y min, x max, y max.
fn set_box(bytes: &mut [u8], name: &str, value: [i32; 4]) {
    let attribute = [name.as_bytes(), b"\0box2i\0\x10\0\0\0"].concat();
    let at = bytes
        .windows(attribute.len())
        .position(|w| w == attribute)
        .expect("a box2i attribute")
        + attribute.len();
    for (i, v) in value.iter().enumerate() {
        bytes[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
}

fn write_exr(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let [r, g, b] = PICKED;

    // Noise, uncompressed, so that a cut loses pixel rows.
    let codes = noise(16 * 16);
    let noisy = |c: usize| {
        AnyChannel::new(
            ["B", "G", "R"][c],
            FlatSamples::F16(
                codes
                    .iter()
                    .map(|&v| f16::from_f32(f32::from(v) / 64.0 + c as f32))
                    .collect(),
            ),
        )
    };
    let layer = Layer::new(
        (16, 16),
        LayerAttributes::named("noise"),
        Encoding::UNCOMPRESSED,
        AnyChannels::sort((0..3).map(noisy).collect()),
    );
    let path = dir.join("truncated.exr");
    write_layer(&path, layer);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() * 6 / 10]).unwrap();

    // DWAA written by the `exr` crate, which reads and writes it.
    let ramp = Layer::new(
        (64, 32),
        LayerAttributes::named("ramp"),
        Encoding {
            compression: Compression::DWAA(None),
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        SpecificChannels::rgb(|p: Vec2<usize>| {
            let v = f16::from_f32(0.5 + p.x() as f32 / 64.0 + p.y() as f32 / 16.0);
            (v, v, v)
        }),
    );
    Image::from_layer(ramp)
        .write()
        .to_file(dir.join("dwaa.exr"))
        .unwrap();

    // One ZIP scan line, then the compression attribute set by hand to DWAB
    // (9: the ZIP data is no DWAB data) and HTJ2K (10: a compression the
    // `exr` crate does not implement).
    let one_line = dir.join("one_line.exr");
    write_layer(
        &one_line,
        exr_layer(
            "line",
            8,
            1,
            Compression::ZIP1,
            &[("R", r), ("G", g), ("B", b)],
        ),
    );
    let zip = std::fs::read(&one_line).unwrap();
    std::fs::remove_file(&one_line).unwrap();
    for (name, code) in [("dwab_bad_data.exr", 9), ("htj2k.exr", 10)] {
        let mut bytes = zip.clone();
        set_compression(&mut bytes, code);
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    // The same line, its windows set to HUGE_SIDE × HUGE_SIDE.
    let mut bytes = zip;
    let last = HUGE_SIDE as i32 - 1;
    for window in ["dataWindow", "displayWindow"] {
        set_box(&mut bytes, window, [0, 0, last, last]);
    }
    std::fs::write(dir.join("huge_header.exr"), bytes).unwrap();

    // A depth part before the colour part.
    let depth = exr_layer("depth", 4, 2, Compression::ZIP1, &[("Z", DECOY)]);
    let beauty = exr_layer(
        "beauty",
        4,
        2,
        Compression::ZIP1,
        &[("R", r), ("G", g), ("B", b), ("A", 1.0)],
    );
    Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((4, 2))),
        vec![depth, beauty],
    )
    .write()
    .to_file(dir.join("multi_part.exr"))
    .unwrap();

    // Layers by channel-name prefix in one part: depth, diffuse, specular.
    write_layer(
        &dir.join("multi_layer.exr"),
        exr_layer(
            "render",
            4,
            2,
            Compression::ZIP1,
            &[
                ("depth.Z", DECOY),
                ("diffuse.R", r),
                ("diffuse.G", g),
                ("diffuse.B", b),
                ("specular.R", DECOY),
                ("specular.G", DECOY),
                ("specular.B", DECOY),
            ],
        ),
    );
    write_layer(
        &dir.join("luminance_only.exr"),
        exr_layer("grey", 4, 2, Compression::ZIP1, &[("Y", LUMINANCE)]),
    );
    write_layer(
        &dir.join("lowercase_rgb.exr"),
        exr_layer(
            "lower",
            4,
            2,
            Compression::ZIP1,
            &[("r", r), ("g", g), ("b", b)],
        ),
    );
    write_layer(
        &dir.join("no_colour.exr"),
        exr_layer(
            "aux",
            4,
            2,
            Compression::ZIP1,
            &[("Z", DECOY), ("N.x", DECOY)],
        ),
    );
}

fn write_envmaps(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    // Row 0 holds the non-finite values, row 1 is clean.
    exr::prelude::write_rgb_file(dir.join("nan_inf.exr"), 4, 2, |x, y| match (x, y) {
        (0, 0) => (f32::NAN, 1.0, 1.0),
        (1, 0) => (f32::INFINITY, f32::NEG_INFINITY, 1.0),
        (2, 0) => (f32::NAN, f32::NAN, f32::INFINITY),
        _ => (0.5, 0.5, 0.5),
    })
    .unwrap();
    let sky = image::Rgb32FImage::from_pixel(16, 8, image::Rgb([0.5, 0.75, 1.0]));
    let mut hdr = Vec::new();
    image::DynamicImage::ImageRgb32F(sky)
        .write_to(&mut std::io::Cursor::new(&mut hdr), image::ImageFormat::Hdr)
        .unwrap();
    std::fs::write(dir.join("truncated.hdr"), &hdr[..hdr.len() / 2]).unwrap();
}
