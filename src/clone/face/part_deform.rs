//! Deformations of rigid-part meshes carried to the target's part of the same role (module
//! docs of [`super`], step 7): the source FAT deforms its tongue mesh (tongue roll, tongue
//! tip FAPs) and its eyeballs (pupil dilation), no surface method applies to them, and a
//! target with such meshes of its own should bend them the same way rather than translate
//! the tongue and drop the pupils.
//!
//! Both parts are put in the face frame (the target's through the alignment). When they are
//! one mesh — the same meshes with the same vertex counts and polygons, as a face and its
//! reshaped copy — target vertex `i` takes source vertex `i`'s displacement. Otherwise each
//! target vertex takes the displacement of its nearest source part vertex after both parts
//! are normalised to their bounding boxes (centre and per-axis size), so a longer or
//! narrower tongue still maps tip to tip. Displacements are scaled by the target / source
//! FAPU ratio of the FAP's unit (MNS for high-level tables and angles) and mapped back to
//! each target mesh's frame. Tables whose part motion is transferred so get no rigid tongue
//! translation.

use std::collections::{HashMap, HashSet};

use glam::{DMat3, DVec3, Vec3};

use super::part_motion::part_fapu_ratio;
use super::{FaceParts, Part, Similarity};
use crate::face::FaceModel;
use crate::fat::morph::{MorphMesh, MorphTarget};
use crate::fat::TableKey;
use crate::fdp::Fapu;
use crate::mesh::VertexIndex;

/// Parts whose deformation is transferred: the tongue and the eyeballs (pupil dilation).
/// Teeth are rigid.
const DEFORMABLE: [Part; 3] = [Part::Tongue, Part::LeftEye, Part::RightEye];

/// Part-mesh displacements per source morph target (key, value bits), and the source mesh
/// names whose deformation they carry.
pub(super) struct PartDeformations {
    /// Target part meshes' displacements.
    pub meshes: HashMap<(TableKey, u64), Vec<MorphMesh>>,
    /// Source meshes handled (their deformation needs no rigid stand-in).
    pub handled: HashSet<String>,
}

/// One part of a face in a common frame: its meshes, their concatenated vertices.
struct PartPoints {
    meshes: Vec<usize>,
    starts: Vec<usize>,
    points: Vec<Vec3>,
}

impl PartPoints {
    fn new(face: &FaceModel, meshes: &[usize], place: impl Fn(usize, Vec3) -> Vec3) -> Self {
        let mut starts = Vec::with_capacity(meshes.len());
        let mut points = Vec::new();
        for &mi in meshes {
            starts.push(points.len());
            points.extend(face.meshes[mi].mesh.positions.iter().map(|&p| place(mi, p)));
        }
        PartPoints {
            meshes: meshes.to_vec(),
            starts,
            points,
        }
    }

    /// Points normalised to their bounding box: centre at 0, each axis to [-1, 1] (an axis
    /// without extent keeps scale 1).
    fn normalised(&self) -> Vec<Vec3> {
        let (lo, hi) = self.points.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let c = (lo + hi) / 2.0;
        let h = (hi - lo) / 2.0;
        let h = Vec3::select(h.cmpgt(Vec3::ZERO), h, Vec3::ONE);
        self.points.iter().map(|&p| (p - c) / h).collect()
    }
}

/// Whether two faces' part meshes are one mesh (same vertex counts and polygons, in order).
fn same_meshes(a: &FaceModel, am: &[usize], b: &FaceModel, bm: &[usize]) -> bool {
    am.len() == bm.len()
        && am.iter().zip(bm).all(|(&x, &y)| {
            let (mx, my) = (&a.meshes[x].mesh, &b.meshes[y].mesh);
            mx.positions.len() == my.positions.len() && mx.polygons == my.polygons
        })
}

/// One face of a clone as this step sees it.
pub(super) struct PartSide<'a> {
    /// The face (the target after the rigid step).
    pub face: &'a FaceModel,
    /// Its parts.
    pub parts: &'a FaceParts,
    /// Its FAPU (the target's in the aligned frame).
    pub fapu: &'a Fapu,
}

