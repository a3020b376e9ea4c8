//! The ARKit ⇄ MPEG-4 bridge on the real ICT-FaceKit rig (feature points derived from its
//! iBUG-68 landmark vertices): weight curves → FAP stream → weight curves, the ARKit-named
//! glb export of a FAT face, and the commands' exit codes. Tests that need
//! `../shared/data/ict-facekit` print a note and return when it is absent.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use fbakit::face::FaceModel;
use fbakit::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use fbakit::mesh::{Mesh, Polygons};
use fbakit::rig::arkit_names::ARKIT_SHAPES;
use fbakit::rig::arkit_weights::ArkitBridge;
use fbakit::rig::fap_map::FapMap;
use fbakit::rig::fat_build::face_from_rig;
use fbakit::rig::fat_build::RigFatReport;
use fbakit::rig::weights_csv::parse_weights_csv;
use fbakit::rig::Rig;
use fbakit::rig::{BlendShape, RigMesh, ShapeDelta};
use fbakit::spec::FapId;
use glam::Vec3;

mod support;
use support::cli::fbakit;
use support::validator::validate;

#[path = "../examples/make_arkit_amplitudes.rs"]
mod make_arkit_amplitudes;

const MANIFEST: &str = env!("CARGO_MANIFEST_DIR");

fn ict_dir() -> Option<PathBuf> {
    let dir = Path::new(MANIFEST).join("../shared/data/ict-facekit");
    if dir.join("generic_neutral_mesh.obj").is_file() {
        Some(dir)
    } else {
        eprintln!("note: {} not found; skipping", dir.display());
        None
    }
}

struct Ict {
    dir: PathBuf,
    rig: Rig,
    face: FaceModel,
    report: RigFatReport,
}

/// The ICT rig, its face with a FAT and the calibration report, loaded once per test binary.
fn ict() -> Option<&'static Ict> {
    static ICT: OnceLock<Option<Ict>> = OnceLock::new();
    ICT.get_or_init(|| {
        let dir = ict_dir()?;
        let (rig, face, report) = make_arkit_amplitudes::load_ict(&dir).unwrap();
        Some(Ict {
            dir,
            rig,
            face,
            report,
        })
    })
    .as_ref()
}

/// 20 frames at 60 fps crossing a second, a few ARKit shapes moving on smooth curves.
fn weight_csv() -> String {
    let shapes = [
        "JawOpen",
        "EyeBlinkLeft",
        "MouthSmileRight",
        "BrowInnerUp",
        "MouthFunnel",
        "BrowDownLeft",
    ];
    let mut s = String::from("Timecode,BlendShapeCount");
    for n in shapes {
        s.push(',');
        s.push_str(n);
    }
    s.push_str(",HeadYaw\n");
    for i in 0..20 {
        let f = 50 + i;
        let (sec, ff) = (45 + f / 60, f % 60);
        s.push_str(&format!("10:23:{sec:02}:{ff:02}.000,61"));
        let t = i as f64 / 19.0;
        for (k, _) in shapes.iter().enumerate() {
            let phase = k as f64 * 0.7;
            let w = 0.5 - 0.45 * (std::f64::consts::TAU * t + phase).cos();
            s.push_str(&format!(",{w:.4}"));
        }
        s.push_str(",0.05\n");
    }
    s
}

