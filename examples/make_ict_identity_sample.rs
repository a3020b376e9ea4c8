//! Makes the bundled second real head `samples/faces/ict-identity/` from ICT-FaceKit's linear
//! identity model (MIT):
//!
//! ```sh
//! cargo run --release --example make_ict_identity_sample -- ../shared/data/ict-facekit samples/faces/ict-identity
//! ```
//!
//! The head is `N + 2.5 (identity003 − N) − 3 (identity033 − N)` (`N` the generic neutral; the
//! identities are principal components at one standard deviation, so these are weights of
//! 2.5 and −3 standard deviations), trimmed like `ict-head` (`make_ict_sample`): vertices
//! 0–24590 (no lacrimal fluid, eye blend, eye occlusion or lashes), no UVs, metres. Only the
//! neutral is written: the head is a cloning target (a mesh with feature points). Its true
//! FAT needs no second copy of the shapes: ICT's model is linear, so this head's ARKit shapes
//! are its neutral plus the same expression deltas `ict-head.glb` carries (`fbakit demo`
//! builds it so). Feature points come from ICT's iBUG-68 landmarks on this head, as for
//! `ict-head`.

use std::path::{Path, PathBuf};

use fbakit::fdp::landmarks::{feature_points_from_landmarks, read_landmark_ids, LandmarkScheme};
use glam::Vec3;

/// First vertex of ICT's see-through overlays and lashes (as in `make_ict_sample`).
const FIRST_OVERLAY_VERTEX: usize = 24591;

/// Metres per centimetre: the sample is written in metres.
const CM_TO_M: f32 = 0.01;

/// The identity components and their weights in standard deviations.
const IDENTITY: [(&str, f32); 2] = [("identity003", 2.5), ("identity033", -3.0)];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(ict), Some(out)) = (args.get(1), args.get(2)) else {
        return Err("usage: make_ict_identity_sample ICT_FACEKIT_DIR OUT_DIR".into());
    };
    let ict = PathBuf::from(ict);
    let out = PathBuf::from(out);
    std::fs::create_dir_all(&out)?;

    let mut rig = fbakit::rig::read_rig(&ict)?;
    let neutral = obj_vertices(&ict.join("generic_neutral_mesh.obj"))?;
    let positions = &mut rig.meshes[0].mesh.positions;
    if positions.len() != neutral.len() {
        return Err("the rig's neutral and generic_neutral_mesh.obj differ in size".into());
    }
    for (name, weight) in IDENTITY {
        let id = obj_vertices(&ict.join("identities").join(format!("{name}.obj")))?;
        if id.len() != neutral.len() {
            return Err(format!("{name}.obj: {} vertices, not {}", id.len(), neutral.len()).into());
        }
        for ((p, a), n) in positions.iter_mut().zip(&id).zip(&neutral) {
            *p += weight * (*a - *n);
        }
    }
    // The neutral's normals (if the reader made any) belong to the generic head.
    rig.meshes[0].mesh.normals.clear();
    rig.meshes[0].mesh.normal_polygons = None;
    let keep: Vec<bool> = (0..rig.meshes[0].mesh.vertex_count())
        .map(|v| v < FIRST_OVERLAY_VERTEX)
        .collect();
    rig.retain_vertices(0, &keep)?;
    rig.meshes[0].mesh.uvs.clear();
    rig.meshes[0].mesh.uv_polygons = None;
    rig.meshes[0].name = "ict_identity".into();
    rig.name = "ict-identity".into();
    rig.retain_shapes(|_| false);

    let ids = read_landmark_ids(&ict.join("vertex_indices.json"))?;
    let found =
        feature_points_from_landmarks(&rig.meshes[0].mesh, LandmarkScheme::Ibug68, &ids.ids)?;
    let fp_path = out.join("ict-identity-fp.csv");
    fbakit::fdp::csv::write_csv_file(&fp_path, &found.table())?;

    for p in &mut rig.meshes[0].mesh.positions {
        *p *= CM_TO_M;
    }
    let glb = out.join("ict-identity.glb");
    fbakit::rig::gltf_write::write_rig_gltf(&rig, &glb)?;
    std::fs::copy(ict.join("LICENSE"), out.join("LICENSE"))?;
    println!(
        "{}: {} vertices, {} bytes; {}: {} feature points",
        glb.display(),
        rig.vertex_count(),
        std::fs::metadata(&glb)?.len(),
        fp_path.display(),
        found.points.len()
    );
    Ok(())
}

/// The `v` lines of an OBJ file.
fn obj_vertices(path: &Path) -> Result<Vec<Vec3>, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let Some(rest) = line.strip_prefix("v ") else {
            continue;
        };
        let c: Vec<f32> = rest
            .split_whitespace()
            .take(3)
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{}:{}: {e}", path.display(), n + 1))?;
        if c.len() != 3 {
            return Err(format!("{}:{}: expected x y z", path.display(), n + 1).into());
        }
        out.push(Vec3::new(c[0], c[1], c[2]));
    }
    Ok(out)
}
