#![no_main]
//! Any text must parse or fail with an error; a successful parse must survive the format's
//! own round trip where it has a writer.

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let parsed = fbakit::fdp::csv::parse_csv(text, Path::new("f.csv"));
    if let Ok(table) = parsed {
        let text2 = fbakit::fdp::csv::to_csv_string(&table).expect("CSV writes");
        let back = fbakit::fdp::csv::parse_csv(&text2, Path::new("w.csv"))
            .expect("written CSV must read back");
        assert_eq!(back, table);
    }
    // The format-detecting entry point must not panic either.
    let _ = fbakit::fdp::parse_feature_points(text, Path::new("f.csv"));
});
