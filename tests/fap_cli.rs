//! `fbakit fap ...` through the real binary: snapshots of `info` and exit codes.

use std::path::Path;
use std::process::Output;

mod support;
use support::cli::fbakit;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn info_text_snapshots() {
    for name in ["speech", "lowlevel"] {
        let o = fbakit(&["fap", "info", &format!("samples/{name}.fap")]);
        assert_eq!(o.status.code(), Some(0));
        insta::assert_snapshot!(format!("info_{name}"), stdout(&o));
    }
}

#[test]
fn info_json_snapshot() {
    let o = fbakit(&["fap", "info", "samples/speech.fap", "--json", "--strict"]);
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    insta::assert_json_snapshot!("info_speech_json", v);
}

#[test]
fn validate_exit_codes() {
    let o = fbakit(&["fap", "validate", "samples/lowlevel.fap"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert_eq!(stdout(&o), "samples/lowlevel.fap: valid\n");

    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.fap");
    let good =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap"))
            .unwrap();
    // Two problems: a name with a space and a frame count that does not match.
    let broken = good.replacen("2.1 lowlevel 25 50", "2.1 low level 25 51", 1);
    std::fs::write(&bad, broken).unwrap();
    let o = fbakit(&["fap", "validate", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let out = stdout(&o);
    assert!(
        out.contains("bad.fap:4:5: error: name `low level` contains spaces"),
        "{out}"
    );
    assert!(
        out.contains("bad.fap:4:18: error: header declares 51 frames but 50 are present"),
        "{out}"
    );
    assert!(out.contains("2 problem(s)"), "{out}");
    let o = fbakit(&["fap", "validate", bad.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["valid"], false);
    assert_eq!(v["problems"].as_array().unwrap().len(), 2);

    let o = fbakit(&["fap", "validate", "no/such/file.fap"]);
    assert_eq!(o.status.code(), Some(2));
    let bin = dir.path().join("bin.fap");
    std::fs::write(&bin, b"\x00\xff\xfe garbage").unwrap();
    let o = fbakit(&["fap", "validate", bin.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    // Binary data is refused at its first NUL byte, before any UTF-8 check.
    assert!(String::from_utf8_lossy(&o.stderr).contains("bin.fap:1:1: expected text"));
    std::fs::write(&bin, b"2.1 x 25 1\n\xff\xfe garbage").unwrap();
    let o = fbakit(&["fap", "validate", bin.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("bin.fap:2:1: expected UTF-8 text"));
}

#[test]
fn info_strict_fails_with_exit_2_on_deviations() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("x.fap");
    std::fs::write(&p, "2.1 a b 25 0\n").unwrap();
    let o = fbakit(&["fap", "info", p.to_str().unwrap(), "--strict"]);
    assert_eq!(o.status.code(), Some(2));
    let o = fbakit(&["fap", "info", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    assert!(stdout(&o).contains("warnings:   1"));
}

#[test]
fn convert_round_trips_through_json() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("speech.json");
    let fap = dir.path().join("speech.fap");
    let o = fbakit(&[
        "fap",
        "convert",
        "samples/speech.fap",
        json.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0));
    let o = fbakit(&[
        "fap",
        "convert",
        json.to_str().unwrap(),
        fap.to_str().unwrap(),
        "--strict",
    ]);
    assert_eq!(o.status.code(), Some(0));
    let original =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/speech.fap"))
            .unwrap();
    let canonical: String = original
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(std::fs::read_to_string(&fap).unwrap(), canonical);
    let o = fbakit(&["fap", "convert", "missing.fap", fap.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn convert_refuses_unknown_outputs_and_its_own_input() {
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("out.xyz");
    let o = fbakit(&[
        "fap",
        "convert",
        "samples/speech.fap",
        xyz.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o)
            .contains("`fap convert` output must be .fap, .json; found unknown extension `.xyz`"),
        "{}",
        stderr(&o)
    );
    assert!(!xyz.exists(), "nothing written");
    let own = dir.path().join("own.fap");
    std::fs::copy("samples/speech.fap", &own).unwrap();
    let before = std::fs::read(&own).unwrap();
    let o = fbakit(&[
        "fap",
        "convert",
        own.to_str().unwrap(),
        own.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("refusing to write over the input"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&own).unwrap(), before, "input untouched");
}

#[test]
fn help_has_examples() {
    for cmd in ["info", "validate", "convert", "from-arkit", "to-arkit"] {
        let o = fbakit(&["fap", cmd, "--help"]);
        assert_eq!(o.status.code(), Some(0));
        assert!(stdout(&o).contains("fbakit fap"), "{cmd}");
    }
}
