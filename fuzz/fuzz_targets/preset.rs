//! Preset files: arbitrary bytes through the UTF-8 check and the RON parser,
//! the path resolution and the scene's sanitising, as `preset::load` does.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = marbre_core::preset::parse_bytes(data, Path::new("/fuzz/presets/input.ron"));
});
