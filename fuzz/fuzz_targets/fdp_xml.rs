#![no_main]
//! Any text must parse or fail with an error; a successful parse must survive the format's
//! own round trip where it has a writer.

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let parsed = fbakit::fdp::xml::parse_xml(text, Path::new("f.xml"));
    if let Ok(doc) = parsed {
        let text2 = fbakit::fdp::xml::to_xml_string(&doc);
        let back = fbakit::fdp::xml::parse_xml(&text2, Path::new("w.xml"))
            .expect("written XML must read back");
        assert_eq!(back, doc);
    }
    // The format-detecting entry point must not panic either.
    let _ = fbakit::fdp::parse_feature_points(text, Path::new("f.xml"));
});
