//! Landmarks → MPEG-4 feature points on real heads: ICT-FaceKit (iBUG-68 vertex ids) and the
//! MediaPipe canonical face (468 landmarks in vertex order), through the library and the
//! `fbakit fp from-landmarks` command; the result feeds `fbakit fapu` and both cloners.
//! Tests on `../shared/data` are skipped with a note when it is absent.

use std::path::{Path, PathBuf};

use fbakit::fdp::landmarks::{
    feature_points_from_landmarks, read_landmark_ids, LandmarkFeaturePoints, LandmarkScheme,
};
use fbakit::fdp::Fapu;
use fbakit::mesh::obj::read_obj_file;
use fbakit::mesh::Mesh;
use fbakit::spec::{FeaturePointId, Side};
use glam::Vec3;

mod support;
use support::cli::fbakit;

const MANIFEST: &str = env!("CARGO_MANIFEST_DIR");

fn shared(rel: &str) -> Option<PathBuf> {
    let p = Path::new(MANIFEST).join("../shared/data").join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("note: {} not found; skipping", p.display());
        None
    }
}

fn fp(s: &str) -> FeaturePointId {
    s.parse().unwrap()
}

fn mesh(path: &Path) -> Mesh {
    read_obj_file(path).unwrap().0.mesh
}

fn ict() -> Option<(PathBuf, Mesh, LandmarkFeaturePoints)> {
    let dir = shared("ict-facekit")?;
    let neutral = mesh(&dir.join("generic_neutral_mesh.obj"));
    let ids = read_landmark_ids(&dir.join("vertex_indices.json")).unwrap();
    let found = feature_points_from_landmarks(&neutral, LandmarkScheme::Ibug68, &ids.ids).unwrap();
    Some((dir, neutral, found))
}

/// Every left point mirrors its right partner (x → −x) within `tol`.
fn assert_mirrored(found: &LandmarkFeaturePoints, tol: f32) -> usize {
    let mut pairs = 0;
    for p in found
        .points
        .iter()
        .filter(|p| p.id.info().side == Side::Left)
    {
        let partner = found.points.iter().find(|q| {
            q.id.info().side == Side::Right
                && q.id.group() == p.id.group()
                && mirror_label(p.id) == Some(q.id)
        });
        let Some(q) = partner else { continue };
        let m = Vec3::new(-p.position.x, p.position.y, p.position.z);
        let d = m.distance(q.position);
        assert!(
            d <= tol,
            "{} at {} does not mirror {} at {} ({d})",
            p.id,
            p.position,
            q.id,
            q.position
        );
        pairs += 1;
    }
    pairs
}

/// The right partner of a left point: the standard numbers most pairs as consecutive odd/even
/// indices (3.1/3.2, 8.3/8.4, 2.11/2.12); the exceptions are listed.
fn mirror_label(left: FeaturePointId) -> Option<FeaturePointId> {
    let special = [
        ("8.10", "8.9"),
        ("3.7", "3.12"),
        ("3.11", "3.8"),
        ("9.5", "9.4"),
        ("9.7", "9.6"),
        ("11.3", "11.2"),
    ];
    if let Some((_, r)) = special.iter().find(|(l, _)| fp(l) == left) {
        return Some(fp(r));
    }
    FeaturePointId::new(left.group(), left.index() + 1)
}