/// A tiny rig whose vertices are feature points (mm; ES0 60, IRISD0 10, MNS0 20, MW0 50), so
/// every number below follows by hand: MNS = 20/1024, IRISD = 10/1024.
fn synthetic_rig() -> (Rig, FeaturePointSet) {
    let points: [(&str, [f32; 3]); 10] = [
        ("3.5", [30.0, 40.0, 0.0]),
        ("3.6", [-30.0, 40.0, 0.0]),
        ("3.1", [30.0, 45.0, 0.0]),
        ("3.3", [30.0, 35.0, 0.0]),
        ("9.15", [0.0, 0.0, 0.0]),
        ("2.2", [0.0, -20.0, 0.0]),
        ("8.3", [25.0, -25.0, 0.0]),
        ("8.4", [-25.0, -25.0, 0.0]),
        ("2.1", [0.0, -60.0, 0.0]),
        ("2.4", [20.0, -25.0, 0.0]),
    ];
    let positions: Vec<Vec3> = points.iter().map(|p| Vec3::from(p.1)).collect();
    let tris: Vec<[u32; 3]> = (1..positions.len() as u32 - 1)
        .map(|i| [0, i, i + 1])
        .collect();
    let mesh = Mesh {
        name: "face".into(),
        positions,
        polygons: Polygons::from_triangles(&tris),
        ..Mesh::default()
    };
    let shape = |name: &str, moves: &[(u32, [f32; 3])]| BlendShape {
        name: name.into(),
        default_weight: 0.0,
        deltas: vec![ShapeDelta {
            mesh: 0,
            vertices: moves.iter().map(|m| m.0).collect(),
            offsets: moves.iter().map(|m| Vec3::from(m.1)).collect(),
        }],
    };
    let rig = Rig {
        name: "synthetic".into(),
        meshes: vec![RigMesh {
            name: "face".into(),
            mesh,
        }],
        shapes: vec![
            // 2.1 drops 10 mm: open_jaw 512 MNS.
            shape("jawOpen", &[(8, [0.0, -10.0, 0.0])]),
            // 2.4 and 8.3 rise 4 and 5 mm: raise_l_cornerlip 204.8, raise_l_cornerlip_o 256.
            shape(
                "mouthSmile_L",
                &[(6, [0.0, 5.0, 0.0]), (9, [0.0, 4.0, 0.0])],
            ),
            // 3.1 drops 5 mm: close_t_l_eyelid 512 IRISD.
            shape("eyeBlink_L", &[(2, [0.0, -5.0, 0.0])]),
        ],
        warnings: vec![],
        source: None,
    };
    let mut set = FeaturePointSet::new();
    for (i, (label, p)) in points.iter().enumerate() {
        let mut point = FeaturePoint::at(label.parse().unwrap(), Vec3::from(*p));
        point.binding = Some(VertexBinding::vertex(i as u32));
        set.insert(point);
    }
    (rig, set)
}

#[test]
fn synthetic_rig_round_trips_exactly() {
    let (rig, points) = synthetic_rig();
    let (face, calibration) = face_from_rig(&rig, Some(points), &FapMap::arkit()).unwrap();
    let text = "time,JawOpen,MouthSmileLeft,eyeBlink_L,HeadYaw\n\
                0,0,0,0,0.1\n0.04,0.5,0.25,1,0.1\n0.08,1,1,0.5,0.1\n";
    let csv = parse_weights_csv(text, Path::new("w.csv"), None).unwrap();
    assert_eq!(csv.fps, 25.0);
    let mut bridge = ArkitBridge::new(&rig, &face, &calibration).unwrap();
    let (stream, report) = bridge.weights_to_faps(&csv, "w").unwrap();
    // Only the Tikhonov term keeps the fit from being exact.
    assert!(
        report.relative_residual < 1e-3,
        "{}",
        report.relative_residual
    );
    let v = |n: usize, fap: &str| stream.frames[n].value(FapId::from_name(fap).unwrap());
    // Whole FAPU of weight × calibrated value (Tikhonov shifts them by far less than 0.5).
    assert_eq!(v(1, "open_jaw"), Some(256.0));
    assert_eq!(v(2, "open_jaw"), Some(512.0));
    assert_eq!(v(1, "raise_l_cornerlip"), Some(51.0));
    assert_eq!(v(1, "raise_l_cornerlip_o"), Some(64.0));
    assert_eq!(v(1, "close_t_l_eyelid"), Some(512.0));
    assert_eq!(v(0, "open_jaw"), Some(0.0));
    let (weights, _) = bridge.faps_to_weights(&stream).unwrap();
    let idx = |n: &str| ARKIT_SHAPES.iter().position(|a| *a == n).unwrap();
    for (row, w) in csv.rows.iter().zip(&weights) {
        for (c, name) in [(0, "jawOpen"), (1, "mouthSmileLeft"), (2, "eyeBlinkLeft")] {
            assert!(
                (row.weights[c] - w[idx(name)]).abs() < 0.005,
                "{name}: {} vs {}",
                row.weights[c],
                w[idx(name)]
            );
        }
    }
}

