//! A face read from glTF, written back into its own document ([`crate::gltf::patch`]).
//!
//! The FAT becomes morph targets of the user's meshes, with the same pieces as
//! [`super::gltf`] makes (one target per interval of a table entry, shown at its span), but
//! grouped per glTF mesh: a target is one `(key, interval borders, interval)` and every
//! primitive of the mesh carries every target of the mesh (zeros where the primitive does not
//! move), so one weight per target drives all primitives alike. Offsets are computed in the
//! file's world frame and mapped back into each primitive's own space through the rest pose
//! it was read with ([`crate::gltf::source::RestPose`]); the file's units are kept.
//!
//! FAT motion of transforms (rigid parts turned by the cloner) is shown by the user's own
//! node where the document has one for it — an eyeball alone under an eye node or skinned to
//! an eye joint ([`super::gltf_user_nodes`]), the head rotations' transform on the head
//! node: animated on that node and recorded, not baked. Eyeballs that are vertices of a bigger
//! mesh (VRM: both in one primitive), which the cloner baked into per-vertex rows, are shown
//! by the eye joints that carry them alone the same way ([`super::gltf_eye_parts`]): their
//! rows under the eye's yaw and pitch leave the targets. Otherwise transform motion
//! has no node of its own in the user's document: it is baked into per-vertex targets,
//! piecewise linear over
//! `±2 V` in 8 intervals for rotations (`V` the key's reference value), one interval for
//! translations and scales (linear in the FAP value). A document fbakit generated records
//! its transforms' nodes (`specs/gltf-fat.md`): their motion is animated on those nodes and
//! recorded, not baked, and the document's `faceUnit` is kept.
//!
//! With frames, one animation `play` drives the weights of the first node showing each
//! patched mesh (the user's own targets held at their default weights).

use std::collections::BTreeMap;

use glam::{Affine3A, Quat, Vec3};
use serde_json::{Map, Value};

use super::gltf::FaceMorphs;
use super::gltf_carried::carries_point;
use super::gltf_eye_parts::{eye_parts, EyePart};
use super::gltf_rotations::{
    face_axes, head_node, jaw_node, rotated_nodes, same_hemisphere, JawNode, RotationNodes,
    HEAD_FAPS,
};
use super::gltf_user_nodes::{eye_transforms, world_delta, UserNode};
use crate::error::{Diagnostic, Result};
use crate::face::gltf_fat::{self, TargetRecord};
use crate::face::gltf_fat::{exact_offset, rate_of};
use crate::face::FaceModel;
use crate::fat::eval::Activation;
use crate::fat::morph::default_value;
use crate::fat::{interval_weights, Fat, TableKey, TransformField};
use crate::gltf::patch::{GltfPatch, MeshPatch, PatchAnimation, PatchedGltf, SparseOffsets};
use crate::gltf::source::{GltfSource, RestPose};
use crate::player::AnimationFrame;
use crate::spec::FeaturePointId;

/// Rotation bake: intervals over `±ROTATION_REACH × V`.
const ROTATION_INTERVALS: usize = 8;
const ROTATION_REACH: f64 = 2.0;

/// A patched document and what was worked around.
#[derive(Clone, Debug)]
pub struct GltfPatchExport {
    /// The document to write.
    pub document: PatchedGltf,
    /// Number of morph targets added over all meshes.
    pub morph_targets: usize,
    /// Things that could not be written exactly.
    pub warnings: Vec<Diagnostic>,
}

/// Which table motion a glTF target shows (the same on every primitive of a mesh).
#[derive(Clone, Debug, PartialEq)]
pub struct TargetPiece {
    /// The table key.
    pub key: TableKey,
    /// Interval borders of the entry.
    pub borders: Vec<f64>,
    /// Which interval.
    pub interval: usize,
    /// The value span the target shows.
    pub span: f64,
}

impl TargetPiece {
    fn same(&self, o: &TargetPiece) -> bool {
        self.key == o.key
            && self.interval == o.interval
            && self.borders.len() == o.borders.len()
            && self
                .borders
                .iter()
                .zip(&o.borders)
                .all(|(a, b)| a.to_bits() == b.to_bits())
    }

    /// Weight of this target for `activations`.
    pub fn weight(&self, activations: &[Activation], scratch: &mut Vec<f64>) -> f32 {
        let mut w = 0.0;
        for a in activations.iter().filter(|a| a.key == self.key) {
            if a.value == 0.0 || !a.value.is_finite() {
                continue;
            }
            interval_weights(&self.borders, a.value, scratch);
            w += scratch.get(self.interval).copied().unwrap_or(0.0) / self.span;
        }
        w as f32
    }
}

/// World-frame motion of one face mesh under one piece.
struct FaceMeshPiece {
    piece: TargetPiece,
    vertices: Vec<u32>,
    world: Vec<Vec3>,
    /// `world` is a FAT row times the span (a vertex table of a mesh placed by the identity),
    /// so it can be written to read back bit for bit.
    exact: bool,
}

/// The targets of one glTF mesh under construction.
#[derive(Default)]
struct MeshTargets {
    pieces: Vec<TargetPiece>,
    /// Per primitive, per target index, vertex → local offset.
    prims: BTreeMap<usize, BTreeMap<usize, BTreeMap<u32, Vec3>>>,
}

