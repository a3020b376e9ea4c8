//! Strict and lenient `.fap` reading of arbitrary text must never panic; whatever reads
//! strictly must write and read back to an equal model, and lenient models must survive a
//! write → lenient read round trip too.
#![no_main]

use std::path::Path;

use fbakit::fap::{parse_fap, validate_fap_str, write_fap_string, ReadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let p = Path::new("fuzz.fap");
    if let Ok((s, _)) = parse_fap(text, p, &ReadOptions::strict()) {
        let out = write_fap_string(&s);
        let (back, w) = parse_fap(&out, p, &ReadOptions::strict())
            .expect("canonical output of a strict stream reads strictly");
        assert!(w.is_empty());
        assert_eq!(back, s);
        assert!(validate_fap_str(text, p).is_empty(), "strict-valid text has no findings");
    }
    if let Ok((s, _)) = parse_fap(text, p, &ReadOptions::lenient()) {
        let out = write_fap_string(&s);
        let (back, _) = parse_fap(&out, p, &ReadOptions::lenient())
            .expect("canonical output of a lenient stream reads leniently");
        assert_eq!(back, s);
    }
    let _ = validate_fap_str(text, p);
});
