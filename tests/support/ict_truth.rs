//! A real-head ground truth for cloning, from the ICT-FaceKit rig (shared by the
//! `clone_ict` test and bench).
//!
//! Head A: the ICT neutral with the FAT `face_from_rig` builds from its ARKit shapes,
//! restricted to [`FAPS`]. Head B: A's neutral under a smooth symmetric shape change
//! ([`reshape`]: wider jaw, longer nose, fuller cheeks), feature points carried over by vertex.
//! B's true FAT is A's tables with every per-vertex rate unchanged and multiplied by
//! B/A's FAPU ratio of the FAP's unit. Why that is the truth: FAT rates are per unit of FAP
//! value, and a FAP unit is a fraction of the face's own FAPU distance, so the same FAP value
//! must move B's feature points by B's FAPU; with the same topology and a smooth, mild shape
//! change every vertex keeps its anatomical role, and the rig is linear, so carrying each
//! vertex's motion over and scaling it is the motion B's animator would make (the ICT-based
//! ground truth of the issue was made exactly so). `B×10 + offset` checks units and position.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

use fbakit::face::FaceModel;
use fbakit::fdp::landmarks::{feature_points_from_landmarks, read_landmark_ids, LandmarkScheme};
use fbakit::rig::fap_map::FapMap;
use fbakit::rig::fat_build::face_from_rig;
use fbakit::spec::{FapId, FapuKind};
use glam::Vec3;

/// The FAPs of head A's FAT: jaw, lids, lip corners, brows.
pub const FAPS: [u8; 14] = [
    3,  // open_jaw
    14, // thrust_jaw
    15, // shift_jaw
    19, // close_t_l_eyelid
    20, // close_t_r_eyelid
    12, // raise_l_cornerlip
    13, // raise_r_cornerlip
    6,  // stretch_l_cornerlip
    7,  // stretch_r_cornerlip
    31, // raise_l_i_eyebrow
    32, // raise_r_i_eyebrow
    35, // raise_l_o_eyebrow
    36, // raise_r_o_eyebrow
    33, // raise_l_m_eyebrow
];

pub fn ict_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/ict-facekit");
    if dir.join("generic_neutral_mesh.obj").is_file() {
        Some(dir)
    } else {
        eprintln!("note: {} not found; skipping", dir.display());
        None
    }
}

/// Head A: the ICT neutral with its rig FAT restricted to [`FAPS`].
pub fn head_a(dir: &Path) -> FaceModel {
    let mut face = rig_head(dir);
    face.fat.tables.retain(
        |t| matches!(t.key, fbakit::fat::TableKey::LowLevel(f) if FAPS.contains(&f.number())),
    );
    face.name = "ict_a".into();
    face
}

/// The ICT neutral with every table of its rig FAT.
pub fn rig_head(dir: &Path) -> FaceModel {
    let rig = fbakit::rig::read_rig(dir).unwrap();
    let ids = read_landmark_ids(&dir.join("vertex_indices.json")).unwrap();
    let found =
        feature_points_from_landmarks(&rig.meshes[0].mesh, LandmarkScheme::Ibug68, &ids.ids)
            .unwrap();
    let (mut face, _) =
        face_from_rig(&rig, Some(found.feature_point_set()), &FapMap::arkit()).unwrap();
    face.name = "ict".into();
    face
}

/// The smooth symmetric shape change from A to B (face frame, centimetres, centred on A's
/// landmarks `nose` = 9.3 and `chin` = 2.1).
pub fn reshape(p: Vec3, nose: Vec3, chin: Vec3) -> Vec3 {
    let g = |c: Vec3, s: f32| (-(p - c).length_squared() / (2.0 * s * s)).exp();
    let mut q = p;
    // Longer nose: forward around the tip.
    q.z += 0.6 * g(nose, 1.8);
    // Wider jaw: sideways, growing below the mouth.
    let jaw = g(Vec3::new(0.0, chin.y + 1.0, chin.z - 4.0), 5.0);
    q.x += 0.12 * p.x * jaw;
    // Fuller cheeks, both sides.
    for side in [-1.0, 1.0] {
        let c = Vec3::new(side * 4.5, nose.y - 1.0, nose.z - 3.0);
        q += Vec3::new(side * 0.35, 0.0, 0.2) * g(c, 2.0);
    }
    q
}

