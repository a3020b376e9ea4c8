//! One-mesh heads: eyes, teeth and gums that are separate connected pieces of the skin mesh
//! (the bundled `ict`) are split into part meshes before cloning, so the rigid-part step can
//! move them (module docs of [`super`], step 1); so are part meshes holding several parts
//! (both eyeballs in one mesh or glTF primitive, both rows of teeth), and a mesh holding both
//! rows of teeth but no feature point (no 9.8–9.11, as iBUG-68 landmarks give): its pieces
//! above the lip line (2.2/2.3) are the upper row, those below the lower, and a piece free
//! in the mouth reaching across the line (gums joined to a tongue) is cut along it
//! ([`teeth_row_plans`]: the rule); and meshes without feature points lying wholly on the
//! eyeballs, one piece per eye (VRoid's iris and highlight layers, an eye white behind an
//! iris cap holding the pupil: [`eye_layer_plans`]) go to the eye each piece lies on —
//! unless its rim rests on the lids (an eye occlusion shell, a lacrimal film, an eye blend):
//! a mesh all of such pieces is skin ([`lid_layers`]), and one holding both kinds is cut,
//! its lid-resting pieces staying in it as skin. A one-mesh head's pieces are sorted the same
//! way ([`eye_layer_pieces`]). The split is an internal view: its index maps
//! ([`SplitPart::source_vertices`]) fold the clone back into the target's own mesh (step 9;
//! a part cut out of a mesh whose rest is skin, under an eye transform kept for a mesh of
//! its own, is baked into per-vertex rows of that mesh, since the transform no longer holds
//! its vertices).

use std::collections::{BTreeMap, BTreeSet};

use glam::Vec3;
use parry3d::math::Vector as PVec;
use parry3d::shape::{CompositeShapeRef, TriMesh};
use serde::Serialize;

use super::eyeball::{eyeballs, EYE_LAYER_REACH};
use super::parts::{face_diagonal, fp_mesh_vertex};
use super::Part;
use crate::face::{FaceFrames, FaceMesh, FaceModel};
use crate::fdp::VertexBinding;
use crate::mesh::{find_coincident_vertices, Mesh, Polygons};
use crate::spec::FeaturePointId;

/// A part split out of a one-mesh head.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SplitPart {
    /// The part.
    pub part: Part,
    /// The mesh it was cut from.
    pub from: String,
    /// The new mesh's name.
    pub mesh: String,
    /// Its vertices.
    pub vertices: usize,
    /// Connected pieces it gathers (a piece straddling the lip line counts for both jaws).
    pub pieces: usize,
    /// For each of its vertices, the vertex of the original mesh it is (the index map that
    /// folds the part's motion back into that mesh; vertices on a cut along the lip line are
    /// in both jaws' parts).
    #[serde(skip)]
    pub source_vertices: Vec<u32>,
}

/// One mesh of the target cut into parts: the part meshes appended to the view, and the
/// rest, which keeps the mesh's name.
#[derive(Clone, Debug)]
pub(super) struct Cut {
    /// Name of the mesh that was cut (its rest keeps the name).
    pub mesh: String,
    /// What the rest is: `None` the skin of a one-mesh head, `Some(part)` the first part of a
    /// part mesh holding several (both eyeballs, both rows of teeth).
    pub rest: Option<Part>,
    /// For each vertex of the rest, its vertex in the original mesh.
    pub rest_vertices: Vec<u32>,
}

/// The internal view of a face whose meshes were cut into parts, with the index maps back to
/// it.
#[derive(Clone, Debug)]
pub(super) struct SplitView {
    /// The face with each cut mesh replaced by its rest and the part meshes appended.
    pub face: FaceModel,
    /// Every part of the view taken from a cut mesh (their `source_vertices` map their
    /// vertices back), a rest that is a part included.
    pub parts: Vec<SplitPart>,
    /// The meshes cut.
    pub cuts: Vec<Cut>,
}

/// Connected pieces of a mesh (polygon connectivity, coincident vertices joined): the piece
/// of every vertex and the piece count.
pub fn mesh_pieces(mesh: &Mesh, eps: f32) -> (Vec<usize>, usize) {
    let co = find_coincident_vertices(&mesh.positions, eps);
    let joined: Vec<(u32, u32)> = co
        .representative
        .iter()
        .enumerate()
        .map(|(i, &r)| (i as u32, r))
        .collect();
    let (piece, count) = crate::mesh::components::connected_components(mesh, &joined);
    (piece.into_iter().map(|p| p as usize).collect(), count)
}

/// Where a piece goes.
#[derive(Clone, Copy, PartialEq)]
enum Fate {
    Skin,
    Part(Part),
    /// Cut at the lip line: polygons above to the upper teeth, below to the lower.
    Jaws,
}

/// The face's landmarks the recognition needs (face frame).
struct Landmarks {
    pupils: [(Part, Vec3); 2],
    lip_y: f32,
    lip_z: f32,
    mouth_x: f32,
    es: f32,
    mns: f32,
    mw: f32,
}

impl Landmarks {
    fn of(face: &FaceModel) -> Option<Landmarks> {
        let p = |id: FeaturePointId| face.feature_points.position(id);
        let d = face.fapu().ok()?.distances;
        let (l, r) = (p(FeaturePointId::FP_3_5)?, p(FeaturePointId::FP_3_6)?);
        let (u, lo) = (p(FeaturePointId::FP_2_2)?, p(FeaturePointId::FP_2_3)?);
        Some(Landmarks {
            pupils: [(Part::LeftEye, l), (Part::RightEye, r)],
            lip_y: (u.y + lo.y) / 2.0,
            lip_z: u.z.min(lo.z),
            mouth_x: (u.x + lo.x) / 2.0,
            es: d.es0 as f32,
            mns: d.mns0 as f32,
            mw: d.mw0 as f32,
        })
    }

    /// The jaw a polygon of a piece cut along the lip line goes to: by the side of the lip
    /// line its mean height lies on.
    fn jaw_of(&self, poly: &[u32], world: &[Vec3]) -> Part {
        let y = poly
            .iter()
            .filter_map(|&v| world.get(v as usize))
            .map(|p| p.y)
            .sum::<f32>()
            / poly.len() as f32;
        if y > self.lip_y {
            Part::UpperTeeth
        } else {
            Part::LowerTeeth
        }
    }

    /// Eyeball: a roughly spherical piece (distance to its centroid varying < 35 %) whose
    /// centroid is within 0.4 ES0 of a pupil. Mouth: a piece centred between the lip corners,
    /// within 1.5 MNS0 of the lip line and behind the lips: teeth or gums, by side of the lip
    /// line, cut there when it reaches well into both jaws (ICT's gums and tongue).
    fn fate(&self, pts: &[Vec3]) -> Fate {
        let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
        let dist: Vec<f32> = pts.iter().map(|p| p.distance(c)).collect();
        let mean = dist.iter().sum::<f32>() / dist.len() as f32;
        let var = dist.iter().map(|d| (d - mean).powi(2)).sum::<f32>() / dist.len() as f32;
        let round = mean > 0.0 && var.sqrt() / mean < 0.35;
        for (part, pupil) in self.pupils {
            if round && c.distance(pupil) < 0.4 * self.es {
                return Fate::Part(part);
            }
        }
        let (lo, hi) = pts.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |a, p| {
            (a.0.min(p.y), a.1.max(p.y))
        });
        let in_mouth = (c.x - self.mouth_x).abs() < 0.75 * self.mw
            && (c.y - self.lip_y).abs() < 1.5 * self.mns
            && c.z < self.lip_z;
        if !in_mouth {
            return Fate::Skin;
        }
        if lo < self.lip_y - 0.5 * self.mns && hi > self.lip_y + 0.5 * self.mns {
            Fate::Jaws
        } else if c.y > self.lip_y {
            Fate::Part(Part::UpperTeeth)
        } else {
            Fate::Part(Part::LowerTeeth)
        }
    }
}

