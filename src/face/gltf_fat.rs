//! fbakit's FAT and feature points inside a glTF document's extras (`specs/gltf-fat.md`), so
//! a glTF fbakit wrote reads back as the same face, FAT included, without `--fp`.
//!
//! - `mesh.extras.fbakit.targets`: one record per morph target fbakit added — its
//!   `target` name (as in `targetNames`), table `key` (`open_jaw`, `viseme_7`, `joy`),
//!   interval `borders`, `interval` index and `span` (the FAP value the target shows).
//! - `scene.extras.fbakit`: `version`, `featurePoints` (label, position in the file's world
//!   frame, and the face mesh and vertices it is bound to) and `fapu` (the five distances);
//!   for faces with transforms or polygons other than triangles also `faceUnit`,
//!   `transforms`, `meshes` (order, transform, polygon run lengths) and `transformTables`;
//!   `nodeParts` for mesh parts a user's node turns (eyeballs on the VRM eye joints, in one
//!   primitive or over several: VRoid's eye white, iris and highlight), whose rows are
//!   rebuilt from the recorded rotations.
//!
//! Reading back: a target's offsets divided by its span are the rates of its interval; the
//! targets of one `(key, borders)` on one primitive make one `FaceDefMesh`.

use std::collections::BTreeMap;

use glam::{DVec3, Quat, Vec3};
use serde_json::{json, Map, Value};

use super::{FaceModel, FaceTransform};
use crate::error::Result;
use crate::fat::bake::on_borders;
use crate::fat::{FaceDefMesh, FaceDefTable, FaceDefTransform, Fat, TableKey, TransformField};
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::gltf::source::RestPose;
use crate::rig::{Rig, RigError, RigMesh};

/// The extras key fbakit's records live under, on meshes and scenes.
pub const KEY: &str = "fbakit";

/// Schema version written in the scene record.
pub const VERSION: u64 = 1;

/// One added target's FAT meaning.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetRecord {
    /// Target name (an entry of `targetNames`).
    pub target: String,
    /// The table it belongs to.
    pub key: TableKey,
    /// Interval borders of its entry.
    pub borders: Vec<f64>,
    /// Which interval.
    pub interval: usize,
    /// The FAP value the target shows.
    pub span: f64,
}

/// The mesh record: `{"targets": [...]}`.
pub fn targets_record(records: &[TargetRecord]) -> Value {
    let list: Vec<Value> = records
        .iter()
        .map(|r| {
            json!({
                "target": r.target,
                "key": r.key.name(),
                "borders": r.borders,
                "interval": r.interval,
                "span": r.span,
            })
        })
        .collect();
    json!({ "targets": list })
}

/// The scene record of `face`: feature points and FAPU (when they can be measured), the
/// face's transforms and which mesh hangs under which, and the transform motion of its tables
/// whose transform is shown by a node of the document (`nodes[t]`, per face transform; the
/// others are baked into targets by the writer). Lengths are multiplied by `scale` (the
/// output's units per face unit), which is recorded as `faceUnit` when it is not 1.
pub fn scene_record(face: &FaceModel, scale: f32, nodes: &[Option<usize>]) -> Map<String, Value> {
    let mut out = Map::new();
    if face.feature_points.is_empty() && face.fat.tables.is_empty() {
        return out;
    }
    let points: Vec<Value> = face
        .feature_points
        .iter()
        .map(|p| {
            let mut v = json!({ "id": p.id.to_string() });
            if let Some(pos) = p.position {
                let pos = to_file(pos, scale);
                v["position"] = json!([pos.x, pos.y, pos.z]);
            }
            if let Some(b) = &p.binding {
                if let Some(m) = &b.mesh {
                    v["mesh"] = json!(m);
                }
                v["vertices"] = json!(b.vertices);
            }
            v
        })
        .collect();
    let mut record = json!({ "version": VERSION, "featurePoints": points });
    if let Ok(f) = face.fapu() {
        let d = f.distances;
        let s = f64::from(scale);
        record["fapu"] = json!({
            "irisd0": d.irisd0 * s, "es0": d.es0 * s, "ens0": d.ens0 * s,
            "mns0": d.mns0 * s, "mw0": d.mw0 * s,
        });
    }
    if scale != 1.0 {
        record["faceUnit"] = json!(scale);
    }
    let runs: Vec<Option<Vec<[usize; 2]>>> =
        face.meshes.iter().map(|m| polygon_runs(&m.mesh)).collect();
    if !face.transforms.is_empty() || runs.iter().any(Option::is_some) {
        record["meshes"] = face
            .meshes
            .iter()
            .zip(&runs)
            .map(|(m, runs)| {
                let mut r = json!({ "mesh": m.name, "transform": m.transform });
                if let Some(runs) = runs {
                    r["polygons"] = json!(runs);
                }
                r
            })
            .collect();
    }
    if !face.transforms.is_empty() {
        record["transforms"] = transforms_record(face, scale, nodes);

        let tables: Vec<Value> = face
            .fat
            .canonical_tables()
            .iter()
            .filter_map(|t| {
                let list: Vec<Value> = t
                    .transforms
                    .iter()
                    .filter(|x| {
                        face.transform_index(&x.transform)
                            .and_then(|i| nodes.get(i).copied().flatten())
                            .is_some()
                    })
                    .map(|x| transform_motion_record(x, scale))
                    .collect();
                (!list.is_empty()).then(|| json!({ "key": t.key.name(), "transforms": list }))
            })
            .collect();
        if !tables.is_empty() {
            record["transformTables"] = Value::Array(tables);
        }
    }
    out.insert(KEY.into(), record);
    out
}