/// The deformations of the source's part meshes under `targets`, on the target's parts of
/// the same role.
pub(super) fn part_deformations(
    source: &PartSide,
    targets: &[MorphTarget],
    target: &PartSide,
    frame: &Similarity,
) -> PartDeformations {
    let (sparts, tparts, sfapu, tfapu) = (source.parts, target.parts, source.fapu, target.fapu);
    let (source, face) = (source.face, target.face);
    let mut out = PartDeformations {
        meshes: HashMap::new(),
        handled: HashSet::new(),
    };
    let sframes = source.frames();
    let tframes = face.frames();
    for part in DEFORMABLE {
        let (Some(sm), Some(tm)) = (sparts.parts.get(&part), tparts.parts.get(&part)) else {
            continue;
        };
        let names: HashMap<&str, usize> = sm
            .iter()
            .enumerate()
            .map(|(k, &m)| (source.meshes[m].name.as_str(), k))
            .collect();
        // Only parts the source FAT deforms.
        if !targets
            .iter()
            .flat_map(|t| &t.meshes)
            .any(|mm| names.contains_key(mm.mesh.as_str()))
        {
            continue;
        }
        let src = PartPoints::new(source, sm, |mi, p| sframes.meshes[mi].transform_point3(p));
        let tgt = PartPoints::new(face, tm, |mi, p| {
            frame.point(tframes.meshes[mi].transform_point3(p))
        });
        if src.points.is_empty() || tgt.points.is_empty() {
            continue;
        }
        // Source vertex (concatenated) of every target vertex.
        let pick: Vec<u32> = if same_meshes(source, sm, face, tm) {
            (0..tgt.points.len() as u32).collect()
        } else {
            let index = VertexIndex::new(&src.normalised());
            tgt.normalised()
                .iter()
                .map(|&p| index.nearest_vertex(p).map_or(0, |(k, _)| k))
                .collect()
        };
        let inv: Vec<DMat3> = tgt
            .meshes
            .iter()
            .map(|&mi| tframes.meshes[mi].matrix3.as_dmat3().inverse())
            .collect();
        for t in targets {
            // Source displacements of this part, face frame, by concatenated vertex.
            let mut disp: HashMap<u32, DVec3> = HashMap::new();
            for mm in &t.meshes {
                let Some(&k) = names.get(mm.mesh.as_str()) else {
                    continue;
                };
                let mi = src.meshes[k];
                let lin = sframes.meshes[mi].matrix3.as_dmat3();
                let len = source.meshes[mi].mesh.positions.len();
                for (&v, o) in mm.vertices.iter().zip(&mm.offsets) {
                    if (v as usize) < len {
                        disp.insert((src.starts[k] + v as usize) as u32, lin * *o);
                    }
                }
            }
            if disp.is_empty() {
                continue;
            }
            let r = part_fapu_ratio(t.key, sfapu, tfapu);
            let mut meshes = Vec::new();
            for (k, &mi) in tgt.meshes.iter().enumerate() {
                let end = tgt.starts.get(k + 1).copied().unwrap_or(tgt.points.len());
                let mut vertices = Vec::new();
                let mut offsets = Vec::new();
                for (c, src_v) in pick.iter().enumerate().take(end).skip(tgt.starts[k]) {
                    let Some(d) = disp.get(src_v) else {
                        continue;
                    };
                    let local = inv[k] * frame.inverse_vector(*d * r);
                    if local != DVec3::ZERO && local.is_finite() {
                        vertices.push((c - tgt.starts[k]) as u32);
                        offsets.push(local);
                    }
                }
                if !vertices.is_empty() {
                    meshes.push(MorphMesh {
                        mesh: face.meshes[mi].name.clone(),
                        vertices,
                        offsets,
                    });
                }
            }
            out.meshes
                .entry((t.key, t.value.to_bits()))
                .or_default()
                .extend(meshes);
        }
        out.handled
            .extend(sm.iter().map(|&m| source.meshes[m].name.clone()));
    }
    out
}