/// Round-trip tolerance on the weights of the captured shapes (measured worst: 0.013).
const ROUND_TRIP_TOLERANCE: f32 = 0.03;

/// Largest weight the round trip may give a shape that was not captured (measured: 0.021).
const CROSSTALK_TOLERANCE: f32 = 0.05;

#[test]
fn weights_round_trip_through_a_fap_stream() {
    let Some(ict) = ict() else { return };
    let text = weight_csv();
    let csv = parse_weights_csv(&text, Path::new("capture.csv"), None).unwrap();
    assert_eq!(csv.fps, 60.0);
    assert_eq!(csv.rows.len(), 20);
    let mut bridge = ArkitBridge::new(&ict.rig, &ict.face, &ict.report).unwrap();
    let (stream, report) = bridge.weights_to_faps(&csv, "capture").unwrap();
    eprintln!(
        "from-arkit: residual {:.5}, {} FAPs, {} feature points",
        report.relative_residual,
        report.faps.len(),
        report.feature_points
    );
    assert_eq!(stream.frame_rate, 60.0);
    assert_eq!(stream.frames.len(), 20);
    assert!(
        report.relative_residual < 0.01,
        "{}",
        report.relative_residual
    );
    // The head yaw column sets head_yaw (0.05 rad = 5000 AU), no shape.
    let yaw = report
        .columns
        .iter()
        .find(|c| c.column == "HeadYaw")
        .unwrap();
    assert!(yaw.shapes.is_empty() && yaw.ignored.is_empty());
    assert_eq!(yaw.fap.as_deref(), Some("head_yaw"));
    let head_yaw = FapId::from_name("head_yaw").unwrap();
    assert!(stream
        .frames
        .iter()
        .all(|f| f.value(head_yaw) == Some(5000.0)));
    let brow = report
        .columns
        .iter()
        .find(|c| c.column == "BrowInnerUp")
        .unwrap();
    assert_eq!(brow.shapes, ["browInnerUp_L", "browInnerUp_R"]);
    // jawOpen drives open_jaw up to about its calibrated value.
    let jaw = fbakit::spec::FapId::from_name("open_jaw").unwrap();
    let max_jaw = stream
        .frames
        .iter()
        .filter_map(|f| f.value(jaw))
        .fold(0.0, f64::max);
    assert!(max_jaw > 1000.0, "open_jaw max {max_jaw}");

    let (weights, back) = bridge.faps_to_weights(&stream).unwrap();
    eprintln!("to-arkit: residual {:.5}", back.relative_residual);
    assert_eq!(weights.len(), 20);
    assert!(back.absent.contains(&"tongueOut".to_string()));
    assert!(back.unplayable.is_empty(), "{:?}", back.unplayable);
    for (c, col) in csv.columns.iter().enumerate() {
        let Some(i) = ARKIT_SHAPES
            .iter()
            .position(|a| a.eq_ignore_ascii_case(&col.name))
        else {
            continue;
        };
        let worst = csv
            .rows
            .iter()
            .zip(&weights)
            .map(|(r, w)| (r.weights[c] - w[i]).abs())
            .fold(0.0f32, f32::max);
        eprintln!("{:<16} worst |Δw| {worst:.4}", col.name);
        assert!(worst < ROUND_TRIP_TOLERANCE, "{}: {worst}", col.name);
    }
    let crosstalk = weights
        .iter()
        .flat_map(|w| w.iter().enumerate())
        .filter(|(i, _)| {
            !csv.columns
                .iter()
                .any(|c| ARKIT_SHAPES[*i].eq_ignore_ascii_case(&c.name))
        })
        .map(|(_, v)| *v)
        .fold(0.0f32, f32::max);
    eprintln!("largest weight of a shape not in the capture: {crosstalk:.4}");
    assert!(crosstalk < CROSSTALK_TOLERANCE, "{crosstalk}");
}

