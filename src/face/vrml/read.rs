//! Reading a face file: the scene → [`FaceModel`] entry points and what reading reports.

use std::path::Path;

use serde::Serialize;

use super::bindings::{find_record, points_from_record};
use super::fp_match::{bind_to_nearest_vertices, FeaturePointMatch};
use super::read_fat::read_fat;
use super::read_geometry::{is_face_node, Walk};
use crate::error::{Diagnostic, Result, Severity};
use crate::face::FaceModel;
use crate::fdp::FeaturePointSet;
use crate::vrml::{NodeId, Scene};

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

/// The FDP's feature points: from fbakit's record when the file has one, else every
/// `featurePointsCoord` entry bound to its nearest vertex.
fn read_feature_points(
    scene: &Scene,
    fdp: NodeId,
    model: &FaceModel,
    report: &mut FaceReadReport,
) -> Result<FeaturePointSet> {
    let Some(coord) = scene.get_sfnode(fdp, "featurePointsCoord") else {
        return Ok(FeaturePointSet::new());
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
    if let Some((entries, rloc)) = find_record(scene) {
        return Ok(points_from_record(
            &entries,
            &rloc,
            points,
            &loc,
            &mut report.diagnostics,
        ));
    }
    Ok(bind_to_nearest_vertices(
        points,
        model,
        &mut report.fp_matches,
    ))
}