/// Splits eyeballs, teeth and gums out of the skin meshes of a face that has no such part
/// meshes (a one-mesh head), recognised by shape and place: roughly spherical pieces near
/// the pupils are eyeballs, pieces behind the lips near the lip line are teeth or gums of
/// the jaw on their side (cut along the lip line when they reach well into both); and cuts
/// part meshes holding several parts' feature points (both eyeballs, both rows of teeth) into
/// one part each. Only meshes no FAT table deforms are cut (a FAT would need remapping).
/// Returns the face (unchanged when nothing was split) and its part meshes taken from cut
/// meshes (a cut part mesh keeps its name for its first part).
pub fn split_embedded_parts(face: &FaceModel) -> (FaceModel, Vec<SplitPart>) {
    match split_view(face) {
        Some(v) => (v.face, v.parts),
        None => (face.clone(), Vec::new()),
    }
}

/// New → old vertex indices from an old → new map.
fn inverse(map: &BTreeMap<u32, u32>) -> Vec<u32> {
    let mut out = vec![0; map.len()];
    for (&old, &new) in map {
        if let Some(o) = out.get_mut(new as usize) {
            *o = old;
        }
    }
    out
}

/// A mesh of the view by name, and its vertices' numbers there by old vertex.
type VertexMap = (String, BTreeMap<u32, u32>);

/// Where the polygons of one mesh go, before the cut.
struct CutPlan {
    /// The mesh (index in the face).
    mesh: usize,
    /// Polygons per destination (`None`: the skin).
    dest: BTreeMap<Option<Part>, Vec<usize>>,
    /// The destination that stays in the mesh under its name.
    rest: Option<Part>,
    /// Connected pieces each part gathers.
    pieces: BTreeMap<Part, BTreeSet<usize>>,
}

/// [`split_embedded_parts`] with the index maps, `None` when nothing is cut: the skin mesh of
/// a one-mesh head ([`chin_plan`]) and every part mesh holding several parts
/// ([`shared_part_plans`]) are cut, unless a FAT table deforms them.
pub(super) fn split_view(face: &FaceModel) -> Option<SplitView> {
    let deformed: BTreeSet<&str> = face
        .fat
        .tables
        .iter()
        .flat_map(|t| t.meshes.iter().map(|m| m.mesh.as_str()))
        .collect();
    // The cuts are found by place in the face's upright frame (a face modelled facing −z is
    // read turned round, [`super::upright`]) and, being polygon lists, applied to the face.
    let mut plans = {
        let look = super::upright::for_recognition(face);
        let look = look.as_ref();
        let frames = look.frames();
        let diag = face_diagonal(look, &frames);
        let chin = chin_plan(look, &frames, diag);
        let chin_mesh = chin.as_ref().map(|p| p.mesh);
        let mut plans: Vec<CutPlan> = chin.into_iter().collect();
        plans.extend(shared_part_plans(look, &frames, diag, chin_mesh));
        plans.extend(teeth_row_plans(look, &frames, diag, chin_mesh));
        let planned: BTreeSet<usize> = plans.iter().map(|p| p.mesh).collect();
        plans.extend(eye_layer_plans(look, &frames, diag, &planned));
        plans
    };
    plans.retain(|p| !deformed.contains(face.meshes[p.mesh].name.as_str()));
    if plans.is_empty() {
        return None;
    }
    let mut out = face.clone();
    let mut parts = Vec::new();
    let mut cuts = Vec::new();
    let mut maps = Vec::new();
    for plan in &plans {
        let (cut, mut cut_parts, cut_maps) = apply_cut(&mut out, face, plan);
        cuts.push(cut);
        parts.append(&mut cut_parts);
        maps.push((plan.mesh, cut_maps));
    }
    rebind_feature_points(&mut out, face, &maps);
    Some(SplitView {
        face: out,
        parts,
        cuts,
    })
}

