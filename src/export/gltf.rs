//! A face (and optionally a played animation) as a glTF 2.0 document.
//!
//! ## Nodes
//! Every face `Transform` becomes nodes that reproduce the VRML matrix
//! `T · C · R · S · C⁻¹` (glTF has no `center`): a node **A** named after the transform with
//! translation `t + c`, rotation `r` and scale `s`, and, when `c ≠ 0`, a child **pivot** node
//! **B** (`<name>_pivot`) with translation `−c` that holds the transform's children and meshes.
//! `scaleOrientation` has no glTF equivalent either; a non-identity one is dropped with a
//! warning. Each face mesh is a node (named after the mesh) under its transform's holder node.
//! Coordinates are written as they are (MPEG-4 and glTF agree: +y up, +z towards the viewer);
//! no unit conversion is made.
//!
//! ## Morph targets
//! The FAT becomes morph targets of each mesh, per table key and `FaceDefMesh` entry:
//! - A **single-interval** entry moves vertices by `rate × P` for every value `P` (the one
//!   interval extends both ways). It is one target showing the table at its reference value
//!   `V` (the entry's non-zero border of largest magnitude, else
//!   [`crate::fat::morph::default_value`]): offsets `rate × V`, weight `P / V`.
//! - A **multi-interval** entry is baked into one target per interval `j`: offsets
//!   `rate_j × s_j` with `s_j` the interval's signed span (`b_{j+1} − b_j` above zero,
//!   `b_j − b_{j+1}` below), weight `w_j(P) / s_j` where `w_j` is the signed length of
//!   `[0, P]` inside interval `j` ([`crate::fat::interval_weights`], outermost intervals
//!   extended to ±∞). So weights run 0..1 while `P` walks through an interval and the sum
//!   `Σ_j weight_j × target_j` is exactly the piecewise-linear FAT rule, extrapolation included.
//!
//! Target names are the key name ([`TableKey::name`]: `open_jaw`, `viseme_7`, `joy`), with
//! `#j` appended when the key has several targets on the mesh; they go to
//! `mesh.extras.targetNames`.
//!
//! ## Animation
//! One animation, `play`, with LINEAR keyframes at every frame (times start at 0 at the first
//! played frame) and a closing key one frame after the last that holds it, so the clip lasts
//! exactly frames / fps: per mesh with targets a weights channel (the weight of a target sums over the
//! frame's activations of its key — a viseme pair selecting the same viseme twice adds up), and
//! per transform driven by the FAT a rotation / translation / scale channel on its node **A**
//! with the animated field values (rotation `ΔR · r`, translation `t + Δt + c`, scale `s + Δs`).
//! Between keyframes glTF interpolates weights and rotations, which matches the player only at
//! the keyframes (where the test checks it).

use std::collections::BTreeMap;

use glam::{Quat, Vec3};

use super::ExportError;
use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::eval::Activation;
use crate::fat::morph::default_value;
use crate::fat::FatError;
use crate::fat::{interval_weights, TableKey, TransformField};
use crate::gltf::{
    AnimationData, ChannelData, ChannelValues, GltfDocument, Interpolation, MaterialData, MeshData,
    NodeData, NodeId, SceneBuilder,
};
use crate::player::AnimationFrame;

/// One morph target of one mesh: one interval of one `FaceDefMesh` entry, shown at its span.
#[derive(Clone, Debug, PartialEq)]
pub struct MorphPiece {
    /// Target name (see the module docs).
    pub name: String,
    /// The table key it belongs to.
    pub key: TableKey,
    /// Interval borders of its entry.
    pub borders: Vec<f64>,
    /// Which interval of the entry.
    pub interval: usize,
    /// The value span the target shows (`V` for single-interval entries, `s_j` otherwise).
    pub span: f64,
    /// Moved vertices.
    pub vertices: Vec<u32>,
    /// Offsets of the moved vertices (`rate × span`).
    pub offsets: Vec<Vec3>,
}

/// The morph targets of every mesh of a face, and the weights that reproduce the FAT.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceMorphs {
    /// Per face mesh, its targets in output order.
    pub meshes: Vec<Vec<MorphPiece>>,
}

