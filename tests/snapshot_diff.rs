//! `fbakit::snapshot` and its commands: faces and FAP streams compared within a tolerance
//! (perturbed below and above it), snapshots of the bundled faces pinned with insta, the
//! snapshot's guarantee, and the exit codes and JSON contract of `face diff`,
//! `face snapshot` and `fap diff`.

mod support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use fbakit::face::FaceModel;
use fbakit::fat::TableKey;
use fbakit::snapshot::{
    diff, fap_diff, snapshot, try_diff, try_snapshot, DiffOptions, FapDiffOptions, Side,
    SnapshotOptions, Tolerance, VertexMatch,
};
use glam::{Mat3, Vec3};
use support::cli::{fbakit, text};

fn alma() -> &'static FaceModel {
    static FACE: OnceLock<FaceModel> = OnceLock::new();
    FACE.get_or_init(|| fbakit::face::read("alma").unwrap())
}

fn key(name: &str) -> TableKey {
    TableKey::from_name(name).unwrap()
}

/// Changes the first vertex of `key`'s first mesh entry so its face-frame displacement
/// moves by `delta` along the face's x axis at the table's largest compared value: every
/// interval rate gets the same change, and the weights of `[0, p]` sum to `p`, so the
/// displacement changes by `p ×` that change. Returns the global vertex index changed.
fn perturb(face: &mut FaceModel, name: &str, delta: f64) -> u32 {
    let k = key(name);
    let frames = face.frames();
    let reference = fbakit::fat::morph::default_value(k);
    let table = face.fat.tables.iter_mut().find(|t| t.key == k).unwrap();
    let m = table
        .meshes
        .iter_mut()
        .find(|m| !m.coord_index.is_empty())
        .expect("a mesh entry");
    let p_max = m
        .interval_borders
        .iter()
        .map(|b| b.abs())
        .fold(reference.abs(), f64::max);
    let mesh = face.meshes.iter().position(|x| x.name == m.mesh).unwrap();
    let linear = Mat3::from(frames.meshes[mesh].matrix3);
    let change = linear.inverse() * Vec3::new((delta / p_max) as f32, 0.0, 0.0);
    let n = m.interval_count();
    for r in &mut m.displacements[..n] {
        *r += change;
    }
    let offset: usize = face.meshes[..mesh]
        .iter()
        .map(|x| x.mesh.vertex_count())
        .sum();
    (offset + m.coord_index[0] as usize) as u32
}

fn abs(tol: f64) -> DiffOptions {
    DiffOptions {
        tolerance: Tolerance::Absolute(tol),
        ..DiffOptions::default()
    }
}

#[test]
fn a_face_equals_itself_and_its_vrml_round_trip() {
    let a = alma();
    let report = diff(a, a, &DiffOptions::default());
    assert!(report.is_equal(), "{report}");
    assert!(report.tables.iter().all(|t| t.max_difference == 0.0));
    assert_eq!(report.tables.len(), a.fat.keys().len());

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("alma.wrl");
    fbakit::face::write(&path, a).unwrap();
    let back = fbakit::face::read(&path).unwrap();
    let report = diff(a, &back, &DiffOptions::default());
    assert!(report.is_equal(), "{report}");
    // The snapshot too: VRML keeps the topology and writes shortest round-trip floats.
    let opts = SnapshotOptions::default();
    assert_eq!(snapshot(a, &opts), snapshot(&back, &opts));
}