impl MeshTargets {
    fn index_of(&mut self, p: &TargetPiece) -> usize {
        match self.pieces.iter().position(|q| q.same(p)) {
            Some(i) => i,
            None => {
                self.pieces.push(p.clone());
                self.pieces.len() - 1
            }
        }
    }
}

/// Why `face` no longer fits the document it was read from, if it does not: a mesh the
/// FAT moves that the document lacks, or one whose vertex count changed (a cloner that cut
/// parts out of a mesh). Callers then write a new document instead of losing that motion.
pub fn mismatch(face: &FaceModel, source: &GltfSource) -> Option<String> {
    let moved: std::collections::HashSet<&str> = face
        .fat
        .tables
        .iter()
        .flat_map(|t| t.meshes.iter().map(|m| m.mesh.as_str()))
        .collect();
    for m in &face.meshes {
        match source.part(&m.name) {
            None if moved.contains(m.name.as_str()) || m.transform.is_some() => {
                return Some(format!("mesh `{}` is not in the document", m.name))
            }
            Some(p) if p.vertex_count != m.mesh.vertex_count() => {
                return Some(format!(
                    "mesh `{}` has {} vertices, its glTF primitive {}",
                    m.name,
                    m.mesh.vertex_count(),
                    p.vertex_count
                ))
            }
            _ => {}
        }
    }
    None
}

/// The face's glTF output: its own document patched when it was read from glTF and still
/// fits it ([`mismatch`]), else `None` with the reason as a warning in `warnings`.
pub fn patch_if_fits(
    face: &FaceModel,
    frames: Option<&[AnimationFrame]>,
    nodes: &RotationNodes,
    warnings: &mut Vec<Diagnostic>,
) -> Result<Option<GltfPatchExport>> {
    let Some(source) = &face.gltf_source else {
        return Ok(None);
    };
    if let Some(why) = mismatch(face, source) {
        warnings.push(Diagnostic::warning(format!(
            "{} cannot be patched ({why}): written as a new document",
            source.path.display()
        )));
        return Ok(None);
    }
    patch_face(face, source, frames, nodes).map(Some)
}