/// The skin mesh of a one-mesh head (the mesh holding the chin, 2.1) with its eyes, teeth
/// and gums as separate connected pieces: where each polygon goes.
fn chin_plan(face: &FaceModel, frames: &FaceFrames, diag: f32) -> Option<CutPlan> {
    let lm = Landmarks::of(face)?;
    let chin = FeaturePointId::FP_2_1;
    let (mi, _) = fp_mesh_vertex(face, frames, chin, diag * 1e-4)?;
    let mesh = &face.meshes[mi].mesh;
    let world = face.mesh_world(frames, mi);
    let (piece, count) = mesh_pieces(mesh, diag * 1e-6);
    if count < 2 {
        return None;
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (v, &k) in piece.iter().enumerate() {
        members[k].push(v);
    }
    let core = (0..count).max_by_key(|&k| members[k].len()).unwrap_or(0);
    let mut fates: Vec<Fate> = (0..count)
        .map(|k| {
            if k == core {
                Fate::Skin
            } else {
                let pts: Vec<Vec3> = members[k].iter().map(|&v| world[v]).collect();
                lm.fate(&pts)
            }
        })
        .collect();
    eye_layer_pieces(
        face, frames, &lm, mesh, &world, &piece, core, &mut fates, diag,
    );
    let mut dest: BTreeMap<Option<Part>, Vec<usize>> = BTreeMap::new();
    let mut pieces: BTreeMap<Part, BTreeSet<usize>> = BTreeMap::new();
    for (pi, poly) in mesh.polygons.iter().enumerate() {
        let Some(&v0) = poly.first() else { continue };
        let k = piece.get(v0 as usize).copied().unwrap_or(core);
        let part = match fates[k] {
            Fate::Skin => None,
            Fate::Part(p) => Some(p),
            Fate::Jaws => Some(lm.jaw_of(poly, &world)),
        };
        if let Some(p) = part {
            pieces.entry(p).or_default().insert(k);
        }
        dest.entry(part).or_default().push(pi);
    }
    if dest.keys().all(|p| p.is_none()) {
        return None;
    }
    Some(CutPlan {
        mesh: mi,
        dest,
        rest: None,
        pieces,
    })
}

/// Part meshes (no skin feature point) holding the feature points of several parts — both
/// pupils in one eyes mesh or primitive, the upper and lower teeth points in one teeth mesh —
/// and where each of their polygons goes: a connected piece holding one part's points, or
/// none, goes to that part (to the part of the nearest point held); a piece holding several
/// parts' points (two eyeballs joined, teeth and gums in one piece) is cut polygon by polygon,
/// each to the part of its nearest point. The first part stays in the mesh.
fn shared_part_plans(
    face: &FaceModel,
    frames: &FaceFrames,
    diag: f32,
    skip: Option<usize>,
) -> Vec<CutPlan> {
    // Per mesh, the part points it holds: (part, world position).
    let mut held: BTreeMap<usize, Vec<(Part, Vec3)>> = BTreeMap::new();
    let mut has_skin: BTreeSet<usize> = BTreeSet::new();
    for fp in face.feature_points.iter() {
        let Some((mi, v)) = fp_mesh_vertex(face, frames, fp.id, diag * 1e-4) else {
            continue;
        };
        let Some(&q) = face.meshes[mi].mesh.positions.get(v as usize) else {
            continue;
        };
        match Part::of_feature_point(fp.id) {
            Some(p) => held
                .entry(mi)
                .or_default()
                .push((p, frames.meshes[mi].transform_point3(q))),
            None => {
                has_skin.insert(mi);
            }
        }
    }
    let mut plans = Vec::new();
    for (mi, points) in held {
        let kinds: BTreeSet<Part> = points.iter().map(|p| p.0).collect();
        if Some(mi) == skip || has_skin.contains(&mi) || kinds.len() < 2 {
            continue;
        }
        let mesh = &face.meshes[mi].mesh;
        let world = face.mesh_world(frames, mi);
        let nearest_part = |q: Vec3| {
            points
                .iter()
                .min_by(|a, b| a.1.distance(q).total_cmp(&b.1.distance(q)))
                .map(|p| p.0)
        };
        let (piece, count) = mesh_pieces(mesh, diag * 1e-6);
        // Per piece: the parts of the points on it, else the part of the point nearest it.
        let mut on_piece: Vec<BTreeSet<Part>> = vec![BTreeSet::new(); count];
        let mut nearest: Vec<Option<(f32, Part)>> = vec![None; count];
        for (v, &k) in piece.iter().enumerate() {
            for &(p, q) in &points {
                let d = world[v].distance(q);
                if d <= diag * 1e-6 {
                    on_piece[k].insert(p);
                }
                if nearest[k].is_none_or(|n| d < n.0) {
                    nearest[k] = Some((d, p));
                }
            }
        }
        let mut dest: BTreeMap<Option<Part>, Vec<usize>> = BTreeMap::new();
        let mut pieces: BTreeMap<Part, BTreeSet<usize>> = BTreeMap::new();
        for (pi, poly) in mesh.polygons.iter().enumerate() {
            let Some(&v0) = poly.first() else { continue };
            let Some(&k) = piece.get(v0 as usize) else {
                continue;
            };
            let part = if on_piece[k].len() > 1 {
                let c = poly
                    .iter()
                    .filter_map(|&v| world.get(v as usize))
                    .sum::<Vec3>()
                    / poly.len() as f32;
                nearest_part(c)
            } else {
                on_piece[k].first().copied().or(nearest[k].map(|n| n.1))
            };
            let Some(part) = part else { continue };
            pieces.entry(part).or_default().insert(k);
            dest.entry(Some(part)).or_default().push(pi);
        }
        if dest.len() < 2 {
            continue;
        }
        let rest = dest.keys().next().copied().flatten();
        plans.push(CutPlan {
            mesh: mi,
            dest,
            rest,
            pieces,
        });
    }
    plans
}

/// Largest overlap of a row of teeth across the lip line, in MNS0: lower incisors may reach
/// above it behind the upper ones.
const ROW_OVERLAP: f32 = 0.25;

/// How far behind the lips gums joined to a tongue reach at least, in MW0 (ICT's: 2.0 MW0,
/// back to the throat; the test avatar's mouth cap: about 0.5).
const GUMS_DEPTH: f32 = 1.0;

/// Whether every piece in `across` (pieces of `mesh` reaching across the lip line) is free in
/// the mouth: open (it has a rim: gums end at the teeth and the mouth's floor), running back
/// along the jaws at least [`GUMS_DEPTH`] behind the lips, and with no rim vertex on the skin.
/// A closed bag has no rim, a mouth interior hung from the lips has its rim on them, and a
/// shallow cap just behind the lips (the test avatar's `mouth`) is no jaw; they deform with
/// the skin rather than being cut into two rigid jaws, which would tear them where they cross
/// the lip line.
#[allow(clippy::too_many_arguments)]
fn free_in_mouth(
    face: &FaceModel,
    frames: &FaceFrames,
    lm: &Landmarks,
    mesh: &Mesh,
    world: &[Vec3],
    piece: &[usize],
    across: &BTreeSet<usize>,
    diag: f32,
) -> bool {
    let eps = diag * 1e-6;
    let back = lm.lip_z - GUMS_DEPTH * lm.mw;
    let deep: BTreeSet<usize> = piece
        .iter()
        .zip(world)
        .filter(|(_, q)| q.z < back)
        .map(|(&k, _)| k)
        .collect();
    if !across.iter().all(|k| deep.contains(k)) {
        return false;
    }
    let rim = rim_vertices(mesh, eps);
    let open: BTreeSet<usize> = rim
        .iter()
        .filter_map(|&v| piece.get(v as usize).copied())
        .collect();
    if !across.iter().all(|k| open.contains(k)) {
        return false;
    }
    let Some(skin) = LidSurface::of(face, frames, eps, &|_| None, None) else {
        return false;
    };
    // Seam vertices of an artist's mesh coincide with the skin's up to float rounding.
    let touch = diag * 1e-5;
    !rim.iter().any(|&v| {
        piece.get(v as usize).is_some_and(|k| across.contains(k))
            && world
                .get(v as usize)
                .is_some_and(|&q| skin.within(q, touch))
    })
}

/// Meshes (or glTF primitives) holding both rows of teeth but no feature point at all (the
/// face has no 9.8–9.11, as with iBUG-68 landmarks), recognised by place: the mesh lies in
/// the mouth (centred between the lip corners, within 1.5 MNS0 of the lip line, behind the
/// lips), and each of its connected pieces lies on one side of the lip line (the 2.2/2.3
/// midline; its centroid there and at most [`ROW_OVERLAP`] MNS0 across), some above and
/// some below. Pieces above are the upper row, below the lower; the upper row stays in the
/// mesh. A piece reaching well across the lip line is cut along it, polygon by polygon, when
/// it is free in the mouth (gums joined to a tongue: [`free_in_mouth`]); a closed bag or a
/// mouth interior hung from the lips leaves the mesh uncut, as does a mesh of one row.
fn teeth_row_plans(
    face: &FaceModel,
    frames: &FaceFrames,
    diag: f32,
    skip: Option<usize>,
) -> Vec<CutPlan> {
    let Some(lm) = Landmarks::of(face) else {
        return Vec::new();
    };
    let mut with_fp: BTreeSet<usize> = BTreeSet::new();
    for fp in face.feature_points.iter() {
        if let Some((mi, _)) = fp_mesh_vertex(face, frames, fp.id, diag * 1e-4) {
            with_fp.insert(mi);
        }
    }
    let mut plans = Vec::new();
    for mi in 0..face.meshes.len() {
        if Some(mi) == skip || with_fp.contains(&mi) {
            continue;
        }
        let mesh = &face.meshes[mi].mesh;
        let world = face.mesh_world(frames, mi);
        if world.is_empty() || mesh.polygons.is_empty() {
            continue;
        }
        let c = world.iter().copied().sum::<Vec3>() / world.len() as f32;
        let in_mouth = (c.x - lm.mouth_x).abs() < 0.75 * lm.mw
            && (c.y - lm.lip_y).abs() < 1.5 * lm.mns
            && c.z < lm.lip_z;
        if !in_mouth {
            continue;
        }
        let (piece, count) = mesh_pieces(mesh, diag * 1e-6);
        let mut stats = vec![(Vec3::ZERO, 0usize, f32::INFINITY, f32::NEG_INFINITY); count];
        for (v, &k) in piece.iter().enumerate() {
            let p = world[v];
            let s = &mut stats[k];
            s.0 += p;
            s.1 += 1;
            s.2 = s.2.min(p.y);
            s.3 = s.3.max(p.y);
        }
        let overlap = ROW_OVERLAP * lm.mns;
        let rows: Vec<Option<Part>> = stats
            .iter()
            .map(|&(sum, n, lo, hi)| {
                let cy = sum.y / n.max(1) as f32;
                if cy > lm.lip_y && lo > lm.lip_y - overlap {
                    Some(Part::UpperTeeth)
                } else if cy <= lm.lip_y && hi < lm.lip_y + overlap {
                    Some(Part::LowerTeeth)
                } else {
                    None
                }
            })
            .collect();
        // Pieces across the lip line: gums joined to a tongue (ICT's, in a mesh of their own)
        // are cut along it like a one-mesh head's; a closed bag or a piece whose rim is on
        // the skin (a mouth interior hung from the lips) deforms with the skin instead.
        let across: BTreeSet<usize> = (0..count).filter(|&k| rows[k].is_none()).collect();
        if !across.is_empty()
            && !free_in_mouth(face, frames, &lm, mesh, &world, &piece, &across, diag)
        {
            continue;
        }
        let mut dest: BTreeMap<Option<Part>, Vec<usize>> = BTreeMap::new();
        let mut pieces: BTreeMap<Part, BTreeSet<usize>> = BTreeMap::new();
        for (pi, poly) in mesh.polygons.iter().enumerate() {
            let Some(&k) = poly.first().and_then(|&v| piece.get(v as usize)) else {
                continue;
            };
            let row = rows[k].unwrap_or_else(|| lm.jaw_of(poly, &world));
            pieces.entry(row).or_default().insert(k);
            dest.entry(Some(row)).or_default().push(pi);
        }
        if dest.len() < 2 {
            continue;
        }
        plans.push(CutPlan {
            mesh: mi,
            dest,
            rest: Some(Part::UpperTeeth),
            pieces,
        });
    }
    plans
}

/// Where a connected piece of a mesh lying on the eyeballs goes ([`eye_layers`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LayerPiece {
    /// Lies on this eye's eyeball, clear of the lids: turns with it.
    Eye(Part),
    /// Its rim rests on the lids: moves with them, never with the eye.
    OnLids,
    /// Reaches over both eyeballs: neither.
    BothEyes,
}

