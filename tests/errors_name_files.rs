//! Errors from layers that cannot know the file (player limits, FAPUs of a degenerate
//! feature-point set, a clone's alignment) still name the file the user gave: exit 2, one
//! line, nothing written.

mod support;

use std::path::Path;

use support::cli::{command, text};

/// Runs `fbakit` with path-like arguments; returns (exit code, stderr).
fn run(args: &[&std::ffi::OsStr]) -> (i32, String) {
    let out = command().args(args).output().expect("run fbakit");
    (out.status.code().unwrap_or(-1), text(&out.stderr))
}

fn os(s: &str) -> &std::ffi::OsStr {
    s.as_ref()
}

/// A two-frame stream of the lowlevel sample's first record, the second at frame `last`.
fn stream_to(last: u64) -> String {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap"))
            .unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    lines.next();
    let mask = lines.next().unwrap();
    let values = lines.next().unwrap();
    let rest: Vec<&str> = values.split_whitespace().skip(1).collect();
    format!(
        "2.1 far 25 2\n{mask}\n0 {r}\n{mask}\n{last} {r}\n",
        r = rest.join(" ")
    )
}

#[test]
fn player_limits_name_the_stream_and_the_face() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("far-away.fap");
    std::fs::write(&stream, stream_to(4_000_000_000)).unwrap();
    let out = dir.path().join("out.glb");
    let (code, err) = run(&[
        os("play"),
        os("alma"),
        stream.as_os_str(),
        os("-o"),
        out.as_os_str(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("far-away.fap") && err.contains("alma"),
        "{err}"
    );
    assert!(err.contains("4000000000"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists());
}

#[test]
fn degenerate_feature_points_name_their_file() {
    let dir = tempfile::tempdir().unwrap();
    let fp = dir.path().join("all-in-one-place.xml");
    let mut xml =
        String::from("<?xml version=\"1.0\"?>\n<featurePoints version=\"1\" units=\"mm\">\n");
    for id in [
        "3.5", "3.6", "3.1", "3.3", "9.15", "2.1", "2.2", "8.3", "8.4",
    ] {
        xml.push_str(&format!("  <point id=\"{id}\" x=\"1\" y=\"0\" z=\"0\"/>\n"));
    }
    xml.push_str("</featurePoints>\n");
    std::fs::write(&fp, xml).unwrap();
    let (code, err) = run(&[os("fapu"), fp.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("all-in-one-place.xml"), "{err}");
}

#[test]
fn collinear_target_points_name_the_target() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("flat-target.obj");
    // A thin strip along x, so points on the x axis lie on the mesh.
    let mut text = String::new();
    for row in [0.0, 0.1] {
        for i in 0..=20 {
            text.push_str(&format!("v {} {row} 0\n", i as f64 * 0.1 - 1.0));
        }
    }
    for i in 1..=20 {
        text.push_str(&format!("f {} {} {} {}\n", i, i + 1, i + 22, i + 21));
    }
    std::fs::write(&obj, text).unwrap();
    let fp = dir.path().join("on-a-line.xml");
    let mut xml =
        String::from("<?xml version=\"1.0\"?>\n<featurePoints version=\"1\" units=\"mm\">\n");
    for (i, id) in [
        "3.5", "3.6", "3.1", "3.3", "3.2", "3.4", "9.15", "2.1", "2.2", "2.3", "8.3", "8.4",
        "11.1", "7.1",
    ]
    .iter()
    .enumerate()
    {
        let x = i as f64 * 0.1 - 0.7;
        xml.push_str(&format!(
            "  <point id=\"{id}\" x=\"{x}\" y=\"0\" z=\"0\"/>\n"
        ));
    }
    xml.push_str("</featurePoints>\n");
    std::fs::write(&fp, xml).unwrap();
    let out = dir.path().join("out.wrl");
    let (code, err) = run(&[
        os("clone"),
        os("alma"),
        obj.as_os_str(),
        os("--fp-target"),
        fp.as_os_str(),
        os("-o"),
        out.as_os_str(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("flat-target.obj"), "{err}");
    assert!(!out.exists());
}