/// `face` (read from `source`) patched into that document; with `frames`, its animation
/// (head and eye rotations on `nodes`, or on the nodes found by their usual names).
pub fn patch_face(
    face: &FaceModel,
    source: &GltfSource,
    frames: Option<&[AnimationFrame]>,
    nodes: &RotationNodes,
) -> Result<GltfPatchExport> {
    face.check_structure()?;
    let mut warnings = Vec::new();
    // A face fbakit generated and read back: its transforms are nodes of the document (their
    // motion is animated there, not baked) and its lengths may be in other units.
    let unit = gltf_fat::face_unit(&source.json);
    // A head node of the user's (named, or found by its usual names and carrying the nose
    // tip) turns the head: the head rotations (48–50) are left to it, not baked into morph
    // targets (never a rotation and a morph for one motion). A face without a nose tip or
    // chin cannot be checked: the node is taken.
    let head = head_node(source, nodes).filter(|&n| {
        [FeaturePointId::FP_9_3, FeaturePointId::FP_2_1]
            .into_iter()
            .find(|&id| face.feature_points.position(id).is_some())
            .is_none_or(|nose| {
                node_takes(
                    NodeCheck {
                        source,
                        face,
                        node: n,
                        role: "head",
                        fp: nose,
                        named: nodes.head.is_some(),
                        motion: "the head rotations",
                        option: "--head-node",
                    },
                    &mut warnings,
                )
            })
    });
    // Head turns given per vertex (a clone onto a face without a head transform gets the
    // standard's rotations that way) become one turn of that node about its origin, as a
    // head transform's would: the user's rig bends the neck, and the turn is not also a morph.
    let turned;
    let face = match head.filter(|_| head_transform(face).is_none()) {
        Some(n) => match head_turns_on_node(face, source, n, unit) {
            Some(f) => {
                turned = f;
                &turned
            }
            None => face,
        },
        None => face,
    };
    let by_name = gltf_fat::transform_nodes(&source.json);
    let mut transform_nodes: Vec<Option<usize>> = face
        .transforms
        .iter()
        .map(|t| by_name.get(&t.name).copied())
        .collect();
    // Transforms the user's own nodes show (the eyeballs on eye nodes): recorded by an
    // earlier write, or found now. Their motion is animated on the node, not baked.
    let recorded_user = gltf_fat::user_node_transforms(&source.json);
    let mut user_nodes: Vec<bool> = face
        .transforms
        .iter()
        .map(|t| recorded_user.contains(&t.name))
        .collect();
    let mut apart: Vec<(usize, Vec<usize>)> = Vec::new();
    for e in eye_transforms(face, source, nodes, &transform_nodes, &mut warnings) {
        transform_nodes[e.transform] = Some(e.node);
        user_nodes[e.transform] = true;
        if !e.apart.is_empty() {
            apart.push((e.transform, e.apart));
        }
    }
    // Eyeballs that are vertices of a bigger mesh, turned by the eye joints carrying them:
    // their rows under the eye's tables leave the targets (never a rotation and a morph).
    let shown: Vec<usize> = transform_nodes.iter().flatten().copied().collect();
    let parts = eye_parts(face, source, nodes, &shown, &mut warnings);
    let parted;
    let face = if parts.is_empty() {
        face
    } else {
        parted = without_parts(face, &parts);
        &parted
    };
    // The transform the head rotations turn (the cloner's `head`) is shown by that node:
    // recorded as a user node like the eyes, so the written file reads back with the head's
    // motion, and animated there. A transform on a node of fbakit's own keeps it.
    if let (Some(n), Some(t)) = (head, head_transform(face)) {
        let own = transform_nodes[t].is_some() && !user_nodes[t];
        let elsewhere = transform_nodes
            .iter()
            .enumerate()
            .any(|(i, x)| i != t && *x == Some(n));
        if !own && !elsewhere {
            transform_nodes[t] = Some(n);
            user_nodes[t] = true;
        }
    }
    let trimmed;
    let face = match head {
        Some(_) => {
            trimmed = without_head_rotations(face, &transform_nodes);
            &trimmed
        }
        None => face,
    };
    let world_pieces = face_pieces(face, &transform_nodes, &apart)?;
    let mut meshes: BTreeMap<usize, MeshTargets> = BTreeMap::new();
    // A glTF mesh shown by several nodes is patched once: from its first instance.
    let mut taken: BTreeMap<(usize, usize), String> = BTreeMap::new();
    for (mi, fm) in face.meshes.iter().enumerate() {
        let Some(part) = source.part(&fm.name) else {
            if !world_pieces[mi].is_empty() {
                warnings.push(Diagnostic::warning(format!(
                    "mesh `{}` is not part of {}: its motion is not written",
                    fm.name,
                    source.path.display()
                )));
            }
            continue;
        };
        if part.vertex_count != fm.mesh.vertex_count() {
            warnings.push(Diagnostic::warning(format!(
                "mesh `{}` has {} vertices but its glTF primitive has {}: its motion is not written",
                fm.name,
                fm.mesh.vertex_count(),
                part.vertex_count
            )));
            continue;
        }
        if let Some(first) = taken.get(&(part.mesh, part.primitive)) {
            if first != &fm.name && !world_pieces[mi].is_empty() {
                warnings.push(Diagnostic::warning(format!(
                    "mesh `{}` shows the same glTF mesh as `{first}`: one target list is \
                     written, from `{first}`",
                    fm.name
                )));
            }
            continue;
        }
        taken.insert((part.mesh, part.primitive), fm.name.clone());
        let targets = meshes.entry(part.mesh).or_default();
        for wp in &world_pieces[mi] {
            let t = targets.index_of(&wp.piece);
            let slot = targets
                .prims
                .entry(part.primitive)
                .or_default()
                .entry(t)
                .or_default();
            // Rest poses that are the file's unit scale only (fbakit's own documents): the
            // offsets fbakit writes read back as the FAT's rates exactly.
            let unit_rest = match &part.rest {
                RestPose::Matrix(m) => {
                    (glam::Mat3::from_mat4(*m) * unit).abs_diff_eq(glam::Mat3::IDENTITY, 1e-6)
                }
                RestPose::PerVertex(_) => false,
            };
            let per_rate = wp.piece.span * f64::from(unit);
            for (&v, &d) in wp.vertices.iter().zip(&wp.world) {
                let local = if wp.exact && unit_rest {
                    let exact = |o: f32| exact_offset(rate_of(o, wp.piece.span), per_rate);
                    Vec3::new(exact(d.x), exact(d.y), exact(d.z))
                } else {
                    part.rest.to_local(v as usize, d)
                };
                *slot.entry(v).or_insert(Vec3::ZERO) += local;
            }
        }
    }
    let mut patch = GltfPatch::default();
    let mut morph_targets = 0;
    let mut layouts: BTreeMap<usize, TargetLayout> = BTreeMap::new();
    for (&m, t) in &meshes {
        if t.pieces.is_empty() {
            continue;
        }
        morph_targets += t.pieces.len();
        let existing = source.target_names(m);
        let recorded = recorded_pieces(source, m, &existing);
        let mut names = piece_names(&t.pieces, &existing);
        let mut replaces = vec![None; t.pieces.len()];
        let mut final_index = Vec::with_capacity(t.pieces.len());
        let mut appended = 0;
        for (pi, p) in t.pieces.iter().enumerate() {
            match recorded.iter().find(|(_, q)| q.same(p)) {
                Some(&(i, _)) => {
                    replaces[pi] = Some(i);
                    names[pi] = existing[i].clone();
                    final_index.push(i);
                }
                None => {
                    final_index.push(existing.len() + appended);
                    appended += 1;
                }
            }
        }
        let zeroed: Vec<usize> = recorded
            .iter()
            .map(|(i, _)| *i)
            .filter(|i| !replaces.contains(&Some(*i)))
            .collect();
        layouts.insert(
            m,
            TargetLayout {
                final_index,
                total: existing.len() + appended,
            },
        );
        let mut primitives = BTreeMap::new();
        for (&p, per_target) in &t.prims {
            let list = (0..t.pieces.len())
                .map(|ti| {
                    let mut s = SparseOffsets::default();
                    for (&v, &o) in per_target.get(&ti).into_iter().flatten() {
                        if o != Vec3::ZERO && o.is_finite() {
                            s.vertices.push(v);
                            s.offsets.push(o);
                        }
                    }
                    s
                })
                .collect();
            primitives.insert(p, list);
        }
        let records: Vec<TargetRecord> = t
            .pieces
            .iter()
            .zip(&names)
            .map(|(p, name)| TargetRecord {
                target: name.clone(),
                key: p.key,
                borders: p.borders.clone(),
                interval: p.interval,
                span: p.span,
            })
            .collect();
        let mut extras = Map::new();
        extras.insert(gltf_fat::KEY.into(), gltf_fat::targets_record(&records));
        patch.meshes.insert(
            m,
            MeshPatch {
                names,
                replaces,
                zeroed,
                primitives,
                extras,
            },
        );
    }
    // Meshes a node-shown transform moves apart from the node (an eye white beside the iris
    // under the eye node) carry its motion as targets: recorded above that transform, so the
    // file reads back with their motion once.
    let lifted;
    let recorded = if apart.is_empty() {
        face
    } else {
        lifted = lift_apart(face, &apart);
        &lifted
    };
    patch.scene_extras = gltf_fat::scene_record(recorded, unit, &transform_nodes);
    gltf_fat::mark_user_nodes(&mut patch.scene_extras, &user_nodes);
    if !parts.is_empty() {
        if let Some(Value::Object(record)) = patch.scene_extras.get_mut(gltf_fat::KEY) {
            let list = parts.iter().map(|p| p.record(face, unit)).collect();
            record.insert("nodeParts".into(), Value::Array(list));
        }
    }
    if let Some(frames) = frames.filter(|f| !f.is_empty()) {
        // The jaw joint, when there is one, takes open_jaw, thrust_jaw and shift_jaw over
        // from the targets (never a joint and a morph for one motion).
        let driven: Vec<usize> = transform_nodes
            .iter()
            .flatten()
            .copied()
            .chain(parts.iter().map(|p| p.node))
            .collect();
        let jaw = match jaw_node(source, face, nodes.jaw.as_deref(), unit, &driven) {
            Ok(Some(jaw)) => node_takes(
                NodeCheck {
                    source,
                    face,
                    node: jaw.node,
                    role: "jaw",
                    fp: FeaturePointId::FP_2_1,
                    named: nodes.jaw.is_some(),
                    motion: "open_jaw, thrust_jaw and shift_jaw",
                    option: "--jaw-node",
                },
                &mut warnings,
            )
            .then_some(jaw),
            Ok(None) => None,
            Err(why) => {
                warnings.push(Diagnostic::warning(format!(
                    "{}: {why}; open_jaw, thrust_jaw and shift_jaw stay morph targets",
                    source.path.display()
                )));
                None
            }
        };
        let morph_frames: Vec<AnimationFrame>;
        let weight_frames = if jaw.is_some() {
            morph_frames = frames
                .iter()
                .map(|f| {
                    let mut f = f.clone();
                    f.activations.retain(|a| !JawNode::takes(a.key));
                    f
                })
                .collect();
            &morph_frames[..]
        } else {
            frames
        };
        patch.animation = animation(source, &meshes, &layouts, weight_frames);
        let mut turned = rotated_nodes(source, face, nodes);
        // Eye joints turning eyeball parts take the eye FAPs by the parts' fitted turns.
        turned.retain(|n| !parts.iter().any(|p| p.node == n.node));
        if !turned.is_empty() {
            let anim = patch
                .animation
                .get_or_insert_with(|| empty_animation(frames));
            for n in &turned {
                let mut values: Vec<Quat> = keyed_frames(frames)
                    .iter()
                    .map(|f| n.rotation(&f.activations))
                    .collect();
                same_hemisphere(&mut values);
                anim.rotations.push((n.node, values));
            }
        }
        transform_channels(
            face,
            source,
            (&transform_nodes, &user_nodes),
            unit,
            frames,
            &mut patch.animation,
        );
        part_channels(&parts, source, unit, frames, &mut patch.animation);
        if let Some(jaw) = &jaw {
            let anim = patch
                .animation
                .get_or_insert_with(|| empty_animation(frames));
            let keyed = keyed_frames(frames);
            if !anim.rotations.iter().any(|(n, _)| *n == jaw.node) {
                let mut values: Vec<Quat> =
                    keyed.iter().map(|f| jaw.rotation(&f.activations)).collect();
                same_hemisphere(&mut values);
                anim.rotations.push((jaw.node, values));
            }
            let values = keyed
                .iter()
                .map(|f| jaw.translation(&f.activations))
                .collect();
            anim.translations.push((jaw.node, values));
        }
    }
    let document = patch.apply(source)?;
    warnings.extend(document.warnings.iter().cloned());
    Ok(GltfPatchExport {
        document,
        morph_targets,
        warnings,
    })
}

