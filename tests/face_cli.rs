//! `fbakit face ...`, `fbakit candide`, `fbakit sample` through the real binary: snapshots of
//! `face info`, exit codes, conversions, morph-set round trips, hostile inputs; and the
//! committed sample faces against the generator.

use std::path::{Path, PathBuf};
use std::process::Output;

use fbakit::face::read_with;
use fbakit::fat::{Fat, TableKey};

mod support;
use support::cli::fbakit;

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn candide_data() -> Option<PathBuf> {
    let d = root().join("../shared/data/candide3");
    if d.join("candide3.wfm").exists() {
        Some(d)
    } else {
        eprintln!("note: {} absent; CANDIDE tests skipped", d.display());
        None
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn committed_sample_faces_match_the_generator() {
    for (file, synth) in [
        ("alma.wrl.gz", fbakit::synth::alma as fn() -> _),
        ("bruno.wrl.gz", fbakit::synth::bruno),
    ] {
        let (read, report) =
            read_with(root().join("samples/faces").join(file), &Default::default()).unwrap();
        assert!(
            report.diagnostics.is_empty(),
            "{file}: {:?}",
            report.diagnostics
        );
        let fresh = synth().to_face_model();
        assert!(
            read == fresh,
            "samples/faces/{file} differs from the generator; regenerate it (see samples/faces/README.md)"
        );
    }
}

#[test]
fn info_snapshots_alma() {
    let o = fbakit(&["face", "info", "samples/faces/alma.wrl.gz"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    insta::assert_snapshot!("info_alma", stdout(&o));
    let o = fbakit(&["face", "info", "samples/faces/alma.wrl.gz", "--json"]);
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    insta::assert_json_snapshot!("info_alma_json", v);
}

#[test]
fn candide_face_info_snapshots_and_validates() {
    let Some(d) = candide_data() else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("candide.wrl");
    let o = fbakit(&[
        "candide",
        s(&d.join("candide3.wfm")),
        "--fp",
        s(&d.join("feature-points.csv")),
        "--shape",
        "Mouth width=0.3,Eyes, width=0.2",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("FAPs 23, 24, 25, 26, 27, 28, 29, 30"));
    let o = fbakit(&["face", "info", s(&out)]);
    assert_eq!(o.status.code(), Some(0));
    insta::assert_snapshot!("info_candide", stdout(&o));
    let o = fbakit(&["face", "info", s(&out), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    insta::assert_json_snapshot!("info_candide_json", v);
    let o = fbakit(&["face", "validate", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    // Bad shape spec: exit 2 naming the valid names.
    let o = fbakit(&[
        "candide",
        s(&d.join("candide3.wfm")),
        "--fp",
        s(&d.join("feature-points.csv")),
        "--shape",
        "Nose size=1",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unknown shape unit `Nose size`"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn validate_exit_codes() {
    let o = fbakit(&["face", "validate", "samples/faces/alma.wrl.gz"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(stdout(&o).ends_with("alma.wrl.gz: valid\n"));

    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.wrl");
    std::fs::write(
        &bad,
        "#VRML V2.0 utf8\nShape { geometry DEF m IndexedFaceSet {\n  coord Coordinate { point [0 0 0, 1 0 0, 0 1 0] }\n  coordIndex [0 1 7 -1]\n} }\n",
    )
    .unwrap();
    let o = fbakit(&["face", "validate", s(&bad)]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(
        stdout(&o).contains("coordIndex value(s) beyond its 3 points"),
        "{}",
        stdout(&o)
    );
    assert!(stdout(&o).contains("bad.wrl:2:"), "{}", stdout(&o));

    std::fs::write(
        &bad,
        "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord [",
    )
    .unwrap();
    let o = fbakit(&["face", "validate", s(&bad)]);
    assert_eq!(o.status.code(), Some(2));
    let o = fbakit(&["face", "validate", "no/such/face.wrl"]);
    assert_eq!(o.status.code(), Some(2));
    let o = fbakit(&["face", "validate", "samples/speech.fap"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("not a face file fbakit recognises"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn convert_between_formats() {
    let dir = tempfile::tempdir().unwrap();
    let wrl = dir.path().join("alma.wrl");
    let o = fbakit(&["face", "convert", "samples/faces/alma.wrl.gz", s(&wrl)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (a, _) = read_with(&wrl, &Default::default()).unwrap();
    assert!(a == fbakit::synth::alma().to_face_model());

    // To OBJ (merged, face coordinates) plus the merged feature points, and back.
    let obj = dir.path().join("alma.obj");
    let o = fbakit(&["face", "convert", s(&wrl), s(&obj)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let csv = dir.path().join("alma.csv");
    fbakit::fdp::csv::write_csv_file(
        &csv,
        &fbakit::fdp::csv::FeaturePointTable::from_set(
            &fbakit::face::morphs::merged_feature_points(&a),
        ),
    )
    .unwrap();
    let back = dir.path().join("back.wrl");
    let o = fbakit(&["face", "convert", s(&obj), s(&back), "--fp", s(&csv)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (b, _) = read_with(&back, &Default::default()).unwrap();
    assert_eq!(b.meshes.len(), 1);
    assert_eq!(b.vertex_count(), a.vertex_count());
    // Same feature-point positions (up to float rounding of the transforms), same FAPU.
    for p in a.feature_points.iter() {
        let q = b.feature_points.position(p.id).unwrap();
        assert!((q - p.position.unwrap()).length() < 1e-4, "{}", p.id);
    }
    let (fa, fb) = (a.fapu().unwrap(), b.fapu().unwrap());
    for k in fbakit::spec::FapuKind::ALL {
        assert!((fa.unit(k) - fb.unit(k)).abs() < 1e-6, "{k:?}");
    }
    // OBJ info with matched (position-only) points reports the distances.
    let xml = dir.path().join("pos.xml");
    std::fs::write(
        &xml,
        r#"<featurePoints version="1"><point id="2.1" x="0" y="-70" z="60"/><point id="9.3" x="0" y="-10" z="100"/></featurePoints>"#,
    )
    .unwrap();
    let o = fbakit(&["face", "info", s(&obj), "--fp", s(&xml), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["fp_matches"]["count"].as_u64().unwrap() > 0, "{v}");
}

/// Compares two FATs: same keys, borders and moved vertices, rates equal within `rel` of the
/// table's largest rate.
fn assert_fat_close(a: &Fat, b: &Fat, rel: f32) {
    assert_eq!(a.keys(), b.keys());
    for key in a.keys() {
        let (ta, tb) = (a.table(key).unwrap(), b.table(key).unwrap());
        assert_eq!(ta.meshes.len(), tb.meshes.len(), "{key}");
        for (ma, mb) in ta.meshes.iter().zip(&tb.meshes) {
            assert_eq!(ma.interval_borders, mb.interval_borders, "{key}");
            // Morph sets list moved vertices in index order; compare per vertex.
            let n = ma.interval_count();
            let rows = |m: &fbakit::fat::FaceDefMesh| {
                let mut r: Vec<(u32, Vec<glam::Vec3>)> = (0..m.coord_index.len())
                    .map(|k| {
                        (
                            m.coord_index[k],
                            m.displacements[k * n..(k + 1) * n].to_vec(),
                        )
                    })
                    .collect();
                r.sort_by_key(|x| x.0);
                r
            };
            let (ra, rb) = (rows(ma), rows(mb));
            let va: Vec<u32> = ra.iter().map(|x| x.0).collect();
            let vb: Vec<u32> = rb.iter().map(|x| x.0).collect();
            assert_eq!(va, vb, "{key}");
            let max = ma
                .displacements
                .iter()
                .map(|d| d.length())
                .fold(0.0, f32::max);
            for ((_, da), (_, db)) in ra.iter().zip(&rb) {
                for (x, y) in da.iter().zip(db) {
                    assert!((*x - *y).length() <= rel * max, "{key}: {x} vs {y}");
                }
            }
        }
    }
}

#[test]
fn morph_set_round_trip_on_candide() {
    let Some(d) = candide_data() else { return };
    let dir = tempfile::tempdir().unwrap();
    let face = dir.path().join("c.wrl");
    let o = fbakit(&[
        "candide",
        s(&d.join("candide3.wfm")),
        "--fp",
        s(&d.join("feature-points.csv")),
        "-o",
        s(&face),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let morphs = dir.path().join("morphs");
    let o = fbakit(&["face", "to-morphs", s(&face), s(&morphs)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Borders 0 1024 are not the default 512: the value is in the name.
    assert!(morphs.join("open_jaw@1024.obj").exists());
    let rebuilt = dir.path().join("r.wrl");
    let o = fbakit(&[
        "face",
        "from-morphs",
        s(&morphs.join("neutral.obj")),
        s(&morphs),
        "--fp",
        s(&morphs.join("feature-points.csv")),
        "--tolerance",
        "0",
        "-o",
        s(&rebuilt),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (a, _) = read_with(&face, &Default::default()).unwrap();
    let (b, _) = read_with(&rebuilt, &Default::default()).unwrap();
    assert_fat_close(&a.fat, &b.fat, 1e-5);
    assert_eq!(a.fapu().unwrap(), b.fapu().unwrap());
}

#[test]
fn morph_set_round_trip_on_a_skin_only_synthetic_face() {
    // alma's skin with its skin-only FAPs (no transforms): bidirectional tables come back as
    // two morphs (-1024, 1024) and rebuild the same two-interval tables.
    let mut face = fbakit::synth::alma().to_face_model();
    face.meshes.truncate(1);
    face.meshes[0].transform = None;
    face.transforms.clear();
    face.feature_points = face
        .feature_points
        .iter()
        .filter(|p| {
            p.binding
                .as_ref()
                .is_some_and(|b| b.mesh.as_deref() == Some("skin"))
        })
        .cloned()
        .collect();
    face.fat.tables.retain(|t| {
        matches!(t.key, TableKey::LowLevel(_))
            && t.transforms.is_empty()
            && t.meshes.iter().all(|m| m.mesh == "skin")
            && !t.meshes.is_empty()
    });
    assert!(face.fat.tables.len() > 30);
    let dir = tempfile::tempdir().unwrap();
    let wrl = dir.path().join("skin.wrl");
    fbakit::face::write(&wrl, &face).unwrap();
    let morphs = dir.path().join("m");
    let o = fbakit(&["face", "to-morphs", s(&wrl), s(&morphs)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = dir.path().join("back.wrl.gz");
    let o = fbakit(&[
        "face",
        "from-morphs",
        s(&morphs.join("neutral.obj")),
        s(&morphs),
        "--fp",
        s(&morphs.join("feature-points.csv")),
        "--tolerance",
        "0",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (b, _) = read_with(&out, &Default::default()).unwrap();
    // Vertices whose motion is below float resolution at the reference value cannot come
    // back; compare on evaluation instead of structure for those tables.
    let mut ea = face.evaluator().unwrap();
    let mut eb = b.evaluator().unwrap();
    let (mut oa, mut ob) = (ea.output(), eb.output());
    for key in face.fat.keys() {
        for p in [-700.0, 300.0, 1024.0] {
            let act = [fbakit::fat::eval::Activation { key, value: p }];
            ea.evaluate(&act, &mut oa);
            eb.evaluate(&act, &mut ob);
            let max = oa.displacements[0]
                .iter()
                .map(|d| d.length())
                .fold(0.0, f32::max);
            for (x, y) in oa.displacements[0].iter().zip(&ob.displacements[0]) {
                assert!((*x - *y).length() <= 1e-5 * max.max(1e-3), "{key} at {p}");
            }
        }
        let (ta, tb) = (face.fat.table(key).unwrap(), b.fat.table(key).unwrap());
        assert_eq!(
            ta.meshes[0].interval_borders, tb.meshes[0].interval_borders,
            "{key}"
        );
    }
    // --value writes one file per table with the value in its name.
    let single = dir.path().join("single");
    let o = fbakit(&["face", "to-morphs", s(&wrl), s(&single), "--value", "-300"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(single.join("raise_b_midlip@-300.obj").exists());
}

#[test]
fn hostile_inputs_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    // Not gzip / truncated gzip.
    std::fs::write(p("junk.wrl.gz"), b"\x1f\x8b\x08\x00garbage").unwrap();
    let o = fbakit(&["face", "info", s(&p("junk.wrl.gz"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("junk.wrl.gz"), "{}", stderr(&o));
    let gz = std::fs::read(root().join("samples/faces/alma.wrl.gz")).unwrap();
    std::fs::write(p("cut.wrl.gz"), &gz[..gz.len() / 3]).unwrap();
    let o = fbakit(&["face", "info", s(&p("cut.wrl.gz"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));

    // OBJ + feature points that do not fit it.
    std::fs::write(p("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(p("fp.csv"), "fp,vertices\n2.1,1\n9.3,5;7\n").unwrap();
    let o = fbakit(&["face", "info", s(&p("tri.obj")), "--fp", s(&p("fp.csv"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // The file and line, the point, the vertex and the mesh's range.
    let e = stderr(&o);
    assert!(e.contains("fp.csv:3:"), "{e}");
    assert!(
        e.contains("feature point 9.3") && e.contains("vertex 5"),
        "{e}"
    );
    assert!(e.contains("ids 0 to 2"), "{e}");

    // Morph folder with junk: a text file is ignored; unknown names, other topologies and
    // non-OBJ content named .obj are errors naming the file.
    let m = p("morphs");
    std::fs::create_dir(&m).unwrap();
    std::fs::write(p("ok.csv"), "fp,vertices\n2.1,1\n").unwrap();
    std::fs::write(m.join("notes.txt"), "hello").unwrap();
    std::fs::write(
        m.join("open_jaw.obj"),
        "v 0 -1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let run = || {
        fbakit(&[
            "face",
            "from-morphs",
            s(&p("tri.obj")),
            s(&m),
            "--fp",
            s(&p("ok.csv")),
            "-o",
            s(&p("out.wrl")),
        ])
    };
    let o = run();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("ignored"), "{}", stderr(&o));
    let (f, _) = read_with(p("out.wrl"), &Default::default()).unwrap();
    assert_eq!(f.fat.tables[0].meshes[0].coord_index, vec![0]);

    std::fs::write(m.join("open_jaws.obj"), "v 0 0 0\n").unwrap();
    let o = run();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("open_jaws.obj: `open_jaws` is not a FAP name"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_file(m.join("open_jaws.obj")).unwrap();

    std::fs::write(
        m.join("joy.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let o = run();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("joy.obj: has 4 vertices, the neutral has 3"),
        "{}",
        stderr(&o)
    );

    std::fs::write(m.join("joy.obj"), [0u8, 159, 146, 150, 255]).unwrap();
    let o = run();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("joy.obj"), "{}", stderr(&o));
    std::fs::remove_file(m.join("joy.obj")).unwrap();

    std::fs::write(m.join("open_jaw@nan.obj"), "v 0 0 0\n").unwrap();
    let o = run();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("finite, non-zero"), "{}", stderr(&o));
    std::fs::remove_file(m.join("open_jaw@nan.obj")).unwrap();

    // Same key and value twice.
    std::fs::copy(m.join("open_jaw.obj"), m.join("open_jaw@512.obj")).unwrap();
    let o = run();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("both show FAP 3 open_jaw at value 512"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_file(m.join("open_jaw@512.obj")).unwrap();

    // Manifest: bad values and names of no file.
    std::fs::write(p("m.json"), r#"{"open_jaw": 0}"#).unwrap();
    let (tri, okcsv, outw, mj) = (p("tri.obj"), p("ok.csv"), p("out.wrl"), p("m.json"));
    let args = [
        "face",
        "from-morphs",
        s(&tri),
        s(&m),
        "--fp",
        s(&okcsv),
        "-o",
        s(&outw),
        "--manifest",
        s(&mj),
    ];
    let o = fbakit(&args);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("not a finite, non-zero FAP value"),
        "{}",
        stderr(&o)
    );
    std::fs::write(p("m.json"), r#"{"open_jaw": 1024, "joy": 63}"#).unwrap();
    let o = fbakit(&args);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("`joy` names no morph file"),
        "{}",
        stderr(&o)
    );
    std::fs::write(p("m.json"), r#"{"open_jaw": 1024}"#).unwrap();
    let o = fbakit(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (f, _) = read_with(p("out.wrl"), &Default::default()).unwrap();
    assert_eq!(
        f.fat.tables[0].meshes[0].interval_borders,
        vec![0.0, 1024.0]
    );
}
