//! Reading and writing face models as VRML97 face files.
//!
//! A file may hold a whole `Face` node, a bare `FDP`, or a plain scene (meshes only).
//!
//! **Reading.** The face's geometry is `FDP.faceSceneGraph` when given, else
//! `Face.renderedFace`, else every root node other than the face nodes. Each `Transform` becomes
//! a [`FaceTransform`], each `Shape` with an `IndexedFaceSet` a [`FaceMesh`]. Nodes without a
//! `DEF` name get a generated one (`transform_N`, `mesh_N`) in the kept scene, so names are
//! stable across read → write → read. A node reached a second time through `USE` is not
//! instanced twice (a warning says so). `FDP.featurePointsCoord` holds the feature points in
//! the standard's label order, in the face frame; each is bound to the nearest mesh vertex and
//! the distance is reported, unless fbakit's own record says which points are present and
//! which vertices they are bound to (below). `FDP.faceDefTables` become the [`Fat`].
//!
//! **Writing.** A face read from a file is written by patching that scene: mesh coordinates
//! and polygons, transform fields, and the `FDP`'s feature points and tables are replaced;
//! every other node (lights, viewpoints, unknown nodes, PROTOs, ROUTEs) is written back as it
//! was. A face without a scene is written as `Face { fdp FDP { featurePointsCoord,
//! faceSceneGraph [transforms and shapes], faceDefTables } }`, so every `USE` follows its `DEF`.
//!
//! **fbakit's feature-point record.** `featurePointsCoord` must list all 84 points, but real
//! faces rarely have them all, and the standard does not say which vertex a point is. fbakit
//! therefore also writes `DEF fbakit_feature_points WorldInfo { title "fbakit feature points"
//! info [ "2.1 skin 123" ... ] }`: one entry per present point, `id mesh vertices` (vertices
//! `;`-separated, `-` for a point with a position only). Missing points are written into
//! `featurePointsCoord` at the mean of the present ones. Other readers ignore the `WorldInfo`.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::{Quat, Vec2, Vec3};
use serde::Serialize;

use super::{FaceMesh, FaceModel, FaceTransform};
use crate::error::{Diagnostic, Error, Location, Result, Severity};
use crate::fat::{FaceDefMesh, FaceDefTable, FaceDefTransform, Fat, TableKey, TransformField};
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::mesh::{Mesh, Polygons, SurfaceFlags, VertexIndex};
use crate::spec::FeaturePointId;
use crate::vrml::{FieldValue, Node, NodeId, NodeRef, Scene, Statement};

/// Title of fbakit's feature-point record (`WorldInfo`).
pub const FP_RECORD_TITLE: &str = "fbakit feature points";
const FP_RECORD_DEF: &str = "fbakit_feature_points";

/// How a `featurePointsCoord` entry was matched to a mesh vertex.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointMatch {
    /// The point.
    pub id: FeaturePointId,
    /// Mesh it was bound to.
    pub mesh: String,
    /// Vertex it was bound to.
    pub vertex: u32,
    /// Distance between the given position and the vertex.
    pub distance: f32,
}

/// Nodes a FAT entry came from, for located validation messages.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TableNodes {
    /// The `FaceDefTables` node.
    pub table: Option<NodeId>,
    /// Its `FaceDefMesh` nodes, in the order of the table's `meshes`.
    pub meshes: Vec<NodeId>,
    /// Its `FaceDefTransform` nodes, in the order of the table's `transforms`.
    pub transforms: Vec<NodeId>,
}

/// What reading a face file found besides the model.
#[derive(Clone, Debug, Default)]
pub struct FaceReadReport {
    /// Problems and notes, located where possible.
    pub diagnostics: Vec<Diagnostic>,
    /// Feature points matched to the nearest vertex.
    pub fp_matches: Vec<FeaturePointMatch>,
    /// For each table of the model's FAT, the nodes it came from.
    pub table_nodes: Vec<TableNodes>,
    /// Scene path of each mesh's `IndexedFaceSet`.
    pub mesh_paths: Vec<String>,
    /// Whether the file had a `Face` node, a bare `FDP`, or neither.
    pub kind: FaceFileKind,
}

/// What kind of face file was read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaceFileKind {
    /// A `Face` node.
    Face,
    /// An `FDP` node without `Face`.
    BareFdp,
    /// Meshes only.
    #[default]
    PlainScene,
}

/// Reads a VRML face file.
pub fn read_face_file(path: &Path) -> Result<(FaceModel, FaceReadReport)> {
    let scene = crate::vrml::read_vrml_file(path)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "face".into());
    face_from_scene(scene, &name)
}