/// `face` without the rows of `parts` (vertices a user's node turns) in the tables they take;
/// the tables stay, so nothing else takes their FAPs for those nodes.
fn without_parts(face: &FaceModel, parts: &[EyePart]) -> FaceModel {
    let mut out = face.clone();
    for table in &mut out.fat.tables {
        for m in parts
            .iter()
            .filter(|p| p.takes(table.key))
            .flat_map(|p| &p.meshes)
        {
            let name = &face.meshes[m.mesh].name;
            for e in table.meshes.iter_mut().filter(|e| &e.mesh == name) {
                let k = e.interval_count();
                let mut coord = Vec::with_capacity(e.coord_index.len());
                let mut rows = Vec::with_capacity(e.displacements.len());
                for (i, &v) in e.coord_index.iter().enumerate() {
                    if m.vertices.binary_search(&v).is_err() {
                        coord.push(v);
                        rows.extend_from_slice(&e.displacements[i * k..(i + 1) * k]);
                    }
                }
                e.coord_index = coord;
                e.displacements = rows;
            }
            table.meshes.retain(|e| !e.coord_index.is_empty());
        }
    }
    out
}

/// Rotation (and, for a pivot off the node's origin, translation) channels on the nodes
/// turning `parts`: each part's motion in the face frame carried onto its node's rest pose
/// ([`UserNode`]), lengths × `unit`.
fn part_channels(
    parts: &[EyePart],
    source: &GltfSource,
    unit: f32,
    frames: &[AnimationFrame],
    animation: &mut Option<PatchAnimation>,
) {
    let keyed = keyed_frames(frames);
    let s = Affine3A::from_scale(Vec3::splat(unit));
    for p in parts {
        let Some(frame) = UserNode::new(&source.json, p.node) else {
            continue;
        };
        let anim = animation.get_or_insert_with(|| empty_animation(frames));
        if anim.rotations.iter().any(|(n, _)| *n == p.node) {
            continue;
        }
        let keys: Vec<(Quat, Vec3)> = keyed
            .iter()
            .map(|f| frame.local(s * p.motion(&f.activations) * s.inverse()))
            .collect();
        let mut values: Vec<Quat> = keys.iter().map(|k| k.0).collect();
        same_hemisphere(&mut values);
        anim.rotations.push((p.node, values));
        let t0 = frame.rest_translation();
        let reach = 1e-6 * (t0.length() + unit);
        if keys.iter().any(|k| k.1.distance(t0) > reach) {
            anim.translations
                .push((p.node, keys.iter().map(|k| k.1).collect()));
        }
    }
}

