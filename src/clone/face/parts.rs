//! Sorting a face's meshes into the deformable skin and rigid parts (eyes, teeth, tongue) from
//! the feature points they hold (module docs of [`super`], step 1).

use std::collections::{BTreeMap, BTreeSet, HashMap};

use glam::Vec3;
use serde::Serialize;

use crate::face::{FaceFrames, FaceModel};
use crate::spec::{FapuKind, FeaturePointId};

/// A rigid part of a face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Part {
    /// Left eyeball (holds 3.5).
    LeftEye,
    /// Right eyeball (holds 3.6).
    RightEye,
    /// Upper teeth (9.8, 9.10).
    UpperTeeth,
    /// Lower teeth (9.9, 9.11).
    LowerTeeth,
    /// Tongue (6.1–6.4).
    Tongue,
}

impl Part {
    /// All parts, in the order roles are looked up.
    pub const ALL: [Part; 5] = [
        Part::LeftEye,
        Part::RightEye,
        Part::UpperTeeth,
        Part::LowerTeeth,
        Part::Tongue,
    ];

    /// Short name used for new transforms and messages.
    pub fn name(self) -> &'static str {
        match self {
            Part::LeftEye => "eye_l",
            Part::RightEye => "eye_r",
            Part::UpperTeeth => "teeth_upper",
            Part::LowerTeeth => "teeth_lower",
            Part::Tongue => "tongue",
        }
    }

    /// The feature points that identify the part.
    pub fn feature_points(self) -> Vec<FeaturePointId> {
        use FeaturePointId as F;
        match self {
            Part::LeftEye => vec![F::FP_3_5],
            Part::RightEye => vec![F::FP_3_6],
            Part::UpperTeeth => vec![F::FP_9_8, F::FP_9_10],
            Part::LowerTeeth => vec![F::FP_9_9, F::FP_9_11],
            Part::Tongue => vec![F::FP_6_1, F::FP_6_2, F::FP_6_3, F::FP_6_4],
        }
    }

    /// The part a feature point identifies, if any.
    pub fn of_feature_point(id: FeaturePointId) -> Option<Part> {
        Part::ALL
            .into_iter()
            .find(|p| p.feature_points().contains(&id))
    }

    /// FAPU kind used to scale this part's translations for high-level tables.
    pub(super) fn unit(self) -> FapuKind {
        match self {
            Part::LeftEye | Part::RightEye => FapuKind::Es,
            _ => FapuKind::Mns,
        }
    }
}

/// How a face's meshes split into skin and rigid parts (mesh indices).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FaceParts {
    /// The deformable surface.
    pub skin: Vec<usize>,
    /// Rigid parts.
    pub parts: BTreeMap<Part, Vec<usize>>,
    /// Meshes of neither (no feature point, not connected): rigid with the head.
    pub other: Vec<usize>,
}

impl FaceParts {
    /// Skin and part meshes: every mesh the face's motion moves (not [`FaceParts::other`]).
    pub(super) fn face_meshes(&self) -> Vec<usize> {
        self.skin
            .iter()
            .chain(self.parts.values().flatten())
            .copied()
            .collect()
    }
}

/// Mesh and vertex of a feature point: its binding, else the nearest vertex of any mesh when
/// that is within `tol` of its position.
pub(super) fn fp_mesh_vertex(
    face: &FaceModel,
    frames: &FaceFrames,
    id: FeaturePointId,
    tol: f32,
) -> Option<(usize, u32)> {
    if let Some(mv) = face.fp_vertex(id) {
        if face
            .meshes
            .get(mv.0)
            .is_some_and(|m| (mv.1 as usize) < m.mesh.positions.len())
        {
            return Some(mv);
        }
    }
    let p = face.feature_points.position(id)?;
    let mut best: Option<(usize, u32, f32)> = None;
    for (mi, m) in face.meshes.iter().enumerate() {
        let w = frames.meshes[mi];
        for (vi, &q) in m.mesh.positions.iter().enumerate() {
            let d = w.transform_point3(q).distance(p);
            if best.is_none_or(|b| d < b.2) {
                best = Some((mi, vi as u32, d));
            }
        }
    }
    best.filter(|b| b.2 <= tol).map(|b| (b.0, b.1))
}