#[test]
fn one_table_perturbed_below_the_tolerance_is_equal_and_above_it_is_not() {
    let tol = 1e-3;
    let mut below = alma().clone();
    perturb(&mut below, "open_jaw", 0.5 * tol);
    let report = diff(alma(), &below, &abs(tol));
    assert!(report.is_equal(), "{report}");
    let jaw = report
        .tables
        .iter()
        .find(|t| t.table == "open_jaw")
        .unwrap();
    assert!(
        (jaw.max_difference - 0.5 * tol).abs() < 1e-3 * tol,
        "{}",
        jaw.max_difference
    );

    let mut above = alma().clone();
    let vertex = perturb(&mut above, "open_jaw", 2.0 * tol);
    let report = diff(alma(), &above, &abs(tol));
    assert!(!report.is_equal());
    let worst = report.worst_table().expect("a differing table");
    assert_eq!(worst.table, "open_jaw");
    assert_eq!(worst.fap, Some(3));
    assert_eq!(worst.only_in, None);
    assert!(
        (worst.max_difference - 2.0 * tol).abs() < 1e-3 * tol,
        "{}",
        worst.max_difference
    );
    assert_eq!(worst.differing_vertices, 1);
    assert_eq!(worst.worst_vertex, Some(vertex));
    // open_jaw moves in MNS units: the FAPU figure is the difference over one unit.
    let mns = alma().fapu().unwrap().unit(fbakit::spec::FapuKind::Mns);
    let fapu = worst.max_difference_fapu.unwrap();
    assert!((fapu - worst.max_difference / mns).abs() < 1e-9 * fapu);
    // Only that table differs, and it comes first.
    assert_eq!(report.differing_tables().count(), 1);
    assert!(report.neutral.equal && report.feature_points.equal && report.fapu.equal);
    let text = report.to_string();
    assert!(text.starts_with("DIFFERENT:"), "{text}");
    assert!(text.contains("worst table: open_jaw (FAP 3)"), "{text}");
}

#[test]
fn relative_tolerances_are_of_face_a_size() {
    let a = alma();
    let report = diff(a, a, &DiffOptions::default());
    let size = report.tolerance.face_size;
    assert!(size > 0.0);
    assert!((report.tolerance.absolute - 1e-4 * size).abs() < 1e-12 * size);
    assert_eq!(report.tolerance.given, "0.0001x");
}

#[test]
fn tables_only_in_one_face_are_listed_once_and_first() {
    let a = alma();
    let mut b = a.clone();
    b.fat.tables.retain(|t| t.key != key("joy"));
    let report = diff(a, &b, &DiffOptions::default());
    assert!(!report.is_equal());
    let json = serde_json::to_value(&report).unwrap();
    let tables = json["tables"].as_array().unwrap();
    let mut names: Vec<&str> = tables
        .iter()
        .map(|t| t["table"].as_str().unwrap())
        .collect();
    assert_eq!(tables[0]["table"], "joy");
    assert_eq!(tables[0]["only_in"], "a");
    assert_eq!(tables[0]["fap"], serde_json::Value::Null);
    assert_eq!(tables[0]["equal"], false);
    assert!(tables[1..]
        .iter()
        .all(|t| t["equal"] == true && t["only_in"].is_null()));
    let n = names.len();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), n, "every table once");
    assert_eq!(n, a.fat.keys().len());
    // The contract's other fields.
    for field in [
        "equal",
        "tolerance",
        "tables",
        "neutral",
        "feature_points",
        "fapu",
    ] {
        assert!(json.get(field).is_some(), "{field}");
    }
    let jaw = tables.iter().find(|t| t["table"] == "open_jaw").unwrap();
    assert_eq!(jaw["fap"], 3);
    for field in [
        "max_difference",
        "max_difference_fapu",
        "mean_difference",
        "differing_vertices",
    ] {
        assert!(jaw.get(field).is_some(), "{field}");
    }
    // Swapped, the table is only in B.
    let report = diff(&b, a, &DiffOptions::default());
    assert_eq!(report.worst_table().unwrap().only_in, Some(Side::B));
}

