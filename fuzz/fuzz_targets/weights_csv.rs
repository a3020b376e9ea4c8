//! ARKit weight CSVs (Live Link Face and plain): any text must give weights or a located
//! error, with and without a frame rate given.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("fuzz.csv");
    let _ = fbakit::rig::weights_csv::parse_weights_csv(text, file, None);
    let _ = fbakit::rig::weights_csv::parse_weights_csv(text, file, Some(30.0));
});