#[test]
fn ict_points_give_plausible_fapus_and_mirror() {
    let Some((_, _, found)) = ict() else { return };
    assert!(found.absent.is_empty(), "{:?}", found.absent);
    let fapu = Fapu::from_feature_points(&found.feature_point_set()).unwrap();
    let d = fapu.distances;
    eprintln!("ICT FAPU distances (cm): {d:?}");
    // Centimetres: an adult's pupils ~6 cm apart, lids ~1 cm apart when open, mouth ~5 cm.
    for (name, v, lo, hi) in [
        ("ES0", d.es0, 5.5, 7.0),
        ("IRISD0", d.irisd0, 0.6, 1.4),
        ("ENS0", d.ens0, 3.5, 6.0),
        ("MNS0", d.mns0, 1.2, 3.0),
        ("MW0", d.mw0, 4.0, 6.5),
    ] {
        assert!(
            (lo..=hi).contains(&v),
            "{name} = {v} cm, expected {lo}..{hi}"
        );
    }
    let pairs = assert_mirrored(&found, 0.02 * d.es0 as f32);
    assert!(pairs >= 20, "{pairs} mirrored pairs");
    // What fmc needed and ICT's landmarks lacked.
    for id in [
        "2.10", "2.11", "2.12", "2.13", "2.14", "5.1", "5.2", "5.3", "5.4", "9.1", "9.2", "9.12",
    ] {
        assert!(found.get(fp(id)).is_some(), "{id} missing");
    }
    let required = fbakit::clone::fmc::required_feature_points();
    let missing: Vec<_> = required
        .iter()
        .filter(|&&id| found.get(id).is_none())
        .collect();
    assert!(missing.is_empty(), "fmc still lacks {missing:?}");
    // The pupils sit on the eyeballs (ICT vertices 21451-24590), not on the tear film or
    // occlusion shells in front of them.
    for id in ["3.5", "3.6"] {
        let v = found.get(fp(id)).unwrap().vertices[0];
        assert!((21451..=24590).contains(&v), "{id} on vertex {v}");
    }
}

/// Largest displacement of a vertex between two meshes.
fn moved(a: &Mesh, b: &Mesh, v: u32) -> f32 {
    a.positions[v as usize].distance(b.positions[v as usize])
}

#[test]
fn ict_lid_points_follow_the_blink_and_the_chin_the_jaw() {
    let Some((dir, neutral, found)) = ict() else {
        return;
    };
    let pupil = |id: &str| found.get(fp(id)).unwrap().position;
    for (shape, upper, lower, eye) in [
        ("eyeBlink_L.obj", "3.1", "3.3", "3.5"),
        ("eyeBlink_R.obj", "3.2", "3.4", "3.6"),
    ] {
        let blink = mesh(&dir.join(shape));
        let centre = pupil(eye);
        // The lid's own motion: the most any face-skin vertex above (below) the pupil moves
        // within a quarter eye width (0.65 cm) of the lid's centre line (ICT's face part is
        // vertices 0-9408; wider, the lid corners at pupil height would count as the lower
        // lid).
        let lid_max = |above: bool| {
            (0..9409u32)
                .filter(|&v| {
                    let p = neutral.positions[v as usize];
                    (p.x - centre.x).abs() < 0.65 && (p.y > centre.y) == above
                })
                .map(|v| moved(&neutral, &blink, v))
                .fold(0.0f32, f32::max)
        };
        for (id, above) in [(upper, true), (lower, false)] {
            let v = found.get(fp(id)).unwrap().vertices[0];
            let (ours, most) = (moved(&neutral, &blink, v), lid_max(above));
            eprintln!("{shape}: {id} moves {ours:.3} cm of the lid's {most:.3} cm");
            assert!(
                ours >= 0.8 * most,
                "{id} (vertex {v}) moves {ours} under {shape}, the lid up to {most}"
            );
        }
    }
    let jaw = mesh(&dir.join("jawOpen.obj"));
    let chin = found.get(fp("2.1")).unwrap().vertices[0];
    let mns0 = Fapu::from_feature_points(&found.feature_point_set())
        .unwrap()
        .distances
        .mns0 as f32;
    let drop = neutral.positions[chin as usize].y - jaw.positions[chin as usize].y;
    eprintln!("jawOpen drops 2.1 by {drop:.3} cm (MNS0 {mns0:.3})");
    assert!(drop > 0.5 * mns0, "2.1 drops {drop} under jawOpen");
}

#[test]
fn ict_derived_table_snapshot() {
    let Some((_, _, found)) = ict() else { return };
    let mut text = String::new();
    for p in &found.points {
        let v: Vec<String> = p.vertices.iter().map(u32::to_string).collect();
        text.push_str(&format!(
            "{:<5} {:<6} {}\n",
            p.id.to_string(),
            v.join(";"),
            p.provenance
        ));
    }
    insta::assert_snapshot!("ict_ibug68_feature_points", text);
}