/// `face` without the transform entries of its head rotation tables (48–50) on transforms
/// the document has no node for (`transform_nodes`); a table left empty is dropped.
fn without_head_rotations(face: &FaceModel, transform_nodes: &[Option<usize>]) -> FaceModel {
    let mut out = face.clone();
    for table in &mut out.fat.tables {
        if !matches!(table.key, TableKey::LowLevel(f) if HEAD_FAPS.contains(&f.number())) {
            continue;
        }
        table.transforms.retain(|x| {
            face.transform_index(&x.transform)
                .and_then(|i| transform_nodes.get(i).copied().flatten())
                .is_some()
        });
    }
    out.fat
        .tables
        .retain(|t| !t.meshes.is_empty() || !t.transforms.is_empty());
    out
}

/// `face` with its per-vertex head rotation tables (48–50) turned into rotations of a new
/// root transform above every mesh, centred on node `node`'s rest origin (face frame: the
/// file's world / `unit`), which the caller maps onto that node; `None` when no head table is
/// given per vertex alone.
fn head_turns_on_node(
    face: &FaceModel,
    source: &GltfSource,
    node: usize,
    unit: f32,
) -> Option<FaceModel> {
    let per_vertex = |t: &crate::fat::FaceDefTable| {
        matches!(t.key, TableKey::LowLevel(f) if HEAD_FAPS.contains(&f.number()))
            && t.transforms.is_empty()
            && !t.meshes.is_empty()
    };
    if !face.fat.tables.iter().any(per_vertex) || unit <= 0.0 {
        return None;
    }
    let origin = UserNode::new(&source.json, node)?.world_origin() / unit;
    let mut out = face.clone();
    let mut name = "head".to_string();
    let mut k = 1;
    while out.transform_index(&name).is_some() || out.mesh_index(&name).is_some() {
        k += 1;
        name = format!("head_{k}");
    }
    // A root above everything, first (parents come before children).
    for t in &mut out.transforms {
        t.parent = Some(t.parent.map_or(0, |p| p + 1));
    }
    for m in &mut out.meshes {
        m.transform = Some(m.transform.map_or(0, |t| t + 1));
    }
    out.transforms.insert(
        0,
        crate::face::FaceTransform::new(name.clone(), None, origin),
    );
    for table in out.fat.tables.iter_mut().filter(|t| per_vertex(t)) {
        let TableKey::LowLevel(f) = table.key else {
            continue;
        };
        let Some(axis) = f.info().rotation_axis() else {
            continue;
        };
        // About the face's own axis (turned from the file's for a face modelled facing −z).
        let axis = (face_axes(face) * axis).normalize();
        table.meshes.clear();
        // One AU (1e-5 rad) per FAP unit, the standard's angle.
        table
            .transforms
            .push(crate::fat::FaceDefTransform::rotation(
                name.clone(),
                axis,
                1e-5,
            ));
    }
    Some(out)
}

/// The one transform the head rotation tables (48–50) turn, if they turn exactly one.
fn head_transform(face: &FaceModel) -> Option<usize> {
    let mut found = None;
    for table in &face.fat.tables {
        if !matches!(table.key, TableKey::LowLevel(f) if HEAD_FAPS.contains(&f.number())) {
            continue;
        }
        for x in &table.transforms {
            let t = face.transform_index(&x.transform)?;
            if found.is_some_and(|f| f != t) {
                return None;
            }
            found = Some(t);
        }
    }
    found
}

/// Where a mesh's pieces land among its targets after the patch.
struct TargetLayout {
    /// Per piece, its target index.
    final_index: Vec<usize>,
    /// Targets of the mesh after the patch.
    total: usize,
}

