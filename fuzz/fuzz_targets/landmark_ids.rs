//! Landmark id lists (ICT `vertex_indices.json`, JSON arrays, CSV or text lists): any text
//! must give ids or a located error; the ids' checks must not panic either.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(ids) = fbakit::fdp::landmarks::parse_landmark_ids(text, Path::new("fuzz.json")) {
        let _ = ids.check(68, 1000, "iBUG-68 landmarks");
        let _ = ids.check(468, 468, "MediaPipe landmarks");
    }
});