/// A mesh holding no feature point whose every vertex lies on an eyeball, with the fate of
/// each of its connected pieces.
struct EyeLayer {
    /// The mesh (index in the face).
    mesh: usize,
    /// The piece of every vertex ([`mesh_pieces`]).
    piece: Vec<usize>,
    /// Per piece (`None`: a piece of no polygon).
    fate: Vec<Option<LayerPiece>>,
}

/// Meshes (or glTF primitives) holding no feature point whose connected pieces all lie on an
/// eyeball — every vertex within [`EYE_LAYER_REACH`] radii of its centre ([`eyeballs`]: the
/// piece holding the pupil, or the eye white behind an iris cap holding it, which is such a
/// layer itself) —, each piece sorted: a piece whose rim
/// comes within [`LID_CLEARANCE`] eyeball radii of the skin rests on the lids (ICT's eye
/// occlusion, lacrimal film and corner blends), any other goes to the eye it lies on (VRoid's
/// iris and highlight layers). Meshes in `planned` (cut already) are left out.
fn eye_layers(
    face: &FaceModel,
    frames: &FaceFrames,
    diag: f32,
    planned: &BTreeSet<usize>,
) -> Vec<EyeLayer> {
    let Some(lm) = Landmarks::of(face) else {
        return Vec::new();
    };
    let eps = diag * 1e-6;
    let mut with_fp: BTreeSet<usize> = BTreeSet::new();
    for fp in face.feature_points.iter() {
        if let Some((mi, _)) = fp_mesh_vertex(face, frames, fp.id, diag * 1e-4) {
            with_fp.insert(mi);
        }
    }
    let candidates: Vec<usize> = (0..face.meshes.len())
        .filter(|mi| !planned.contains(mi) && !with_fp.contains(mi))
        .filter(|&mi| !face.meshes[mi].mesh.polygons.is_empty())
        .collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    // Each eyeball: (eye, centre, radius).
    let balls: Vec<(Part, Vec3, f32)> = eyeballs(face, frames, diag, lm.es)
        .into_iter()
        .map(|b| (b.part, b.centre, b.radius))
        .collect();
    if balls.is_empty() {
        return Vec::new();
    }
    let on_ball = |q: Vec3| ball_under(&balls, q);
    // The lids' surface (a BVH over the skin) is built at the first rim it must measure:
    // most faces have no eye layer to sort.
    let mut lids: Option<Option<LidSurface>> = None;
    let mut out = Vec::new();
    for mi in candidates {
        let mesh = &face.meshes[mi].mesh;
        let world = face.mesh_world(frames, mi);
        let eyes: Option<Vec<(u32, Part)>> = mesh
            .polygons
            .indices()
            .iter()
            .map(|&v| Some((v, on_ball(*world.get(v as usize)?)?)))
            .collect();
        let Some(eyes) = eyes else { continue };
        let (piece, count) = mesh_pieces(mesh, eps);
        let mut fate: Vec<Option<LayerPiece>> = vec![None; count];
        for (v, on) in eyes {
            let Some(&k) = piece.get(v as usize) else {
                continue;
            };
            fate[k] = Some(match fate[k] {
                None => LayerPiece::Eye(on),
                Some(LayerPiece::Eye(seen)) if seen == on => LayerPiece::Eye(on),
                Some(_) => LayerPiece::BothEyes,
            });
        }
        for v in rim_vertices(mesh, eps) {
            let (Some(&k), Some(&q)) = (piece.get(v as usize), world.get(v as usize)) else {
                continue;
            };
            let Some(LayerPiece::Eye(part)) = fate[k] else {
                continue;
            };
            let Some(lids) =
                lids.get_or_insert_with(|| LidSurface::of(face, frames, eps, &on_ball, None))
            else {
                break;
            };
            let radius = balls.iter().find(|b| b.0 == part).map_or(0.0, |b| b.2);
            if lids.within(q, LID_CLEARANCE * radius) {
                fate[k] = Some(LayerPiece::OnLids);
            }
        }
        out.push(EyeLayer {
            mesh: mi,
            piece,
            fate,
        });
    }
    out
}