/// Builds a face model from a parsed scene.
pub fn face_from_scene(mut scene: Scene, name: &str) -> Result<(FaceModel, FaceReadReport)> {
    let mut report = FaceReadReport::default();
    let face_node = scene.nodes_of_type("Face").next();
    let fdp = face_node
        .and_then(|f| scene.get_sfnode(f, "fdp"))
        .or_else(|| scene.nodes_of_type("FDP").next());
    report.kind = match (face_node, fdp) {
        (Some(_), _) => FaceFileKind::Face,
        (None, Some(_)) => FaceFileKind::BareFdp,
        _ => FaceFileKind::PlainScene,
    };

    let mut geometry: Vec<NodeId> = fdp
        .map(|f| scene.get_mfnode(f, "faceSceneGraph"))
        .unwrap_or_default();
    if geometry.is_empty() {
        geometry = face_node
            .map(|f| scene.get_mfnode(f, "renderedFace"))
            .unwrap_or_default();
    }
    if geometry.is_empty() {
        geometry = scene
            .roots()
            .filter(|&r| !is_face_node(&scene.node(r).type_name))
            .collect();
    }

    let mut walk = Walk::default();
    for root in geometry {
        walk.visit(&mut scene, root, None, "", &mut report);
    }
    let mut model = FaceModel::new(name);
    model.transforms = walk.transforms;
    model.meshes = walk.meshes;
    report.mesh_paths = walk.mesh_paths;

    if let Some(fdp) = fdp {
        model.fat = read_fat(
            &scene,
            fdp,
            &walk.mesh_nodes,
            &walk.transform_nodes,
            &mut report,
        );
        model.feature_points = read_feature_points(&scene, fdp, &model, &mut report)?;
    }
    model.scene = Some(scene);
    Ok((model, report))
}

fn is_face_node(t: &str) -> bool {
    matches!(
        t,
        "Face" | "FDP" | "FAP" | "FIT" | "FaceDefTables" | "FaceDefMesh" | "FaceDefTransform"
    )
}

#[derive(Default)]
struct Walk {
    transforms: Vec<FaceTransform>,
    meshes: Vec<FaceMesh>,
    mesh_paths: Vec<String>,
    mesh_nodes: HashMap<NodeId, usize>,
    transform_nodes: HashMap<NodeId, usize>,
    visited: HashSet<NodeId>,
    used_names: HashSet<String>,
}

impl Walk {
    fn unique_name(&mut self, scene: &mut Scene, id: NodeId, prefix: &str) -> String {
        if let Some(n) = scene.node(id).def_name.clone() {
            self.used_names.insert(n.clone());
            return n;
        }
        // Generated names must not collide with any DEF in the file.
        let mut k = self.used_names.len();
        loop {
            let candidate = format!("{prefix}_{k}");
            if scene.find_def(&candidate).is_none() && !self.used_names.contains(&candidate) {
                self.used_names.insert(candidate.clone());
                scene.nodes[id.0].def_name = Some(candidate.clone());
                return candidate;
            }
            k += 1;
        }
    }

    fn visit(
        &mut self,
        scene: &mut Scene,
        id: NodeId,
        parent: Option<usize>,
        path: &str,
        report: &mut FaceReadReport,
    ) {
        let type_name = scene.node(id).type_name.clone();
        if type_name == "Transform" && !self.visited.contains(&id) {
            self.unique_name(scene, id, "transform");
        }
        let label = match &scene.node(id).def_name {
            Some(d) => format!("{type_name}(DEF {d})"),
            None => type_name.clone(),
        };
        let here = if path.is_empty() {
            label
        } else {
            format!("{path} > {label}")
        };
        if !self.visited.insert(id) {
            if matches!(type_name.as_str(), "Transform" | "Shape" | "Group") {
                report.diagnostics.push(Diagnostic {
                    severity: Severity::Warning,
                    location: Some(scene.node(id).location.clone()),
                    message: format!(
                        "{here} is used a second time; fbakit keeps only its first instance"
                    ),
                });
            }
            return;
        }
        match type_name.as_str() {
            "Transform" => {
                let name = self.unique_name(scene, id, "transform");
                let t = read_transform(scene, id, name, parent);
                self.transforms.push(t);
                let index = self.transforms.len() - 1;
                self.transform_nodes.insert(id, index);
                for child in scene.get_mfnode(id, "children") {
                    self.visit(scene, child, Some(index), &here, report);
                }
            }
            "Shape" => {
                let Some(geom) = scene.get_sfnode(id, "geometry") else {
                    return;
                };
                if scene.node(geom).type_name != "IndexedFaceSet" {
                    return;
                }
                if !self.visited.insert(geom) {
                    report.diagnostics.push(Diagnostic {
                        severity: Severity::Warning,
                        location: Some(scene.node(geom).location.clone()),
                        message: format!(
                            "{here}: its IndexedFaceSet is used a second time; only its first instance is kept"
                        ),
                    });
                    return;
                }
                let name = self.unique_name(scene, geom, "mesh");
                let color = scene
                    .get_sfnode(id, "appearance")
                    .and_then(|a| scene.get_sfnode(a, "material"))
                    .and_then(|m| scene.get_sfvec3f(m, "diffuseColor"));
                let mesh = read_indexed_face_set(scene, geom, &name, report);
                self.mesh_nodes.insert(geom, self.meshes.len());
                self.mesh_paths
                    .push(format!("{here} > IndexedFaceSet(DEF {name})"));
                self.meshes.push(FaceMesh {
                    name,
                    transform: parent,
                    mesh,
                    color,
                });
            }
            t if is_face_node(t) => {}
            _ => {
                // Any other grouping node (Group, Switch, LOD, Anchor, Billboard, Collision,
                // unknown nodes): look into its node-valued fields.
                let children: Vec<NodeId> = scene
                    .node(id)
                    .fields
                    .iter()
                    .flat_map(|(_, v)| v.node_refs())
                    .map(|r| r.id)
                    .collect();
                for child in children {
                    self.visit(scene, child, parent, &here, report);
                }
            }
        }
    }
}