#[test]
fn bundled_amplitudes_match_a_fresh_measurement() {
    let Some(ict) = ict() else { return };
    let fresh = make_arkit_amplitudes::table_text(&ict.rig, &ict.face, &ict.report).unwrap();
    let path = Path::new(MANIFEST).join("specs/arkit-fap-amplitudes.csv");
    let parse = |name: &str, text: &str| {
        fbakit::rig::arkit_amplitudes::parse_amplitudes(text, Path::new(name)).unwrap()
    };
    let fresh = parse("fresh", &fresh);
    let bundled = parse("bundled", &std::fs::read_to_string(&path).unwrap());
    assert_eq!(
        fresh.len(),
        bundled.len(),
        "regenerate with `cargo run --example make_arkit_amplitudes`"
    );
    for (f, b) in fresh.iter().zip(&bundled) {
        assert_eq!((&f.shape, f.fap, &f.unit), (&b.shape, b.fap, &b.unit));
        assert!(
            (f.value - b.value).abs() <= 0.1,
            "{} {}: measured {} vs bundled {} (regenerate with `cargo run --example make_arkit_amplitudes`)",
            f.shape,
            f.fap,
            f.value,
            b.value
        );
    }
    // The bundled table is what the library embeds.
    assert_eq!(fbakit::rig::arkit_amplitudes::arkit_amplitudes(), bundled);
}

