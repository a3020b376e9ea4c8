//! `fbakit rig ...` and `fbakit face from-rig` through the real binary: exit codes and
//! messages on good and bad rigs.

use std::path::Path;
use std::process::{Command, Output};

fn fbakit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fbakit"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run fbakit")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

fn quad_rig(dir: &Path) {
    std::fs::write(dir.join("neutral.obj"), QUAD).unwrap();
    std::fs::write(
        dir.join("jawOpen.obj"),
        "v 0 -1 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
}

#[test]
fn rig_info_lists_shapes_in_text_and_json() {
    let tmp = tempfile::tempdir().unwrap();
    quad_rig(tmp.path());
    let dir = tmp.path().to_str().unwrap();
    let o = fbakit(&["rig", "info", dir]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(
        out.contains("1 shapes:") && out.contains("jawOpen"),
        "{out}"
    );
    let o = fbakit(&["rig", "info", dir, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["shapes"][0]["name"], "jawOpen");
    assert_eq!(v["shapes"][0]["moved_vertices"], 1);
    assert_eq!(v["vertices"], 4);
}

#[test]
fn bad_rigs_exit_2_with_one_located_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // No morph targets.
    let gltf = dir.join("plain.gltf");
    let doc = fbakit::gltf::SceneBuilder::new("plain");
    let mut doc = doc;
    let m = doc
        .add_mesh(fbakit::gltf::builder::MeshData::new(
            "m",
            vec![glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y],
            vec![[0u32, 1, 2]],
        ))
        .unwrap();
    doc.add_node(fbakit::gltf::builder::NodeData::new("n").with_mesh(m))
        .unwrap();
    doc.build().unwrap().write(&gltf).unwrap();
    let o = fbakit(&["rig", "info", gltf.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(err.contains("plain.gltf: no morph targets"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    // Mismatched vertex counts name both files.
    quad_rig(dir);
    std::fs::write(dir.join("short.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\n").unwrap();
    let o = fbakit(&["rig", "info", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.contains("short.obj") && err.contains("neutral.obj"),
        "{err}"
    );
}
