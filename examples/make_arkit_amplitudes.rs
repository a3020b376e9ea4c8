//! Measures `specs/arkit-fap-amplitudes.csv` on the ICT-FaceKit rig: the FAP value each ARKit
//! shape shows at weight 1, from the calibration of `fbakit::rig::fat_build::face_from_rig`
//! with feature points derived from ICT's iBUG-68 landmark vertices
//! (`fbakit::rig::arkit_amplitudes::measure_amplitudes`).
//!
//! Run: `cargo run --example make_arkit_amplitudes [ICT_DIR]` (default
//! `../shared/data/ict-facekit`); it rewrites the table. `tests/arkit_bridge.rs` regenerates it
//! and compares with the committed file.
#![allow(dead_code)] // Also included as a module by the tests, which do not call `main`.

use std::path::{Path, PathBuf};

use fbakit::error::Result;
use fbakit::face::FaceModel;
use fbakit::fdp::landmarks::{feature_points_from_landmarks, read_landmark_ids, LandmarkScheme};
use fbakit::rig::arkit_amplitudes::{amplitudes_csv, measure_amplitudes};
use fbakit::rig::fap_map::FapMap;
use fbakit::rig::fat_build::{face_from_rig, RigFatReport};
use fbakit::rig::Rig;

/// Where the measured values come from (the table's `source` column starts with it).
pub const SOURCE: &str = "ICT-FaceKit calibration";

/// The ICT rig, its face with a FAT calibrated on feature points from its landmarks, and the
/// calibration report.
pub fn load_ict(dir: &Path) -> Result<(Rig, FaceModel, RigFatReport)> {
    let rig = fbakit::rig::read_rig(dir)?;
    let ids = read_landmark_ids(&dir.join("vertex_indices.json"))?;
    let found =
        feature_points_from_landmarks(&rig.meshes[0].mesh, LandmarkScheme::Ibug68, &ids.ids)?;
    let (face, report) = face_from_rig(&rig, Some(found.feature_point_set()), &FapMap::arkit())?;
    Ok((rig, face, report))
}

/// The table's text for a loaded rig.
pub fn table_text(rig: &Rig, face: &FaceModel, report: &RigFatReport) -> Result<String> {
    Ok(amplitudes_csv(&measure_amplitudes(
        rig, face, report, SOURCE,
    )?))
}

fn main() {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/ict-facekit")
        });
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("specs/arkit-fap-amplitudes.csv");
    let result = load_ict(&dir)
        .and_then(|(rig, face, report)| table_text(&rig, &face, &report))
        .and_then(|text| fbakit::io::write_atomic(&out, text.as_bytes()));
    match result {
        Ok(()) => println!("wrote {}", out.display()),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    }
}