/// A length in face units in the file's (`scale` per face unit), exactly invertible.
pub fn to_file(v: Vec3, scale: f32) -> Vec3 {
    let s = f64::from(scale);
    Vec3::new(
        exact_offset(v.x, s),
        exact_offset(v.y, s),
        exact_offset(v.z, s),
    )
}

fn vec_json(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn quat_json(q: Quat) -> Value {
    json!([q.x, q.y, q.z, q.w])
}

/// `transforms`: every face transform with its fields (lengths × `scale`), parent index and node.
fn transforms_record(face: &FaceModel, scale: f32, nodes: &[Option<usize>]) -> Value {
    face.transforms
        .iter()
        .enumerate()
        .map(|(i, t)| {
            json!({
                "name": t.name,
                "parent": t.parent,
                "translation": vec_json(to_file(t.translation, scale)),
                "rotation": quat_json(t.rotation),
                "scale": vec_json(t.scale),
                "scaleOrientation": quat_json(t.scale_orientation),
                "center": vec_json(to_file(t.center, scale)),
                "node": nodes.get(i).copied().flatten(),
            })
        })
        .collect()
}

/// One `FaceDefTransform` (translation per unit × `scale`).
fn transform_motion_record(x: &FaceDefTransform, scale: f32) -> Value {
    let field = match x.field {
        TransformField::Rotation => "rotation",
        TransformField::Scale => "scale",
        TransformField::Translation => "translation",
    };
    json!({
        "transform": x.transform,
        "field": field,
        "axis": vec_json(x.rotation_axis),
        "angle": x.rotation_angle,
        "scale": vec_json(x.scale),
        "translation": vec_json(to_file(x.translation, scale)),
    })
}

/// The length of one face unit in the units of the document `json` (its scene record's
/// `faceUnit`, 1 when absent or not a positive number).
pub fn face_unit(json: &Value) -> f32 {
    scene_value(json)
        .0
        .get("faceUnit")
        .and_then(Value::as_f64)
        .filter(|u| u.is_finite() && *u > 0.0)
        .map_or(1.0, |u| u as f32)
}

/// The node each recorded face transform is shown by, by transform name.
pub fn transform_nodes(json: &Value) -> BTreeMap<String, usize> {
    let mut out = BTreeMap::new();
    for t in scene_value(json).0["transforms"]
        .as_array()
        .into_iter()
        .flatten()
    {
        if let (Some(name), Some(node)) = (t["name"].as_str(), t["node"].as_u64()) {
            if json["nodes"].get(node as usize).is_some() {
                out.insert(name.to_string(), node as usize);
            }
        }
    }
    out
}

/// The recorded face transforms whose node is the user's own (`userNode`), by name.
pub fn user_node_transforms(json: &Value) -> std::collections::BTreeSet<String> {
    scene_value(json).0["transforms"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|t| t["userNode"] == Value::Bool(true))
        .filter_map(|t| t["name"].as_str().map(str::to_string))
        .collect()
}

/// Marks the face transforms `user` flags (per transform) in a [`scene_record`] as shown by
/// the user's own nodes (`userNode`): `play` carries their motion onto the node's rest pose.
pub fn mark_user_nodes(record: &mut Map<String, Value>, user: &[bool]) {
    let Some(list) = record
        .get_mut(KEY)
        .and_then(|r| r.get_mut("transforms"))
        .and_then(Value::as_array_mut)
    else {
        return;
    };
    for (t, &flag) in list.iter_mut().zip(user) {
        if flag {
            t["userNode"] = Value::Bool(true);
        }
    }
}

/// The shown scene's record and its JSON path (`asset.extras` for a file without scenes).
fn scene_value(json: &Value) -> (&Value, String) {
    let s = json["scene"].as_u64().unwrap_or(0) as usize;
    match json["scenes"].get(s) {
        Some(scene) => (&scene["extras"][KEY], format!("scenes[{s}].extras.{KEY}")),
        None => (&json["asset"]["extras"][KEY], format!("asset.extras.{KEY}")),
    }
}

/// An error at JSON path `at` of the rig's file.
fn bad(rig: &Rig, at: &str, what: impl Into<String>) -> crate::error::Error {
    let file = rig
        .source
        .as_ref()
        .map(|s| s.path.clone())
        .unwrap_or_default();
    RigError::GltfContent {
        file,
        at: at.into(),
        what: what.into(),
    }
    .into()
}

/// What a document fbakit wrote records about its face, lengths in the file's units.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceRecords {
    /// Feature points (positions in the file's world frame).
    pub points: FeaturePointSet,
    /// The FAT: vertex tables from the targets (displacements in the file's world frame) and
    /// the recorded transform motion.
    pub fat: Fat,
    /// Length of one face unit in the file's units (`faceUnit`, 1 when absent).
    pub face_unit: f32,
    /// The face's transforms (lengths in the file's units), parents first.
    pub transforms: Vec<FaceTransform>,
    /// The face's meshes in its order, with the transform each hangs under.
    pub meshes: Vec<MeshRecord>,
}

