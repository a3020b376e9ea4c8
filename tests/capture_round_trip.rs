//! Capture files through the commands: a Live Link Face CSV with moving head and eye rotations
//! → `fap from-arkit` → `.fap` → `fap to-arkit` → a Live Link Face CSV again, on the real ICT
//! rig (with its feature points) and on a face with only a FAT (bundled `bruno`); MediaPipe
//! JSON lines and CSV in; bad capture files exit 2 with one line and write nothing.

use std::path::Path;

use fbakit::rig::arkit_names::{capture_name, ARKIT_SHAPES};
use fbakit::rig::capture::{parse_capture, ROTATIONS};

mod support;
use support::cli::{fbakit, text};

const MANIFEST: &str = env!("CARGO_MANIFEST_DIR");

/// Round-trip tolerance of the captured shapes' weights on ICT (as `tests/arkit_bridge.rs`).
const ROUND_TRIP_TOLERANCE: f32 = 0.03;

/// Pearson correlation of two series (0 when either is constant).
fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa == 0.0 || sbb == 0.0 {
        0.0
    } else {
        sab / (saa * sbb).sqrt()
    }
}

/// How series `got` follows `want`: their correlation and the largest difference.
fn compare(want: &[f64], got: &[f64]) -> (f64, f64) {
    let worst = want
        .iter()
        .zip(got)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    (pearson(want, got), worst)
}

/// The moving shapes and their weight at frame `i` of 90.
const SHAPES: [&str; 5] = [
    "jawOpen",
    "eyeBlinkLeft",
    "mouthSmileRight",
    "browInnerUp",
    "mouthFunnel",
];

fn shape_weight(k: usize, i: usize) -> f64 {
    let t = i as f64 / 89.0;
    0.5 - 0.45 * (std::f64::consts::TAU * t + k as f64 * 0.7).cos()
}

/// Rotation `r` (ROTATIONS order) at frame `i`: every column moves, eye roll included, each on
/// its own curve, within ±0.3 rad.
fn rotation(r: usize, i: usize) -> f64 {
    let t = i as f64 / 89.0;
    0.3 * (std::f64::consts::TAU * (1.0 + 0.3 * r as f64) * t + r as f64).sin()
}

/// 90 frames at 60 fps in the Live Link Face layout, starting mid-second at 10:23:45:50.
fn live_link_csv() -> String {
    let mut s = String::from("Timecode,BlendShapeCount");
    for n in ARKIT_SHAPES {
        s.push(',');
        s.push_str(&capture_name(n));
    }
    for r in ROTATIONS {
        s.push(',');
        s.push_str(r.column);
    }
    s.push('\n');
    for i in 0..90 {
        let f = 50 + i;
        let (sec, ff) = (45 + f / 60, f % 60);
        s.push_str(&format!("10:23:{sec:02}:{ff:02}.000,61"));
        for n in ARKIT_SHAPES {
            let w = SHAPES
                .iter()
                .position(|x| *x == n)
                .map_or(0.0, |k| shape_weight(k, i));
            s.push_str(&format!(",{w:.5}"));
        }
        for r in 0..9 {
            s.push_str(&format!(",{:.5}", rotation(r, i)));
        }
        s.push('\n');
    }
    s
}