/// `a` with every position through `f` (feature points carried over) and its FAT's rates
/// scaled by the FAPU ratio: the face and its true FAT.
pub fn head_b(a: &FaceModel, f: impl Fn(Vec3) -> Vec3) -> FaceModel {
    let mut b = a.clone();
    b.name = "ict_b".into();
    b.scene = None;
    // `a` has no transforms (a rig face): local = world.
    for m in &mut b.meshes {
        for p in &mut m.mesh.positions {
            *p = f(*p);
        }
        m.mesh.normals.clear();
        m.mesh.normal_polygons = None;
    }
    let ids: Vec<_> = b.feature_points.iter().map(|p| p.id).collect();
    for id in ids {
        let mut fp = b.feature_points.get(id).unwrap().clone();
        fp.position = fp.position.map(&f);
        b.feature_points.insert(fp);
    }
    let (fa, fb) = (a.fapu().unwrap(), b.fapu().unwrap());
    for t in &mut b.fat.tables {
        let kind = match t.key {
            fbakit::fat::TableKey::LowLevel(fap) => fap.info().fapu.unwrap_or(FapuKind::Mns),
            _ => FapuKind::Mns,
        };
        let r = (fb.unit(kind) / fa.unit(kind)) as f32;
        for m in &mut t.meshes {
            for d in &mut m.displacements {
                *d *= r;
            }
        }
    }
    b
}

/// The nose tip and chin of `a`.
pub fn anchors(a: &FaceModel) -> (Vec3, Vec3) {
    let p = |s: &str| a.feature_points.position(s.parse().unwrap()).unwrap();
    (p("9.3"), p("2.1"))
}

/// FAP by number (for messages).
pub fn fap(n: u8) -> FapId {
    FapId::new(n).unwrap()
}

/// `face` with every polygon of every mesh split once at its edge midpoints (triangles into
/// four triangles, other polygons into one quad per corner around their centre). New
/// vertices' positions and FAT rates are the means of the vertices they lie between, so a
/// true FAT stays exactly true (the rig is linear). Original vertices keep their indices, so
/// feature points stay bound. (Unlike `fbakit::face::subdivide`, which triangulates first,
/// quads stay quads here: the subdivided ICT target is a quad mesh like the original.)
pub fn subdivide(face: &FaceModel) -> FaceModel {
    use std::collections::HashMap;
    let mut out = face.clone();
    out.name = format!("{}_sub", face.name);
    // Per mesh: the new vertices as lists of the old vertices they average.
    let mut recipes: Vec<Vec<Vec<u32>>> = Vec::new();
    for m in &mut out.meshes {
        let mesh = &mut m.mesh;
        let n = mesh.positions.len() as u32;
        let mut extra: Vec<Vec<u32>> = Vec::new();
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        let mut polys: Vec<Vec<u32>> = Vec::new();
        let mut mid = |a: u32, b: u32, extra: &mut Vec<Vec<u32>>| -> u32 {
            *edges.entry((a.min(b), a.max(b))).or_insert_with(|| {
                extra.push(vec![a, b]);
                n + extra.len() as u32 - 1
            })
        };
        for poly in mesh.polygons.iter() {
            let k = poly.len();
            let mids: Vec<u32> = (0..k)
                .map(|i| mid(poly[i], poly[(i + 1) % k], &mut extra))
                .collect();
            if k == 3 {
                polys.push(vec![poly[0], mids[0], mids[2]]);
                polys.push(vec![mids[0], poly[1], mids[1]]);
                polys.push(vec![mids[2], mids[1], poly[2]]);
                polys.push(vec![mids[0], mids[1], mids[2]]);
            } else {
                extra.push(poly.to_vec());
                let c = n + extra.len() as u32 - 1;
                for i in 0..k {
                    polys.push(vec![poly[i], mids[i], c, mids[(i + k - 1) % k]]);
                }
            }
        }
        for r in &extra {
            let p = r.iter().map(|&v| mesh.positions[v as usize]).sum::<Vec3>() / r.len() as f32;
            mesh.positions.push(p);
        }
        mesh.polygons = fbakit::mesh::Polygons::from_lists(&polys);
        mesh.colors.clear();
        mesh.uvs.clear();
        mesh.uv_polygons = None;
        mesh.normals.clear();
        mesh.normal_polygons = None;
        mesh.groups.clear();
        recipes.push(extra);
    }
    for t in &mut out.fat.tables {
        for dm in &mut t.meshes {
            let Some(mi) = face.mesh_index(&dm.mesh) else {
                continue;
            };
            let k = dm.interval_count().max(1);
            let n = face.meshes[mi].mesh.positions.len();
            let mut rates = vec![vec![Vec3::ZERO; k]; n];
            for (slot, &v) in dm.coord_index.iter().enumerate() {
                rates[v as usize].copy_from_slice(&dm.displacements[slot * k..(slot + 1) * k]);
            }
            for r in &recipes[mi] {
                let mean: Vec<Vec3> = (0..k)
                    .map(|j| r.iter().map(|&v| rates[v as usize][j]).sum::<Vec3>() / r.len() as f32)
                    .collect();
                rates.push(mean);
            }
            dm.coord_index.clear();
            dm.displacements.clear();
            for (v, r) in rates.iter().enumerate() {
                if r.iter().any(|d| *d != Vec3::ZERO) {
                    dm.coord_index.push(v as u32);
                    dm.displacements.extend_from_slice(r);
                }
            }
        }
    }
    out
}