/// One recorded face mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshRecord {
    /// The face mesh's name.
    pub mesh: String,
    /// The transform it hangs under (index into the recorded transforms).
    pub transform: Option<usize>,
    /// Its polygons as run lengths `[corners, count]` when they are not all triangles.
    pub polygons: Option<Vec<[usize; 2]>>,
}

impl FaceRecords {
    /// Puts the recorded face into `face` (its meshes read from the document in the file's
    /// world frame): feature points, FAT, transforms, the face's mesh order, and every length
    /// back in face units and each mesh's vertices and table rows back in its transform's
    /// frame, so the face reads back as it was written. The document kept on the face maps
    /// its rest poses the same way, so patching it again writes in the file's units.
    pub fn apply(self, face: &mut FaceModel) {
        let inv_unit = 1.0 / self.face_unit;
        let unit = f64::from(self.face_unit);
        let back = |v: Vec3| Vec3::new(rate_of(v.x, unit), rate_of(v.y, unit), rate_of(v.z, unit));
        let mut fat = self.fat;
        // Vertex rows are read in face units already (`rate_of`).
        for t in fat.tables.iter_mut() {
            for x in t.transforms.iter_mut() {
                x.translation = back(x.translation);
            }
        }
        let mut points = FeaturePointSet::new();
        for p in self.points.iter() {
            let mut p = p.clone();
            if let Some(pos) = p.position.as_mut() {
                *pos = back(*pos);
            }
            points.insert(p);
        }
        for m in face.meshes.iter_mut() {
            for p in m.mesh.positions.iter_mut() {
                *p = back(*p);
            }
        }
        face.transforms = self.transforms;
        for t in face.transforms.iter_mut() {
            t.translation = back(t.translation);
            t.center = back(t.center);
        }
        // The face's mesh order; meshes the record does not name keep theirs, after.
        let mut order: Vec<usize> = Vec::with_capacity(face.meshes.len());
        for r in &self.meshes {
            if let Some(i) = face.mesh_index(&r.mesh) {
                if !order.contains(&i) {
                    order.push(i);
                    let m = &mut face.meshes[i];
                    m.transform = r.transform.filter(|&t| t < face.transforms.len());
                    // Triangles a writer made of polygons; left as they are when they do not
                    // regroup (the document was edited).
                    let regrouped = r
                        .polygons
                        .as_ref()
                        .and_then(|runs| regroup(&m.mesh.polygons, runs));
                    if let Some(polygons) = regrouped {
                        if m.mesh.uv_polygons.as_ref() == Some(&m.mesh.polygons) {
                            m.mesh.uv_polygons = Some(polygons.clone());
                        }
                        if m.mesh.normal_polygons.as_ref() == Some(&m.mesh.polygons) {
                            m.mesh.normal_polygons = Some(polygons.clone());
                        }
                        m.mesh.polygons = polygons;
                    }
                }
            }
        }
        for i in 0..face.meshes.len() {
            if !order.contains(&i) {
                order.push(i);
            }
        }
        let mut old: Vec<Option<super::FaceMesh>> = std::mem::take(&mut face.meshes)
            .into_iter()
            .map(Some)
            .collect();
        face.meshes = order.iter().filter_map(|&i| old[i].take()).collect();
        // Back into each transform's frame.
        let frames = face.frames();
        let mut to_local: BTreeMap<String, glam::Affine3A> = BTreeMap::new();
        for (mi, m) in face.meshes.iter_mut().enumerate() {
            if m.transform.is_none() {
                continue;
            }
            let inv = frames.meshes[mi].inverse();
            for p in m.mesh.positions.iter_mut() {
                *p = inv.transform_point3(*p);
            }
            for n in m.mesh.normals.iter_mut() {
                *n = inv.transform_vector3(*n).normalize_or_zero();
            }
            to_local.insert(m.name.clone(), inv);
        }
        for t in fat.tables.iter_mut() {
            for m in t.meshes.iter_mut() {
                if let Some(inv) = to_local.get(&m.mesh) {
                    for d in m.displacements.iter_mut() {
                        *d = inv.transform_vector3(*d);
                    }
                }
            }
        }
        face.feature_points = points;
        face.fat = fat;
        // Rest poses now place vertices in the face frame.
        if self.face_unit != 1.0 {
            if let Some(source) = face.gltf_source.as_mut() {
                let source = std::sync::Arc::make_mut(source);
                let s = glam::Mat4::from_scale(Vec3::splat(inv_unit));
                for part in source.parts.iter_mut() {
                    part.rest = match &part.rest {
                        RestPose::Matrix(m) => RestPose::Matrix(s * *m),
                        RestPose::PerVertex(list) => {
                            RestPose::PerVertex(list.iter().map(|m| s * *m).collect())
                        }
                    };
                }
            }
        }
    }
}

