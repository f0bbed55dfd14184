//! The info files beside the viewer's autosaved scenes, through
//! `viewer_files::RecoveryInfo::parse`, the reader the recovery offer
//! uses; an info read must write back (`RecoveryInfo::to_text`, what the
//! autosave writes) to a text that reads to the same info. Bytes that are
//! not UTF-8 are skipped: the viewer refuses them when it reads the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marbre_core::viewer_files::RecoveryInfo;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(info) = RecoveryInfo::parse(text) {
        let written = info.to_text().expect("an info read can be written");
        assert_eq!(RecoveryInfo::parse(&written), Ok(info), "{written}");
    }
});
