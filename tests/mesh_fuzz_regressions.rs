//! Replays inputs the `obj` and `wfm` fuzz targets once crashed on, with the targets' checks.

use std::path::{Path, PathBuf};

use fbakit::candide::parse_wfm;
use fbakit::mesh::obj::{parse_obj, write_obj_string};

fn inputs(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz-regressions")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default();
    files.sort();
    files
}

#[test]
fn obj_regressions() {
    let files = inputs("obj");
    assert!(!files.is_empty(), "regression inputs present");
    for f in files {
        let bytes = std::fs::read(&f).unwrap();
        let Ok(text) = std::str::from_utf8(&bytes) else {
            continue;
        };
        let Ok((scene, _)) = parse_obj(text, Path::new("fuzz.obj")) else {
            continue;
        };
        let _ = scene.mesh.triangles();
        if let Ok(out) = write_obj_string(&scene) {
            let (again, _) = parse_obj(&out, Path::new("fuzz.obj")).unwrap();
            assert_eq!(again, scene, "{}", f.display());
        }
    }
}

#[test]
fn wfm_regressions() {
    for f in inputs("wfm") {
        let bytes = std::fs::read(&f).unwrap();
        let Ok(text) = std::str::from_utf8(&bytes) else {
            continue;
        };
        let Ok(model) = parse_wfm(text, Path::new("fuzz.wfm")) else {
            continue;
        };
        assert!(model.to_mesh().validate().is_valid(), "{}", f.display());
        let names: Vec<(String, f32)> = model
            .shape_units
            .iter()
            .map(|u| (u.name.clone(), 0.5))
            .collect();
        model.with_shape(&names).unwrap();
    }
}