/// The feature points, FAT and face structure recorded in the document `rig` was read from,
/// if it has fbakit's records (see the module docs). Malformed records are errors naming
/// their path.
pub fn read_records(rig: &Rig) -> Result<Option<FaceRecords>> {
    let Some(source) = &rig.source else {
        return Ok(None);
    };
    let json = &source.json;
    let (scene, scene_at) = scene_value(json);
    if scene.is_null() {
        return Ok(None);
    }
    let mut points = FeaturePointSet::new();
    for (i, p) in scene["featurePoints"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        let at = format!("{scene_at}.featurePoints[{i}]");
        let id = p["id"]
            .as_str()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| {
                bad(
                    rig,
                    &at,
                    "`id` must be a feature point label such as \"2.1\"",
                )
            })?;
        let position = match p.get("position") {
            None => None,
            Some(v) => Some(vec3(v).ok_or_else(|| {
                bad(
                    rig,
                    &format!("{at}.position"),
                    "must be three finite numbers",
                )
            })?),
        };
        let binding = match p.get("vertices") {
            None => None,
            Some(v) => {
                let vertices = v
                    .as_array()
                    .and_then(|a| {
                        a.iter()
                            .map(|x| x.as_u64().and_then(|n| u32::try_from(n).ok()))
                            .collect::<Option<Vec<u32>>>()
                    })
                    .ok_or_else(|| bad(rig, &format!("{at}.vertices"), "must be vertex indices"))?;
                Some(VertexBinding {
                    mesh: p["mesh"].as_str().map(str::to_string),
                    vertices,
                })
            }
        };
        points.insert(FeaturePoint {
            id,
            position,
            binding,
        });
    }
    let face_unit = match scene.get("faceUnit") {
        None => 1.0,
        Some(u) => u
            .as_f64()
            .filter(|u| u.is_finite() && *u > 0.0)
            .ok_or_else(|| {
                bad(
                    rig,
                    &format!("{scene_at}.faceUnit"),
                    "must be a positive number",
                )
            })? as f32,
    };
    // Tables: per (key, borders bits) and face mesh, the targets of each interval.
    type Group = (TableKey, Vec<u64>);
    // Per glTF mesh: (interval, span, target name).
    type Pieces = BTreeMap<usize, Vec<(usize, f64, String)>>;
    let mut tables: BTreeMap<Group, Pieces> = BTreeMap::new();
    let mut borders_of: BTreeMap<Group, Vec<f64>> = BTreeMap::new();
    for (m, mesh) in json["meshes"].as_array().into_iter().flatten().enumerate() {
        let Some(list) = mesh["extras"][KEY]["targets"].as_array() else {
            continue;
        };
        for (i, r) in list.iter().enumerate() {
            let at = format!("meshes[{m}].extras.{KEY}.targets[{i}]");
            let target = r["target"]
                .as_str()
                .ok_or_else(|| bad(rig, &at, "`target` must name a morph target"))?;
            let key = r["key"]
                .as_str()
                .and_then(TableKey::from_name)
                .ok_or_else(|| {
                    bad(
                        rig,
                        &format!("{at}.key"),
                        "not a FAP, viseme or expression name",
                    )
                })?;
            let borders: Vec<f64> = r["borders"]
                .as_array()
                .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
                .filter(|b| b.len() >= 2 && b.iter().all(|x| x.is_finite()))
                .ok_or_else(|| bad(rig, &format!("{at}.borders"), "must be two or more numbers"))?;
            let interval = r["interval"]
                .as_u64()
                .map(|j| j as usize)
                .filter(|&j| j + 1 < borders.len())
                .ok_or_else(|| {
                    bad(
                        rig,
                        &format!("{at}.interval"),
                        "must index an interval of `borders`",
                    )
                })?;
            let span = r["span"]
                .as_f64()
                .filter(|s| s.is_finite() && *s != 0.0)
                .ok_or_else(|| bad(rig, &format!("{at}.span"), "must be a non-zero number"))?;
            if rig.shape(target).is_none() {
                return Err(bad(
                    rig,
                    &format!("{at}.target"),
                    format!("no morph target named `{target}`"),
                ));
            }
            let group = (key, borders.iter().map(|b| b.to_bits()).collect());
            borders_of.insert(group.clone(), borders);
            tables
                .entry(group)
                .or_default()
                .entry(m)
                .or_default()
                .push((interval, span, target.to_string()));
        }
    }
    let mut fat = Fat::default();
    let mut by_key: BTreeMap<TableKey, FaceDefTable> = BTreeMap::new();
    for (group, per_mesh) in &tables {
        let borders = &borders_of[group];
        let n = borders.len() - 1;
        for (&m, pieces) in per_mesh {
            // Every face mesh read from this glTF mesh.
            for part in source.parts.iter().filter(|p| p.mesh == m) {
                let Some(mi) = rig.meshes.iter().position(|r| r.name == part.face_mesh) else {
                    continue;
                };
                let mut rates: BTreeMap<u32, Vec<Vec3>> = BTreeMap::new();
                for (j, span, target) in pieces {
                    let Some(shape) = rig.shape(target) else {
                        continue;
                    };
                    let Some(d) = shape.delta(mi) else { continue };
                    for (&v, &o) in d.vertices.iter().zip(&d.offsets) {
                        let slot = rates.entry(v).or_insert_with(|| vec![Vec3::ZERO; n]);
                        let per_rate = *span * f64::from(face_unit);
                        slot[*j] += Vec3::new(
                            rate_of(o.x, per_rate),
                            rate_of(o.y, per_rate),
                            rate_of(o.z, per_rate),
                        );
                    }
                }
                if rates.is_empty() {
                    continue;
                }
                let table = by_key.entry(group.0).or_insert_with(|| FaceDefTable {
                    key: group.0,
                    meshes: Vec::new(),
                    transforms: Vec::new(),
                });
                table.meshes.push(FaceDefMesh {
                    mesh: part.face_mesh.clone(),
                    interval_borders: borders.clone(),
                    coord_index: rates.keys().copied().collect(),
                    displacements: rates.values().flatten().copied().collect(),
                });
            }
        }
    }
    read_node_parts(rig, scene, &scene_at, face_unit, &mut by_key)?;
    let (transforms, meshes) = read_structure(rig, scene, &scene_at)?;
    for (i, t) in scene["transformTables"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        let at = format!("{scene_at}.transformTables[{i}]");
        let key = t["key"]
            .as_str()
            .and_then(TableKey::from_name)
            .ok_or_else(|| {
                bad(
                    rig,
                    &format!("{at}.key"),
                    "not a FAP, viseme or expression name",
                )
            })?;
        let table = by_key.entry(key).or_insert_with(|| FaceDefTable::new(key));
        for (j, x) in t["transforms"].as_array().into_iter().flatten().enumerate() {
            table.transforms.push(read_transform_motion(
                rig,
                x,
                &format!("{at}.transforms[{j}]"),
                &transforms,
            )?);
        }
    }
    fat.tables = by_key.into_values().collect();
    Ok(Some(FaceRecords {
        points,
        fat,
        face_unit,
        transforms,
        meshes,
    }))
}

