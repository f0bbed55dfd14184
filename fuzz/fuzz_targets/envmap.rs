//! Environment maps: the first byte picks the file type (its low seven bits
//! index `SUPPORTED_EXTENSIONS`, modulo its length) and, by its top bit, how
//! 8- and 16-bit codes decode; the rest is the file. Decoded through
//! `image_decode::decode_bytes`, the decoder every map and image texture
//! loads through, then the importance-sampling table the renderer builds
//! from every map, and one sample drawn from it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::EnvLoad;
use marbre_core::image_decode::{IntegerDecode, SUPPORTED_EXTENSIONS, decode_bytes};
use std::path::PathBuf;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, file)) = data.split_first() else {
        return;
    };
    let extension = SUPPORTED_EXTENSIONS[usize::from(selector & 0x7f) % SUPPORTED_EXTENSIONS.len()];
    let decode = if selector & 0x80 == 0 {
        IntegerDecode::Srgb
    } else {
        IntegerDecode::Linear
    };
    let path = PathBuf::from(format!("/fuzz/envmaps/input.{extension}"));
    if let Ok(decoded) = decode_bytes(file, &path, decode) {
        let distribution = EnvDistribution::new(&EnvLoad::from(decoded).image);
        let (t, _) = distribution.sample(0.5, 0.5);
        distribution.pdf_texel_uv(t);
    }
});