fn rotation_quat(r: [f32; 4]) -> Quat {
    let axis = Vec3::new(r[0], r[1], r[2]);
    match axis.try_normalize() {
        Some(a) if r[3].is_finite() => Quat::from_axis_angle(a, r[3]),
        _ => Quat::IDENTITY,
    }
}

fn quat_rotation(q: Quat) -> [f32; 4] {
    let (axis, angle) = q.to_axis_angle();
    if angle == 0.0 || !axis.is_finite() {
        [0.0, 0.0, 1.0, 0.0]
    } else {
        [axis.x, axis.y, axis.z, angle]
    }
}

fn read_transform(scene: &Scene, id: NodeId, name: String, parent: Option<usize>) -> FaceTransform {
    let v3 = |f: &str, d: Vec3| scene.get_sfvec3f(id, f).map_or(d, Vec3::from_array);
    FaceTransform {
        name,
        parent,
        translation: v3("translation", Vec3::ZERO),
        rotation: scene
            .get_sfrotation(id, "rotation")
            .map_or(Quat::IDENTITY, rotation_quat),
        scale: v3("scale", Vec3::ONE),
        scale_orientation: scene
            .get_sfrotation(id, "scaleOrientation")
            .map_or(Quat::IDENTITY, rotation_quat),
        center: v3("center", Vec3::ZERO),
    }
}

/// Splits a `-1`-separated index list into polygons; other negative values are reported.
fn polygons_from_index(
    index: &[i32],
    what: &str,
    location: &Location,
    report: &mut FaceReadReport,
) -> Polygons {
    let mut polys = Polygons::new();
    let mut current: Vec<u32> = Vec::new();
    let mut bad = 0usize;
    for &i in index {
        if i == -1 {
            if !current.is_empty() {
                polys.push(&current);
                current.clear();
            }
        } else if i < 0 {
            bad += 1;
        } else {
            current.push(i as u32);
        }
    }
    if !current.is_empty() {
        polys.push(&current);
    }
    if bad > 0 {
        report.diagnostics.push(Diagnostic {
            severity: Severity::Error,
            location: Some(location.clone()),
            message: format!(
                "{what} has {bad} negative index value(s) other than the -1 separator"
            ),
        });
    }
    polys
}

fn read_indexed_face_set(
    scene: &Scene,
    id: NodeId,
    name: &str,
    report: &mut FaceReadReport,
) -> Mesh {
    let loc = scene.node(id).location.clone();
    let positions: Vec<Vec3> = scene
        .get_sfnode(id, "coord")
        .and_then(|c| scene.get_mfvec3f(c, "point"))
        .map(|p| p.iter().map(|&a| Vec3::from_array(a)).collect())
        .unwrap_or_default();
    let polygons = polygons_from_index(
        scene.get_mfint32(id, "coordIndex").unwrap_or(&[]),
        "coordIndex",
        &loc,
        report,
    );
    let mut mesh = Mesh {
        name: name.to_string(),
        positions,
        polygons,
        ..Mesh::default()
    };
    if let Some(tc) = scene.get_sfnode(id, "texCoord") {
        mesh.uvs = scene
            .get_mfvec2f(tc, "point")
            .map(|p| p.iter().map(|&a| Vec2::from_array(a)).collect())
            .unwrap_or_default();
        mesh.uv_polygons = Some(match scene.get_mfint32(id, "texCoordIndex") {
            Some(ix) if !ix.is_empty() => polygons_from_index(ix, "texCoordIndex", &loc, report),
            _ => mesh.polygons.clone(),
        });
    }
    if let Some(n) = scene.get_sfnode(id, "normal") {
        mesh.normals = scene
            .get_mfvec3f(n, "vector")
            .map(|p| p.iter().map(|&a| Vec3::from_array(a)).collect())
            .unwrap_or_default();
        mesh.normal_polygons = Some(match scene.get_mfint32(id, "normalIndex") {
            Some(ix) if !ix.is_empty() => polygons_from_index(ix, "normalIndex", &loc, report),
            _ => mesh.polygons.clone(),
        });
    }
    let d = SurfaceFlags::default();
    mesh.flags = SurfaceFlags {
        ccw: scene.get_sfbool(id, "ccw").unwrap_or(d.ccw),
        solid: scene.get_sfbool(id, "solid").unwrap_or(d.solid),
        convex: scene.get_sfbool(id, "convex").unwrap_or(d.convex),
        crease_angle: scene
            .get_sffloat(id, "creaseAngle")
            .unwrap_or(d.crease_angle),
    };
    mesh
}