/// The per-vertex rows of the recorded `nodeParts` (mesh parts a user's node turns: eyeballs
/// on the VRM eye joints, over one mesh or several), added to `by_key`: each vertex's displacement at
/// each border is the recorded rotation about the recorded centre applied to its rest
/// position (file world frame), and the rates between borders are in face units like the
/// targets' rows.
fn read_node_parts(
    rig: &Rig,
    scene: &Value,
    scene_at: &str,
    face_unit: f32,
    by_key: &mut BTreeMap<TableKey, FaceDefTable>,
) -> Result<()> {
    for (i, p) in scene["nodeParts"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        let at = format!("{scene_at}.nodeParts[{i}]");
        // Several meshes (`meshes[]`), or one (`mesh`, `vertices`: files before eyeballs
        // over several primitives).
        let listed: Vec<(&Value, String)> = match p["meshes"].as_array() {
            Some(list) => list
                .iter()
                .enumerate()
                .map(|(k, m)| (m, format!("{at}.meshes[{k}]")))
                .collect(),
            None => vec![(p, at.clone())],
        };
        let mut part: Vec<(&RigMesh, Vec<u32>)> = Vec::with_capacity(listed.len());
        for (m, m_at) in listed {
            part.push(part_mesh(rig, m, &m_at)?);
        }
        let center = vec3_field(rig, p, &at, "center")?.as_dvec3();
        let rests: Vec<Vec<DVec3>> = part
            .iter()
            .map(|(mesh, vertices)| {
                vertices
                    .iter()
                    .map(|&v| mesh.mesh.positions[v as usize].as_dvec3())
                    .collect()
            })
            .collect();
        for (j, t) in p["tables"].as_array().into_iter().flatten().enumerate() {
            let at = format!("{at}.tables[{j}]");
            let key = t["key"]
                .as_str()
                .and_then(TableKey::from_name)
                .ok_or_else(|| {
                    bad(
                        rig,
                        &format!("{at}.key"),
                        "not a FAP, viseme or expression name",
                    )
                })?;
            let borders: Vec<f64> = t["borders"]
                .as_array()
                .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
                .filter(|b| b.len() >= 2 && b.windows(2).all(|w| w[0] < w[1]))
                .ok_or_else(|| {
                    bad(
                        rig,
                        &format!("{at}.borders"),
                        "must be two or more increasing numbers",
                    )
                })?;
            let rotations: Vec<Quat> = t["rotations"]
                .as_array()
                .and_then(|a| a.iter().map(quat).collect::<Option<Vec<Quat>>>())
                .filter(|r| r.len() == borders.len())
                .ok_or_else(|| {
                    bad(
                        rig,
                        &format!("{at}.rotations"),
                        "must be one quaternion per border",
                    )
                })?;
            let table = by_key.entry(key).or_insert_with(|| FaceDefTable::new(key));
            for ((mesh, vertices), rest) in part.iter().zip(&rests) {
                let entry = FaceDefMesh {
                    mesh: mesh.name.clone(),
                    coord_index: vertices.clone(),
                    displacements: turned_rows(rest, center, &rotations, &borders, face_unit),
                    interval_borders: borders.clone(),
                };
                match table.meshes.iter_mut().find(|m| m.mesh == entry.mesh) {
                    Some(old) => *old = joined(old, &entry),
                    None => table.meshes.push(entry),
                }
            }
        }
    }
    Ok(())
}