/// fbakit's targets recorded on mesh `m` by an earlier write: `(target index, piece)`.
fn recorded_pieces(source: &GltfSource, m: usize, names: &[String]) -> Vec<(usize, TargetPiece)> {
    let mut out = Vec::new();
    let list = &source.json["meshes"][m]["extras"][gltf_fat::KEY]["targets"];
    for r in list.as_array().into_iter().flatten() {
        let (Some(target), Some(key), Some(borders), Some(interval), Some(span)) = (
            r["target"].as_str(),
            r["key"].as_str().and_then(TableKey::from_name),
            r["borders"]
                .as_array()
                .and_then(|a| a.iter().map(|v| v.as_f64()).collect::<Option<Vec<f64>>>()),
            r["interval"].as_u64(),
            r["span"].as_f64(),
        ) else {
            continue;
        };
        if let Some(i) = names.iter().position(|n| n == target) {
            out.push((
                i,
                TargetPiece {
                    key,
                    borders,
                    interval: interval as usize,
                    span,
                },
            ));
        }
    }
    out
}

/// Target names: the key's name, `#j` appended when the key has several targets, and
/// `_fbakit` when the mesh already has a target of that name.
fn piece_names(pieces: &[TargetPiece], taken: &[String]) -> Vec<String> {
    let mut per_key: BTreeMap<TableKey, usize> = BTreeMap::new();
    for p in pieces {
        *per_key.entry(p.key).or_default() += 1;
    }
    let mut seen: BTreeMap<TableKey, usize> = BTreeMap::new();
    pieces
        .iter()
        .map(|p| {
            let j = seen.entry(p.key).or_default();
            let mut name = if per_key[&p.key] == 1 {
                p.key.name()
            } else {
                format!("{}#{j}", p.key.name())
            };
            *j += 1;
            while taken.contains(&name) {
                name.push_str("_fbakit");
            }
            name
        })
        .collect()
}

/// `face` with each mesh of `apart` (transform, meshes) moved from that transform to its
/// parent, its positions re-expressed there.
fn lift_apart(face: &FaceModel, apart: &[(usize, Vec<usize>)]) -> FaceModel {
    let mut out = face.clone();
    let frames = face.frames();
    for (t, meshes) in apart {
        let parent = face.transforms.get(*t).and_then(|x| x.parent);
        let to_parent = parent
            .map_or(Affine3A::IDENTITY, |p| frames.transforms[p])
            .inverse();
        for &m in meshes {
            let Some(fm) = out.meshes.get_mut(m) else {
                continue;
            };
            let map = to_parent * frames.meshes[m];
            for q in &mut fm.mesh.positions {
                *q = map.transform_point3(*q);
            }
            fm.transform = parent;
        }
    }
    out
}

/// Per face mesh, the world-frame motion of every piece: the FAT's vertex tables, then its
/// transform motion baked — for a transform a node shows, only on the meshes it moves apart
/// from that node (`apart`: transform, meshes).
fn face_pieces(
    face: &FaceModel,
    transform_nodes: &[Option<usize>],
    apart: &[(usize, Vec<usize>)],
) -> Result<Vec<Vec<FaceMeshPiece>>> {
    let morphs = FaceMorphs::new(face)?;
    let frames = face.frames();
    let mut out: Vec<Vec<FaceMeshPiece>> = Vec::with_capacity(face.meshes.len());
    for (mi, pieces) in morphs.meshes.iter().enumerate() {
        let linear = frames.meshes.get(mi).copied().unwrap_or(Affine3A::IDENTITY);
        out.push(
            pieces
                .iter()
                .map(|p| FaceMeshPiece {
                    piece: TargetPiece {
                        key: p.key,
                        borders: p.borders.clone(),
                        interval: p.interval,
                        span: p.span,
                    },
                    vertices: p.vertices.clone(),
                    world: p
                        .offsets
                        .iter()
                        .map(|&o| linear.transform_vector3(o))
                        .collect(),
                    exact: linear == Affine3A::IDENTITY,
                })
                .collect(),
        );
    }
    for table in &face.fat.tables {
        // Motion of transforms the document shows as nodes is animated on them instead.
        let mut baked = table.clone();
        baked.transforms.retain(|x| {
            face.transform_index(&x.transform)
                .and_then(|i| transform_nodes.get(i).copied().flatten())
                .is_none()
        });
        if !baked.transforms.is_empty() {
            bake_transforms(face, &baked, None, &mut out)?;
        }
        for (t, meshes) in apart {
            let mut only = table.clone();
            only.transforms
                .retain(|x| face.transform_index(&x.transform) == Some(*t));
            if !only.transforms.is_empty() {
                bake_transforms(face, &only, Some(meshes), &mut out)?;
            }
        }
    }
    Ok(out)
}