fn read_fat(
    scene: &Scene,
    fdp: NodeId,
    meshes: &HashMap<NodeId, usize>,
    transforms: &HashMap<NodeId, usize>,
    report: &mut FaceReadReport,
) -> Fat {
    let mesh_name = |id: NodeId| -> Option<String> {
        meshes.get(&id)?;
        scene.node(id).def_name.clone()
    };
    let mut fat = Fat::default();
    for table_id in scene.get_mfnode(fdp, "faceDefTables") {
        let loc = scene.node(table_id).location.clone();
        let mut err = |loc: &Location, message: String| {
            report.diagnostics.push(Diagnostic {
                severity: Severity::Error,
                location: Some(loc.clone()),
                message,
            })
        };
        if scene.node(table_id).type_name != "FaceDefTables" {
            err(
                &loc,
                format!(
                    "faceDefTables holds a {} node",
                    scene.node(table_id).type_name
                ),
            );
            continue;
        }
        let fap_id = scene.get_sfint32(table_id, "fapID").unwrap_or(1);
        let select = scene.get_sfint32(table_id, "highLevelSelect").unwrap_or(1);
        let key = match TableKey::from_node_fields(fap_id as i64, select as i64) {
            Ok(k) => k,
            Err(m) => {
                err(&loc, format!("FaceDefTables: {m}"));
                continue;
            }
        };
        let mut table = FaceDefTable::new(key);
        let mut nodes = TableNodes {
            table: Some(table_id),
            ..TableNodes::default()
        };
        for m in scene.get_mfnode(table_id, "faceDefMesh") {
            let mloc = scene.node(m).location.clone();
            let target = scene.get_sfnode(m, "faceSceneGraphNode");
            let Some(name) = target.and_then(mesh_name) else {
                err(
                    &mloc,
                    format!("{key}: FaceDefMesh.faceSceneGraphNode must be an IndexedFaceSet of the face"),
                );
                continue;
            };
            let coord_index = scene.get_mfint32(m, "coordIndex").unwrap_or(&[]);
            if let Some(bad) = coord_index.iter().find(|&&i| i < 0) {
                err(
                    &mloc,
                    format!("{key}: FaceDefMesh.coordIndex has a negative value {bad}"),
                );
                continue;
            }
            table.meshes.push(FaceDefMesh {
                mesh: name,
                interval_borders: scene
                    .get_mfint32(m, "intervalBorders")
                    .unwrap_or(&[])
                    .iter()
                    .map(|&b| b as f64)
                    .collect(),
                coord_index: coord_index.iter().map(|&i| i as u32).collect(),
                displacements: scene
                    .get_mfvec3f(m, "displacements")
                    .unwrap_or(&[])
                    .iter()
                    .map(|&a| Vec3::from_array(a))
                    .collect(),
            });
            nodes.meshes.push(m);
        }
        for t in scene.get_mfnode(table_id, "faceDefTransform") {
            let tloc = scene.node(t).location.clone();
            let target = scene.get_sfnode(t, "faceSceneGraphNode");
            let Some(name) = target
                .filter(|id| transforms.contains_key(id))
                .and_then(|id| scene.node(id).def_name.clone())
            else {
                err(
                    &tloc,
                    format!("{key}: FaceDefTransform.faceSceneGraphNode must be a Transform of the face"),
                );
                continue;
            };
            let field_id = scene.get_sfint32(t, "fieldId").unwrap_or(1);
            let Some(field) = TransformField::from_field_id(field_id as i64) else {
                err(
                    &tloc,
                    format!("{key}: fieldId {field_id} is not 1 (rotation), 2 (scale) or 3 (translation)"),
                );
                continue;
            };
            let r = scene
                .get_sfrotation(t, "rotationDef")
                .unwrap_or([0.0, 0.0, 1.0, 0.0]);
            table.transforms.push(FaceDefTransform {
                transform: name,
                field,
                rotation_axis: Vec3::new(r[0], r[1], r[2]),
                rotation_angle: r[3],
                scale: scene
                    .get_sfvec3f(t, "scaleDef")
                    .map_or(Vec3::ONE, Vec3::from_array),
                translation: scene
                    .get_sfvec3f(t, "translationDef")
                    .map_or(Vec3::ZERO, Vec3::from_array),
            });
            nodes.transforms.push(t);
        }
        fat.tables.push(table);
        report.table_nodes.push(nodes);
    }
    fat
}

/// Parses one entry of fbakit's feature-point record: `id mesh vertices`.
fn parse_record_entry(entry: &str) -> Option<(FeaturePointId, Option<VertexBinding>)> {
    let mut parts = entry.split_whitespace();
    let id: FeaturePointId = parts.next()?.parse().ok()?;
    let mesh = parts.next()?;
    let vertices = parts.next()?;
    if parts.next().is_some() {
        return None;
    }
    if mesh == "-" && vertices == "-" {
        return Some((id, None));
    }
    let vertices: Option<Vec<u32>> = vertices.split(';').map(|v| v.parse().ok()).collect();
    let vertices = vertices.filter(|v| !v.is_empty())?;
    Some((
        id,
        Some(VertexBinding {
            mesh: (mesh != "-").then(|| mesh.to_string()),
            vertices,
        }),
    ))
}

