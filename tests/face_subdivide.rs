//! `fbakit face subdivide` end to end: a denser face whose FAT plays like the original.

mod support;

use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use support::cli::{fbakit, text};

#[test]
fn subdivided_face_plays_like_the_original() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("alma-fine.wrl.gz");
    let o = fbakit(&[
        "face",
        "subdivide",
        "alma",
        "--scheme",
        "midpoint",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (before, after) = (
        report["vertices_before"].as_u64().unwrap(),
        report["vertices"].as_u64().unwrap(),
    );
    assert!(after > 3 * before, "{report}");

    let alma = fbakit::face::read("alma").unwrap();
    let fine = fbakit::face::read(&out).unwrap();
    assert_eq!(fine.fat.tables.len(), alma.fat.tables.len());
    // Midpoint subdivision keeps old vertices first and unmoved: they play exactly as before
    // (after the file round trip), and so does every feature point.
    let key = TableKey::from_name("open_jaw").unwrap();
    let a = [Activation { key, value: 512.0 }];
    let (pa, pf) = (alma.pose(&a).unwrap(), fine.pose(&a).unwrap());
    let mut worst = 0.0f32;
    for (ma, mf) in pa.iter().zip(&pf) {
        for (p, q) in ma.iter().zip(mf) {
            worst = worst.max(p.distance(*q));
        }
    }
    assert!(worst < 1e-3, "{worst}");
    assert_eq!(fine.fapu().unwrap(), alma.fapu().unwrap());
}

#[test]
fn bad_requests_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.wrl");
    let o = fbakit(&[
        "face",
        "subdivide",
        "alma",
        "--rounds",
        "9",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("--rounds"), "{}", text(&o.stderr));
    let o = fbakit(&["face", "subdivide", "alma", "-o", "x.unknown"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
}