/// The face mesh and vertices one `nodeParts` entry names (`mesh`, `vertices` of `m`).
fn part_mesh<'a>(rig: &'a Rig, m: &Value, at: &str) -> Result<(&'a RigMesh, Vec<u32>)> {
    let mesh = m["mesh"]
        .as_str()
        .and_then(|n| rig.meshes.iter().find(|f| f.name == n))
        .ok_or_else(|| bad(rig, &format!("{at}.mesh"), "must name a face mesh"))?;
    let count = mesh.mesh.positions.len();
    let vertices: Vec<u32> = m["vertices"]
        .as_array()
        .and_then(|a| {
            a.iter()
                .map(|x| {
                    x.as_u64()
                        .filter(|&v| (v as usize) < count)
                        .map(|v| v as u32)
                })
                .collect::<Option<Vec<u32>>>()
        })
        .ok_or_else(|| {
            bad(
                rig,
                &format!("{at}.vertices"),
                "must be vertex indices of the mesh",
            )
        })?;
    Ok((mesh, vertices))
}

/// The rows of vertices at `rest` (file world frame) turned about `center` by `rotations`,
/// one per border: each vertex's displacement at each border, then the rates between
/// borders in face units.
fn turned_rows(
    rest: &[DVec3],
    center: DVec3,
    rotations: &[Quat],
    borders: &[f64],
    face_unit: f32,
) -> Vec<Vec3> {
    let at_border: Vec<Vec<DVec3>> = rotations
        .iter()
        .map(|q| {
            let r = q.as_dquat();
            rest.iter()
                .map(|&x| r * (x - center) + center - x)
                .collect()
        })
        .collect();
    let unit = f64::from(face_unit);
    let n = borders.len() - 1;
    (0..rest.len())
        .flat_map(|v| {
            let at_border = &at_border;
            (0..n).map(move |k| {
                ((at_border[k + 1][v] - at_border[k][v]) / ((borders[k + 1] - borders[k]) * unit))
                    .as_vec3()
            })
        })
        .collect()
}

/// Two entries of one mesh as one: both on the union of their borders, rates of a vertex in
/// both added.
fn joined(a: &FaceDefMesh, b: &FaceDefMesh) -> FaceDefMesh {
    let mut borders: Vec<f64> = a
        .interval_borders
        .iter()
        .chain(&b.interval_borders)
        .copied()
        .collect();
    borders.sort_by(f64::total_cmp);
    borders.dedup();
    let (a, b) = (on_borders(a, &borders), on_borders(b, &borders));
    let n = borders.len().saturating_sub(1);
    let mut rows: BTreeMap<u32, Vec<Vec3>> = BTreeMap::new();
    for e in [&a, &b] {
        for (i, &v) in e.coord_index.iter().enumerate() {
            let row = rows.entry(v).or_insert_with(|| vec![Vec3::ZERO; n]);
            for (k, r) in row.iter_mut().enumerate() {
                *r += e
                    .displacements
                    .get(i * n + k)
                    .copied()
                    .unwrap_or(Vec3::ZERO);
            }
        }
    }
    FaceDefMesh {
        mesh: a.mesh.clone(),
        interval_borders: borders,
        coord_index: rows.keys().copied().collect(),
        displacements: rows.into_values().flatten().collect(),
    }
}

type Structure = (Vec<FaceTransform>, Vec<MeshRecord>);

/// The recorded transforms and mesh order (`transforms`, `meshes`).
fn read_structure(rig: &Rig, scene: &Value, scene_at: &str) -> Result<Structure> {
    let mut transforms: Vec<FaceTransform> = Vec::new();
    for (i, t) in scene["transforms"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        let at = format!("{scene_at}.transforms[{i}]");
        let name = t["name"]
            .as_str()
            .filter(|n| !n.is_empty() && !transforms.iter().any(|x| x.name == *n))
            .ok_or_else(|| bad(rig, &format!("{at}.name"), "must be a new transform name"))?;
        let parent = index_field(rig, t, &at, "parent", i, "an earlier transform")?;
        transforms.push(FaceTransform {
            name: name.to_string(),
            parent,
            translation: vec3_field(rig, t, &at, "translation")?,
            rotation: quat_field(rig, t, &at, "rotation")?,
            scale: vec3_field(rig, t, &at, "scale")?,
            scale_orientation: quat_field(rig, t, &at, "scaleOrientation")?,
            center: vec3_field(rig, t, &at, "center")?,
        });
    }
    let mut meshes = Vec::new();
    for (i, m) in scene["meshes"].as_array().into_iter().flatten().enumerate() {
        let at = format!("{scene_at}.meshes[{i}]");
        let name = m["mesh"]
            .as_str()
            .ok_or_else(|| bad(rig, &format!("{at}.mesh"), "must name a face mesh"))?;
        let transform = index_field(rig, m, &at, "transform", transforms.len(), "`transforms`")?;
        let polygons = match m.get("polygons") {
            None => None,
            Some(v) => Some(
                v.as_array()
                    .and_then(|a| {
                        a.iter()
                            .map(|r| {
                                let r = r.as_array().filter(|r| r.len() == 2)?;
                                Some([r[0].as_u64()? as usize, r[1].as_u64()? as usize])
                            })
                            .collect::<Option<Vec<_>>>()
                    })
                    .ok_or_else(|| {
                        bad(
                            rig,
                            &format!("{at}.polygons"),
                            "must be [corners, count] pairs",
                        )
                    })?,
            ),
        };
        meshes.push(MeshRecord {
            mesh: name.to_string(),
            transform,
            polygons,
        });
    }
    Ok((transforms, meshes))
}

