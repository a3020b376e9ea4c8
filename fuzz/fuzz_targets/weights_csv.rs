//! Capture files through their one front door (`rig::capture::parse_capture`): Live Link Face
//! and plain weight CSVs, MediaPipe CSV and JSON lines. Any text must give weights or a
//! located error, with and without a frame rate given.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("fuzz.csv");
    let _ = fbakit::rig::capture::parse_capture(text, file, None);
    let _ = fbakit::rig::capture::parse_capture(text, file, Some(30.0));
});
