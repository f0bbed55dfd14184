//! `gallery.ron`, the index `marbre tx --gallery` reads from a folder of TX
//! examples, through `tx_preview::parse_gallery`. Bytes that are not UTF-8
//! are skipped: the command refuses them when it reads the file.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = marbre_core::tx_preview::parse_gallery(text);
    }
});
