//! The ARKit ⇄ MPEG-4 bridge on the real ICT-FaceKit rig (feature points derived from its
//! iBUG-68 landmark vertices): weight curves → FAP stream → weight curves, the ARKit-named
//! glb export of a FAT face, and the commands' exit codes. Tests that need
//! `../shared/data/ict-facekit` print a note and return when it is absent.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use fbakit::face::FaceModel;
use fbakit::fdp::landmarks::{feature_points_from_landmarks, read_landmark_ids, LandmarkScheme};
use fbakit::rig::arkit_names::ARKIT_SHAPES;
use fbakit::rig::arkit_weights::ArkitBridge;
use fbakit::rig::fap_map::FapMap;
use fbakit::rig::fat_build::{face_from_rig, RigFatReport};
use fbakit::rig::weights_csv::parse_weights_csv;
use fbakit::rig::Rig;

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
        let rig = fbakit::rig::read_rig(&dir).unwrap();
        let ids = read_landmark_ids(&dir.join("vertex_indices.json")).unwrap();
        let found =
            feature_points_from_landmarks(&rig.meshes[0].mesh, LandmarkScheme::Ibug68, &ids.ids)
                .unwrap();
        let (face, report) =
            face_from_rig(&rig, Some(found.feature_point_set()), &FapMap::arkit()).unwrap();
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

#[test]
fn weights_round_trip_through_a_fap_stream() {
    let Some(ict) = ict() else { return };
    let text = weight_csv();
    let csv = parse_weights_csv(Path::new("capture.csv"), &text, None).unwrap();
    assert_eq!(csv.fps, 60.0);
    let mut bridge = ArkitBridge::new(&ict.rig, &ict.face, &ict.report).unwrap();
    let (stream, report) = bridge.weights_to_faps(&csv, "capture").unwrap();
    eprintln!("from-arkit residual {:.4}, faps {:?}", report.relative_residual, report.faps);
    assert_eq!(stream.frames.len(), 20);
    let (weights, back) = bridge.faps_to_weights(&stream).unwrap();
    eprintln!("to-arkit residual {:.4}", back.relative_residual);
    assert_eq!(weights.len(), 20);
    for (c, col) in csv.columns.iter().enumerate() {
        let Some(i) = ARKIT_SHAPES.iter().position(|a| a.eq_ignore_ascii_case(&col.name)) else {
            continue;
        };
        let worst = csv
            .rows
            .iter()
            .zip(&weights)
            .map(|(r, w)| (r.weights[c] - w[i]).abs())
            .fold(0.0f32, f32::max);
        eprintln!("{:<16} worst |Δw| {worst:.4}", col.name);
    }
    let others = weights
        .iter()
        .flat_map(|w| w.iter().enumerate())
        .filter(|(i, _)| {
            !csv.columns
                .iter()
                .any(|c| ARKIT_SHAPES[*i].eq_ignore_ascii_case(&c.name))
        })
        .map(|(_, v)| *v)
        .fold(0.0f32, f32::max);
    eprintln!("largest weight of a shape not in the capture: {others:.4}");
    let _ = &ict.dir;
}