/// The transform motion of `table` as per-vertex pieces of the meshes it moves (of `meshes`
/// only, when given).
fn bake_transforms(
    face: &FaceModel,
    table: &crate::fat::FaceDefTable,
    meshes: Option<&[usize]>,
    out: &mut [Vec<FaceMeshPiece>],
) -> Result<()> {
    let mut only = face.clone();
    only.fat = Fat::default();
    let mut t = table.clone();
    t.meshes.clear();
    let rotates = t
        .transforms
        .iter()
        .any(|x| x.field == TransformField::Rotation);
    only.fat.tables.push(t);
    let v = default_value(table.key);
    let borders: Vec<f64> = if rotates {
        let n = ROTATION_INTERVALS as f64;
        (0..=ROTATION_INTERVALS)
            .map(|i| (i as f64 / n * 2.0 - 1.0) * ROTATION_REACH * v)
            .collect()
    } else {
        vec![0.0, v]
    };
    let at: Vec<Vec<Vec<Vec3>>> = borders
        .iter()
        .map(|&b| {
            only.pose(&[Activation {
                key: table.key,
                value: b,
            }])
        })
        .collect::<Result<_>>()?;
    for j in 0..borders.len() - 1 {
        let (lo, hi) = (borders[j], borders[j + 1]);
        let span = if hi <= 0.0 { lo - hi } else { hi - lo };
        for (mi, list) in out.iter_mut().enumerate() {
            if meshes.is_some_and(|m| !m.contains(&mi)) {
                continue;
            }
            let mut vertices = Vec::new();
            let mut world = Vec::new();
            let (lo_at, hi_at) = (&at[j][mi], &at[j + 1][mi]);
            for (v, (a, b)) in lo_at.iter().zip(hi_at).enumerate() {
                // Offsets at the span: the change across the interval, signed towards zero's
                // far side (the rule of `FaceMorphs`).
                let d = if hi <= 0.0 { *a - *b } else { *b - *a };
                if d.length_squared() > 0.0 && d.is_finite() {
                    vertices.push(v as u32);
                    world.push(d);
                }
            }
            if !vertices.is_empty() {
                list.push(FaceMeshPiece {
                    piece: TargetPiece {
                        key: table.key,
                        borders: borders.clone(),
                        interval: j,
                        span,
                    },
                    vertices,
                    world,
                    exact: false,
                });
            }
        }
    }
    Ok(())
}

/// Channels on the nodes that show the face's FAT-driven transforms: on fbakit's own nodes (a
/// face fbakit generated and read back) the animated field values, lengths × `unit` (the rule
/// of `export::gltf`); on the user's nodes (`user`, per transform) the transform's motion
/// in the face frame carried onto the node's rest pose ([`UserNode`]).
fn transform_channels(
    face: &FaceModel,
    source: &GltfSource,
    (transform_nodes, user): (&[Option<usize>], &[bool]),
    unit: f32,
    frames: &[AnimationFrame],
    animation: &mut Option<PatchAnimation>,
) {
    let rest_frames = face.frames();
    let mut driven = vec![[false; 3]; face.transforms.len()];
    for x in face.fat.tables.iter().flat_map(|t| &t.transforms) {
        if let Some(i) = face.transform_index(&x.transform) {
            let f = match x.field {
                TransformField::Rotation => 0,
                TransformField::Translation => 1,
                TransformField::Scale => 2,
            };
            driven[i][f] = true;
        }
    }
    let keyed = keyed_frames(frames);
    for (i, t) in face.transforms.iter().enumerate() {
        let Some(node) = transform_nodes.get(i).copied().flatten() else {
            continue;
        };
        let [rot, tr, sc] = driven[i];
        if !(rot || tr || sc) {
            continue;
        }
        let delta = |f: &AnimationFrame| {
            f.transform_deltas
                .get(i)
                .copied()
                .unwrap_or(crate::fat::eval::TransformDelta::IDENTITY)
        };
        let anim = animation.get_or_insert_with(|| empty_animation(frames));
        if user.get(i).copied().unwrap_or(false) {
            let Some(frame) = UserNode::new(&source.json, node) else {
                continue;
            };
            let parent = t
                .parent
                .and_then(|p| rest_frames.transforms.get(p).copied())
                .unwrap_or(Affine3A::IDENTITY);
            let rest = t.local_matrix();
            let keys: Vec<(Quat, Vec3)> = keyed
                .iter()
                .map(|f| {
                    frame.local(world_delta(
                        parent,
                        rest,
                        t.animated_matrix(&delta(f)),
                        unit,
                    ))
                })
                .collect();
            if !anim.rotations.iter().any(|(n, _)| *n == node) {
                let mut values: Vec<Quat> = keys.iter().map(|k| k.0).collect();
                same_hemisphere(&mut values);
                anim.rotations.push((node, values));
            }
            // A pivot off the node's origin (or a thrust) moves it.
            let t0 = frame.rest_translation();
            let reach = 1e-6 * (t0.length() + unit);
            if keys.iter().any(|k| k.1.distance(t0) > reach) {
                anim.translations
                    .push((node, keys.iter().map(|k| k.1).collect()));
            }
            continue;
        }
        // A node already turned as a head or eye keeps that one rotation.
        if rot && !anim.rotations.iter().any(|(n, _)| *n == node) {
            let mut values: Vec<Quat> = keyed
                .iter()
                .map(|f| (delta(f).rotation * t.rotation).normalize())
                .collect();
            same_hemisphere(&mut values);
            anim.rotations.push((node, values));
        }
        if tr {
            let values = keyed
                .iter()
                .map(|f| (t.translation + delta(f).translation + t.center) * unit)
                .collect();
            anim.translations.push((node, values));
        }
        if sc {
            let values = keyed.iter().map(|f| t.scale + delta(f).scale).collect();
            anim.scales.push((node, values));
        }
    }
}

/// The played frames with a closing key one frame after the last that holds it (the rule of
/// `export::gltf`: the clip lasts frames / fps).
fn keyed_frames(frames: &[AnimationFrame]) -> Vec<&AnimationFrame> {
    let closing = frames.len() >= 2;
    frames
        .iter()
        .chain(closing.then(|| &frames[frames.len() - 1]))
        .collect()
}

