//! `fbakit rig ...` and `fbakit face from-rig` through the real binary: exit codes and
//! messages on good and bad rigs.

use std::path::Path;

mod support;
use support::cli::{fbakit, text};

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
        .add_mesh(fbakit::gltf::MeshData::new(
            "m",
            vec![glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y],
            vec![[0u32, 1, 2]],
        ))
        .unwrap();
    doc.add_node(fbakit::gltf::NodeData::new("n").with_mesh(m))
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

/// The quad rig plus feature points for the FAPU (CSV, vertex ids): a chin vertex that
/// `jawOpen` drops.
fn fat_rig(dir: &Path) {
    let verts = [
        (30.0, 40.0),   // 0 3.5
        (-30.0, 40.0),  // 1 3.6
        (30.0, 45.0),   // 2 3.1
        (30.0, 35.0),   // 3 3.3
        (0.0, 0.0),     // 4 9.15
        (0.0, -20.0),   // 5 2.2
        (25.0, -25.0),  // 6 8.3
        (-25.0, -25.0), // 7 8.4
        (0.0, -60.0),   // 8 2.1
    ];
    let mut neutral = String::new();
    let mut jaw = String::new();
    for (i, (x, y)) in verts.iter().enumerate() {
        neutral += &format!("v {x} {y} 0\n");
        let dy = if i == 8 { -10.0 } else { 0.0 };
        jaw += &format!("v {x} {} 0\n", y + dy);
    }
    let faces: String = (2..verts.len())
        .map(|i| format!("f 1 {i} {}\n", i + 1))
        .collect();
    std::fs::write(dir.join("neutral.obj"), neutral + &faces).unwrap();
    std::fs::write(dir.join("jawOpen.obj"), jaw + &faces).unwrap();
    std::fs::write(
        dir.join("fp.csv"),
        "fp,vertices\n3.5,0\n3.6,1\n3.1,2\n3.3,3\n9.15,4\n2.2,5\n8.3,6\n8.4,7\n2.1,8\n",
    )
    .unwrap();
}

#[test]
fn face_from_rig_writes_a_compliant_face() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("rig");
    std::fs::create_dir(&dir).unwrap();
    fat_rig(&dir);
    let out = tmp.path().join("face.wrl");
    let fp = dir.join("fp.csv");
    let o = fbakit(&[
        "face",
        "from-rig",
        dir.to_str().unwrap(),
        "--fp",
        fp.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["calibrated"][0]["fap"], "open_jaw");
    assert!((v["calibrated"][0]["value"].as_f64().unwrap() - 512.0).abs() < 1e-6);
    assert!(v["unmapped"].as_array().unwrap().len() > 10);
    // The written face passes the compliance check like the bundled faces.
    let o = fbakit(&["eval", "compliance", out.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let c: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(c["faps"][0]["fap"], "open_jaw");
    assert!(c["worst"].as_f64().unwrap() < 1e-5, "{c}");
    // glb output too; text report lists what was not realised.
    let glb = tmp.path().join("face.glb");
    let o = fbakit(&[
        "face",
        "from-rig",
        dir.to_str().unwrap(),
        "--fp",
        fp.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(glb.is_file());
    let out_text = text(&o.stdout);
    assert!(
        out_text.contains("not realised") && out_text.contains("unused shapes (0)"),
        "{out_text}"
    );
}

#[test]
fn bad_map_exits_2_naming_file_and_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("rig");
    std::fs::create_dir(&dir).unwrap();
    fat_rig(&dir);
    let out = tmp.path().join("face.wrl");
    for (csv, want) in [
        (
            "fap,positive,negative,reasoning\nopen_jaw,jawOpen,,\nwiggle,x,,\n",
            "map.csv:3:1",
        ),
        (
            "fap,positive,negative,reasoning\nopen_jaw,grin,,\n",
            "map.csv:2: unknown shape `grin`",
        ),
    ] {
        let map = tmp.path().join("map.csv");
        std::fs::write(&map, csv).unwrap();
        let o = fbakit(&[
            "face",
            "from-rig",
            dir.to_str().unwrap(),
            "--map",
            map.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2));
        let err = text(&o.stderr);
        assert!(err.contains(want), "{err}");
        assert!(!out.exists());
    }
}
