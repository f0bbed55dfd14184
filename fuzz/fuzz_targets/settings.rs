//! The viewer's `settings.ron`, through `viewer_files::Settings::parse`,
//! the reader `Settings::load` uses; settings read must write back
//! (`Settings::to_text`, what `Settings::save` writes) to a text that
//! reads to the same settings, or the next start would lose them. Bytes
//! that are not UTF-8 are skipped: the viewer refuses them when it reads
//! the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marbre_core::viewer_files::{MAX_RECENT_FILES, Settings};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(settings) = Settings::parse(text) {
        assert!(settings.recent_files.len() <= MAX_RECENT_FILES);
        let written = settings.to_text().expect("settings read can be written");
        assert_eq!(Settings::parse(&written), Ok(settings), "{written}");
    }
});
