//! Runs the Khronos glTF validator on generated `.glb` and `.gltf` files and requires zero
//! errors and zero warnings (infos are allowed).
//!
//! Needs `node` and the npm package `gltf-validator`, found through `$GLTF_VALIDATOR_DIR`
//! (`npm install --prefix <dir> gltf-validator`) or ordinary node_modules resolution. When
//! either is missing the test prints a note and returns.

mod support;

use support::gltf_scenes::{grid_scene, tiny_scene, two_mesh_scene};
use support::validator::validate;

#[test]
fn generated_files_pass_the_khronos_validator() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for (name, doc) in [
        ("two_mesh", two_mesh_scene()),
        ("tiny", tiny_scene()),
        ("grid_u32", grid_scene(260)),
    ] {
        for ext in ["glb", "gltf"] {
            let p = dir.path().join(format!("{name}.{ext}"));
            doc.write(&p).unwrap();
            files.push(p);
        }
    }
    let Some(reports) = validate(&files) else {
        return;
    };
    for r in &reports {
        eprintln!("{r}");
    }
    for r in &reports {
        assert_eq!(r["errors"], 0, "{r:#}");
        assert_eq!(r["warnings"], 0, "{r:#}");
    }
}

/// The harness itself must be able to fail: a file with a wrong `POSITION` bound and a
/// non-unit rotation is reported.
#[test]
fn validator_reports_a_corrupted_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = two_mesh_scene();
    doc.root.accessors[0].min[0] -= 1.0;
    doc.root.nodes[1].rotation = Some([0.0, 0.0, 0.6, 0.6]);
    let p = dir.path().join("broken.glb");
    doc.write(&p).unwrap();
    let Some(reports) = validate(&[p]) else {
        return;
    };
    let messages = reports[0]["messages"].to_string();
    assert!(reports[0]["errors"].as_u64().unwrap() >= 2, "{messages}");
    assert!(messages.contains("ACCESSOR_MIN_MISMATCH"), "{messages}");
    assert!(messages.contains("ROTATION_NON_UNIT"), "{messages}");
}
