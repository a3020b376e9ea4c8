//! OBJ reader: any bytes must give a model or a located error, never a panic; whatever reads
//! must write and read back equal.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok((scene, _)) = fbakit::mesh::obj::parse_obj(text, Path::new("fuzz.obj")) else {
        return;
    };
    let _ = scene.mesh.triangles();
    let _ = scene.mesh.validate();
    if let Ok(out) = fbakit::mesh::obj::write_obj_string(&scene) {
        let (again, _) = fbakit::mesh::obj::parse_obj(&out, Path::new("fuzz.obj"))
            .expect("written OBJ reads back");
        assert_eq!(again, scene);
    }
});