impl FaceMorphs {
    /// The targets of `face`'s FAT (see the module docs). Errors when a `FaceDefMesh` refers
    /// to an unknown mesh or vertex, or has the wrong number of displacements.
    pub fn new(face: &FaceModel) -> Result<FaceMorphs> {
        FaceMorphs::scaled(face, 1.0)
    }

    /// [`FaceMorphs::new`] with offsets in other units: `scale` output units per face unit.
    /// Each offset is the one that gives the FAT's rate back exactly when divided by
    /// `span × scale` ([`crate::face::gltf_fat::exact_offset`]), so a read-back FAT is the
    /// written one bit for bit.
    pub fn scaled(face: &FaceModel, scale: f32) -> Result<FaceMorphs> {
        use crate::face::gltf_fat::exact_offset;
        let mut meshes: Vec<Vec<MorphPiece>> = vec![Vec::new(); face.meshes.len()];
        // Targets in the canonical order: equal FATs in any table order give one document.
        for table in &face.fat.canonical_tables() {
            if table.key.slot().is_none() {
                return Err(FatError::NeutralTable { key: table.key }.into());
            }
            for m in &table.meshes {
                let mi = face
                    .mesh_index(&m.mesh)
                    .ok_or_else(|| FatError::UnknownMesh {
                        key: table.key,
                        mesh: m.mesh.clone(),
                    })?;
                let count = face.meshes[mi].mesh.vertex_count();
                if let Some(bad) = m.coord_index.iter().find(|&&i| i as usize >= count) {
                    return Err(ExportError::CoordIndexOutOfRange {
                        key: table.key,
                        mesh: m.mesh.clone(),
                        index: *bad,
                    }
                    .into());
                }
                let n = m.interval_count();
                if n == 0 || m.displacements.len() != m.coord_index.len() * n {
                    return Err(ExportError::DisplacementCount {
                        key: table.key,
                        mesh: m.mesh.clone(),
                        found: m.displacements.len(),
                        vertices: m.coord_index.len(),
                        intervals: n,
                    }
                    .into());
                }
                for j in 0..n {
                    let span = piece_span(table.key, &m.interval_borders, j);
                    let offsets = (0..m.coord_index.len())
                        .map(|k| {
                            let r = m.displacements[k * n + j];
                            let per = span * f64::from(scale);
                            Vec3::new(
                                exact_offset(r.x, per),
                                exact_offset(r.y, per),
                                exact_offset(r.z, per),
                            )
                        })
                        .collect();
                    meshes[mi].push(MorphPiece {
                        name: String::new(),
                        key: table.key,
                        borders: m.interval_borders.clone(),
                        interval: j,
                        span,
                        vertices: m.coord_index.clone(),
                        offsets,
                    });
                }
            }
        }
        for pieces in &mut meshes {
            let mut per_key: BTreeMap<TableKey, usize> = BTreeMap::new();
            for p in pieces.iter() {
                *per_key.entry(p.key).or_default() += 1;
            }
            let mut seen: BTreeMap<TableKey, usize> = BTreeMap::new();
            for p in pieces.iter_mut() {
                let j = seen.entry(p.key).or_default();
                p.name = if per_key[&p.key] == 1 {
                    p.key.name()
                } else {
                    format!("{}#{j}", p.key.name())
                };
                *j += 1;
            }
        }
        Ok(FaceMorphs { meshes })
    }

    /// Morph weights of mesh `mesh` for `activations`, written into `out` (one per target).
    pub fn weights_into(&self, mesh: usize, activations: &[Activation], out: &mut Vec<f32>) {
        out.clear();
        let mut scratch = Vec::new();
        for p in &self.meshes[mesh] {
            let mut w = 0.0f64;
            for a in activations.iter().filter(|a| a.key == p.key) {
                if a.value == 0.0 || !a.value.is_finite() {
                    continue;
                }
                interval_weights(&p.borders, a.value, &mut scratch);
                w += scratch.get(p.interval).copied().unwrap_or(0.0) / p.span;
            }
            out.push(w as f32);
        }
    }

