#![no_main]
//! Any text must parse or fail with an error; a successful parse must survive the format's
//! own round trip.
//!
//! The text goes through the format-detecting front door only once: building a `csv`
//! reader is most of an execution under coverage instrumentation, so parsing the same
//! bytes twice (directly and through the front door) halved the rate.

use fbakit::fdp::file::FormatExtras;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(file) = fbakit::fdp::parse_feature_points(text, Path::new("f.csv")) else {
        return;
    };
    if let FormatExtras::Csv(table) = file.extras {
        let text2 = fbakit::fdp::csv::to_csv_string(&table).expect("CSV writes");
        let back = fbakit::fdp::csv::parse_csv(&text2, Path::new("w.csv"))
            .expect("written CSV must read back");
        assert_eq!(back, table);
    }
});
