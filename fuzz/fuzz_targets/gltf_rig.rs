//! The glTF rig reader: any bytes (a `.glb` or `.gltf` JSON) must give a rig or an error.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = fbakit::rig::gltf_read::read_gltf_bytes(data, Path::new("fuzz.glb"));
});
