//! The ICT-FaceKit's whole generic head as its users have it (`../shared`): one OBJ of
//! 26 719 vertices with eyeballs, teeth, lashes and the eye layers its renderer blends (eye
//! occlusion, lacrimal film, corner blends), its feature points placed by
//! `fbakit fp from-landmarks` from ICT's iBUG-68 vertex ids.

use std::path::{Path, PathBuf};

use fbakit::face::{read_with, FaceModel, FaceReadOptions};

/// The ICT-FaceKit folder in `../shared/data`, or `None` with a note.
pub fn ict_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/ict-facekit");
    if dir.join("generic_neutral_mesh.obj").exists() {
        Some(dir)
    } else {
        eprintln!("note: {} not found; skipping", dir.display());
        None
    }
}

/// The head with its feature points (written to `work`), or `None` without `../shared`.
pub fn ict_full_head(work: &Path) -> Option<(PathBuf, FaceModel)> {
    let dir = ict_dir()?;
    let obj = dir.join("generic_neutral_mesh.obj");
    let fp = work.join("ict-fp.csv");
    let out = super::cli::command()
        .arg("fp")
        .arg("from-landmarks")
        .arg(&obj)
        .arg("--ibug68")
        .arg(dir.join("vertex_indices.json"))
        .arg("-o")
        .arg(&fp)
        .output()
        .expect("run fbakit");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let opts = FaceReadOptions {
        feature_points: Some(fp),
        ..Default::default()
    };
    let (face, _) = read_with(&obj, &opts).expect("read the ICT head");
    Some((obj, face))
}

/// The vertices (0-based, ascending) of the polygons under each `usemtl` name in `obj`.
pub fn vertices_by_material(obj: &Path) -> std::collections::BTreeMap<String, Vec<u32>> {
    let text = std::fs::read_to_string(obj).expect("read the OBJ");
    let mut out: std::collections::BTreeMap<String, std::collections::BTreeSet<u32>> =
        Default::default();
    let mut current = String::new();
    for line in text.lines() {
        if let Some(name) = line.strip_prefix("usemtl ") {
            current = name.trim().to_string();
        } else if let Some(rest) = line.strip_prefix("f ") {
            let set = out.entry(current.clone()).or_default();
            for corner in rest.split_whitespace() {
                let v: u32 = corner.split('/').next().unwrap().parse().unwrap();
                set.insert(v - 1);
            }
        }
    }
    out.into_iter()
        .map(|(k, v)| (k, v.into_iter().collect()))
        .collect()
}
