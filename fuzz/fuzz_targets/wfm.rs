//! CANDIDE `.wfm` reader: any bytes must give a model or a located error, never a panic, hang
//! or unbounded allocation; a model that reads must give a valid mesh and accept its own units.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(model) = fbakit::candide::parse_wfm(text, Path::new("fuzz.wfm")) else {
        return;
    };
    assert!(model.to_mesh().validate().is_valid());
    let names: Vec<(String, f32)> = model.shape_units.iter().map(|u| (u.name.clone(), 0.5)).collect();
    model.with_shape(&names).expect("own shape units apply");
});
