//! Played frame data (snapshot) and `fbakit play` / `fbakit face export` through the binary.

use std::fmt::Write as _;
use std::path::Path;

use fbakit::fap::{read_fap_file, ReadOptions};
use fbakit::player::{PlayOptions, Player};

mod support;
use support::cli::fbakit;

/// Per frame: per mesh the summed and largest displacement length, per transform the rotation
/// angle (degrees) — enough to see speech open the mouth, blink and smile.
#[test]
fn speech_on_alma_first_frames() {
    let face = fbakit::synth::alma().to_face_model();
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap");
    let stream = read_fap_file(&p, &ReadOptions::strict()).unwrap().0;
    let opts = PlayOptions {
        fps: None,
        frames: Some(0..10),
    };
    let mut player = Player::new(&face, &stream, &opts).unwrap();
    let mut frame = player.new_frame();
    let mut s = String::new();
    while player.next_frame(&mut frame) {
        let _ = write!(s, "frame {} t={:.2}:", frame.index, frame.time);
        for (mi, m) in face.meshes.iter().enumerate() {
            let (sum, max) = frame.pose.positions[mi]
                .iter()
                .zip(&m.mesh.positions)
                .map(|(p, n)| (*p - *n).length())
                .fold((0.0f32, 0.0f32), |(s, mx), d| (s + d, mx.max(d)));
            let _ = write!(s, " {}={:.1}/{:.2}", m.name, sum, max);
        }
        for (ti, t) in face.transforms.iter().enumerate() {
            let angle = frame.transform_deltas[ti].rotation.to_axis_angle().1;
            if angle.abs() > 1e-6 {
                let _ = write!(s, " {}:{:.2}deg", t.name, angle.to_degrees());
            }
        }
        s.push('\n');
    }
    insta::assert_snapshot!("speech_alma_first_10", s);
}

#[test]
fn play_writes_glb_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("speech.glb");
    let o = fbakit(&[
        "play",
        "alma",
        "samples/speech.fap",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["output"] = "OUT".into();
    insta::assert_json_snapshot!("play_speech_glb_json", v);
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
}

#[test]
fn play_writes_an_obj_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let o = fbakit(&[
        "play",
        "alma",
        "samples/lowlevel.fap",
        "-o",
        out.to_str().unwrap(),
        "--frames",
        "20..23",
        "--fps",
        "50",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("played 3 frames from 20"), "{text}");
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "frame_00020.obj",
            "frame_00021.obj",
            "frame_00022.obj",
            "frames.json"
        ]
    );
    let index: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("frames.json")).unwrap()).unwrap();
    assert_eq!(index["fps"], 50.0);
    assert_eq!(index["frames"][1]["file"], "frame_00021.obj");
    assert_eq!(index["frames"][1]["time"], 0.42);
    // Each OBJ reads back with all vertices of the face.
    let face = fbakit::synth::alma().to_face_model();
    let (obj, _) = fbakit::mesh::obj::read_obj_file(&out.join("frame_00021.obj")).unwrap();
    assert_eq!(obj.mesh.vertex_count(), face.vertex_count());
}

#[test]
fn play_reports_missing_tables() {
    // A face without a FAT: every FAP used is reported with its frame count.
    let dir = tempfile::tempdir().unwrap();
    let mut face = fbakit::synth::alma().to_face_model();
    face.fat.tables.clear();
    let face_path = dir.path().join("bare.wrl");
    fbakit::face::vrml::write_face_file(&face_path, &face).unwrap();
    let out = dir.path().join("o.glb");
    let o = fbakit(&[
        "play",
        face_path.to_str().unwrap(),
        "samples/speech.fap",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("FAP 3 open_jaw in "), "{text}");
    assert!(text.contains("expression 1 (joy) in "), "{text}");
    assert!(text.contains("viseme "), "{text}");
}

#[test]
fn play_usage_errors_exit_2() {
    let o = fbakit(&["play", "alma", "samples/speech.fap", "-o", "x.txt"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("x.txt") && err.contains("unknown extension `.txt`") && err.contains(".glb"),
        "{err}"
    );
    let o = fbakit(&["play", "nobody", "samples/speech.fap", "-o", "x.glb"]);
    assert_eq!(o.status.code(), Some(2));
    let o = fbakit(&[
        "play",
        "alma",
        "samples/speech.fap",
        "-o",
        "x.glb",
        "--frames",
        "500..600",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!Path::new(env!("CARGO_MANIFEST_DIR")).join("x.glb").exists());
}

#[test]
fn export_face_writes_morph_targets() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("alma.gltf");
    let o = fbakit(&[
        "face",
        "export",
        "alma",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["face"], "alma");
    assert!(v["morph_targets"].as_u64().unwrap() >= 86, "{v}");
    let gltf: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert!(gltf.get("animations").is_none());
    let names = &gltf["meshes"][0]["extras"]["targetNames"];
    assert!(
        names.as_array().unwrap().iter().any(|n| n == "open_jaw#1"),
        "{names}"
    );
    let o = fbakit(&["face", "export", "alma", "-o", "alma.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!Path::new("alma.png").exists());
}

#[test]
fn bundled_gzipped_faces_export_and_play() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("alma.glb");
    let o = fbakit(&[
        "face",
        "export",
        "samples/faces/alma.wrl.gz",
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let bytes = std::fs::read(&glb).unwrap();
    assert!(fbakit::gltf::parse_glb(&bytes).is_ok());
    let anim = dir.path().join("speech.glb");
    let o = fbakit(&[
        "play",
        "samples/faces/alma.wrl.gz",
        "samples/speech.fap",
        "-o",
        anim.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(std::fs::metadata(&anim).unwrap().len() > 1000);
}