/// One recorded `FaceDefTransform`.
fn read_transform_motion(
    rig: &Rig,
    x: &Value,
    at: &str,
    transforms: &[FaceTransform],
) -> Result<FaceDefTransform> {
    let transform = x["transform"]
        .as_str()
        .filter(|n| transforms.iter().any(|t| t.name == *n))
        .ok_or_else(|| {
            bad(
                rig,
                &format!("{at}.transform"),
                "must name a recorded transform",
            )
        })?;
    let field = match x["field"].as_str() {
        Some("rotation") => TransformField::Rotation,
        Some("scale") => TransformField::Scale,
        Some("translation") => TransformField::Translation,
        _ => {
            return Err(bad(
                rig,
                &format!("{at}.field"),
                "must be \"rotation\", \"scale\" or \"translation\"",
            ))
        }
    };
    let angle = x["angle"]
        .as_f64()
        .filter(|a| a.is_finite())
        .ok_or_else(|| bad(rig, &format!("{at}.angle"), "must be a number"))?;
    Ok(FaceDefTransform {
        transform: transform.to_string(),
        field,
        rotation_axis: vec3_field(rig, x, at, "axis")?,
        rotation_angle: angle as f32,
        scale: vec3_field(rig, x, at, "scale")?,
        translation: vec3_field(rig, x, at, "translation")?,
    })
}

/// `obj[field]` as three finite numbers, or an error at `{at}.{field}`.
fn vec3_field(rig: &Rig, obj: &Value, at: &str, field: &str) -> Result<Vec3> {
    vec3(&obj[field]).ok_or_else(|| {
        bad(
            rig,
            &format!("{at}.{field}"),
            "must be three finite numbers",
        )
    })
}

/// `obj[field]` as a quaternion, or an error at `{at}.{field}`.
fn quat_field(rig: &Rig, obj: &Value, at: &str, field: &str) -> Result<Quat> {
    quat(&obj[field]).ok_or_else(|| {
        bad(
            rig,
            &format!("{at}.{field}"),
            "must be a unit quaternion [x, y, z, w]",
        )
    })
}

/// `obj[field]`: null, or an index below `below` into `what`.
fn index_field(
    rig: &Rig,
    obj: &Value,
    at: &str,
    field: &str,
    below: usize,
    what: &str,
) -> Result<Option<usize>> {
    match &obj[field] {
        Value::Null => Ok(None),
        v => v
            .as_u64()
            .map(|i| i as usize)
            .filter(|&i| i < below)
            .map(Some)
            .ok_or_else(|| {
                bad(
                    rig,
                    &format!("{at}.{field}"),
                    format!("must index {what} or be null"),
                )
            }),
    }
}

fn quat(v: &Value) -> Option<Quat> {
    let a = v.as_array()?;
    if a.len() != 4 {
        return None;
    }
    let mut q = [0.0f32; 4];
    for (o, x) in q.iter_mut().zip(a) {
        *o = x.as_f64()? as f32;
    }
    let q = Quat::from_array(q);
    (q.is_finite() && (q.length() - 1.0).abs() < 1e-3).then_some(q)
}

fn vec3(v: &Value) -> Option<Vec3> {
    let a = v.as_array()?;
    if a.len() != 3 {
        return None;
    }
    let p = Vec3::new(
        a[0].as_f64()? as f32,
        a[1].as_f64()? as f32,
        a[2].as_f64()? as f32,
    );
    p.is_finite().then_some(p)
}

/// The offset a writer stores for `rate` so that a reader dividing by `per_rate` in double
/// precision ([`rate_of`]) gets `rate` back bit for bit: the nearest float to
/// `rate × per_rate`, or one of its neighbours a few steps away when that one reads back
/// differently (single-precision rounding of the product can land one step off).
pub fn exact_offset(rate: f32, per_rate: f64) -> f32 {
    let first = (f64::from(rate) * per_rate) as f32;
    if !first.is_finite() || rate_of(first, per_rate) == rate {
        return first;
    }
    let (mut up, mut down) = (first, first);
    for _ in 0..4 {
        up = float_step(up, true);
        down = float_step(down, false);
        for o in [up, down] {
            if rate_of(o, per_rate) == rate {
                return o;
            }
        }
    }
    first
}

/// The neighbouring float of finite `x` towards +∞ (`up`) or −∞ (`f32::next_up` is newer
/// than the crate's minimum Rust).
fn float_step(x: f32, up: bool) -> f32 {
    if x == 0.0 {
        let tiny = f32::from_bits(1);
        return if up { tiny } else { -tiny };
    }
    let bits = x.to_bits();
    f32::from_bits(if (x > 0.0) == up { bits + 1 } else { bits - 1 })
}

/// The rate a stored `offset` shows when `per_rate` value units make it (see [`exact_offset`]).
pub fn rate_of(offset: f32, per_rate: f64) -> f32 {
    (f64::from(offset) / per_rate) as f32
}

/// Run lengths `[corners, count]` of a mesh's polygons when it has other polygons than
/// triangles and [`regroup`] gives them back from the triangles a glTF holds; `None` else.
pub fn polygon_runs(mesh: &crate::mesh::Mesh) -> Option<Vec<[usize; 2]>> {
    if mesh.polygons.iter().all(|p| p.len() == 3) {
        return None;
    }
    let mut runs: Vec<[usize; 2]> = Vec::new();
    for p in mesh.polygons.iter() {
        match runs.last_mut() {
            Some(r) if r[0] == p.len() => r[1] += 1,
            _ => runs.push([p.len(), 1]),
        }
    }
    let triangles = crate::mesh::Polygons::from_triangles(&mesh.triangles());
    (regroup(&triangles, &runs).as_ref() == Some(&mesh.polygons)).then_some(runs)
}

