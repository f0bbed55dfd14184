//! TX texts, down the path of `marbre tx` short of rendering: `tx::parse`,
//! the printer of `--print` (whose text must parse back to the same
//! document), `tx_preview::preview_scene` lowering the text onto the
//! preview's material, and the scene's sanitising; then the reader of TX
//! text written in a preset in place of a property
//! (`tx::read_preset_property`), for every coefficient. Bytes that are not
//! UTF-8 are skipped: the command refuses them when it reads the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marbre_core::{tx, tx_preview};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(doc) = tx::parse(text) {
        let printed = tx::print(&doc);
        assert_eq!(tx::parse(&printed), Ok(doc.clone()), "{printed}");
        if let Ok(mut scene) = tx_preview::preview_scene(&doc, Path::new("/fuzz/tx")) {
            scene.sanitize();
        }
    }
    for channel in tx::Channel::ALL {
        let _ = tx::read_preset_property(channel.name(), text);
    }
});