/// The `play` animation with its key times and no channels yet.
fn empty_animation(frames: &[AnimationFrame]) -> PatchAnimation {
    let t0 = frames[0].time;
    let mut times: Vec<f32> = frames.iter().map(|f| (f.time - t0) as f32).collect();
    if frames.len() >= 2 {
        let last = frames[frames.len() - 1].time - t0;
        times.push((last + last / (frames.len() - 1) as f64) as f32);
    }
    PatchAnimation {
        name: "play".into(),
        times,
        ..PatchAnimation::default()
    }
}

/// One weights channel per patched mesh, on the first node that shows it.
fn animation(
    source: &GltfSource,
    meshes: &BTreeMap<usize, MeshTargets>,
    layouts: &BTreeMap<usize, TargetLayout>,
    frames: &[AnimationFrame],
) -> Option<PatchAnimation> {
    let keyed = keyed_frames(frames);
    let mut anim = empty_animation(frames);
    let mut scratch = Vec::new();
    for (&m, t) in meshes {
        if t.pieces.is_empty() {
            continue;
        }
        let Some(node) = source
            .parts
            .iter()
            .find(|p| p.mesh == m)
            .and_then(|p| p.node)
        else {
            continue;
        };
        let mesh = &source.json["meshes"][m];
        let old: Vec<f32> = source.json["nodes"][node]["weights"]
            .as_array()
            .or_else(|| mesh["weights"].as_array())
            .map(|w| w.iter().map(|x| x.as_f64().unwrap_or(0.0) as f32).collect())
            .unwrap_or_else(|| {
                let n = mesh["primitives"][0]["targets"]
                    .as_array()
                    .map_or(0, Vec::len);
                vec![0.0; n]
            });
        let Some(layout) = layouts.get(&m) else {
            continue;
        };
        let mut key = old.clone();
        key.resize(layout.total, 0.0);
        // fbakit's earlier targets are driven below or stay at zero.
        for i in recorded_pieces(source, m, &source.target_names(m))
            .iter()
            .map(|r| r.0)
        {
            if let Some(w) = key.get_mut(i) {
                *w = 0.0;
            }
        }
        let mut values = Vec::with_capacity(keyed.len() * layout.total);
        for f in &keyed {
            for (p, &i) in t.pieces.iter().zip(&layout.final_index) {
                key[i] = p.weight(&f.activations, &mut scratch);
            }
            values.extend_from_slice(&key);
        }
        anim.weights.push((node, values));
    }
    (!anim.weights.is_empty()).then_some(anim)
}

/// A user's node checked before it takes a motion from the morph targets (see
/// [`NodeCheck`]).
struct NodeCheck<'a> {
    source: &'a GltfSource,
    face: &'a FaceModel,
    node: usize,
    /// "head", "jaw": for messages.
    role: &'a str,
    /// The feature point the node must carry.
    fp: FeaturePointId,
    /// Whether the user named the node (`option`), rather than it being found by its name.
    named: bool,
    /// The FAPs it would take, for messages.
    motion: &'a str,
    option: &'a str,
}

/// Whether the node takes its motion: when it carries the feature point
/// ([`carries_point`]); else a node the user named is taken at their word and one found by
/// its name is not, with a warning either way.
fn node_takes(c: NodeCheck, warnings: &mut Vec<Diagnostic>) -> bool {
    let Err(why) = carries_point(c.source, c.face, c.node, c.role, c.fp) else {
        return true;
    };
    let (file, motion, option) = (c.source.path.display(), c.motion, c.option);
    warnings.push(Diagnostic::warning(if c.named {
        format!("{file}: {why}; it takes {motion} as {option} asks")
    } else {
        format!(
            "{file}: {why}; {motion} stay morph targets ({option} NAME hands them to a node \
             anyway)"
        )
    }));
    c.named
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Baked transform motion reproduces the posed face at the bake's borders, where the
    /// piecewise-linear targets are exact.
    #[test]
    fn baked_transforms_reproduce_the_pose_at_their_borders() {
        let face = crate::synth::alma().to_face_model();
        let table = face
            .fat
            .tables
            .iter()
            .find(|t| {
                t.transforms
                    .iter()
                    .any(|x| x.field == TransformField::Rotation)
            })
            .expect("alma turns something by a transform");
        let mut only = face.clone();
        only.fat.tables = vec![crate::fat::FaceDefTable {
            meshes: Vec::new(),
            ..table.clone()
        }];
        let mut pieces: Vec<Vec<FaceMeshPiece>> =
            (0..face.meshes.len()).map(|_| Vec::new()).collect();
        bake_transforms(&face, table, None, &mut pieces).unwrap();
        assert!(pieces.iter().any(|p| !p.is_empty()));
        let v = default_value(table.key);
        let neutral = only.pose(&[]).unwrap();
        let mut scratch = Vec::new();
        for value in [-2.0 * v, -0.5 * v, 0.5 * v, v, 2.0 * v] {
            let a = [Activation {
                key: table.key,
                value,
            }];
            let want = only.pose(&a).unwrap();
            for (mi, list) in pieces.iter().enumerate() {
                let mut got = neutral[mi].clone();
                for p in list {
                    let w = p.piece.weight(&a, &mut scratch);
                    for (&vi, d) in p.vertices.iter().zip(&p.world) {
                        got[vi as usize] += *d * w;
                    }
                }
                for (g, w) in got.iter().zip(&want[mi]) {
                    assert!(g.distance(*w) < 1e-4, "{value}: {g} vs {w}");
                }
            }
        }
    }
}
