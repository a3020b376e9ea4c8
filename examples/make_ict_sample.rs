//! Makes the bundled real head `samples/faces/ict-head/` from the ICT-FaceKit rig (MIT):
//!
//! ```sh
//! cargo run --release --example make_ict_sample -- ../shared/data/ict-facekit samples/faces/ict-head
//! ```
//!
//! What it keeps, so the sample stays under 4 MB: the face, back of the head, mouth socket,
//! eye sockets, gums, tongue, teeth and eyeballs (vertices 0–24590 of the neutral: ICT's
//! lacrimal fluid, eye blend, eye occlusion and eyelash layers are dropped), the shapes the
//! ARKit-52 map turns into FAT tables, and shape motion above 0.1 mm (ICT is in cm). It
//! writes the rig in metres as `ict-head.glb` (sparse morph targets, ARKit names), its MPEG-4 feature
//! points derived from ICT's iBUG-68 landmarks as `ict-head-fp.csv` (with provenance), and
//! ICT's licence. `fbakit face info samples/faces/ict-head/ict-head.glb --fp
//! samples/faces/ict-head/ict-head-fp.csv` (or the bundled name `ict`) builds its FAT.

use std::path::{Path, PathBuf};

use fbakit::fdp::landmarks::{feature_points_from_landmarks, read_landmark_ids, LandmarkScheme};
use fbakit::rig::fap_map::FapMap;
use fbakit::rig::fat_build::face_from_rig;

/// First vertex of ICT's lacrimal-fluid layer: everything from here on (lacrimal fluid, eye
/// blend, eye occlusion, eyelashes) is a see-through overlay or hair.
const FIRST_OVERLAY_VERTEX: usize = 24591;

/// Shape motion at or below this is dropped (cm: 0.1 mm).
const MIN_MOTION_CM: f32 = 0.01;

/// Metres per centimetre: the sample is written in metres.
const CM_TO_M: f32 = 0.01;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(ict), Some(out)) = (args.get(1), args.get(2)) else {
        return Err("usage: make_ict_sample ICT_FACEKIT_DIR OUT_DIR".into());
    };
    let ict = PathBuf::from(ict);
    let out = PathBuf::from(out);
    std::fs::create_dir_all(&out)?;

    let mut rig = fbakit::rig::read_rig(&ict)?;
    let full_shapes = rig.shapes.len();
    let keep: Vec<bool> = (0..rig.meshes[0].mesh.vertex_count())
        .map(|v| v < FIRST_OVERLAY_VERTEX)
        .collect();
    rig.retain_vertices(0, &keep)?;
    rig.meshes[0].mesh.uvs.clear();
    rig.meshes[0].mesh.uv_polygons = None;
    rig.meshes[0].name = "ict_head".into();
    rig.name = "ict-head".into();

    // Feature points from the landmarks: the kept vertices are a prefix, so ICT's ids hold.
    let ids = read_landmark_ids(&ict.join("vertex_indices.json"))?;
    let found =
        feature_points_from_landmarks(&rig.meshes[0].mesh, LandmarkScheme::Ibug68, &ids.ids)?;
    let fp_path = out.join("ict-head-fp.csv");
    fbakit::fdp::csv::write_csv_file(&fp_path, &found.table())?;

    // Keep the shapes the ARKit map uses (calibrated on the full-motion rig).
    let (_, report) = face_from_rig(&rig, Some(found.feature_point_set()), &FapMap::arkit())?;
    let unused: Vec<String> = report.unused_shapes.clone();
    rig.retain_shapes(|name| !unused.iter().any(|u| u == name));
    let dropped = rig.drop_motion_below(MIN_MOTION_CM);
    // glTF is in metres: ICT's centimetres are scaled once here, so viewers show a 34 cm
    // head, not a 34 m one (vertex order and ids are untouched, so the feature points hold).
    for m in &mut rig.meshes {
        for p in &mut m.mesh.positions {
            *p *= CM_TO_M;
        }
    }
    for s in &mut rig.shapes {
        for d in &mut s.deltas {
            for o in &mut d.offsets {
                *o *= CM_TO_M;
            }
        }
    }

    let glb = out.join("ict-head.glb");
    fbakit::rig::gltf_write::write_rig_gltf(&rig, &glb)?;
    std::fs::copy(ict.join("LICENSE"), out.join("LICENSE"))?;

    println!(
        "{}: {} vertices, {} of {} shapes ({} motions at or below {} cm dropped), {} bytes",
        glb.display(),
        rig.vertex_count(),
        rig.shapes.len(),
        full_shapes,
        dropped,
        MIN_MOTION_CM,
        size(&glb)
    );
    println!(
        "{}: {} feature points",
        fp_path.display(),
        found.points.len()
    );
    Ok(())
}

fn size(p: &Path) -> u64 {
    std::fs::metadata(p).map_or(0, |m| m.len())
}