/// The eye whose eyeball (`balls`: eye, centre, radius) `q` lies on: within
/// [`EYE_LAYER_REACH`] radii of its centre, the nearest such.
pub(super) fn ball_under(balls: &[(Part, Vec3, f32)], q: Vec3) -> Option<Part> {
    balls
        .iter()
        .filter(|b| q.distance(b.1) <= EYE_LAYER_REACH * b.2)
        .min_by(|a, b| q.distance(a.1).total_cmp(&q.distance(b.1)))
        .map(|b| b.0)
}

/// Pieces of a one-mesh head's skin mesh (`fates` from their shape and place) that are eye
/// layers, sorted as such layers are as meshes of their own ([`eye_layers`]): a piece left to
/// the skin or taken for an eyeball that lies wholly on one eyeball ([`eyeballs`]) goes to
/// that eye when its rim is clear of the lids (an iris cap holding the pupil in front of its
/// eye white, a highlight; a closed eyeball has no rim) and is skin when its rim rests on
/// them (an occlusion shell, round enough to pass for an eyeball, a tear film, corner
/// blends).
#[allow(clippy::too_many_arguments)]
fn eye_layer_pieces(
    face: &FaceModel,
    frames: &FaceFrames,
    lm: &Landmarks,
    mesh: &Mesh,
    world: &[Vec3],
    piece: &[usize],
    core: usize,
    fates: &mut [Fate],
    diag: f32,
) {
    let eps = diag * 1e-6;
    let balls: Vec<(Part, Vec3, f32)> = eyeballs(face, frames, diag, lm.es)
        .into_iter()
        .map(|b| (b.part, b.centre, b.radius))
        .collect();
    if balls.is_empty() {
        return;
    }
    // Per piece left to the skin: the one eye all its vertices lie on, `None` for none.
    let mut on: Vec<Option<Option<Part>>> = fates
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let eye = matches!(f, Fate::Part(Part::LeftEye | Part::RightEye));
            (k != core && (*f == Fate::Skin || eye)).then_some(None)
        })
        .collect();
    let mut seen = vec![false; fates.len()];
    for (&k, &q) in piece.iter().zip(world) {
        let Some(slot) = on.get_mut(k) else { continue };
        let Some(eye) = slot else { continue };
        let here = ball_under(&balls, q);
        *eye = if seen[k] && *eye != here { None } else { here };
        if eye.is_none() {
            *slot = None;
        }
        seen[k] = true;
    }
    if !on.iter().any(|o| matches!(o, Some(Some(_)))) {
        return;
    }
    let on_ball = |q: Vec3| ball_under(&balls, q);
    // Only skin near the rims can be within their clearance: the surface is built over the
    // triangles in their box (the whole skin's tree cost more than the rest of the cut).
    let rim = rim_vertices(mesh, eps);
    let mut near: Option<(Vec3, Vec3)> = None;
    for &v in &rim {
        let (Some(&k), Some(&q)) = (piece.get(v as usize), world.get(v as usize)) else {
            continue;
        };
        let Some(Some(part)) = on[k] else { continue };
        let radius = balls.iter().find(|b| b.0 == part).map_or(0.0, |b| b.2);
        let reach = Vec3::splat(2.0 * LID_CLEARANCE * radius + eps);
        let (lo, hi) = near.get_or_insert((q, q));
        *lo = lo.min(q - reach);
        *hi = hi.max(q + reach);
    }
    if let Some(lids) = near.and_then(|n| LidSurface::of(face, frames, eps, &on_ball, Some(n))) {
        for v in rim {
            let (Some(&k), Some(&q)) = (piece.get(v as usize), world.get(v as usize)) else {
                continue;
            };
            let Some(Some(part)) = on[k] else { continue };
            let radius = balls.iter().find(|b| b.0 == part).map_or(0.0, |b| b.2);
            if lids.within(q, LID_CLEARANCE * radius) {
                fates[k] = Fate::Skin;
                on[k] = None;
            }
        }
    }
    for (k, o) in on.into_iter().enumerate() {
        if let Some(Some(part)) = o {
            fates[k] = Fate::Part(part);
        }
    }
}

/// [`eye_layers`] with a piece going to an eye and none over both eyes, cut one piece per
/// eye so each turns with its eyeball. Pieces resting on the lids (an occlusion shell in one
/// primitive with an iris highlight) are skin and stay in the mesh under its name, moved by
/// the surface method; without them the first eye stays there. A mesh all on the lids is
/// left whole ([`lid_layers`]).
fn eye_layer_plans(
    face: &FaceModel,
    frames: &FaceFrames,
    diag: f32,
    planned: &BTreeSet<usize>,
) -> Vec<CutPlan> {
    let mut plans = Vec::new();
    for layer in eye_layers(face, frames, diag, planned) {
        let mesh = &face.meshes[layer.mesh].mesh;
        let mut dest: BTreeMap<Option<Part>, Vec<usize>> = BTreeMap::new();
        let mut pieces: BTreeMap<Part, BTreeSet<usize>> = BTreeMap::new();
        let mut both = false;
        for (pi, poly) in mesh.polygons.iter().enumerate() {
            let Some(&k) = poly.first().and_then(|&v| layer.piece.get(v as usize)) else {
                continue;
            };
            match layer.fate[k] {
                Some(LayerPiece::Eye(part)) => {
                    pieces.entry(part).or_default().insert(k);
                    dest.entry(Some(part)).or_default().push(pi);
                }
                Some(LayerPiece::OnLids) => dest.entry(None).or_default().push(pi),
                Some(LayerPiece::BothEyes) | None => both = true,
            }
        }
        if both || pieces.is_empty() {
            continue;
        }
        let rest = dest.keys().next().copied().flatten();
        plans.push(CutPlan {
            mesh: layer.mesh,
            dest,
            rest,
            pieces,
        });
    }
    plans
}

/// Meshes holding no feature point whose every piece lies on an eyeball with its rim resting
/// on the lids ([`eye_layers`]): an eye blend, occlusion shell or lacrimal film given as a mesh
/// or primitive of its own. They are skin ([`super::identify_parts`]), as they are when pieces
/// of a one-mesh head's skin: the surface method moves them with the lids. Left to ride on
/// the closest skin point, a band between the lid and the eye (ICT's eye blend) took the
/// still eye socket's motion.
pub(super) fn lid_layers(face: &FaceModel, frames: &FaceFrames, diag: f32) -> Vec<usize> {
    eye_layers(face, frames, diag, &BTreeSet::new())
        .into_iter()
        .filter(|l| {
            let mesh = &face.meshes[l.mesh].mesh;
            mesh.polygons.iter().all(|poly| {
                poly.first()
                    .and_then(|&v| l.piece.get(v as usize))
                    .is_some_and(|&k| l.fate[k] == Some(LayerPiece::OnLids))
            })
        })
        .map(|l| l.mesh)
        .collect()
}

/// Nearest an eye layer's rim may come to the skin, in eyeball radii: a rim closer than
/// this rests on the lids. ICT's eye blend (corner wedges) comes to 0.013 radii of the
/// skin and its eye occlusion and lacrimal film touch it (0); VRoid's iris and highlight
/// caps float over the eye white, clear of the lids.
pub(super) const LID_CLEARANCE: f32 = 0.05;