    /// `neutral + Σ weight × target` for mesh `mesh` (what a glTF viewer shows).
    pub fn apply(&self, mesh: usize, neutral: &[Vec3], weights: &[f32]) -> Vec<Vec3> {
        let mut out = neutral.to_vec();
        for (p, &w) in self.meshes[mesh].iter().zip(weights) {
            for (&v, o) in p.vertices.iter().zip(&p.offsets) {
                if let Some(q) = out.get_mut(v as usize) {
                    *q += *o * w;
                }
            }
        }
        out
    }
}

/// The value span target `j` of an entry with `borders` shows (see the module docs).
fn piece_span(key: TableKey, borders: &[f64], j: usize) -> f64 {
    let n = borders.len() - 1;
    let span = if n == 1 {
        let v = if borders[0].abs() > borders[1].abs() {
            borders[0]
        } else {
            borders[1]
        };
        if v == 0.0 {
            default_value(key)
        } else {
            v
        }
    } else {
        let (lo, hi) = (borders[j], borders[j + 1]);
        if hi <= 0.0 {
            lo - hi
        } else {
            hi - lo
        }
    };
    if span.is_finite() && span != 0.0 {
        span
    } else {
        1.0
    }
}

/// A glTF export with the problems that were worked around.
#[derive(Clone, Debug)]
pub struct GltfExport {
    /// The document.
    pub document: GltfDocument,
    /// Things that could not be represented exactly (e.g. a `scaleOrientation`).
    pub warnings: Vec<crate::error::Diagnostic>,
}

/// `face` as a glTF document; with `anim`, also its animation (see the module docs).
pub fn face_to_gltf(face: &FaceModel, anim: Option<&[AnimationFrame]>) -> Result<GltfDocument> {
    export_face(face, anim).map(|e| e.document)
}

/// [`face_to_gltf`] with the warnings; the face's unit is detected
/// ([`crate::face::units::detect_unit`]) and the output is in metres.
pub fn export_face(face: &FaceModel, anim: Option<&[AnimationFrame]>) -> Result<GltfExport> {
    export_face_with_units(face, anim, None)
}

