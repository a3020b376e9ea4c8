//! CANDIDE-3 with its FAT from the shared data (`../shared/data/candide3/`), for the cloning
//! tests; included with `#[path]` by the tests that use it.
#![allow(dead_code)]

use std::path::Path;

use fbakit::face::candide::candide_face;
use fbakit::face::FaceModel;

/// CANDIDE-3's own shape units, mildly: a shape change of the same face.
pub const SHAPE: [(&str, f32); 5] = [
    ("Mouth width", 0.4),
    ("Nose z-extension", 0.5),
    ("Head height", 0.3),
    ("Eyes, width", 0.3),
    ("Chin width", 0.4),
];

/// CANDIDE-3 with its FAT, shaped by `shape` units; `None` (with a note) without the shared
/// data.
pub fn candide(shape: &[(&str, f32)]) -> Option<FaceModel> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/candide3");
    if !dir.join("candide3.wfm").is_file() {
        eprintln!("note: {} not found; skipping", dir.display());
        return None;
    }
    let model = fbakit::candide::read_wfm_file(&dir.join("candide3.wfm")).unwrap();
    let fp = fbakit::fdp::csv::read_csv_file(&dir.join("feature-points.csv"))
        .unwrap()
        .to_set();
    let shape: Vec<(String, f32)> = shape.iter().map(|(n, v)| (n.to_string(), *v)).collect();
    Some(candide_face(&model, &fp, &shape).unwrap())
}
