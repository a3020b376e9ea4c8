#![no_main]
//! Any text must parse or fail with an error; a successful parse must survive the format's
//! own round trip where it has a writer.

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let parsed = fbakit::fdp::xface::parse_xface(text, Path::new("f.fdp"));
    if let Ok(f) = parsed {
        let _ = f.to_set();
    }
    // The format-detecting entry point must not panic either.
    let _ = fbakit::fdp::parse_feature_points(text, Path::new("f.fdp"));
});