/// [`export_face`] with the face's length unit given (`None`: detected). glTF lengths are
/// metres, so one factor (metres per model unit) scales every position, morph offset,
/// translation and pivot; rotations and scales are unit-free.
pub fn export_face_with_units(
    face: &FaceModel,
    anim: Option<&[AnimationFrame]>,
    units: Option<crate::face::units::LengthUnit>,
) -> Result<GltfExport> {
    face.check_structure()?;
    let morphs = FaceMorphs::new(face)?;
    let mut warnings: Vec<String> = Vec::new();
    let (k, unit_warning) = crate::face::units::metres_factor(face, units);
    warnings.extend(unit_warning);
    let mut scene = SceneBuilder::new(face.name.clone());

    // Transform nodes: A (t + c, r, s) and, when c ≠ 0, pivot B (−c) holding the children.
    let mut node_a: Vec<NodeId> = Vec::with_capacity(face.transforms.len());
    let mut holder: Vec<NodeId> = Vec::with_capacity(face.transforms.len());
    for t in &face.transforms {
        if !t.scale_orientation.abs_diff_eq(Quat::IDENTITY, 1e-6)
            && !t.scale_orientation.abs_diff_eq(-Quat::IDENTITY, 1e-6)
        {
            warnings.push(format!(
                "transform `{}`: scaleOrientation has no glTF equivalent and was dropped",
                t.name
            ));
        }
        let mut a = NodeData::new(t.name.clone())
            .with_translation((t.translation + t.center) * k)
            .with_rotation(t.rotation.normalize())
            .with_scale(t.scale);
        if let Some(p) = t.parent {
            a = a.with_parent(holder[p]);
        }
        let a = scene.add_node(a)?;
        node_a.push(a);
        if t.center == Vec3::ZERO {
            holder.push(a);
        } else {
            let b = NodeData::new(format!("{}_pivot", t.name))
                .with_parent(a)
                .with_translation(-t.center * k);
            holder.push(scene.add_node(b)?);
        }
    }

    // Meshes, scaled to metres (the scene borrows the buffers until it is built).
    let written = if k == 1.0 {
        morphs.clone()
    } else {
        FaceMorphs::scaled(face, k)?
    };
    let scaled: Vec<(Vec<Vec3>, Vec<Vec<Vec3>>)> = face
        .meshes
        .iter()
        .enumerate()
        .map(|(mi, m)| {
            let positions = m
                .mesh
                .positions
                .iter()
                .map(|&p| crate::face::gltf_fat::to_file(p, k))
                .collect();
            let offsets = written.meshes[mi]
                .iter()
                .map(|p| p.offsets.clone())
                .collect();
            (positions, offsets)
        })
        .collect();
    let mut mesh_nodes: Vec<Option<NodeId>> = Vec::with_capacity(face.meshes.len());
    for (mi, m) in face.meshes.iter().enumerate() {
        let triangles = m.mesh.triangles();
        if m.mesh.positions.is_empty() || triangles.is_empty() {
            warnings.push(format!(
                "mesh `{}` has no triangles and was left out",
                m.name
            ));
            mesh_nodes.push(None);
            continue;
        }
        // Without a model colour, the part's usual one (a rig's head is skin, not grey).
        let [r, g, b] = m.color.unwrap_or_else(|| {
            crate::face::parts::FacePart::of_mesh_name(&m.name).default_colour()
        });
        let (positions, offsets) = &scaled[mi];
        let mut data =
            MeshData::new(m.name.clone(), &positions[..], triangles).with_material(MaterialData {
                base_color: [r.clamp(0.0, 1.0), g.clamp(0.0, 1.0), b.clamp(0.0, 1.0), 1.0],
                double_sided: true,
                ..MaterialData::default()
            });
        let per_vertex_uvs = m.mesh.uvs.len() == m.mesh.positions.len()
            && m.mesh.uv_polygons.as_ref() == Some(&m.mesh.polygons);
        if per_vertex_uvs {
            data = data.with_uvs(&m.mesh.uvs[..]);
        }
        for (p, offsets) in morphs.meshes[mi].iter().zip(offsets) {
            data = data.with_sparse_target(p.name.clone(), &p.vertices[..], &offsets[..]);
        }
        let id = scene.add_mesh(data)?;
        let mut node = NodeData::new(m.name.clone()).with_mesh(id);
        if let Some(t) = m.transform {
            node = node.with_parent(holder[t]);
        }
        mesh_nodes.push(Some(scene.add_node(node)?));
    }

    if let Some(frames) = anim.filter(|f| !f.is_empty()) {
        let channels = animation_channels(face, &morphs, &node_a, &mesh_nodes, frames, k)?;
        if !channels.is_empty() {
            scene.add_animation(AnimationData {
                name: "play".into(),
                channels,
            })?;
        }
    }
    let mut document = scene.build()?;
    let transform_nodes: Vec<Option<usize>> = node_a.iter().map(|n| Some(n.index())).collect();
    add_fat_records(
        &mut document,
        face,
        &morphs,
        &mesh_nodes,
        &transform_nodes,
        k,
    );
    Ok(GltfExport {
        document,
        warnings: warnings
            .into_iter()
            .map(crate::error::Diagnostic::warning)
            .collect(),
    })
}

/// fbakit's FAT and feature-point records (`specs/gltf-fat.md`), so the document reads back
/// as the face: per written mesh its targets' tables, on the scene the feature points.
fn add_fat_records(
    document: &mut GltfDocument,
    face: &FaceModel,
    morphs: &FaceMorphs,
    mesh_nodes: &[Option<NodeId>],
    transform_nodes: &[Option<usize>],
    k: f32,
) {
    use crate::face::gltf_fat::{scene_record, targets_record, TargetRecord, KEY};
    let written = mesh_nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.is_some())
        .map(|(mi, _)| mi);
    for (mesh, mi) in document.root.meshes.iter_mut().zip(written) {
        let records: Vec<TargetRecord> = morphs.meshes[mi]
            .iter()
            .map(|p| TargetRecord {
                target: p.name.clone(),
                key: p.key,
                borders: p.borders.clone(),
                interval: p.interval,
                span: p.span,
            })
            .collect();
        if records.is_empty() {
            continue;
        }
        let extras = mesh.extras.get_or_insert_with(|| serde_json::json!({}));
        if let Some(o) = extras.as_object_mut() {
            o.insert(KEY.into(), targets_record(&records));
        }
    }
    let record = scene_record(face, k, transform_nodes);
    if let (Some(scene), false) = (document.root.scenes.first_mut(), record.is_empty()) {
        scene.extras = Some(serde_json::Value::Object(record));
    }
}

