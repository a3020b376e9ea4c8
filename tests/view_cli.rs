//! `fbakit view` through the real binary: the page it writes, its report, and what it refuses.

use std::path::Path;
use std::process::Output;

mod support;
use support::cli::fbakit;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The viewer data embedded in a page.
fn page_model(page: &Path) -> serde_json::Value {
    let html = std::fs::read_to_string(page).unwrap();
    let open = "id=\"fbakit-data\">";
    let start = html.find(open).unwrap() + open.len();
    let len = html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..start + len]).unwrap()
}

#[test]
fn writes_a_page_and_reports_it() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("alma.html");
    let o = fbakit(&[
        "view",
        "alma",
        "samples/speech.fap",
        "-o",
        s(&page),
        "--frames",
        "10..40",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["face"], "alma");
    assert_eq!(r["frames"], 30);
    assert_eq!(r["fps"], 25.0);
    // 30 frames at 25 fps last 1.2 s, as `play` reports them.
    assert!((r["duration_seconds"].as_f64().unwrap() - 30.0 / 25.0).abs() < 1e-9);
    let bytes = std::fs::metadata(&page).unwrap().len();
    assert_eq!(r["bytes"].as_u64().unwrap(), bytes);
    let m = page_model(&page);
    assert_eq!(m["stream"]["name"], "speech.fap");
    assert_eq!(m["stream"]["frames"], 30);
    assert!(m["tracks"]
        .as_array()
        .unwrap()
        .iter()
        .all(|t| t["values"].as_array().unwrap().len() == 30));

    // Text report without --json.
    let o = fbakit(&["view", "alma", "samples/speech.fap", "-o", s(&page)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("viewer page"), "{text}");
    assert!(
        text.contains(
            "plays 75 frames of `samples/speech.fap` on `alma` at 25 fps (3.000 s), looping"
        ),
        "{text}"
    );
}

#[test]
fn refuses_bad_usage_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str, &str); 4] = [
        (&["bruno"], "face.wrl", "the viewer page must be .html"),
        (&["missing-face.wrl"], "a.html", "missing-face.wrl"),
        (&["alma", "--fps", "30"], "b.html", "need a STREAM"),
        (
            &["alma", "no-such-stream.fap"],
            "c.html",
            "no-such-stream.fap",
        ),
    ];
    for (args, out, message) in cases {
        let target = dir.path().join(out);
        let mut all = vec!["view"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", s(&target)]);
        let o = fbakit(&all);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{all:?}: {}", stderr(&o));
        assert!(!target.exists(), "{all:?} wrote {out}");
    }
}

#[test]
fn obj_face_with_feature_points() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("alma.obj");
    let o = fbakit(&["face", "convert", "samples/faces/alma.wrl.gz", s(&obj)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let face = fbakit::synth::alma().to_face_model();
    let csv = dir.path().join("alma.csv");
    fbakit::fdp::csv::write_csv_file(
        &csv,
        &fbakit::fdp::csv::FeaturePointTable::from_set(
            &fbakit::face::morphs::merged_feature_points(&face),
        ),
    )
    .unwrap();
    let page = dir.path().join("obj.html");
    let o = fbakit(&["view", s(&obj), "--fp", s(&csv), "-o", s(&page)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let m = page_model(&page);
    // A plain mesh: no tables, so no sliders, but its FAPU and feature points are shown.
    assert!(m["groups"].as_array().unwrap().is_empty());
    assert_eq!(m["fapu"].as_array().unwrap().len(), 6);
    assert_eq!(
        m["feature_points"].as_array().unwrap().len(),
        face.feature_points.len()
    );
}

#[test]
fn help_has_examples() {
    let o = fbakit(&["view", "--help"]);
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("fbakit view alma samples/speech.fap -o alma.html"));
    assert!(text.contains("FAP sliders"));
}
