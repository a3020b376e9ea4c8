//! The export front door (`fbakit::export::write`, `fbakit face export`): one call for every
//! asset a pipeline needs, with the warnings in its report (issue 19 §6).

mod support;

use std::path::Path;

use fbakit::prelude::*;
use serde_json::Value;
use support::cli::fbakit;
use support::validator::validate;

fn json_of(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    serde_json::from_slice(chunks.json).unwrap()
}

/// Names of mesh `m`'s morph targets.
fn target_names(doc: &Value, m: usize) -> Vec<String> {
    doc["meshes"][m]["extras"]["targetNames"]
        .as_array()
        .map(|a| a.iter().map(|v| v.as_str().unwrap().to_string()).collect())
        .unwrap_or_default()
}

#[test]
fn the_real_head_comes_back_as_its_own_glb_with_arkit_shapes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ict-arkit.glb");
    let face = face::read("ict").unwrap();
    let opts = ExportOptions {
        names: ShapeNames::Arkit,
        ..ExportOptions::default()
    };
    let report = export::write(&out, &face, &opts).unwrap();
    assert_eq!(report.kind, export::ExportKind::PatchedGltf, "{report}");
    let arkit = report.arkit.as_ref().unwrap();
    // The amplitude table has FAP recipes for 34 of the 52 shapes.
    assert!(arkit.targets.len() >= 30, "{report}");
    assert!(arkit.targets.iter().any(|t| t == "jawOpen"));

    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/faces/ict-head/ict-head.glb");
    let (x, y) = (json_of(&input), json_of(&out));
    // Everything but the meshes' target lists and the merged buffer is the user's.
    for k in ["nodes", "materials", "asset"] {
        assert_eq!(x[k], y[k], "{k} changed");
    }
    // The scene gains fbakit's feature-point record in its extras, nothing else.
    let mut scene = y["scenes"][0].clone();
    assert!(
        scene["extras"]["fbakit"]["featurePoints"].is_array(),
        "{scene}"
    );
    scene.as_object_mut().unwrap().remove("extras");
    assert_eq!(x["scenes"][0], scene);
    // The head is an ARKit rig already: its own shapes stay first and untouched, fbakit's
    // (made from the FAT) are appended under other names, and one warning says so.
    let (own, names) = (target_names(&x, 0), target_names(&y, 0));
    assert!(own.iter().any(|n| n == "jawOpen"), "{own:?}");
    assert_eq!(&names[..own.len()], &own[..]);
    assert_eq!(names.len(), own.len() + arkit.targets.len());
    assert!(names.iter().any(|n| n == "jawOpen_fbakit"), "{names:?}");
    assert_eq!(
        report
            .warnings
            .iter()
            .filter(|w| w.message.contains("already has"))
            .count(),
        1,
        "{:?}",
        report.warnings
    );
    // Same vertices in the same order, and jawOpen drops the chin (feature point 2.1).
    let back = face::read(&out).unwrap();
    assert_eq!(back.meshes.len(), face.meshes.len());
    for (a, b) in face.meshes.iter().zip(&back.meshes) {
        assert_eq!(a.mesh.positions, b.mesh.positions);
        assert_eq!(a.mesh.polygons, b.mesh.polygons);
    }
    let rig = fbakit::rig::read_rig(&out).unwrap();
    let (mesh, v) = face.fp_vertex("2.1".parse().unwrap()).unwrap();
    let jaw = rig.shape("jawOpen_fbakit").unwrap().offset(mesh, v);
    assert!(jaw.y < -0.005, "jawOpen moves the chin by {jaw} m");

    // The patched file carries the feature points.
    assert_eq!(back.feature_points.len(), face.feature_points.len());
    // Written into the patched file again, fbakit's ARKit targets are replaced, not
    // appended again.
    let again = dir.path().join("ict-arkit-2.glb");
    let into_patched = FaceModel {
        gltf_source: back.gltf_source.clone(),
        ..face.clone()
    };
    export::write(&again, &into_patched, &opts).unwrap();
    assert_eq!(target_names(&json_of(&again), 0), names);

    if let Some(reports) = validate(&[input, out]) {
        assert_eq!(
            reports[1]["errors"], reports[0]["errors"],
            "{:#}",
            reports[1]
        );
        assert_eq!(
            reports[1]["warnings"], reports[0]["warnings"],
            "{:#}",
            reports[1]
        );
    }
}

#[test]
fn face_export_cli_reports_the_kind_and_units() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("alma.glb");
    let o = fbakit(&[
        "face",
        "export",
        "alma",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["face"], "alma");
    assert_eq!(v["kind"], "gltf");
    assert_eq!(v["units"], "m");
    assert!(v["warnings"].is_array());

    // The glb fbakit made is the user's now: exported again, it is patched in its units.
    let again = dir.path().join("alma2.glb");
    let o = fbakit(&[
        "face",
        "export",
        out.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let line = String::from_utf8_lossy(&o.stdout);
    assert!(line.contains("the face's own glTF, patched"), "{line}");
    assert!(line.contains("in m"), "{line}");

    // An OBJ shape set through the same door.
    let set = dir.path().join("set/");
    let o = fbakit(&[
        "face",
        "export",
        "alma",
        "-o",
        set.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["kind"], "obj_shapes");
    let n = v["morph_targets"].as_u64().unwrap() as usize;
    assert_eq!(v["shapes"]["shapes"].as_array().unwrap().len(), n);
    assert!(dir.path().join("set/neutral.obj").exists());

    // ARKit names cannot go into VRML: exit 2, one line, nothing written.
    let wrl = dir.path().join("alma.wrl");
    let o = fbakit(&[
        "face",
        "export",
        "alma",
        "-o",
        wrl.to_str().unwrap(),
        "--names",
        "arkit",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("alma.wrl"), "{err}");
    assert!(!wrl.exists());
}