/// The skin around the eyes, to tell the layers that rest on the lids (an eye occlusion
/// shell, a lacrimal film, corner blends: rigid with the lids, never turning with the eye)
/// from the eye's own layers (iris, highlight): every mesh holding a skin feature point,
/// without its pieces lying wholly on an eyeball (the eyeballs and layers of a one-mesh
/// head).
pub(super) struct LidSurface {
    mesh: TriMesh,
}

impl LidSurface {
    /// `None` without skin triangles. With `near` (a box `(lo, hi)`), only the triangles
    /// whose box meets it: the same answers for points whose gap reaches no farther.
    pub(super) fn of(
        face: &FaceModel,
        frames: &FaceFrames,
        eps: f32,
        on_ball: &impl Fn(Vec3) -> Option<Part>,
        near: Option<(Vec3, Vec3)>,
    ) -> Option<LidSurface> {
        let diag = face_diagonal(face, frames);
        let mut skin: BTreeSet<usize> = BTreeSet::new();
        for fp in face.feature_points.iter() {
            if Part::of_feature_point(fp.id).is_some() {
                continue;
            }
            if let Some((mi, _)) = fp_mesh_vertex(face, frames, fp.id, diag * 1e-4) {
                skin.insert(mi);
            }
        }
        let mut points: Vec<PVec> = Vec::new();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        for mi in skin {
            let mesh = &face.meshes[mi].mesh;
            let world = face.mesh_world(frames, mi);
            let (piece, count) = mesh_pieces(mesh, eps);
            let mut off_ball = vec![false; count];
            for (k, q) in piece.iter().zip(&world) {
                if on_ball(*q).is_none() {
                    off_ball[*k] = true;
                }
            }
            let base = points.len() as u32;
            points.extend(world.iter().map(|q| PVec::new(q.x, q.y, q.z)));
            let meets = |t: &[u32; 3]| {
                near.is_none_or(|(lo, hi)| {
                    let [Some(p), Some(q), Some(r)] = t.map(|v| world.get(v as usize).copied())
                    else {
                        return true;
                    };
                    let (a, b) = (p.min(q).min(r), p.max(q).max(r));
                    !(a.cmpgt(hi).any() || b.cmplt(lo).any())
                })
            };
            for t in mesh.triangles() {
                if piece.get(t[0] as usize).is_some_and(|&k| off_ball[k]) && meets(&t) {
                    triangles.push(t.map(|v| v + base));
                }
            }
        }
        if triangles.is_empty() {
            return None;
        }
        TriMesh::new(points, triangles)
            .ok()
            .map(|mesh| LidSurface { mesh })
    }

    /// Whether `q` lies within `gap` of the surface.
    pub(super) fn within(&self, q: Vec3, gap: f32) -> bool {
        CompositeShapeRef(&self.mesh)
            .project_local_point_and_get_location(PVec::new(q.x, q.y, q.z), gap, false)
            .is_some()
    }
}

/// Vertices on an open edge of `mesh` (an edge of one polygon; coincident vertices joined,
/// so a UV seam is no rim): empty for closed shells.
fn rim_vertices(mesh: &Mesh, eps: f32) -> Vec<u32> {
    let rep = find_coincident_vertices(&mesh.positions, eps).representative;
    open_edge_vertices(mesh, |v: u32| rep.get(v as usize).copied().unwrap_or(v))
}

