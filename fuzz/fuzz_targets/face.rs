//! The face front door (`face::read_bytes`): the first byte picks the file name (and so the
//! format the extension suggests: VRML, gzip VRML, OBJ, glTF binary), the rest is the
//! content. Any bytes must give a face or an error, never a panic or an unbounded allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

/// The names the first byte picks from (the seed corpus and the replay test use them too).
const NAMES: [&str; 4] = ["x.wrl", "x.wrl.gz", "x.obj", "x.glb"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, content)) = data.split_first() else {
        return;
    };
    let name = NAMES[usize::from(pick) % NAMES.len()];
    let _ = fbakit::face::read_bytes(content, name, &fbakit::face::FaceReadOptions::default());
});