#[test]
fn different_layouts_are_refused_unless_matched_by_nearest_vertex() {
    let a = alma();
    let dense =
        fbakit::face::subdivide::subdivide_face(a, fbakit::mesh::subdivide::Scheme::Midpoint, 1)
            .unwrap();
    let e = try_diff(a, &dense, &DiffOptions::default()).unwrap_err();
    assert!(e.is_input_error());
    assert!(e.to_string().contains("--match nearest"), "{e}");
    // Midpoint subdivision keeps the original vertices and carries the FAT exactly: by
    // nearest vertex, the animation is the same.
    let opts = DiffOptions {
        vertex_match: VertexMatch::Nearest,
        ..DiffOptions::default()
    };
    let report = diff(a, &dense, &opts);
    assert!(report.tables.iter().all(|t| t.equal), "{report}");
    // And a real change still shows through the nearest pairing.
    let mut changed = dense.clone();
    let tol = report.tolerance.absolute;
    perturb(&mut changed, "stretch_l_cornerlip", 3.0 * tol);
    let report = diff(a, &changed, &opts);
    let worst = report.worst_table().expect("differs");
    assert_eq!(worst.table, "stretch_l_cornerlip");
}

#[test]
fn faces_without_a_fat_and_bad_tolerances_are_input_errors() {
    let mut bare = alma().clone();
    bare.fat = Default::default();
    let e = try_diff(alma(), &bare, &DiffOptions::default()).unwrap_err();
    assert!(
        e.is_input_error() && e.to_string().contains("no FAT"),
        "{e}"
    );
    let e = try_snapshot(&bare, &SnapshotOptions::default()).unwrap_err();
    assert!(e.is_input_error(), "{e}");
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = try_diff(alma(), alma(), &abs(bad)).unwrap_err();
        assert!(e.to_string().contains("--tolerance"), "{e}");
    }
    // The test-friendly forms never fail: they give a report that is not equal, or a text
    // no reviewed snapshot matches, naming the problem.
    let report = diff(alma(), &bare, &DiffOptions::default());
    assert!(!report.is_equal());
    assert!(
        report.problem.as_deref().unwrap().contains("no FAT"),
        "{report}"
    );
    assert!(report.to_string().starts_with("NOT COMPARED: "), "{report}");
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["equal"], false);
    assert!(json["problem"].as_str().unwrap().contains("no FAT"));
    let report = diff(alma(), alma(), &abs(f64::NAN));
    assert!(
        !report.is_equal() && report.to_string().contains("--tolerance"),
        "{report}"
    );
    let text = snapshot(&bare, &SnapshotOptions::default());
    assert!(
        text.starts_with("error: \"") && text.contains("no FAT"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 1);
}

/// The two lines issue 20 promises a pipeline's test can be: a reviewed snapshot of a face's
/// FAT, and a diff against a reference face, both without error handling.
#[test]
fn a_pipeline_pins_its_fat_in_one_line() {
    let face = fbakit::face::read("alma").unwrap();
    insta::assert_snapshot!(fbakit::snapshot::snapshot(&face, &Default::default()));

    let (a, mut b) = (face.clone(), face.clone());
    let opts = DiffOptions::default();
    let report = diff(&a, &b, &opts);
    assert!(diff(&a, &b, &opts).is_equal(), "{report}");
    perturb(&mut b, "open_jaw", 1.0);
    let report = diff(&a, &b, &opts);
    assert!(!report.is_equal(), "{report}");
    assert_eq!(report.worst_table().unwrap().table, "open_jaw");
    assert!(report.problem.is_none());
}

#[test]
fn bundled_face_snapshots() {
    let opts = SnapshotOptions::default();
    insta::assert_snapshot!("alma_fat", snapshot(alma(), &opts));
    let bruno = fbakit::face::read("bruno").unwrap();
    insta::assert_snapshot!("bruno_fat", snapshot(&bruno, &opts));
}

#[test]
fn a_change_above_the_tolerance_always_changes_the_snapshot() {
    let opts = SnapshotOptions {
        tolerance: Tolerance::Absolute(1e-3),
    };
    let before = snapshot(alma(), &opts);
    for name in ["open_jaw", "raise_b_midlip", "viseme_3", "joy"] {
        let mut changed = alma().clone();
        perturb(&mut changed, name, 1.01e-3);
        let after = snapshot(&changed, &opts);
        assert_ne!(before, after, "{name}");
        // Only that table's lines change.
        let differing: Vec<(&str, &str)> = before
            .lines()
            .zip(after.lines())
            .filter(|(x, y)| x != y)
            .collect();
        assert!(
            !differing.is_empty() && differing.len() <= 4,
            "{name}: {differing:?}"
        );
    }
}