/// Diagonal of the face's world bounding box (1 without finite vertices): the size that
/// welding and matching tolerances are relative to.
pub(super) fn face_diagonal(face: &FaceModel, frames: &FaceFrames) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for (mi, m) in face.meshes.iter().enumerate() {
        for &p in &m.mesh.positions {
            let q = frames.meshes[mi].transform_point3(p);
            if q.is_finite() {
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
    }
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        1.0
    }
}

/// Sorts a face's meshes into skin and rigid parts from its feature points (module docs,
/// step 1). A mesh without feature points lying on an eyeball with its rim on the lids (an
/// eye blend, occlusion or tear film of its own) is skin too.
pub fn identify_parts(face: &FaceModel) -> FaceParts {
    // By place in the face's upright frame ([`super::upright`]); the result is mesh indices.
    let look = super::upright::for_recognition(face);
    let face = look.as_ref();
    let frames = face.frames();
    let diag = face_diagonal(face, &frames);
    let n = face.meshes.len();
    let (mut part_of, has_skin_fp) = seed_parts(face, &frames, diag);
    let adjacent = mesh_adjacency(face, &frames, diag);
    // Grow parts over connected meshes that hold no skin point and belong to nothing yet.
    let mut queue: Vec<usize> = (0..n).filter(|&m| part_of[m].is_some()).collect();
    while let Some(m) = queue.pop() {
        let p = part_of[m];
        for &o in &adjacent[m] {
            if part_of[o].is_none() && !has_skin_fp[o] {
                part_of[o] = p;
                queue.push(o);
            }
        }
    }
    let mut is_skin = has_skin_fp.clone();
    // Layers resting on the lids are skin, as they are in a one-mesh head.
    for m in super::split::lid_layers(face, &frames, diag) {
        if part_of[m].is_none() {
            is_skin[m] = true;
        }
    }
    let mut queue: Vec<usize> = (0..n).filter(|&m| is_skin[m]).collect();
    while let Some(m) = queue.pop() {
        for &o in &adjacent[m] {
            if part_of[o].is_none() && !is_skin[o] {
                is_skin[o] = true;
                queue.push(o);
            }
        }
    }
    let mut out = FaceParts::default();
    for mi in 0..n {
        if let Some(p) = part_of[mi] {
            out.parts.entry(p).or_default().push(mi);
        } else if is_skin[mi] {
            out.skin.push(mi);
        } else {
            out.other.push(mi);
        }
    }
    out
}

/// Per mesh, the part its feature points identify and whether it holds a skin feature point
/// (which makes it skin even if a part point sits on it too).
fn seed_parts(face: &FaceModel, frames: &FaceFrames, diag: f32) -> (Vec<Option<Part>>, Vec<bool>) {
    let n = face.meshes.len();
    let mut part_of: Vec<Option<Part>> = vec![None; n];
    let mut has_skin_fp = vec![false; n];
    for fp in face.feature_points.iter() {
        let Some((mi, _)) = fp_mesh_vertex(face, frames, fp.id, diag * 1e-4) else {
            continue;
        };
        match Part::of_feature_point(fp.id) {
            Some(p) => {
                if part_of[mi].is_none() {
                    part_of[mi] = Some(p);
                }
            }
            None => has_skin_fp[mi] = true,
        }
    }
    // A mesh holding skin points is skin even if a part point sits on it too (one-mesh heads).
    for mi in 0..n {
        if has_skin_fp[mi] {
            part_of[mi] = None;
        }
    }
    (part_of, has_skin_fp)
}

/// The meshes each mesh is connected to: sharing a vertex position, quantised at 1e-5 of the
/// face's size `diag`.
fn mesh_adjacency(face: &FaceModel, frames: &FaceFrames, diag: f32) -> Vec<BTreeSet<usize>> {
    let q = (diag * 1e-5).max(f32::MIN_POSITIVE);
    let mut cells: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (mi, m) in face.meshes.iter().enumerate() {
        for &p in &m.mesh.positions {
            let w = frames.meshes[mi].transform_point3(p);
            if !w.is_finite() {
                continue;
            }
            let key = (
                (w.x / q).round() as i64,
                (w.y / q).round() as i64,
                (w.z / q).round() as i64,
            );
            let list = cells.entry(key).or_default();
            if !list.contains(&mi) {
                list.push(mi);
            }
        }
    }
    let mut adjacent: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); face.meshes.len()];
    for list in cells.values().filter(|l| l.len() > 1) {
        for &a in list {
            for &b in list {
                if a != b {
                    adjacent[a].insert(b);
                }
            }
        }
    }
    adjacent
}