fn read_feature_points(
    scene: &Scene,
    fdp: NodeId,
    model: &FaceModel,
    report: &mut FaceReadReport,
) -> Result<FeaturePointSet> {
    let mut set = FeaturePointSet::new();
    let Some(coord) = scene.get_sfnode(fdp, "featurePointsCoord") else {
        return Ok(set);
    };
    let points = scene.get_mfvec3f(coord, "point").unwrap_or(&[]);
    let loc = scene.node(coord).location.clone();
    if points.len() > crate::spec::NUM_FEATURE_POINTS {
        report.diagnostics.push(Diagnostic {
            severity: Severity::Warning,
            location: Some(loc.clone()),
            message: format!(
                "featurePointsCoord has {} points; the standard defines 84, the rest are ignored",
                points.len()
            ),
        });
    }
    let record = scene
        .nodes
        .iter()
        .find(|n| {
            n.type_name == "WorldInfo"
                && matches!(n.field("title"), Some(FieldValue::SFString(t)) if t == FP_RECORD_TITLE)
        })
        .and_then(|n| match n.field("info") {
            Some(FieldValue::MFString(v)) => Some((v.clone(), n.location.clone())),
            _ => None,
        });
    if let Some((entries, rloc)) = record {
        for entry in entries {
            let Some((id, binding)) = parse_record_entry(&entry) else {
                report.diagnostics.push(Diagnostic {
                    severity: Severity::Error,
                    location: Some(rloc.clone()),
                    message: format!(
                        "feature-point record entry `{entry}` is not `id mesh vertices`"
                    ),
                });
                continue;
            };
            let Some(&p) = points.get(id.ordinal()) else {
                report.diagnostics.push(Diagnostic {
                    severity: Severity::Error,
                    location: Some(loc.clone()),
                    message: format!("featurePointsCoord has no entry for {id}"),
                });
                continue;
            };
            set.insert(FeaturePoint {
                id,
                position: Some(Vec3::from_array(p)),
                binding,
            });
        }
        return Ok(set);
    }
    // No record: every entry is a point, bound to the nearest vertex of any mesh.
    let frames = model.frames();
    let mut owners: Vec<(usize, u32)> = Vec::new();
    let mut world: Vec<Vec3> = Vec::new();
    for (mi, m) in model.meshes.iter().enumerate() {
        for (vi, p) in m.mesh.positions.iter().enumerate() {
            owners.push((mi, vi as u32));
            world.push(frames.meshes[mi].transform_point3(*p));
        }
    }
    let index = VertexIndex::new(&world);
    for (ordinal, p) in points
        .iter()
        .enumerate()
        .take(crate::spec::NUM_FEATURE_POINTS)
    {
        let Some(id) = FeaturePointId::from_ordinal(ordinal) else {
            continue;
        };
        let pos = Vec3::from_array(*p);
        let mut point = FeaturePoint::at(id, pos);
        if let Some((nearest, distance)) = index.nearest_vertex(pos) {
            let (mi, vi) = owners[nearest as usize];
            let mesh = model.meshes[mi].name.clone();
            point.binding = Some(VertexBinding {
                mesh: Some(mesh.clone()),
                vertices: vec![vi],
            });
            report.fp_matches.push(FeaturePointMatch {
                id,
                mesh,
                vertex: vi,
                distance,
            });
        }
        set.insert(point);
    }
    Ok(set)
}

// ---------------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------------

/// Writes a face as a VRML97 file (atomically).
pub fn write_face_file(path: &Path, face: &FaceModel) -> Result<()> {
    let scene = face_to_scene(face)?;
    crate::vrml::write_vrml_file(path, &scene)
}

/// The VRML text of a face.
pub fn write_face_string(face: &FaceModel) -> Result<String> {
    Ok(crate::vrml::write_vrml_string(&face_to_scene(face)?))
}

fn set_field(node: &mut Node, name: &str, value: FieldValue) {
    match node.fields.iter_mut().find(|(n, _)| n == name) {
        Some((_, v)) => *v = value,
        None => node.fields.push((name.to_string(), value)),
    }
}

fn add(scene: &mut Scene, node: Node) -> NodeRef {
    NodeRef {
        id: scene.add_node(node),
        is_use: false,
    }
}

fn use_of(id: NodeId) -> NodeRef {
    NodeRef { id, is_use: true }
}

fn index_list(polys: &Polygons) -> Vec<i32> {
    let mut out = Vec::with_capacity(polys.corner_count() + polys.len());
    for p in polys.iter() {
        out.extend(p.iter().map(|&i| i as i32));
        out.push(-1);
    }
    out
}

fn vec3s(v: &[Vec3]) -> Vec<[f32; 3]> {
    v.iter().map(|p| p.to_array()).collect()
}