/// ICT-FaceKit identity `name` (`identities/<name>.obj`) as per-vertex offsets from the
/// generic neutral: one standard deviation of that principal component.
pub fn identity_offsets(dir: &Path, name: &str) -> Vec<Vec3> {
    let read = |p: &Path| -> Vec<Vec3> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f32> = l.split_whitespace().map(|s| s.parse().unwrap()).collect();
                Vec3::new(c[0], c[1], c[2])
            })
            .collect()
    };
    let neutral = read(&dir.join("generic_neutral_mesh.obj"));
    let id = read(&dir.join("identities").join(format!("{name}.obj")));
    assert_eq!(neutral.len(), id.len());
    id.iter().zip(&neutral).map(|(a, b)| *a - *b).collect()
}

/// A second real head from ICT's linear identity model: A's neutral plus `Σ w · identity`
/// (`weights` in standard deviations), then `× scale + offset`; its true FAT is A's rates
/// times the FAPU ratio, as for [`head_b`] (an expression's delta applies to every identity
/// unchanged, so the same rates in FAP units of B are B's motion).
pub fn identity_head(
    a: &FaceModel,
    dir: &Path,
    weights: &[(&str, f32)],
    scale: f32,
    offset: Vec3,
) -> FaceModel {
    let offsets: Vec<Vec<Vec3>> = weights
        .iter()
        .map(|(n, _)| identity_offsets(dir, n))
        .collect();
    let mut b = a.clone();
    assert_eq!(b.meshes.len(), 1);
    let n = b.meshes[0].mesh.positions.len();
    assert_eq!(n, offsets[0].len());
    for (v, q) in b.meshes[0].mesh.positions.iter_mut().enumerate() {
        let moved = weights
            .iter()
            .zip(&offsets)
            .fold(*q, |p, ((_, w), o)| p + *w * o[v]);
        *q = moved * scale + offset;
    }
    b.meshes[0].mesh.normals.clear();
    b.meshes[0].mesh.normal_polygons = None;
    b.resolve_feature_points().unwrap();
    b.scene = None;
    let mut truth = b;
    let (fa, fb) = (a.fapu().unwrap(), truth.fapu().unwrap());
    for (t, ta) in truth.fat.tables.iter_mut().zip(&a.fat.tables) {
        let kind = match t.key {
            fbakit::fat::TableKey::LowLevel(fap) => fap.info().fapu.unwrap_or(FapuKind::Mns),
            _ => FapuKind::Mns,
        };
        let r = (fb.unit(kind) / fa.unit(kind)) as f32;
        for (m, ma) in t.meshes.iter_mut().zip(&ta.meshes) {
            for (d, da) in m.displacements.iter_mut().zip(&ma.displacements) {
                *d = *da * r;
            }
        }
    }
    truth.name = "ict_identity".into();
    truth
}