#[test]
fn mediapipe_canonical_face_in_vertex_order() {
    let Some(path) = shared("mediapipe-canonical-face/canonical_face_model.obj") else {
        return;
    };
    let m = mesh(&path);
    let ids: Vec<u32> = (0..468).collect();
    let found = feature_points_from_landmarks(&m, LandmarkScheme::MediaPipe468, &ids).unwrap();
    let absent: Vec<String> = found.absent.iter().map(|a| a.id.to_string()).collect();
    // The canonical face is a mask: no skull.
    assert_eq!(absent, vec!["11.4", "11.6"], "{:?}", found.absent);
    // No eyeballs: the pupils are the lid contours' centres.
    assert_eq!(found.get(fp("3.5")).unwrap().vertices.len(), 4);
    let d = Fapu::from_feature_points(&found.feature_point_set())
        .unwrap()
        .distances;
    eprintln!("MediaPipe FAPU distances (cm): {d:?}");
    assert!((5.5..=7.0).contains(&d.es0), "{d:?}");
    assert!(
        d.irisd0 > 0.3 && d.ens0 > 3.0 && d.mns0 > 1.0 && d.mw0 > 4.0,
        "{d:?}"
    );
    // The mesh is exactly symmetric.
    let pairs = assert_mirrored(&found, 0.01 * d.es0 as f32);
    assert!(pairs >= 20, "{pairs}");
    let required = fbakit::clone::fmc::required_feature_points();
    assert!(required.iter().all(|&id| found.get(id).is_some()));
}

