//! fbakit's FAT and feature points inside a glTF document's extras (`specs/gltf-fat.md`), so
//! a glTF fbakit wrote reads back as the same face, FAT included, without `--fp`.
//!
//! - `mesh.extras.fbakit.targets`: one record per morph target fbakit added — its
//!   `target` name (as in `targetNames`), table `key` (`open_jaw`, `viseme_7`, `joy`),
//!   interval `borders`, `interval` index and `span` (the FAP value the target shows).
//! - `scene.extras.fbakit`: `version`, `featurePoints` (label, position in the file's world
//!   frame, and the face mesh and vertices it is bound to) and `fapu` (the five distances).
//!
//! Reading back: a target's offsets divided by its span are the rates of its interval; the
//! targets of one `(key, borders)` on one primitive make one `FaceDefMesh`.

use std::collections::BTreeMap;

use glam::Vec3;
use serde_json::{json, Map, Value};

use super::FaceModel;
use crate::error::Result;
use crate::fat::{FaceDefMesh, FaceDefTable, Fat, TableKey};
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::rig::{Rig, RigError};

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

/// The scene record of `face`: feature points and FAPU (when they can be measured), lengths
/// multiplied by `scale` (the output's units per face unit).
pub fn scene_record(face: &FaceModel, scale: f32) -> Map<String, Value> {
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
                let pos = pos * scale;
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
    out.insert(KEY.into(), record);
    out
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

/// The feature points and FAT recorded in the document `rig` was read from, if it has
/// fbakit's records (see the module docs). Malformed records are errors naming their path.
pub fn read_records(rig: &Rig) -> Result<Option<(FeaturePointSet, Fat)>> {
    let Some(source) = &rig.source else {
        return Ok(None);
    };
    let json = &source.json;
    let s = json["scene"].as_u64().unwrap_or(0) as usize;
    let (scene, scene_at) = match json["scenes"].get(s) {
        Some(scene) => (&scene["extras"][KEY], format!("scenes[{s}].extras.{KEY}")),
        None => (&json["asset"]["extras"][KEY], format!("asset.extras.{KEY}")),
    };
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
                        slot[*j] += (o.as_dvec3() / *span).as_vec3();
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
    fat.tables = by_key.into_values().collect();
    Ok(Some((points, fat)))
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