/// from-arkit then to-arkit with `face_args`; returns the CSV written back.
fn round_trip(dir: &Path, face_args: &[&str]) -> String {
    let csv = dir.join("llf.csv");
    std::fs::write(&csv, live_link_csv()).unwrap();
    let fap = dir.join("llf.fap");
    let mut args = vec!["fap", "from-arkit", csv.to_str().unwrap()];
    args.extend(face_args);
    args.extend(["-o", fap.to_str().unwrap(), "--json"]);
    let o = fbakit(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let faps: Vec<&str> = report["faps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    for f in [
        "head_yaw",
        "head_pitch",
        "head_roll",
        "yaw_l_eyeball",
        "pitch_r_eyeball",
    ] {
        assert!(faps.contains(&f), "{f} missing from {faps:?}");
    }
    let roll = report["columns"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["column"] == "LeftEyeRoll")
        .unwrap();
    assert_eq!(roll["ignored"], "eye roll has no FAP");
    // The stream holds the angles in AU: frame 10's head yaw is 0.3 sin(...) / 1e-5.
    let stream = fbakit::fap::read_stream_file(&fap, &fbakit::fap::ReadOptions::strict())
        .unwrap()
        .0;
    let yaw = fbakit::spec::FapId::from_name("head_yaw").unwrap();
    let v = stream.frames[10].value(yaw).unwrap();
    assert!((v - (rotation(0, 10) * 1e5).round()).abs() <= 1.0, "{v}");

    // The capture's time of day is reported, and written back with --start.
    let start = report["start_timecode"].as_str().unwrap();
    assert_eq!(start, "10:23:45:50.000");
    let back = dir.join("back.csv");
    let mut args = vec!["fap", "to-arkit", fap.to_str().unwrap()];
    args.extend(face_args);
    args.extend(["-o", back.to_str().unwrap(), "--start", start]);
    let o = fbakit(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains("rotations (radians): HeadYaw, HeadPitch, HeadRoll, LeftEyeYaw, LeftEyePitch, RightEyeYaw, RightEyePitch"), "{}", text(&o.stdout));
    let back = std::fs::read_to_string(&back).unwrap();
    let times = |t: &str| -> Vec<String> {
        t.lines()
            .map(|l| l.split(',').next().unwrap().to_string())
            .collect()
    };
    assert_eq!(times(&back), times(&live_link_csv()));
    back
}

/// Checks the layout and the rotations of a CSV written back; returns it parsed.
fn check_rotations(back: &str) -> fbakit::rig::weights_csv::WeightCsv {
    let header = back.lines().next().unwrap();
    assert!(header.starts_with("Timecode,BlendShapeCount,EyeBlinkLeft,EyeLookDownLeft,"));
    assert!(header.ends_with(",TongueOut,HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll"));
    assert_eq!(header.split(',').count(), 63);
    assert!(back
        .lines()
        .skip(1)
        .all(|l| l.split(',').nth(1) == Some("61")));
    let w = parse_capture(back, Path::new("back.csv"), None).unwrap();
    assert_eq!(w.fps, 60.0);
    assert_eq!(w.rows.len(), 90);
    for (r, rot) in ROTATIONS.iter().enumerate() {
        let c = w.columns.iter().position(|c| c.name == rot.column).unwrap();
        let got: Vec<f64> = w.rows.iter().map(|row| f64::from(row.weights[c])).collect();
        if rot.fap.is_none() {
            assert!(got.iter().all(|v| *v == 0.0), "{}", rot.column);
            continue;
        }
        let want: Vec<f64> = (0..90).map(|i| rotation(r, i)).collect();
        let (corr, worst) = compare(&want, &got);
        eprintln!(
            "{:<14} r = {corr:.6}, worst |Δ| {worst:.2e} rad",
            rot.column
        );
        assert!(corr >= 0.95, "{}: r = {corr}", rot.column);
        // Whole AU both ways: within 1e-5 rad (plus the CSV's 5 decimals).
        assert!(worst <= 2e-5, "{}: {worst}", rot.column);
    }
    w
}

#[test]
fn live_link_round_trip_on_a_face_with_a_fat() {
    let dir = tempfile::tempdir().unwrap();
    let back = round_trip(dir.path(), &["--face", "bruno"]);
    let w = check_rotations(&back);
    // Each captured shape comes back as itself, and no other shape appears: bruno's FAT has
    // tables of several intervals per side (`open_jaw`), which the shapes, being linear, read
    // as `jawForward` and `mouthFunnel` when the jaw was half open.
    for (k, name) in SHAPES.iter().enumerate() {
        let c = w
            .columns
            .iter()
            .position(|c| c.name == capture_name(name))
            .unwrap();
        let got: Vec<f64> = w.rows.iter().map(|r| f64::from(r.weights[c])).collect();
        let want: Vec<f64> = (0..90).map(|i| shape_weight(k, i)).collect();
        let (corr, worst) = compare(&want, &got);
        eprintln!("bruno {name:<16} r = {corr:.4}, worst |Δw| {worst:.4}");
        assert!(corr >= 0.95, "{name} r = {corr}");
        assert!(worst < 0.05, "{name}: {worst}");
    }
    let captured: Vec<String> = SHAPES.iter().map(|n| capture_name(n)).collect();
    for name in ARKIT_SHAPES {
        let column = capture_name(name);
        if captured.contains(&column) {
            continue;
        }
        let c = w.columns.iter().position(|c| c.name == column).unwrap();
        let most = w.rows.iter().map(|r| r.weights[c]).fold(0.0f32, f32::max);
        assert!(
            most < 0.05,
            "{column} appears at {most} though the capture never moved it"
        );
    }
}

#[test]
fn live_link_round_trip_on_the_ict_rig() {
    let ict = Path::new(MANIFEST).join("../shared/data/ict-facekit");
    if !ict.join("generic_neutral_mesh.obj").is_file() {
        eprintln!("note: {} not found; skipping", ict.display());
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let ict_dir = ict.to_str().unwrap();
    let fp = d.join("ict-fp.csv");
    let o = fbakit(&[
        "fp",
        "from-landmarks",
        &format!("{ict_dir}/generic_neutral_mesh.obj"),
        "--ibug68",
        &format!("{ict_dir}/vertex_indices.json"),
        "-o",
        fp.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let back = round_trip(d, &["--face", ict_dir, "--fp", fp.to_str().unwrap()]);
    let w = check_rotations(&back);
    // The 52 shapes still round-trip.
    for (k, name) in SHAPES.iter().enumerate() {
        let c = w
            .columns
            .iter()
            .position(|c| c.name == capture_name(name))
            .unwrap();
        let worst = (0..90)
            .map(|i| (w.rows[i].weights[c] - shape_weight(k, i) as f32).abs())
            .fold(0.0f32, f32::max);
        eprintln!("{name:<16} worst |Δw| {worst:.4}");
        assert!(worst < ROUND_TRIP_TOLERANCE, "{name}: {worst}");
    }
}

#[test]
fn mediapipe_captures_play_on_a_face_with_a_fat() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut jsonl = String::new();
    let mut csv = String::from("timestamp_ms,_neutral");
    let names: Vec<&str> = ARKIT_SHAPES
        .iter()
        .copied()
        .filter(|n| *n != "tongueOut")
        .collect();
    for n in &names {
        csv.push(',');
        csv.push_str(n);
    }
    csv.push('\n');
    for i in 0..40 {
        let ms = (i as f64 * 1000.0 / 30.0).round();
        let scores: Vec<String> = names
            .iter()
            .map(|n| {
                let w = if *n == "jawOpen" {
                    shape_weight(0, i * 2)
                } else {
                    0.0
                };
                format!("\"{n}\": {w:.4}")
            })
            .collect();
        jsonl.push_str(&format!(
            "{{\"timestamp_ms\": {ms}, \"blendshapes\": {{\"_neutral\": 0.5, {}}}}}\n",
            scores.join(", ")
        ));
        csv.push_str(&format!("{ms},0.5"));
        for n in &names {
            let w = if *n == "jawOpen" {
                shape_weight(0, i * 2)
            } else {
                0.0
            };
            csv.push_str(&format!(",{w:.4}"));
        }
        csv.push('\n');
    }
    let mut streams = Vec::new();
    for (name, body) in [("mp.jsonl", &jsonl), ("mp.csv", &csv)] {
        let input = d.join(name);
        std::fs::write(&input, body).unwrap();
        let out = d.join(format!("{name}.fap"));
        let o = fbakit(&[
            "fap",
            "from-arkit",
            input.to_str().unwrap(),
            "--face",
            "bruno",
            "-o",
            out.to_str().unwrap(),
            "--json",
        ]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(report["fps"], 30.0, "{name}");
        assert_eq!(report["frames"], 40, "{name}");
        let stream = fbakit::fap::read_stream_file(&out, &fbakit::fap::ReadOptions::strict())
            .unwrap()
            .0;
        streams.push(stream);
    }
    // Both files say the same, so both streams are the same; the jaw moves.
    assert_eq!(streams[0].frames, streams[1].frames);
    let jaw = fbakit::spec::FapId::from_name("open_jaw").unwrap();
    let max = streams[0]
        .frames
        .iter()
        .filter_map(|f| f.value(jaw))
        .fold(0.0, f64::max);
    assert!(max > 100.0, "open_jaw max {max}");
}

#[test]
fn bad_capture_files_exit_2_with_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let put = |name: &str, body: &str| {
        let p = d.join(name);
        std::fs::write(&p, body).unwrap();
        p.to_str().unwrap().to_string()
    };
    let cases = [
        (
            put("broken.jsonl", "{\"timestamp_ms\": 0, \"blendshapes\": {\"jawOpen\": 0.1}}\n{\"timestamp_ms\": 33, \"blendshapes\": {\"jawOpen\": }}\n"),
            "broken.jsonl:2:",
        ),
        (
            put("score.jsonl", "{\"timestamp_ms\": 0, \"blendshapes\": {\"jawOpen\": 0.1}}\n{\"timestamp_ms\": 33, \"blendshapes\": {\"jawOpen\": \"x\"}}\n"),
            "score.jsonl:2:38: expected `blendshapes.jawOpen`: a finite score",
        ),
        (
            put("degrees.csv", "Timecode,BlendShapeCount,JawOpen,HeadYaw\n00:00:00:00.000,61,0.1,0.1\n00:00:00:01.000,61,0.1,25\n"),
            "degrees.csv:3:24: expected an angle in radians",
        ),
        (
            put("mp-bad.csv", "timestamp_ms,_neutral,jawOpen\n0,1,0.1\nx,1,0.2\n"),
            "mp-bad.csv:3:1: expected a time in milliseconds",
        ),
    ];
    let out = d.join("out.fap");
    for (input, expect) in &cases {
        let o = fbakit(&[
            "fap",
            "from-arkit",
            input,
            "--face",
            "bruno",
            "-o",
            out.to_str().unwrap(),
        ]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(expect), "{expect}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!out.exists());
    }
    // A start timecode that is none, or whose frame the stream's rate does not have.
    let stream = put(
        "s.fap",
        &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/samples/speech.fap"))
            .unwrap(),
    );
    let csv = d.join("out.csv");
    for bad in ["10:00:00:25", "10:00:00", "10:61:00:00", "x"] {
        let o = fbakit(&[
            "fap",
            "to-arkit",
            &stream,
            "--face",
            "bruno",
            "--start",
            bad,
            "-o",
            csv.to_str().unwrap(),
        ]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("--start `{bad}`")) && err.contains("25 fps"),
            "{err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!csv.exists());
    }
    // A face without a FAT and no --fp: the file and the way out are named.
    let obj = put("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let o = fbakit(&[
        "fap",
        "to-arkit",
        "samples/speech.fap",
        "--face",
        &obj,
        "-o",
        d.join("w.csv").to_str().unwrap(),
    ]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("plain.obj"), "{err}");
    assert!(!d.join("w.csv").exists());
}