/// Fills an `IndexedFaceSet` node's geometry fields from a mesh (adding `Coordinate`,
/// `TextureCoordinate` and `Normal` nodes where the node has none).
fn write_mesh_fields(scene: &mut Scene, ifs: NodeId, mesh: &Mesh) {
    let coord = match scene.get_sfnode(ifs, "coord") {
        Some(c) => c,
        None => {
            let c = add(scene, Node::new("Coordinate"));
            set_field(
                &mut scene.nodes[ifs.0],
                "coord",
                FieldValue::SFNode(Some(c)),
            );
            c.id
        }
    };
    set_field(
        &mut scene.nodes[coord.0],
        "point",
        FieldValue::MFVec3f(vec3s(&mesh.positions)),
    );
    set_field(
        &mut scene.nodes[ifs.0],
        "coordIndex",
        FieldValue::MFInt32(index_list(&mesh.polygons)),
    );
    if !mesh.uvs.is_empty() {
        let tc = match scene.get_sfnode(ifs, "texCoord") {
            Some(c) => c,
            None => {
                let c = add(scene, Node::new("TextureCoordinate"));
                set_field(
                    &mut scene.nodes[ifs.0],
                    "texCoord",
                    FieldValue::SFNode(Some(c)),
                );
                c.id
            }
        };
        let uvs = mesh.uvs.iter().map(|p| p.to_array()).collect();
        set_field(&mut scene.nodes[tc.0], "point", FieldValue::MFVec2f(uvs));
        if let Some(up) = &mesh.uv_polygons {
            set_field(
                &mut scene.nodes[ifs.0],
                "texCoordIndex",
                FieldValue::MFInt32(index_list(up)),
            );
        }
    }
    if !mesh.normals.is_empty() {
        let n = match scene.get_sfnode(ifs, "normal") {
            Some(c) => c,
            None => {
                let c = add(scene, Node::new("Normal"));
                set_field(
                    &mut scene.nodes[ifs.0],
                    "normal",
                    FieldValue::SFNode(Some(c)),
                );
                c.id
            }
        };
        set_field(
            &mut scene.nodes[n.0],
            "vector",
            FieldValue::MFVec3f(vec3s(&mesh.normals)),
        );
        if let Some(np) = &mesh.normal_polygons {
            set_field(
                &mut scene.nodes[ifs.0],
                "normalIndex",
                FieldValue::MFInt32(index_list(np)),
            );
        }
    }
    let d = SurfaceFlags::default();
    let f = mesh.flags;
    let node = &mut scene.nodes[ifs.0];
    for (name, value, default) in [
        ("ccw", f.ccw, d.ccw),
        ("solid", f.solid, d.solid),
        ("convex", f.convex, d.convex),
    ] {
        if value != default || node.field(name).is_some() {
            set_field(node, name, FieldValue::SFBool(value));
        }
    }
    if f.crease_angle != d.crease_angle || node.field("creaseAngle").is_some() {
        set_field(node, "creaseAngle", FieldValue::SFFloat(f.crease_angle));
    }
}

fn write_transform_fields(node: &mut Node, t: &FaceTransform) {
    set_field(
        node,
        "translation",
        FieldValue::SFVec3f(t.translation.to_array()),
    );
    set_field(
        node,
        "rotation",
        FieldValue::SFRotation(quat_rotation(t.rotation)),
    );
    set_field(node, "scale", FieldValue::SFVec3f(t.scale.to_array()));
    set_field(
        node,
        "scaleOrientation",
        FieldValue::SFRotation(quat_rotation(t.scale_orientation)),
    );
    set_field(node, "center", FieldValue::SFVec3f(t.center.to_array()));
}