#[test]
fn snapshots_are_identical_across_thread_counts() {
    let opts = SnapshotOptions::default();
    let texts: Vec<String> = [1, 2, 8]
        .into_iter()
        .map(|n| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap();
            pool.install(|| snapshot(alma(), &opts))
        })
        .collect();
    assert_eq!(texts[0], texts[1]);
    assert_eq!(texts[0], texts[2]);
}

fn stream(path: &str) -> fbakit::fap::FapStream {
    fbakit::fap::read_stream_file(path, &fbakit::fap::ReadOptions::lenient())
        .unwrap()
        .0
}

#[test]
fn fap_streams_perturbed_below_and_above_the_tolerance() {
    let a = stream("samples/lowlevel.fap");
    let report = fap_diff(&a, &a, &FapDiffOptions::default()).unwrap();
    assert!(report.is_equal(), "{report}");

    let change = |delta: f64| {
        let mut b = a.clone();
        let frame = b
            .frames
            .iter_mut()
            .find(|f| f.low_level().next().is_some())
            .unwrap();
        let (fap, v) = frame.low_level().next().unwrap();
        frame.set(fap, v + delta);
        (b, fap)
    };
    let (b, _) = change(0.4);
    assert!(fap_diff(&a, &b, &FapDiffOptions::default())
        .unwrap()
        .is_equal());
    let (b, fap) = change(3.0);
    let report = fap_diff(&a, &b, &FapDiffOptions::default()).unwrap();
    assert!(!report.is_equal());
    let worst = &report.faps[0];
    assert_eq!(worst.fap, fap.number());
    assert!(!worst.equal);
    assert!((worst.max_difference - 3.0).abs() < 1e-9);
    assert!(worst.differing_frames >= 1);
    assert!(report.to_string().starts_with("DIFFERENT:"));

    // A stream at another rate differs as a whole.
    let mut c = a.clone();
    c.frame_rate *= 2.0;
    assert!(!fap_diff(&a, &c, &FapDiffOptions::default())
        .unwrap()
        .is_equal());
}