/// Polygons of `runs` (`[corners, count]`) from their triangles in order: each polygon's
/// `corners − 2` triangles, walked round their outer edges from the first triangle's first
/// corner (where a fan starts). `None` when the counts do not add up or a polygon's
/// triangles do not make one loop.
pub fn regroup(
    triangles: &crate::mesh::Polygons,
    runs: &[[usize; 2]],
) -> Option<crate::mesh::Polygons> {
    let mut out = crate::mesh::Polygons::new();
    let mut next = 0usize;
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    for &[n, count] in runs {
        if n < 3 {
            return None;
        }
        for _ in 0..count {
            let tris: Vec<&[u32]> = (next..next + n - 2)
                .map(|i| triangles.get(i).filter(|t| t.len() == 3))
                .collect::<Option<_>>()?;
            next += n - 2;
            edges.clear();
            for t in &tris {
                for k in 0..3 {
                    edges.push((t[k], t[(k + 1) % 3]));
                }
            }
            let outer: Vec<(u32, u32)> = edges
                .iter()
                .copied()
                .filter(|&(a, b)| !edges.contains(&(b, a)))
                .collect();
            if outer.len() != n {
                return None;
            }
            corners.clear();
            let mut at = tris[0][0];
            for _ in 0..n {
                corners.push(at);
                at = outer.iter().find(|e| e.0 == at)?.1;
            }
            if at != corners[0] {
                return None;
            }
            out.push(&corners);
        }
    }
    (next == triangles.len()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_offsets_read_back_as_their_rates_where_one_exists() {
        let mut exact = 0;
        let mut total = 0;
        for i in 1..2000u32 {
            let rate = (i as f32 * 0.618_034).sin() * 1e-3;
            for per in [95.0, 512.0, 0.001 * 340.0, 1.0] {
                total += 1;
                let o = exact_offset(rate, per);
                let back = rate_of(o, per);
                // Never more than one float step off.
                assert!(
                    back == rate
                        || float_step(back, true) == rate
                        || float_step(back, false) == rate
                );
                exact += usize::from(back == rate);
            }
        }
        // Powers of two are always exact; the others mostly.
        assert!(exact * 10 > total * 8, "{exact} of {total}");
        assert_eq!(float_step(1.0, true), 1.0 + f32::EPSILON);
        assert_eq!(float_step(-1.0, false), -1.0 - f32::EPSILON);
        assert!(float_step(0.0, true) > 0.0 && float_step(0.0, false) < 0.0);
    }

    #[test]
    fn polygons_regroup_from_their_fan_triangles() {
        let quad = crate::mesh::Mesh::from_triangles(
            "q",
            vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::Y,
                Vec3::new(2.0, 0.0, 0.0),
            ],
            &[],
        );
        let mut mesh = quad.clone();
        mesh.polygons = crate::mesh::Polygons::from_lists([vec![0u32, 1, 2, 3], vec![1, 4, 2]]);
        let runs = polygon_runs(&mesh).expect("a quad regroups");
        assert_eq!(runs, vec![[4, 1], [3, 1]]);
        let tris = crate::mesh::Polygons::from_triangles(&mesh.triangles());
        assert_eq!(regroup(&tris, &runs), Some(mesh.polygons.clone()));
        // Counts that do not add up are refused.
        assert_eq!(regroup(&tris, &[[4, 2]]), None);
    }

    #[test]
    fn structure_errors_name_their_json_path() {
        let rig = Rig {
            name: "r".into(),
            meshes: Vec::new(),
            shapes: Vec::new(),
            warnings: Vec::new(),
            source: None,
        };
        let t = json!({"name": "a", "parent": null, "translation": [0, 0, 0],
            "rotation": [0, 0, 0, 1], "scale": [1, 1, 1],
            "scaleOrientation": [0, 0, 0, 1], "center": [0, 0, 0]});
        let ok = read_structure(&rig, &json!({"transforms": [t]}), "s").expect("one transform");
        assert_eq!(ok.0.len(), 1);
        let cases = [
            (
                "parent",
                json!(0),
                "s.transforms[0].parent",
                "an earlier transform",
            ),
            (
                "center",
                json!([0, "x", 0]),
                "s.transforms[0].center",
                "three finite",
            ),
            (
                "rotation",
                json!([0, 0, 1]),
                "s.transforms[0].rotation",
                "quaternion",
            ),
        ];
        for (field, value, at, what) in cases {
            let mut bad_t = t.clone();
            bad_t[field] = value;
            let e = read_structure(&rig, &json!({"transforms": [bad_t]}), "s")
                .expect_err(field)
                .to_string();
            assert!(e.contains(at) && e.contains(what), "{e}");
        }
        let mesh = json!({"transforms": [t], "meshes": [{"mesh": "m", "transform": 1}]});
        let e = read_structure(&rig, &mesh, "s")
            .expect_err("index")
            .to_string();
        assert!(
            e.contains("s.meshes[0].transform") && e.contains("`transforms`"),
            "{e}"
        );
    }
}
