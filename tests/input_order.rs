//! Determinism across input order (issue 20 §2): documents fbakit generates are the same
//! bytes for equal content read in another order — a FAT with its tables (and their entries)
//! in another order, a feature-point file with its rows shuffled; a document fbakit patches
//! keeps the user's order.

use std::path::Path;

use fbakit::face::FaceModel;
use fbakit::snapshot::{diff, snapshot, DiffOptions, SnapshotOptions};

/// `face` with its tables, and every table's entries, in reverse order.
fn reversed(face: &FaceModel) -> FaceModel {
    let mut f = face.clone();
    f.fat.tables.reverse();
    for t in &mut f.fat.tables {
        t.meshes.reverse();
        t.transforms.reverse();
    }
    f
}

/// Every generated output of `face` as (name, bytes).
fn outputs(face: &FaceModel, dir: &Path, tag: &str) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for ext in ["wrl", "wrl.gz", "glb", "gltf", "obj"] {
        let path = dir.join(format!("{tag}.{ext}"));
        fbakit::export::write_face(&path, face).unwrap();
        out.push((format!(".{ext}"), std::fs::read(&path).unwrap()));
    }
    let set = dir.join(format!("{tag}-morphs"));
    fbakit::face::morphs::write_morph_set(face, &set, None).unwrap();
    let mut files: Vec<_> = std::fs::read_dir(&set)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        out.push((name, std::fs::read(&f).unwrap()));
    }
    out.push((
        "snapshot".into(),
        snapshot(face, &SnapshotOptions::default()).into_bytes(),
    ));
    out
}

fn assert_same(a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)]) {
    assert_eq!(a.len(), b.len());
    for ((name, x), (other, y)) in a.iter().zip(b) {
        assert_eq!(name, other);
        assert!(x == y, "{name} differs with the input in another order");
    }
}

#[test]
fn generated_documents_do_not_depend_on_the_tables_order() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["alma", "bruno"] {
        let mut face = fbakit::face::read(name).unwrap();
        // Generated, not patched: no kept scene.
        face.scene = None;
        let other = reversed(&face);
        assert_ne!(face.fat.tables[0].key, other.fat.tables[0].key);
        let a = outputs(&face, dir.path(), &format!("{name}-a"));
        let b = outputs(&other, dir.path(), &format!("{name}-b"));
        assert_same(&a, &b);
        // The diff report (JSON) against a third face is the same too.
        let third = fbakit::face::read(name).unwrap();
        let ra = serde_json::to_string(&diff(&face, &third, &DiffOptions::default())).unwrap();
        let rb = serde_json::to_string(&diff(&other, &third, &DiffOptions::default())).unwrap();
        assert_eq!(ra, rb, "{name}: diff JSON");
    }
}

#[test]
fn a_patched_vrml_keeps_the_users_table_order() {
    let dir = tempfile::tempdir().unwrap();
    let face = fbakit::face::read("alma").unwrap();
    assert!(face.scene.is_some());
    let other = reversed(&face);
    let path = dir.path().join("reversed.wrl");
    fbakit::export::write_face(&path, &other).unwrap();
    let back = fbakit::face::read(&path).unwrap();
    let keys = |f: &FaceModel| f.fat.tables.iter().map(|t| t.key).collect::<Vec<_>>();
    assert_eq!(keys(&back), keys(&other), "the user's order is kept");
    let report = diff(&face, &back, &DiffOptions::default());
    assert!(report.is_equal(), "{report}");
}

#[test]
fn shuffled_feature_point_rows_give_the_same_documents() {
    let dir = tempfile::tempdir().unwrap();
    let alma = fbakit::face::read("alma").unwrap();
    let set = dir.path().join("set");
    fbakit::face::morphs::write_morph_set(&alma, &set, None).unwrap();
    let csv = std::fs::read_to_string(set.join("feature-points.csv")).unwrap();
    let mut lines: Vec<&str> = csv.lines().collect();
    let header = lines.remove(0);
    lines.reverse();
    let shuffled = set.join("shuffled.csv");
    std::fs::write(&shuffled, format!("{header}\n{}\n", lines.join("\n"))).unwrap();
    let read = |fp: &Path| {
        let options = fbakit::face::morphs::MorphSetOptions {
            feature_points: Some(fp.to_path_buf()),
            manifest: None,
            tolerance: None,
        };
        fbakit::face::morphs::face_from_morph_set(&set.join("neutral.obj"), &set, &options)
            .unwrap()
            .0
    };
    let a = read(&set.join("feature-points.csv"));
    let b = read(&shuffled);
    let mut out = Vec::new();
    for (tag, face) in [("a", &a), ("b", &b)] {
        let mut bytes = Vec::new();
        for ext in ["glb", "wrl"] {
            let path = dir.path().join(format!("fp-{tag}.{ext}"));
            fbakit::export::write_face(&path, face).unwrap();
            bytes.push((format!(".{ext}"), std::fs::read(&path).unwrap()));
        }
        out.push(bytes);
    }
    assert_same(&out[0], &out[1]);
}