#[test]
fn alma_exports_arkit_named_targets() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("alma-arkit.glb");
    let o = fbakit(&[
        "face",
        "export",
        "alma",
        "-o",
        out.to_str().unwrap(),
        "--names",
        "arkit",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let targets: Vec<&str> = report["arkit"]["targets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let unmapped: Vec<&str> = report["arkit"]["unmapped"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["shape"].as_str().unwrap())
        .collect();
    assert_eq!(targets.len() + unmapped.len(), 52);
    assert!(unmapped.contains(&"cheekPuff") && unmapped.contains(&"mouthClose"));

    // Read back: every target is an ARKit name, at most 52 of them, and jawOpen moves the
    // chin (feature point 2.1) down.
    let rig = fbakit::rig::read_rig(&out).unwrap();
    assert!(!rig.shapes.is_empty() && rig.shapes.len() <= 52);
    for s in &rig.shapes {
        assert!(ARKIT_SHAPES.contains(&s.name.as_str()), "{}", s.name);
    }
    assert_eq!(rig.shapes.len(), targets.len());
    let alma = fbakit::face::read(Path::new("alma")).unwrap();
    let chin = "2.1".parse().unwrap();
    let (mesh, vertex) = alma.fp_vertex(chin).unwrap();
    let jaw = rig.shape("jawOpen").expect("a jawOpen target");
    let d = jaw.offset(mesh, vertex);
    eprintln!("jawOpen moves 2.1 by {d} m");
    assert!(d.y < -0.005, "jawOpen moves the chin by {d}");
    assert!(d.y.abs() > d.x.abs());
    // A blink closes the left upper lid (3.1) downwards.
    let (m, v) = alma.fp_vertex("3.1".parse().unwrap()).unwrap();
    assert!(rig.shape("eyeBlinkLeft").unwrap().offset(m, v).y < 0.0);

    let gltf = dir.path().join("alma-arkit.gltf");
    let o = fbakit(&[
        "face",
        "export",
        "alma",
        "-o",
        gltf.to_str().unwrap(),
        "--names",
        "arkit",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    if let Some(reports) = validate(&[out, gltf]) {
        for r in &reports {
            assert_eq!(r["errors"], 0, "{r:#}");
            assert_eq!(r["warnings"], 0, "{r:#}");
        }
    }
}

#[test]
fn bad_input_exits_2_with_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let put = |name: &str, text: &str| {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let ragged = put(
        "ragged.csv",
        "Timecode,JawOpen
00:00:00:01,0.5
00:00:00:02
",
    );
    let nan = put(
        "nan.csv",
        "time,JawOpen
0,0.5
0.1,NaN
",
    );
    let no_time = put(
        "notime.csv",
        "JawOpen,EyeBlinkLeft
0.1,0.2
",
    );
    let fp = put(
        "fp.csv",
        "not,a,feature,point,file
",
    );
    let out = d.join("out.fap");
    let out_s = out.to_str().unwrap();
    // The CSV is read before the rig, so these fail fast even with a rig path that does not
    // exist.
    let rig = d.join("no-rig").to_str().unwrap().to_string();
    for (csv, expect) in [
        (
            &ragged,
            "ragged.csv:3:12: expected 2 fields like the header",
        ),
        (&nan, "nan.csv:3:5: expected a finite weight"),
        (&no_time, "notime.csv:1:1: expected a `Timecode` column"),
    ] {
        let o = fbakit(&[
            "fap",
            "from-arkit",
            csv,
            "--face",
            &rig,
            "--fp",
            &fp,
            "-o",
            out_s,
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(expect), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!out.exists());
    }
    // Unknown output extension, and writing over the input.
    let good = put(
        "good.csv",
        "time,JawOpen
0,0.5
0.1,0.6
",
    );
    let o = fbakit(&[
        "fap",
        "from-arkit",
        &good,
        "--face",
        &rig,
        "--fp",
        &fp,
        "-o",
        d.join("out.xyz").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let o = fbakit(&[
        "fap", "to-arkit", &good, "--face", &rig, "--fp", &fp, "-o", &good,
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(&good).unwrap(),
        "time,JawOpen
0,0.5
0.1,0.6
"
    );
    // to-arkit with a stream that does not parse.
    let bad_fap = put(
        "bad.fap",
        "2.1 x 25
",
    );
    let o = fbakit(&[
        "fap",
        "to-arkit",
        &bad_fap,
        "--face",
        &rig,
        "--fp",
        &fp,
        "-o",
        d.join("w.csv").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!d.join("w.csv").exists());
    // face export --names arkit of a face file that does not exist.
    let o = fbakit(&[
        "face",
        "export",
        "nope.wrl",
        "-o",
        d.join("x.glb").to_str().unwrap(),
        "--names",
        "arkit",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!d.join("x.glb").exists());
}

#[test]
fn cli_round_trip_on_ict() {
    let Some(ict) = ict() else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let ict_dir = ict.dir.to_str().unwrap();
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
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = d.join("capture.csv");
    // One out-of-range weight (line 4, JawOpen): clamped, one warning naming the place.
    let mut lines: Vec<String> = weight_csv().lines().map(String::from).collect();
    let mut fields: Vec<String> = lines[3].split(',').map(String::from).collect();
    fields[2] = "1.7".into();
    lines[3] = fields.join(",");
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let fap = d.join("capture.fap");
    let o = fbakit(&[
        "fap",
        "from-arkit",
        csv.to_str().unwrap(),
        "--face",
        ict_dir,
        "--fp",
        fp.to_str().unwrap(),
        "-o",
        fap.to_str().unwrap(),
        "--json",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_eq!(err.matches("clamped").count(), 1, "{err}");
    assert!(
        err.contains(
            "capture.csv: 1 weight outside 0..1 clamped (first at line 4, column 3 `JawOpen`)"
        ),
        "{err}"
    );
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["frames"], 20);
    assert_eq!(report["fps"], 60.0);
    let weights = d.join("back.csv");
    let o = fbakit(&[
        "fap",
        "to-arkit",
        fap.to_str().unwrap(),
        "--face",
        ict_dir,
        "--fp",
        fp.to_str().unwrap(),
        "-o",
        weights.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let back = std::fs::read_to_string(&weights).unwrap();
    let header = back.lines().next().unwrap();
    assert!(header.starts_with("Timecode,BlendShapeCount,EyeBlinkLeft,EyeLookDownLeft,"));
    assert!(header.ends_with(",TongueOut,HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll"));
    assert_eq!(header.split(',').count(), 63);
    assert_eq!(back.lines().count(), 21);
    // The written CSV reads back (60 fps given: 20 frames never cross a second).
    let w = parse_weights_csv(&back, &weights, Some(60.0)).unwrap();
    assert_eq!(w.rows.len(), 20);
    let jaw = w.columns.iter().position(|c| c.name == "JawOpen").unwrap();
    let got = w.rows[2].weights[jaw];
    assert!(
        (got - 1.0).abs() < ROUND_TRIP_TOLERANCE,
        "JawOpen at the clamped row: {got}"
    );
    // The constant head yaw of the capture comes back in radians.
    let yaw = w.columns.iter().position(|c| c.name == "HeadYaw").unwrap();
    assert!(w.rows.iter().all(|r| (r.weights[yaw] - 0.05).abs() < 1e-6));
}

#[test]
fn clone_writes_arkit_named_targets() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bruno-arkit.glb");
    let o = fbakit(&[
        "clone",
        "alma",
        "bruno",
        "-o",
        out.to_str().unwrap(),
        "--method",
        "rbf",
        "--names",
        "arkit",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rig = fbakit::rig::read_rig(&out).unwrap();
    assert!(rig.shape("jawOpen").is_some());
    assert!(rig.shapes.len() <= 52);
    assert!(rig
        .shapes
        .iter()
        .all(|s| ARKIT_SHAPES.contains(&s.name.as_str())));
    // ARKit names need a glTF output: refused before cloning, nothing written.
    let wrl = dir.path().join("bruno.wrl");
    let o = fbakit(&[
        "clone",
        "alma",
        "bruno",
        "-o",
        wrl.to_str().unwrap(),
        "--names",
        "arkit",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!wrl.exists());
}

#[test]
fn full_live_link_face_header_resolves_on_ict() {
    let Some(ict) = ict() else { return };
    let rotations = [
        "HeadYaw",
        "HeadPitch",
        "HeadRoll",
        "LeftEyeYaw",
        "LeftEyePitch",
        "LeftEyeRoll",
        "RightEyeYaw",
        "RightEyePitch",
        "RightEyeRoll",
    ];
    let mut header = String::from("Timecode,BlendShapeCount");
    for n in ARKIT_SHAPES {
        header.push(',');
        header.push_str(&fbakit::rig::arkit_names::capture_name(n));
    }
    for r in rotations {
        header.push(',');
        header.push_str(r);
    }
    let zeros = ",0".repeat(52 + 9);
    let text = format!("{header}\n00:00:00:00.000,61{zeros}\n00:00:00:01.000,61{zeros}\n");
    let csv = parse_weights_csv(&text, Path::new("llf.csv"), Some(60.0)).unwrap();
    let bridge = ArkitBridge::new(&ict.rig, &ict.face, &ict.report).unwrap();
    let (stream, report) = bridge.weights_to_faps(&csv, "llf").unwrap();
    assert_eq!(stream.frames.len(), 2);
    let ignored: Vec<(&str, &str)> = report
        .columns
        .iter()
        .filter(|c| !c.ignored.is_empty())
        .map(|c| (c.column.as_str(), c.ignored.as_str()))
        .collect();
    // ICT has every ARKit shape but tongueOut; rotations that stay 0 and eye roll carry
    // nothing.
    assert_eq!(ignored.len(), 10, "{ignored:?}");
    assert!(ignored.contains(&("TongueOut", "ARKit shape the rig does not have")));
    assert!(ignored.contains(&("HeadYaw", "rotation 0 on every row")));
    assert!(ignored.contains(&("LeftEyeRoll", "eye roll has no FAP")));
    // All-zero weights give the neutral: every FAP 0.
    assert!(stream.frames[0].values().iter().all(|v| *v == 0.0));
}
