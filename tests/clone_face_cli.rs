//! `fbakit clone` and `fbakit eval` end to end on the synthetic faces.

use fbakit::face::vrml::write_face_file;

mod support;
use support::cli::command as fbakit;

#[test]
fn clone_writes_a_face_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("alma.wrl"), dir.path().join("bruno.wrl"));
    write_face_file(&a, &fbakit::synth::alma().to_face_model()).unwrap();
    let mut plain = fbakit::synth::bruno().to_face_model();
    plain.fat = Default::default();
    write_face_file(&b, &plain).unwrap();
    let out = dir.path().join("out.wrl");
    let o = fbakit()
        .args(["clone", a.to_str().unwrap(), b.to_str().unwrap(), "-o"])
        .arg(&out)
        .args(["--method", "rbf", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["report"]["method"], "rbf");
    assert!(json["report"]["tables"].as_u64().unwrap() >= 80);
    let (face, _) = fbakit::face::vrml::read_face_file(&out).unwrap();
    assert!(face.fat.tables.len() >= 80);
    let o = fbakit()
        .args(["eval", "compliance"])
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success());
    let c: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(c["worst"].as_f64().unwrap() < 0.05);
    // Unsupported output and an OBJ without feature points are usage errors (exit 2).
    let bad = dir.path().join("x.txt");
    let o = fbakit()
        .args(["clone", a.to_str().unwrap(), b.to_str().unwrap(), "-o"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("the cloned face must be .wrl"));
    assert!(!bad.exists());
    let o = fbakit()
        .args(["clone", a.to_str().unwrap(), "head.obj", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    // It says how to make the missing file.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("head.obj: an OBJ face needs its feature points")
            && err.contains("fbakit fp from-landmarks"),
        "{err}"
    );
    // A face without any feature points: exit 2 saying what to give, nothing written.
    let bare = dir.path().join("bare.wrl");
    let mut none = fbakit::synth::bruno().to_face_model();
    none.fat = Default::default();
    none.feature_points = Default::default();
    write_face_file(&bare, &none).unwrap();
    let fresh = dir.path().join("fresh.wrl");
    let o = fbakit()
        .args(["clone", a.to_str().unwrap(), bare.to_str().unwrap(), "-o"])
        .arg(&fresh)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bare.wrl: the face has no feature points") && err.contains("--fp-target"),
        "{err}"
    );
    assert!(!fresh.exists());
    let o = fbakit().args(["clone", "--help"]).output().unwrap();
    assert!(String::from_utf8_lossy(&o.stdout).contains("Examples"));
}

#[test]
fn eval_ground_truth_clones_and_measures() {
    // alma cloned onto alma: fmc's self-clone is exact, so the truth comes back.
    let o = fbakit()
        .args([
            "eval",
            "ground-truth",
            "alma",
            "--source",
            "alma",
            "--method",
            "fmc",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let row = &rows[0];
    assert_eq!(row["method"], "fmc");
    assert!(row["keys"].as_array().unwrap().len() >= 80);
    assert!(row["median_all"].as_f64().unwrap() < 1e-3, "{row}");
    assert!(row["median_scaled"].as_f64().unwrap() <= row["median_all"].as_f64().unwrap());

    // A clone made elsewhere is measured with --cloned; a face without a FAT is no truth.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bruno-from-alma.wrl");
    let o = fbakit()
        .args(["clone", "alma", "bruno", "--method", "fmc", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = fbakit()
        .args(["eval", "ground-truth", "bruno", "--cloned"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.starts_with("cloned: median "), "{text}");
    assert!(text.contains("open_jaw"), "{text}");
    let o = fbakit()
        .args(["eval", "ground-truth"])
        .arg(&out)
        .args(["--source", "alma"])
        .output()
        .unwrap();
    // The cloned face has a FAT, so it is a valid truth; without --source/--cloned it is usage.
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = fbakit()
        .args(["eval", "ground-truth", "bruno"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// `--lid-cover` (alma's blink onto the real ICT head, whose corneas showed through the
/// closed lids): with `off` against `on` the eyelid tables (FAPs 19–22) change, a table away
/// from the eyes (`open_jaw`) is the same to the bit; the default (`auto`) covers both eyes
/// here, as `on` does, and `--lid-cover` alone means `on`. `--verbose` says per eye why.
#[test]
fn lid_cover_changes_the_lids_and_only_them() {
    let Ok(ict) = fbakit::face::read("ict") else {
        eprintln!("note: bundled face ict not readable; skipped");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("ict.wrl");
    write_face_file(&target, &fbakit::export::picture::strip_fat(&ict)).unwrap();
    let clone = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let o = fbakit()
            .args(["clone", "alma", target.to_str().unwrap(), "-o"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        (fbakit::face::vrml::read_face_file(&out).unwrap().0, text)
    };
    let (plain, _) = clone("plain.wrl", &["--lid-cover", "off"]);
    let (covered, _) = clone("covered.wrl", &["--lid-cover"]);
    let (auto, said) = clone("auto.wrl", &["--verbose"]);
    let table = |face: &fbakit::face::FaceModel, fap: u8| {
        let key = fbakit::fat::TableKey::LowLevel(fbakit::spec::FapId::new(fap).unwrap());
        face.fat.table(key).cloned()
    };
    for fap in 19..=22 {
        let (a, b) = (table(&plain, fap), table(&covered, fap));
        assert!(a.is_some() && b.is_some(), "FAP {fap}");
        assert_ne!(a, b, "FAP {fap} is the same with --lid-cover");
        assert_eq!(
            b,
            table(&auto, fap),
            "FAP {fap}: auto does not cover as on does"
        );
    }
    let (a, b) = (table(&plain, 3), table(&covered, 3));
    assert!(a.is_some());
    assert_eq!(a, b, "open_jaw changed with --lid-cover");
    for eye in ["left", "right"] {
        assert!(
            said.contains(&format!("lid_cover (auto): {eye} eye covered")),
            "{said}"
        );
    }
    let o = fbakit()
        .args(["clone", "alma", target.to_str().unwrap(), "-o"])
        .arg(dir.path().join("bad.wrl"))
        .args(["--lid-cover", "sometimes"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}