fn animation_channels(
    face: &FaceModel,
    morphs: &FaceMorphs,
    node_a: &[NodeId],
    mesh_nodes: &[Option<NodeId>],
    frames: &[AnimationFrame],
    k: f32,
) -> Result<Vec<ChannelData>> {
    let t0 = frames[0].time;
    let mut times: Vec<f32> = frames.iter().map(|f| (f.time - t0) as f32).collect();
    // A closing key one frame after the last, holding it: frame i is shown from i/fps to
    // (i+1)/fps, so the clip lasts frames/fps (what `play` reports) and a looping viewer
    // shows the last frame as long as the others.
    let closing = frames.len() >= 2;
    if closing {
        let step = (frames[frames.len() - 1].time - t0) / (frames.len() - 1) as f64;
        times.push((frames[frames.len() - 1].time - t0 + step) as f32);
    }
    let frames_with_close: Vec<&AnimationFrame> = frames
        .iter()
        .chain(closing.then(|| &frames[frames.len() - 1]))
        .collect();
    let frames = &frames_with_close[..];
    let mut channels = Vec::new();
    let mut w = Vec::new();
    for (mi, node) in mesh_nodes.iter().enumerate() {
        let Some(node) = *node else { continue };
        let n = morphs.meshes[mi].len();
        if n == 0 {
            continue;
        }
        let mut values = Vec::with_capacity(n * frames.len());
        for f in frames {
            morphs.weights_into(mi, &f.activations, &mut w);
            values.extend_from_slice(&w);
        }
        channels.push(ChannelData {
            node,
            times: times.clone(),
            values: ChannelValues::Weights(values),
            interpolation: Interpolation::Linear,
        });
    }
    // Which fields of which transforms the FAT drives.
    let mut driven = vec![[false; 3]; face.transforms.len()];
    for t in face.fat.tables.iter().flat_map(|t| &t.transforms) {
        if let Some(i) = face.transform_index(&t.transform) {
            let k = match t.field {
                TransformField::Rotation => 0,
                TransformField::Translation => 1,
                TransformField::Scale => 2,
            };
            driven[i][k] = true;
        }
    }
    for (i, t) in face.transforms.iter().enumerate() {
        let delta = |f: &&AnimationFrame| {
            f.transform_deltas
                .get(i)
                .copied()
                .unwrap_or(crate::fat::eval::TransformDelta::IDENTITY)
        };
        let [rot, tr, sc] = driven[i];
        if rot {
            let mut prev = Quat::IDENTITY;
            let values = frames
                .iter()
                .map(|f| {
                    let mut q = (delta(f).rotation * t.rotation).normalize();
                    // Keep neighbouring keys in one hemisphere so LINEAR (slerp) takes the
                    // short way.
                    if q.dot(prev) < 0.0 {
                        q = -q;
                    }
                    prev = q;
                    q
                })
                .collect();
            channels.push(ChannelData {
                node: node_a[i],
                times: times.clone(),
                values: ChannelValues::Rotation(values),
                interpolation: Interpolation::Linear,
            });
        }
        if tr {
            let values = frames
                .iter()
                .map(|f| (t.translation + delta(f).translation + t.center) * k)
                .collect();
            channels.push(ChannelData {
                node: node_a[i],
                times: times.clone(),
                values: ChannelValues::Translation(values),
                interpolation: Interpolation::Linear,
            });
        }
        if sc {
            let values = frames.iter().map(|f| t.scale + delta(f).scale).collect();
            channels.push(ChannelData {
                node: node_a[i],
                times: times.clone(),
                values: ChannelValues::Scale(values),
                interpolation: Interpolation::Linear,
            });
        }
    }
    Ok(channels)
}
