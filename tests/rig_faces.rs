//! Rigs wherever a face is accepted (the one front door), and the bundled real head `ict`
//! (derived from ICT-FaceKit): FAT from its shapes, compliant, played, viewed, cloned onto,
//! exported head-sized in metres.

use std::path::Path;
use std::process::Output;

mod support;
use support::cli::{fbakit, text};

fn ok(args: &[&str]) -> Output {
    let out = fbakit(args);
    assert!(
        out.status.success(),
        "{args:?}: {}{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    out
}

const GLB: &str = "samples/faces/ict-head/ict-head.glb";
const FP: &str = "samples/faces/ict-head/ict-head-fp.csv";

#[test]
fn bundled_real_head_has_a_compliant_fat_in_metres() {
    let face = fbakit::face::read("ict").unwrap();
    assert_eq!(face.vertex_count(), 24591);
    assert!(face.fat.tables.len() >= 50, "{}", face.fat.tables.len());
    let c = fbakit::clone::eval::compliance(&face).unwrap();
    assert!(c.faps.len() >= 25, "{} FAPs measured", c.faps.len());
    assert!(c.worst < 1e-4, "compliance worst {}", c.worst);
    // The file in samples/ read through the front door with its feature points is the same
    // face as the embedded one.
    let (from_file, _) = fbakit::face::read_with(
        Path::new(GLB),
        &fbakit::face::FaceReadOptions::with_feature_points(Some(Path::new(FP))),
    )
    .unwrap();
    assert_eq!(from_file.fat, face.fat);
    let info: serde_json::Value =
        serde_json::from_slice(&ok(&["face", "info", "ict", "--json"]).stdout).unwrap();
    assert_eq!(info["units"]["unit"], "m");
}

#[test]
fn a_rig_without_feature_points_reads_as_meshes_with_a_note() {
    let out = ok(&["face", "info", GLB, "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["fat"]["table_count"], 0);
    let notes = info["diagnostics"].to_string();
    assert!(notes.contains("--fp"), "{notes}");
    // With them, the shapes become the FAT.
    let out = ok(&["face", "info", GLB, "--fp", FP, "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(info["fat"]["table_count"].as_u64().unwrap() >= 50);
}

#[test]
fn the_real_head_plays_speech_and_an_xface_stream_head_sized_in_metres() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("ict.glb");
    let out = ok(&[
        "play",
        "ict",
        "samples/speech.fap",
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(text(&out.stdout).contains("75 frames"));
    let bytes = std::fs::read(&glb).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    let json: serde_json::Value = serde_json::from_slice(chunks.json).unwrap();
    let pos = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize;
    let (min, max) = (
        &json["accessors"][pos]["min"],
        &json["accessors"][pos]["max"],
    );
    let extent: Vec<f64> = (0..3)
        .map(|i| max[i].as_f64().unwrap() - min[i].as_f64().unwrap())
        .collect();
    // A head with its neck: 15 to 40 cm on each axis, in metres.
    for e in &extent {
        assert!((0.12..0.45).contains(e), "extent {extent:?} m");
    }
    let xface = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/xface-faps/joy.fap");
    if xface.is_file() {
        let out = ok(&[
            "play",
            "ict",
            xface.to_str().unwrap(),
            "-o",
            dir.path().join("joy.png").to_str().unwrap(),
            "--sheet-frames",
            "3",
            "--size",
            "96x96",
        ]);
        assert!(text(&out.stdout).contains("frames"));
    } else {
        eprintln!("note: ../shared/data/xface-faps absent; skipping the Xface stream");
    }
}

#[test]
fn the_real_head_is_viewed_and_cloned_onto() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("ict.html");
    ok(&[
        "view",
        "ict",
        "samples/speech.fap",
        "-o",
        page.to_str().unwrap(),
    ]);
    assert!(std::fs::metadata(&page).unwrap().len() > 100_000);
    // alma's FAT onto the head given as a rig file plus its feature points.
    let out_face = dir.path().join("ict-cloned.wrl.gz");
    let out = ok(&[
        "clone",
        "alma",
        GLB,
        "--fp-target",
        FP,
        "-o",
        out_face.to_str().unwrap(),
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(report["report"]["tables"].as_u64().unwrap() >= 80);
    let cloned = fbakit::face::read(&out_face).unwrap();
    // The one mesh is cut into skin, eyes and teeth inside the clone only: the face comes
    // back as the one mesh it was, every vertex in its order.
    assert_eq!(report["report"]["split_parts"].as_array().unwrap().len(), 4);
    assert_eq!(cloned.meshes.len(), 1);
    assert_eq!(cloned.vertex_count(), 24591);
}

#[test]
fn play_and_render_take_a_rig_with_its_feature_points() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("rig-speech.glb");
    ok(&[
        "play",
        GLB,
        "samples/speech.fap",
        "--fp",
        FP,
        "-o",
        glb.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&glb).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    let json: serde_json::Value = serde_json::from_slice(chunks.json).unwrap();
    let targets = json["meshes"][0]["primitives"][0]["targets"]
        .as_array()
        .map_or(0, Vec::len);
    assert!(targets >= 50, "{targets} morph targets from the rig's FAT");
    let gif = dir.path().join("rig.gif");
    ok(&[
        "render",
        GLB,
        "samples/speech.fap",
        "--fp",
        FP,
        "--size",
        "64x64",
        "-o",
        gif.to_str().unwrap(),
    ]);
    // No command writes over its input.
    let copy = dir.path().join("copy.glb");
    std::fs::copy(GLB, &copy).unwrap();
    let c = copy.to_str().unwrap();
    for args in [
        &["play", c, "samples/speech.fap", "-o", c][..],
        &["render", c, "samples/speech.fap", "-o", c],
    ] {
        let out = fbakit(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
    }
    assert_eq!(std::fs::read(&copy).unwrap(), std::fs::read(GLB).unwrap());
}

#[test]
fn a_folder_of_shape_objs_is_a_face_too() {
    let dir = tempfile::tempdir().unwrap();
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    std::fs::write(dir.path().join("neutral.obj"), quad).unwrap();
    std::fs::write(
        dir.path().join("jawOpen.obj"),
        "v 0 -1 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let out = ok(&["face", "info", dir.path().to_str().unwrap(), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["vertices"], 4);
    // A rig folder with a broken shape names that shape.
    std::fs::write(dir.path().join("jawOpen.obj"), "v 0 -1 0\nf 1 1 1\n").unwrap();
    let out = fbakit(&["face", "info", dir.path().to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("jawOpen.obj"),
        "{}",
        text(&out.stderr)
    );
    // A folder that is no rig is bad input naming the folder.
    let empty = tempfile::tempdir().unwrap();
    let out = fbakit(&["face", "info", empty.path().to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains(empty.path().to_str().unwrap()));
}