#[test]
fn cli_face_diff_exit_codes_and_json() {
    let ok = fbakit(&["face", "diff", "alma", "samples/faces/alma.wrl.gz"]);
    assert_eq!(ok.status.code(), Some(0), "{}", text(&ok.stderr));
    assert!(text(&ok.stdout).starts_with("EQUAL:"));

    let dir = tempfile::tempdir().unwrap();
    let mut changed = alma().clone();
    perturb(&mut changed, "open_jaw", 0.01);
    let path = dir.path().join("changed.wrl");
    fbakit::face::write(&path, &changed).unwrap();
    let p = path.to_str().unwrap();
    let out = fbakit(&["face", "diff", "alma", p, "--tolerance", "0.001", "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["equal"], false);
    assert_eq!(json["tables"][0]["table"], "open_jaw");
    assert_eq!(json["tolerance"]["absolute"], 0.001);

    let layouts = fbakit(&["face", "diff", "alma", "bruno"]);
    assert_eq!(layouts.status.code(), Some(2));
    assert!(text(&layouts.stderr).contains("--match nearest"));
    let nearest = fbakit(&["face", "diff", "alma", "bruno", "--match", "nearest"]);
    assert_eq!(nearest.status.code(), Some(1), "{}", text(&nearest.stderr));

    let bad = fbakit(&["face", "diff", "alma", "alma", "--tolerance", "-1"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        text(&bad.stderr).contains("--tolerance"),
        "{}",
        text(&bad.stderr)
    );
    let missing = fbakit(&["face", "diff", "alma", "no/such/face.wrl"]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing.stderr).contains("no/such/face.wrl"));
}

#[test]
fn cli_face_snapshot_and_fap_diff() {
    let out = fbakit(&["face", "snapshot", "alma"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        text(&out.stdout),
        snapshot(alma(), &SnapshotOptions::default())
    );
    let json = fbakit(&["face", "snapshot", "alma", "--json", "--tolerance", "0.01"]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(v["grid"], 0.01);
    assert!(v["tables"].as_array().unwrap().len() > 60);

    let obj = fbakit(&["face", "snapshot", "tests/data/no-such.obj"]);
    assert_eq!(obj.status.code(), Some(2));

    let same = fbakit(&["fap", "diff", "samples/speech.fap", "samples/speech.fap"]);
    assert_eq!(same.status.code(), Some(0), "{}", text(&same.stderr));
    let other = fbakit(&[
        "fap",
        "diff",
        "samples/speech.fap",
        "samples/lowlevel.fap",
        "--json",
    ]);
    assert_eq!(other.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&other.stdout).unwrap();
    assert_eq!(v["equal"], false);
    let bad = fbakit(&[
        "fap",
        "diff",
        "samples/speech.fap",
        "samples/speech.fap",
        "--tolerance",
        "nan",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(text(&bad.stderr).contains("--tolerance"));
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(8))]

    /// The snapshot's promise on a whole face: any one displacement changed by more than the
    /// tolerance changes the text (in that table's lines only).
    #[test]
    fn any_change_above_the_tolerance_changes_the_snapshot(
        table in 0usize..86, factor in 1.001f64..20.0, tol in 1e-3f64..1e-1
    ) {
        // Keys with vertex motion (eyeball rotations drive transforms only).
        let keys: Vec<TableKey> = alma()
            .fat
            .keys()
            .into_iter()
            .filter(|k| {
                alma().fat.tables.iter().any(|t| t.key == *k && t.meshes.iter().any(|m| !m.coord_index.is_empty()))
            })
            .collect();
        let name = keys[table % keys.len()].name();
        let opts = SnapshotOptions { tolerance: Tolerance::Absolute(tol) };
        let before = snapshot(alma(), &opts);
        let mut changed = alma().clone();
        perturb(&mut changed, &name, factor * tol);
        let after = snapshot(&changed, &opts);
        proptest::prop_assert_ne!(&before, &after, "{}", name);
        let table_line = format!("  - table: \"{name}\"");
        let section = |text: &str| {
            let start = text.find(&table_line).unwrap();
            let end = text[start + 1..]
                .find("  - table:")
                .map_or(text.len(), |e| start + 1 + e);
            (start, end)
        };
        let ((sb, eb), (sa, ea)) = (section(&before), section(&after));
        proptest::prop_assert_eq!(&before[..sb], &after[..sa]);
        proptest::prop_assert_eq!(&before[eb..], &after[ea..]);
    }
}

/// `face` written as `format` and read back: `.wrl`, `.wrl.gz`, `.glb`, `.gltf`, or an OBJ
/// morph set (`morphs`, which merges the meshes: a new layout). Returns the face and the path
/// the CLI reads it from.
fn through(face: &FaceModel, format: &str, dir: &Path, tag: &str) -> (FaceModel, PathBuf) {
    if format == "morphs" {
        let set = dir.join(format!("{tag}-morphs"));
        fbakit::face::morphs::write_morph_set(face, &set, None).unwrap();
        let options = fbakit::face::morphs::MorphSetOptions {
            feature_points: Some(set.join("feature-points.csv")),
            manifest: None,
            tolerance: None,
        };
        let back =
            fbakit::face::morphs::face_from_morph_set(&set.join("neutral.obj"), &set, &options)
                .unwrap()
                .0;
        return (back, set);
    }
    let path = dir.join(format!("{tag}.{format}"));
    fbakit::export::write_face(&path, face).unwrap();
    (fbakit::face::read(&path).unwrap(), path)
}

/// Issue 20: every pair of formats fbakit writes FATs in, one table perturbed by half and by
/// twice the tolerance on the way: equal, then different with that table named first and its
/// figure right. OBJ morph sets merge meshes, so pairs with one are matched by nearest vertex
/// and differ in structure (meshes, transforms) while every table agrees.
#[test]
fn every_format_pair_sees_a_perturbation_above_the_tolerance_only() {
    let tol = 1e-3;
    let dir = tempfile::tempdir().unwrap();
    let formats = ["wrl", "wrl.gz", "glb", "gltf", "morphs"];
    let mut below = alma().clone();
    perturb(&mut below, "open_jaw", 0.5 * tol);
    let mut above = alma().clone();
    perturb(&mut above, "open_jaw", 2.0 * tol);
    for a_format in formats {
        let (a, _) = through(alma(), a_format, dir.path(), &format!("a-{a_format}"));
        for b_format in formats {
            let pair = format!("{a_format} vs {b_format}");
            let options = DiffOptions {
                tolerance: Tolerance::Absolute(tol),
                vertex_match: if a_format == "morphs" || b_format == "morphs" {
                    VertexMatch::Nearest
                } else {
                    VertexMatch::Index
                },
            };
            let tag = format!("{a_format}-{b_format}");
            let (b, _) = through(&below, b_format, dir.path(), &format!("below-{tag}"));
            let report = diff(&a, &b, &options);
            // A morph set against a format that keeps the meshes differs in its structure
            // (one merged mesh, transforms baked): the animation is what must agree.
            let restructured = (a_format == "morphs") != (b_format == "morphs");
            assert!(
                report.differing_tables().count() == 0 && (restructured || report.is_equal()),
                "{pair}: {report}"
            );
            let (b, _) = through(&above, b_format, dir.path(), &format!("above-{tag}"));
            let report = diff(&a, &b, &options);
            assert!(!report.is_equal(), "{pair}: {report}");
            let worst = report.worst_table().unwrap();
            assert_eq!(worst.table, "open_jaw", "{pair}: {report}");
            assert_eq!(report.differing_tables().count(), 1, "{pair}: {report}");
            assert!(
                (worst.max_difference - 2.0 * tol).abs() < 0.05 * tol,
                "{pair}: {}",
                worst.max_difference
            );
        }
    }
}

/// The same from the CLI, across a VRML file and a glTF file, with the JSON contract.
#[test]
fn cli_face_diff_across_formats() {
    let tol = 1e-3;
    let dir = tempfile::tempdir().unwrap();
    let (_, a) = through(alma(), "wrl.gz", dir.path(), "a");
    let mut above = alma().clone();
    perturb(&mut above, "open_jaw", 2.0 * tol);
    let (_, b) = through(&above, "glb", dir.path(), "b");
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let out = fbakit(&["face", "diff", a, b, "--tolerance", "0.001", "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["equal"], false);
    assert_eq!(json["tables"][0]["table"], "open_jaw");
    assert_eq!(json["tables"][0]["fap"], 3);
    assert_eq!(json["tables"][1]["equal"], true);
    let out = fbakit(&["face", "diff", a, b, "--tolerance", "0.004"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).starts_with("EQUAL:"));

    // A blendshape rig with its feature points (its FAT built from its shapes) against the
    // same face as fbakit bundles it, and against that face written as glb and read back.
    let rig = "samples/faces/ict-head/ict-head.glb";
    let fp = "samples/faces/ict-head/ict-head-fp.csv";
    let out = fbakit(&["face", "diff", rig, "--fp-a", fp, "ict", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["equal"], true);
    assert!(json["tables"].as_array().unwrap().len() > 20);
    let ict = fbakit::face::read("ict").unwrap();
    let (_, written) = through(&ict, "glb", dir.path(), "ict");
    let out = fbakit(&["face", "diff", rig, "--fp-a", fp, written.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
}