/// The VRML scene of a face: its own scene patched, or a new one.
pub fn face_to_scene(face: &FaceModel) -> Result<Scene> {
    face.check_structure()?;
    let mut scene = face.scene.clone().unwrap_or_default();
    let mut mesh_nodes: Vec<NodeId> = Vec::with_capacity(face.meshes.len());
    let mut transform_nodes: Vec<NodeId> = Vec::with_capacity(face.transforms.len());
    let built_fresh = face.scene.is_none();
    let mut geometry_roots: Vec<NodeRef> = Vec::new();

    if built_fresh {
        // Children list: a transform's own shapes first, then its child transforms, so the
        // depth-first reading order gives back the model's order (parents-first models).
        let mut children: Vec<Vec<NodeRef>> = vec![Vec::new(); face.transforms.len()];
        let mut child_transforms: Vec<Vec<NodeRef>> = vec![Vec::new(); face.transforms.len()];
        let mut root_transforms = Vec::new();
        for t in &face.transforms {
            let mut node = Node::new("Transform");
            node.def_name = Some(t.name.clone());
            write_transform_fields(&mut node, t);
            let r = add(&mut scene, node);
            transform_nodes.push(r.id);
            match t.parent {
                Some(p) => child_transforms[p].push(r),
                None => root_transforms.push(r),
            }
        }
        for m in &face.meshes {
            let mut shape = Node::new("Shape");
            if let Some(c) = m.color {
                let mut mat = Node::new("Material");
                mat.fields
                    .push(("diffuseColor".into(), FieldValue::SFColor(c)));
                let mat = add(&mut scene, mat);
                let mut app = Node::new("Appearance");
                app.fields
                    .push(("material".into(), FieldValue::SFNode(Some(mat))));
                let app = add(&mut scene, app);
                shape
                    .fields
                    .push(("appearance".into(), FieldValue::SFNode(Some(app))));
            }
            let shape = add(&mut scene, shape);
            let mut ifs = Node::new("IndexedFaceSet");
            ifs.def_name = Some(m.name.clone());
            let ifs = add(&mut scene, ifs);
            set_field(
                &mut scene.nodes[shape.id.0],
                "geometry",
                FieldValue::SFNode(Some(ifs)),
            );
            write_mesh_fields(&mut scene, ifs.id, &m.mesh);
            mesh_nodes.push(ifs.id);
            match m.transform {
                Some(t) => children[t].push(shape),
                None => geometry_roots.push(shape),
            }
        }
        for (i, list) in children.into_iter().enumerate() {
            let mut all = list;
            all.extend(child_transforms[i].iter().copied());
            if !all.is_empty() {
                scene.nodes[transform_nodes[i].0]
                    .fields
                    .push(("children".into(), FieldValue::MFNode(all)));
            }
        }
        geometry_roots.extend(root_transforms);
    } else {
        for t in &face.transforms {
            let id = find_def_of_type(&scene, &t.name, "Transform").ok_or_else(|| {
                Error::Invalid(format!(
                    "transform `{}` is not in the face's scene; clear `scene` to write a new one",
                    t.name
                ))
            })?;
            write_transform_fields(&mut scene.nodes[id.0], t);
            transform_nodes.push(id);
        }
        for m in &face.meshes {
            let id = find_def_of_type(&scene, &m.name, "IndexedFaceSet").ok_or_else(|| {
                Error::Invalid(format!(
                    "mesh `{}` is not in the face's scene; clear `scene` to write a new one",
                    m.name
                ))
            })?;
            write_mesh_fields(&mut scene, id, &m.mesh);
            mesh_nodes.push(id);
        }
    }

    // Feature points: all 84 in label order, missing ones at the mean of the present ones.
    let present: Vec<&FeaturePoint> = face.feature_points.iter().collect();
    let with_pos: Vec<Vec3> = present.iter().filter_map(|p| p.position).collect();
    let fill = if with_pos.is_empty() {
        Vec3::ZERO
    } else {
        with_pos.iter().sum::<Vec3>() / with_pos.len() as f32
    };
    let coords: Vec<[f32; 3]> = FeaturePointId::all()
        .map(|id| face.feature_points.position(id).unwrap_or(fill).to_array())
        .collect();
    let record: Vec<String> = present
        .iter()
        .map(|p| match &p.binding {
            Some(b) => format!(
                "{} {} {}",
                p.id,
                b.mesh.as_deref().unwrap_or("-"),
                b.vertices
                    .iter()
                    .map(|v| v.to_string())
                    .collect::<Vec<_>>()
                    .join(";")
            ),
            None => format!("{} - -", p.id),
        })
        .collect();

    let mesh_node_of: HashMap<&str, NodeId> = face
        .meshes
        .iter()
        .zip(&mesh_nodes)
        .map(|(m, &id)| (m.name.as_str(), id))
        .collect();
    let transform_node_of: HashMap<&str, NodeId> = face
        .transforms
        .iter()
        .zip(&transform_nodes)
        .map(|(t, &id)| (t.name.as_str(), id))
        .collect();
    let mut tables = Vec::with_capacity(face.fat.tables.len());
    for table in &face.fat.tables {
        let (fap_id, select) = table.key.node_fields();
        let mut node = Node::new("FaceDefTables");
        node.fields
            .push(("fapID".into(), FieldValue::SFInt32(fap_id as i32)));
        node.fields
            .push(("highLevelSelect".into(), FieldValue::SFInt32(select as i32)));
        let mut mesh_refs = Vec::new();
        for m in &table.meshes {
            let target = *mesh_node_of.get(m.mesh.as_str()).ok_or_else(|| {
                Error::Invalid(format!(
                    "{}: FAT refers to unknown mesh `{}`",
                    table.key, m.mesh
                ))
            })?;
            let borders = m
                .interval_borders
                .iter()
                .map(|&b| border_i32(b, table.key))
                .collect::<Result<Vec<i32>>>()?;
            let mut n = Node::new("FaceDefMesh");
            n.fields.push((
                "faceSceneGraphNode".into(),
                FieldValue::SFNode(Some(use_of(target))),
            ));
            n.fields
                .push(("intervalBorders".into(), FieldValue::MFInt32(borders)));
            n.fields.push((
                "coordIndex".into(),
                FieldValue::MFInt32(m.coord_index.iter().map(|&i| i as i32).collect()),
            ));
            n.fields.push((
                "displacements".into(),
                FieldValue::MFVec3f(vec3s(&m.displacements)),
            ));
            mesh_refs.push(n);
        }
        let mut transform_refs = Vec::new();
        for t in &table.transforms {
            let target = *transform_node_of.get(t.transform.as_str()).ok_or_else(|| {
                Error::Invalid(format!(
                    "{}: FAT refers to unknown transform `{}`",
                    table.key, t.transform
                ))
            })?;
            let mut n = Node::new("FaceDefTransform");
            n.fields.push((
                "faceSceneGraphNode".into(),
                FieldValue::SFNode(Some(use_of(target))),
            ));
            n.fields
                .push(("fieldId".into(), FieldValue::SFInt32(t.field.field_id())));
            let a = t.rotation_axis;
            n.fields.push((
                "rotationDef".into(),
                FieldValue::SFRotation([a.x, a.y, a.z, t.rotation_angle]),
            ));
            n.fields
                .push(("scaleDef".into(), FieldValue::SFVec3f(t.scale.to_array())));
            n.fields.push((
                "translationDef".into(),
                FieldValue::SFVec3f(t.translation.to_array()),
            ));
            transform_refs.push(n);
        }
        tables.push((node, mesh_refs, transform_refs));
    }

    // The record goes before the face nodes so readers meet it first.
    let mut info = Node::new("WorldInfo");
    info.def_name = Some(FP_RECORD_DEF.to_string());
    info.fields
        .push(("title".into(), FieldValue::SFString(FP_RECORD_TITLE.into())));
    info.fields
        .push(("info".into(), FieldValue::MFString(record)));
    let old_record: Vec<NodeId> = scene.nodes_of_type("WorldInfo").filter(|&id| {
        matches!(scene.node(id).field("title"), Some(FieldValue::SFString(t)) if t == FP_RECORD_TITLE)
    }).collect();
    scene
        .statements
        .retain(|s| !matches!(s, Statement::Node(r) if old_record.contains(&r.id)));
    let info = add(&mut scene, info);

    let face_node = scene.nodes_of_type("Face").next();
    let fdp = face_node
        .and_then(|f| scene.get_sfnode(f, "fdp"))
        .or_else(|| scene.nodes_of_type("FDP").next());
    let (fdp, new_face) = match fdp {
        Some(f) => (f, None),
        None => {
            let fdp = add(&mut scene, Node::new("FDP"));
            let mut face_n = Node::new("Face");
            face_n
                .fields
                .push(("fdp".into(), FieldValue::SFNode(Some(fdp))));
            let face_ref = add(&mut scene, face_n);
            (fdp.id, Some(face_ref))
        }
    };
    let mut coord = Node::new("Coordinate");
    coord
        .fields
        .push(("point".into(), FieldValue::MFVec3f(coords)));
    let coord = add(&mut scene, coord);
    set_field(
        &mut scene.nodes[fdp.0],
        "featurePointsCoord",
        FieldValue::SFNode(Some(coord)),
    );
    if built_fresh {
        set_field(
            &mut scene.nodes[fdp.0],
            "faceSceneGraph",
            FieldValue::MFNode(geometry_roots),
        );
    }
    let mut table_refs = Vec::with_capacity(tables.len());
    for (node, meshes, transforms) in tables {
        let t = add(&mut scene, node);
        let m: Vec<NodeRef> = meshes.into_iter().map(|n| add(&mut scene, n)).collect();
        let x: Vec<NodeRef> = transforms.into_iter().map(|n| add(&mut scene, n)).collect();
        if !m.is_empty() {
            set_field(
                &mut scene.nodes[t.id.0],
                "faceDefMesh",
                FieldValue::MFNode(m),
            );
        }
        if !x.is_empty() {
            set_field(
                &mut scene.nodes[t.id.0],
                "faceDefTransform",
                FieldValue::MFNode(x),
            );
        }
        table_refs.push(t);
    }
    // faceDefTables after faceSceneGraph, so every USE follows its DEF.
    scene.nodes[fdp.0]
        .fields
        .retain(|(n, _)| n != "faceDefTables");
    if !table_refs.is_empty() {
        scene.nodes[fdp.0]
            .fields
            .push(("faceDefTables".into(), FieldValue::MFNode(table_refs)));
    }
    // The record goes just before the face's root statement; a new face goes last.
    let anchor = match new_face {
        Some(_) => None,
        None => Some(face_node.unwrap_or(fdp)),
    };
    let pos = anchor
        .and_then(|a| {
            scene
                .statements
                .iter()
                .position(|s| matches!(s, Statement::Node(r) if r.id == a))
        })
        .unwrap_or(scene.statements.len());
    scene.statements.insert(pos, Statement::Node(info));
    if let Some(f) = new_face {
        scene.statements.push(Statement::Node(f));
    }
    Ok(scene)
}

fn border_i32(b: f64, key: TableKey) -> Result<i32> {
    if b.fract() != 0.0 || !b.is_finite() || b.abs() > i32::MAX as f64 {
        return Err(Error::Invalid(format!(
            "{key}: interval border {b} is not an integer (intervalBorders is MFInt32)"
        )));
    }
    Ok(b as i32)
}

fn find_def_of_type(scene: &Scene, name: &str, type_name: &str) -> Option<NodeId> {
    scene
        .nodes
        .iter()
        .position(|n| n.def_name.as_deref() == Some(name) && n.type_name == type_name)
        .map(NodeId)
}