/// Vertices on an edge that one polygon alone uses, vertices being the same when `r` maps
/// them to the same representative (identity: by index, so a layer glued to the skin by
/// coincident vertices keeps its border), ascending.
pub(super) fn open_edge_vertices(mesh: &Mesh, r: impl Fn(u32) -> u32) -> Vec<u32> {
    // Every edge end to end as (joined key, corners), sorted by key: an edge alone in its
    // run is open (a map of the edges cost a one-mesh head's cut 10 ms).
    let mut edges: Vec<(u64, [u32; 2])> = Vec::with_capacity(mesh.polygons.indices().len());
    for poly in mesh.polygons.iter() {
        for (i, &a) in poly.iter().enumerate() {
            let b = poly[(i + 1) % poly.len()];
            let (ra, rb) = (r(a), r(b));
            if ra == rb {
                continue;
            }
            edges.push((
                (u64::from(ra.min(rb)) << 32) | u64::from(ra.max(rb)),
                [a, b],
            ));
        }
    }
    edges.sort_unstable_by_key(|e| e.0);
    let mut out: Vec<u32> = Vec::new();
    for (j, e) in edges.iter().enumerate() {
        let alone =
            (j == 0 || edges[j - 1].0 != e.0) && edges.get(j + 1).is_none_or(|n| n.0 != e.0);
        if alone {
            out.extend(e.1);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Cuts `plan`'s mesh in `out` (a copy of `face`): the rest keeps the mesh's place and name,
/// the other destinations are appended as part meshes. Returns the cut, its parts (the rest
/// among them when it is a part) and the old → new vertex maps by mesh name, the rest first.
fn apply_cut(
    out: &mut FaceModel,
    face: &FaceModel,
    plan: &CutPlan,
) -> (Cut, Vec<SplitPart>, Vec<VertexMap>) {
    let mi = plan.mesh;
    let name = face.meshes[mi].name.clone();
    let mesh = &face.meshes[mi].mesh;
    // The rest keeps its polygons and every vertex no other polygon uses (isolated ones too).
    let mut used_elsewhere = vec![false; mesh.positions.len()];
    for (p, polys) in &plan.dest {
        if *p != plan.rest {
            for &pi in polys {
                for &v in mesh.polygons.get(pi).unwrap_or(&[]) {
                    if let Some(u) = used_elsewhere.get_mut(v as usize) {
                        *u = true;
                    }
                }
            }
        }
    }
    let rest_polys = plan.dest.get(&plan.rest).cloned().unwrap_or_default();
    for &pi in &rest_polys {
        for &v in mesh.polygons.get(pi).unwrap_or(&[]) {
            if let Some(u) = used_elsewhere.get_mut(v as usize) {
                *u = false;
            }
        }
    }
    let rest_vertices: Vec<u32> = (0..mesh.positions.len() as u32)
        .filter(|&v| !used_elsewhere[v as usize])
        .collect();
    // A rest that is a part takes only its polygons' vertices: an unused vertex (of any part)
    // would pull its centre and size; it stays out of the view and never moves.
    let keep = plan.rest.is_none().then_some(rest_vertices.as_slice());
    let (rest_mesh, rest_map) = sub_mesh(mesh, &rest_polys, keep);
    let mut report = Vec::new();
    if let Some(p) = plan.rest {
        report.push(SplitPart {
            part: p,
            from: name.clone(),
            mesh: name.clone(),
            vertices: rest_mesh.positions.len(),
            pieces: plan.pieces.get(&p).map_or(0, |s| s.len()),
            source_vertices: inverse(&rest_map),
        });
    }
    let mut maps: Vec<VertexMap> = vec![(name.clone(), rest_map)];
    out.meshes[mi].mesh = rest_mesh;
    for (p, polys) in &plan.dest {
        let Some(p) = p.filter(|_| *p != plan.rest) else {
            continue;
        };
        let (m, map) = sub_mesh(mesh, polys, None);
        let new_name = unique_mesh_name(out, &format!("{name}_{}", p.name()));
        report.push(SplitPart {
            part: p,
            from: name.clone(),
            mesh: new_name.clone(),
            vertices: m.positions.len(),
            pieces: plan.pieces.get(&p).map_or(0, |s| s.len()),
            source_vertices: inverse(&map),
        });
        out.meshes.push(FaceMesh {
            name: new_name.clone(),
            transform: face.meshes[mi].transform,
            mesh: Mesh {
                name: new_name.clone(),
                ..m
            },
            color: face.meshes[mi].color,
        });
        maps.push((new_name, map));
    }
    let cut = Cut {
        mesh: name,
        rest: plan.rest,
        rest_vertices: inverse(&maps[0].1),
    };
    (cut, report, maps)
}

/// Feature points bound to a cut mesh (`cuts`: mesh index, its maps by new mesh name) follow
/// their vertex into its new mesh; the others name their mesh (the face has more meshes now).
fn rebind_feature_points(out: &mut FaceModel, face: &FaceModel, cuts: &[(usize, Vec<VertexMap>)]) {
    let ids: Vec<FeaturePointId> = face.feature_points.iter().map(|f| f.id).collect();
    for id in ids {
        let Some((m, v)) = face.fp_vertex(id) else {
            continue;
        };
        let Some(mut fp) = out.feature_points.get(id).cloned() else {
            continue;
        };
        match cuts.iter().find(|c| c.0 == m) {
            Some((_, maps)) => {
                fp.binding = maps.iter().find_map(|(name, map)| {
                    map.get(&v).map(|&nv| VertexBinding {
                        mesh: Some(name.clone()),
                        vertices: vec![nv],
                    })
                });
            }
            None => {
                let Some(mut b) = fp.binding.clone() else {
                    continue;
                };
                b.mesh = Some(face.meshes[m].name.clone());
                fp.binding = Some(b);
            }
        }
        out.feature_points.insert(fp);
    }
}

/// The polygons `polys` of `mesh` (and `keep` vertices, default those polygons use) as a new
/// mesh; returns it and old → new vertex indices. UVs and normals keep their arrays.
fn sub_mesh(mesh: &Mesh, polys: &[usize], keep: Option<&[u32]>) -> (Mesh, BTreeMap<u32, u32>) {
    let mut vertices: Vec<u32> = match keep {
        Some(k) => k.to_vec(),
        None => polys
            .iter()
            .flat_map(|&pi| mesh.polygons.get(pi).unwrap_or(&[]).iter().copied())
            .collect(),
    };
    vertices.sort_unstable();
    vertices.dedup();
    let map: BTreeMap<u32, u32> = vertices
        .iter()
        .enumerate()
        .map(|(i, &v)| (v, i as u32))
        .collect();
    // The map as a table (a tree lookup per polygon corner was most of a head's cut).
    let mut table = vec![u32::MAX; vertices.last().map_or(0, |&v| v as usize + 1)];
    for (i, &v) in vertices.iter().enumerate() {
        table[v as usize] = i as u32;
    }
    let pick = |src: &Polygons, remap: bool| {
        let mut out = Polygons::new();
        let mut p: Vec<u32> = Vec::new();
        for &pi in polys {
            let poly = src.get(pi).unwrap_or(&[]);
            p.clear();
            if remap {
                p.extend(
                    poly.iter()
                        .filter_map(|&v| table.get(v as usize).copied())
                        .filter(|&i| i != u32::MAX),
                );
            } else {
                p.extend_from_slice(poly);
            }
            out.push(&p);
        }
        out
    };
    fn subset<T: Copy>(all: &[T], n: usize, vertices: &[u32]) -> Vec<T> {
        if all.len() == n {
            vertices.iter().map(|&v| all[v as usize]).collect()
        } else {
            Vec::new()
        }
    }
    let n = mesh.positions.len();
    let m = Mesh {
        name: mesh.name.clone(),
        positions: vertices
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect(),
        colors: if mesh.colors.len() == mesh.positions.len() {
            vertices.iter().map(|&v| mesh.colors[v as usize]).collect()
        } else {
            Vec::new()
        },
        polygons: pick(&mesh.polygons, true),
        // Per-corner attributes keep their arrays; per-vertex ones follow the vertices.
        uvs: match &mesh.uv_polygons {
            Some(_) => mesh.uvs.clone(),
            None => subset(&mesh.uvs, n, &vertices),
        },
        uv_polygons: mesh.uv_polygons.as_ref().map(|p| pick(p, false)),
        normals: match &mesh.normal_polygons {
            Some(_) => mesh.normals.clone(),
            None => subset(&mesh.normals, n, &vertices),
        },
        normal_polygons: mesh.normal_polygons.as_ref().map(|p| pick(p, false)),
        groups: Vec::new(),
        flags: mesh.flags,
    };
    (m, map)
}

/// `base`, or `base_2`, ...: a name no mesh or transform has.
fn unique_mesh_name(face: &FaceModel, base: &str) -> String {
    let mut name = base.to_string();
    let mut k = 1;
    while face.mesh_index(&name).is_some() || face.transform_index(&name).is_some() {
        k += 1;
        name = format!("{base}_{k}");
    }
    name
}

#[cfg(test)]
mod tests {
    use super::super::identify_parts;
    use super::*;
    use crate::synth::{generate, HeadParams};

    /// A cap of the sphere (`centre`, `radius`) about `axis` reaching `half_angle` from it:
    /// a pole and `rings` rings of 12.
    fn cap(name: &str, centre: Vec3, axis: Vec3, radius: f32, half_angle: f32) -> FaceMesh {
        let rot = glam::Quat::from_rotation_arc(Vec3::Z, axis.normalize());
        let (rings, segs) = (3u32, 12u32);
        let mut positions = vec![centre + axis.normalize() * radius];
        for i in 1..=rings {
            let th = half_angle * i as f32 / rings as f32;
            for j in 0..segs {
                let ph = std::f32::consts::TAU * j as f32 / segs as f32;
                let d = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                positions.push(centre + rot * d * radius);
            }
        }
        let mut polygons = Polygons::new();
        let at = |i: u32, j: u32| 1 + (i - 1) * segs + j % segs;
        for j in 0..segs {
            polygons.push(&[0, at(1, j), at(1, j + 1)]);
        }
        for i in 1..rings {
            for j in 0..segs {
                polygons.push(&[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        let mesh = Mesh {
            name: name.into(),
            positions,
            polygons,
            ..Mesh::default()
        };
        FaceMesh {
            name: name.into(),
            transform: None,
            mesh,
            color: None,
        }
    }

    /// The synthetic head without its FAT, its left eyeball's centre and radius (as
    /// [`eye_layer_plans`] finds them) and its gaze.
    fn head() -> (FaceModel, Vec3, f32, Vec3) {
        let mut face = generate(&HeadParams::alma()).to_face_model();
        face.fat = Default::default();
        let frames = face.frames();
        let (mi, v) = face.fp_vertex(FeaturePointId::FP_3_5).unwrap();
        let world = face.mesh_world(&frames, mi);
        let lo = world
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b));
        let hi = world
            .iter()
            .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
        let centre = (lo + hi) / 2.0;
        let radius = ((hi - lo) / 2.0).max_element();
        (face, centre, radius, world[v as usize] - centre)
    }

    /// A sliver of skin from `gap` eyeball radii beyond a rim vertex of `shell` radially
    /// outwards: a lid resting on the shell, as an eye occlusion's or eye blend's rim rests
    /// on the lids (touching them, or just clear of them).
    fn rest_on_lids(face: &mut FaceModel, shell: &FaceMesh, eye: (Vec3, f32, Vec3), gap: f32) {
        let (centre, radius, gaze) = eye;
        let rim = shell.mesh.positions[1 + 2 * 12];
        let out = (rim - centre).normalize();
        let side = out.cross(gaze).normalize();
        let frames = face.frames();
        let to_local = frames.meshes[0].inverse();
        let skin = &mut face.meshes[0].mesh;
        // The sliver has no UVs or normals: the skin drops its own.
        (skin.uv_polygons, skin.normal_polygons) = (None, None);
        skin.uvs.clear();
        skin.normals.clear();
        skin.colors.clear();
        let n = skin.positions.len() as u32;
        let root = rim + out * gap * radius;
        for w in [
            root,
            root + out * radius,
            root + (out + side * 0.2) * radius,
        ] {
            skin.positions.push(to_local.transform_point3(w));
        }
        skin.polygons.push(&[n, n + 1, n + 2]);
    }

    #[test]
    fn a_cap_over_the_eye_turns_with_it_and_one_resting_on_the_lids_is_skin() {
        // A cap clear of the lids turns with its eye; the same cap with a lid resting on its
        // rim (touching it, or 0.02 radii short of it, under the clearance, sharing no
        // vertex: ICT's eye blend comes to 0.013) is skin; 0.1 radii off it is clear again.
        for (gap, rests) in [
            (None, false),
            (Some(0.0), true),
            (Some(0.02), true),
            (Some(0.1), false),
        ] {
            let (mut face, centre, radius, gaze) = head();
            let layer = cap("layer", centre, gaze, 1.02 * radius, 0.35);
            if let Some(gap) = gap {
                rest_on_lids(&mut face, &layer, (centre, radius, gaze), gap);
            }
            face.meshes.push(layer);
            let frames = face.frames();
            let diag = face_diagonal(&face, &frames);
            let mi = face.mesh_index("layer").unwrap();
            let (_, parts) = split_embedded_parts(&face);
            let cut: Vec<Part> = parts
                .iter()
                .filter(|p| p.from == "layer")
                .map(|p| p.part)
                .collect();
            let skin = identify_parts(&face).skin.contains(&mi);
            let lids = lid_layers(&face, &frames, diag);
            if rests {
                assert!(
                    cut.is_empty() && skin && lids == vec![mi],
                    "{gap:?}: {cut:?} {skin} {lids:?}"
                );
            } else {
                assert!(
                    cut == vec![Part::LeftEye] && !skin && lids.is_empty(),
                    "{gap:?}: {cut:?} {skin} {lids:?}"
                );
            }
        }
        // A wider shell comes within the clearance of the synthetic head's own lids.
        let (mut face, centre, radius, gaze) = head();
        let shell = cap("shell", centre, gaze, 1.05 * radius, 0.8);
        // Wholly within the reach an eye layer is looked for in (so only the rim rule keeps
        // it from the eye).
        let far = shell
            .mesh
            .positions
            .iter()
            .map(|p| p.distance(centre) / radius)
            .fold(0.0, f32::max);
        assert!(far <= EYE_LAYER_REACH, "{far}");
        face.meshes.push(shell);
        let (_, parts) = split_embedded_parts(&face);
        assert!(parts.iter().all(|p| p.from != "shell"), "{parts:?}");
        let mi = face.mesh_index("shell").unwrap();
        assert!(identify_parts(&face).skin.contains(&mi));
    }

    #[test]
    fn a_closed_shell_has_no_rim_and_a_uv_seam_is_none() {
        let (face, centre, radius, gaze) = head();
        let eps = 1e-6;
        let open = cap("c", centre, gaze, radius, 0.5);
        let rim = rim_vertices(&open.mesh, eps);
        assert_eq!(rim, (25..37).collect::<Vec<u32>>());
        // The eyeball itself is closed.
        let (mi, _) = face.fp_vertex(FeaturePointId::FP_3_5).unwrap();
        assert!(rim_vertices(&face.meshes[mi].mesh, eps).is_empty());
        // A seam: the cap's first quad strip given its own copies of the ring it shares with
        // the next strip is still no rim there.
        let mut seam = open.mesh.clone();
        let n = seam.positions.len() as u32;
        let copies: Vec<Vec3> = (13..25).map(|v| seam.positions[v as usize]).collect();
        seam.positions.extend(copies);
        let mut polygons = Polygons::new();
        for (pi, poly) in seam.polygons.iter().enumerate() {
            let p: Vec<u32> = if (12..24).contains(&pi) {
                poly.iter()
                    .map(|&v| if (13..25).contains(&v) { n + v - 13 } else { v })
                    .collect()
            } else {
                poly.to_vec()
            };
            polygons.push(&p);
        }
        seam.polygons = polygons;
        assert_eq!(rim_vertices(&seam, eps), rim);
    }

    #[test]
    fn gums_free_in_the_mouth_are_cut_along_the_lip_line_and_a_closed_bag_is_not() {
        let (base, ..) = head();
        let fp = |id| base.feature_points.position(id).unwrap();
        let (u, lo) = (fp(FeaturePointId::FP_2_2), fp(FeaturePointId::FP_2_3));
        let d = base.fapu().unwrap().distances;
        let (mns, mw) = (d.mns0 as f32, d.mw0 as f32);
        // Behind the lips, centred on the lip line, reaching 0.8 MNS0 up and down.
        let centre = Vec3::new((u.x + lo.x) / 2.0, (u.y + lo.y) / 2.0, u.z.min(lo.z) - mns);
        let cut_of = |mesh: FaceMesh| {
            let mut face = base.clone();
            face.meshes.push(mesh);
            let (_, parts) = split_embedded_parts(&face);
            let mut of: Vec<Part> = parts
                .iter()
                .filter(|p| p.from == "gums")
                .map(|p| p.part)
                .collect();
            of.sort();
            of
        };
        // An open sheet facing forward, running back along the jaws (gums and tongue): both
        // jaws.
        let open = cap("gums", centre - Vec3::Z * 1.2 * mw, Vec3::Z, 0.8 * mns, 1.4);
        // The same sheet close behind the lips (a mouth interior's front): not a jaw.
        let shallow = cap("gums", centre, Vec3::Z, 0.8 * mns, 1.4);
        assert_eq!(cut_of(shallow), Vec::<Part>::new());
        assert_eq!(
            cut_of(open),
            vec![Part::UpperTeeth, Part::LowerTeeth]
                .into_iter()
                .collect::<BTreeSet<_>>()
                .into_iter()
                .collect::<Vec<_>>()
        );
        // The same place closed all round (a mouth bag): left to the skin.
        let closed = cap("gums", centre, Vec3::Z, 0.8 * mns, std::f32::consts::PI);
        assert!(rim_vertices(&closed.mesh, 1e-6).is_empty());
        assert_eq!(cut_of(closed), Vec::<Part>::new());
    }
}
