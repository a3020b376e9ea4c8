//! Reading the face's geometry from the scene graph: a depth-first walk that turns each
//! `Transform` into a [`FaceTransform`] and each `Shape` with an `IndexedFaceSet` into a
//! [`FaceMesh`], naming unnamed nodes so names survive read → write → read.

use std::collections::{HashMap, HashSet};

use glam::{Quat, Vec2, Vec3};

use super::FaceReadReport;
use crate::error::{Diagnostic, Location, Severity};
use crate::face::{FaceMesh, FaceTransform};
use crate::mesh::{Mesh, Polygons, SurfaceFlags};
use crate::vrml::{NodeId, Scene};

/// Whether a node type belongs to the MPEG-4 face nodes rather than the face's geometry.
pub(super) fn is_face_node(t: &str) -> bool {
    matches!(
        t,
        "Face" | "FDP" | "FAP" | "FIT" | "FaceDefTables" | "FaceDefMesh" | "FaceDefTransform"
    )
}

/// The walk's state: what it has read so far and which nodes and names it has seen.
#[derive(Default)]
pub(super) struct Walk {
    /// Transforms, parents first.
    pub(super) transforms: Vec<FaceTransform>,
    /// Meshes.
    pub(super) meshes: Vec<FaceMesh>,
    /// Scene path of each mesh's `IndexedFaceSet`.
    pub(super) mesh_paths: Vec<String>,
    /// Mesh index of each `IndexedFaceSet` node read.
    pub(super) mesh_nodes: HashMap<NodeId, usize>,
    /// Transform index of each `Transform` node read.
    pub(super) transform_nodes: HashMap<NodeId, usize>,
    visited: HashSet<NodeId>,
    used_names: HashSet<String>,
}

impl Walk {
    /// The node's DEF name, or a new `prefix_N` set on the node.
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

    /// Reads node `id` and everything below it; `parent` is the enclosing transform and
    /// `path` the scene path to the node (for messages).
    pub(super) fn visit(
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
            "Shape" => self.visit_shape(scene, id, parent, &here, report),
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

    /// Reads a `Shape` at scene path `here`: its `IndexedFaceSet` becomes a mesh (other
    /// geometry is skipped) with the material's diffuse colour.
    fn visit_shape(
        &mut self,
        scene: &mut Scene,
        id: NodeId,
        parent: Option<usize>,
        here: &str,
        report: &mut FaceReadReport,
    ) {
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
}

/// A VRML `SFRotation` (axis, angle) as a quaternion; the identity for a zero axis or a
/// non-finite angle.
fn rotation_quat(r: [f32; 4]) -> Quat {
    let axis = Vec3::new(r[0], r[1], r[2]);
    match axis.try_normalize() {
        Some(a) if r[3].is_finite() => Quat::from_axis_angle(a, r[3]),
        _ => Quat::IDENTITY,
    }
}

/// A `Transform` node's fields (VRML defaults where absent).
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

/// An `IndexedFaceSet` node as a mesh: coordinates, polygons, texture coordinates, normals
/// and surface flags.
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