#[test]
fn cli_writes_points_that_fapu_and_both_cloners_accept() {
    let Some(dir) = shared("ict-facekit") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let neutral = dir.join("generic_neutral_mesh.obj");
    let ids = dir.join("vertex_indices.json");
    let csv = tmp.path().join("ict-fp.csv");
    let out = fbakit(&[
        "fp",
        "from-landmarks",
        neutral.to_str().unwrap(),
        "--ibug68",
        ids.to_str().unwrap(),
        "-o",
        csv.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = report["points"].as_array().unwrap();
    assert!(points.len() >= 50);
    let lid = points.iter().find(|p| p["id"] == "3.1").unwrap();
    assert_eq!(lid["provenance"]["kind"], "derived");
    assert_eq!(lid["provenance"]["rule"], "upper-lid-margin");
    let chin = points.iter().find(|p| p["id"] == "2.1").unwrap();
    assert_eq!(chin["provenance"]["name"], "iBUG 9");
    let es0 = report["fapu"]["es0"].as_f64().unwrap();
    // The CSV carries the provenance in its description column.
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.contains("landmark iBUG 9"), "{text}");
    assert!(text.contains("derived (upper-lid-margin)"), "{text}");

    // `fbakit fapu` measures the same units on the written file with the mesh.
    let out = fbakit(&[
        "fapu",
        csv.to_str().unwrap(),
        "--mesh",
        neutral.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fapu: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let es = fapu["units"]
        .as_array()
        .unwrap()
        .iter()
        .find(|u| u["fapu"] == "ES")
        .unwrap()["distance"]
        .as_f64()
        .unwrap();
    assert!((es - es0).abs() < 1e-4, "{es} vs {es0}");

    // fbakit XML and Xface .fdp (points on the mesh file's name, the FAPU in its head) are
    // written too and read back.
    let fdp = tmp.path().join("ict-fp.fdp");
    for out_path in [tmp.path().join("ict-fp.xml"), fdp.clone()] {
        let out = fbakit(&[
            "fp",
            "from-landmarks",
            neutral.to_str().unwrap(),
            "--ibug68",
            ids.to_str().unwrap(),
            "-o",
            out_path.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let back = fbakit::fdp::read_feature_points(&out_path).unwrap();
        assert_eq!(back.points.len(), points.len(), "{}", out_path.display());
    }
    let info = fbakit(&[
        "face",
        "info",
        neutral.to_str().unwrap(),
        "--fp",
        fdp.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    // ICT is in cm: its eyes are 6.475 cm apart.
    let es0 = v["fapu"]["units"]["ES"].as_f64().unwrap() * 1024.0;
    assert!((es0 - 6.475).abs() < 0.01, "ES0 {es0}: {v:#}");

    // Both cloning methods accept the ICT neutral with these points (fmc used to refuse it
    // for lack of 2.10-2.14, 5.1-5.4, 9.1, 9.2, 9.12).
    for method in ["fmc", "rbf"] {
        let wrl = tmp.path().join(format!("ict-{method}.wrl"));
        let out = fbakit(&[
            "clone",
            "alma",
            neutral.to_str().unwrap(),
            "--fp-target",
            csv.to_str().unwrap(),
            "--method",
            method,
            "-o",
            wrl.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{method}: {err}");
        assert!(!err.contains("needs these feature points"), "{err}");
        assert!(wrl.exists());
    }
}

#[test]
fn cli_refuses_bad_input_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    // A small mesh with 70 vertices is enough for the count and range checks.
    let mut obj = String::new();
    for i in 0..70 {
        obj.push_str(&format!("v {} {} 0\n", i % 10, i / 10));
    }
    obj.push_str("f 1 2 11\n");
    let mesh = tmp.path().join("m.obj");
    std::fs::write(&mesh, &obj).unwrap();
    let out_csv = tmp.path().join("fp.csv");
    let run = |ids: &str, out: &Path| {
        let p = tmp.path().join("ids.json");
        std::fs::write(&p, ids).unwrap();
        fbakit(&[
            "fp",
            "from-landmarks",
            mesh.to_str().unwrap(),
            "--ibug68",
            p.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
    };
    let list = |f: &dyn Fn(u32) -> u32| {
        let v: Vec<String> = (0..68).map(|i| f(i).to_string()).collect();
        format!("{{\"idx_to_landmark_verts\": [{}]}}", v.join(", "))
    };
    let cases: Vec<(String, &str)> = vec![
        (
            list(&|i| if i == 12 { 70 } else { i }),
            "idx_to_landmark_verts[12]: landmark 12 is vertex 70, beyond the mesh's 70 vertices",
        ),
        (
            list(&|i| if i == 40 { 3 } else { i }),
            "idx_to_landmark_verts[40]: landmark 40 repeats vertex 3 of landmark 3",
        ),
        (
            "[1, 2, 3]".to_string(),
            "expected 68 landmark vertex ids, found 3",
        ),
        (
            list(&|i| i).replace("[0,", "[-1,"),
            "idx_to_landmark_verts[0]: expected a vertex index",
        ),
    ];
    for (ids, message) in cases {
        let out = run(&ids, &out_csv);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(message), "expected `{message}` in {err}");
        assert!(err.contains("ids.json"), "{err}");
        assert!(!out_csv.exists());
    }
    // Unknown extensions are refused before anything is read.
    for name in ["fp.txt", "fp.fdp.txt"] {
        let out = run("[1]", &tmp.path().join(name));
        assert_eq!(out.status.code(), Some(2));
        assert!(!tmp.path().join(name).exists());
    }
    // A NaN in the mesh is named by line and column.
    std::fs::write(&mesh, "v 0 0 0\nv nan 1 0\nv 1 1 0\nf 1 2 3\n").unwrap();
    let out = run(&list(&|i| i), &out_csv);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("m.obj:2:3"), "{err}");
    // MediaPipe in vertex order needs 468 vertices.
    std::fs::write(&mesh, &obj).unwrap();
    let out = fbakit(&[
        "fp",
        "from-landmarks",
        mesh.to_str().unwrap(),
        "--mediapipe468",
        "-o",
        out_csv.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("has 70 vertices") && err.contains("468"),
        "{err}"
    );
    assert!(!out_csv.exists());
}
