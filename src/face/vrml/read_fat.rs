//! Reading the FDP's `FaceDefTables` into a [`Fat`], keeping for each table the nodes it came
//! from so validation can point at them.

use std::collections::HashMap;

use glam::Vec3;

use super::{FaceReadReport, TableNodes};
use crate::error::{Diagnostic, Location, Severity};
use crate::fat::{FaceDefMesh, FaceDefTable, FaceDefTransform, Fat, TableKey, TransformField};
use crate::vrml::{NodeId, Scene};

/// The FAT of the `fdp` node; `meshes` and `transforms` are the face's `IndexedFaceSet` and
/// `Transform` nodes. Bad tables and entries are reported and skipped.
pub(super) fn read_fat(
    scene: &Scene,
    fdp: NodeId,
    meshes: &HashMap<NodeId, usize>,
    transforms: &HashMap<NodeId, usize>,
    report: &mut FaceReadReport,
) -> Fat {
    let mut fat = Fat::default();
    for table_id in scene.get_mfnode(fdp, "faceDefTables") {
        let loc = scene.node(table_id).location.clone();
        if scene.node(table_id).type_name != "FaceDefTables" {
            push_error(
                report,
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
                push_error(report, &loc, format!("FaceDefTables: {m}"));
                continue;
            }
        };
        let mut table = FaceDefTable::new(key);
        let mut nodes = TableNodes {
            table: Some(table_id),
            ..TableNodes::default()
        };
        for m in scene.get_mfnode(table_id, "faceDefMesh") {
            match read_def_mesh(scene, m, key, meshes) {
                Ok(entry) => {
                    table.meshes.push(entry);
                    nodes.meshes.push(m);
                }
                Err(message) => push_error(report, &scene.node(m).location, message),
            }
        }
        for t in scene.get_mfnode(table_id, "faceDefTransform") {
            match read_def_transform(scene, t, key, transforms) {
                Ok(entry) => {
                    table.transforms.push(entry);
                    nodes.transforms.push(t);
                }
                Err(message) => push_error(report, &scene.node(t).location, message),
            }
        }
        fat.tables.push(table);
        report.table_nodes.push(nodes);
    }
    fat
}

fn push_error(report: &mut FaceReadReport, loc: &Location, message: String) {
    report.diagnostics.push(Diagnostic {
        severity: Severity::Error,
        location: Some(loc.clone()),
        message,
    })
}

/// A `FaceDefMesh` node of table `key`, or what is wrong with it.
fn read_def_mesh(
    scene: &Scene,
    m: NodeId,
    key: TableKey,
    meshes: &HashMap<NodeId, usize>,
) -> Result<FaceDefMesh, String> {
    let target = scene
        .get_sfnode(m, "faceSceneGraphNode")
        .filter(|id| meshes.contains_key(id));
    let Some(name) = target.and_then(|id| scene.node(id).def_name.clone()) else {
        return Err(format!(
            "{key}: FaceDefMesh.faceSceneGraphNode must be an IndexedFaceSet of the face"
        ));
    };
    let coord_index = scene.get_mfint32(m, "coordIndex").unwrap_or(&[]);
    if let Some(bad) = coord_index.iter().find(|&&i| i < 0) {
        return Err(format!(
            "{key}: FaceDefMesh.coordIndex has a negative value {bad}"
        ));
    }
    Ok(FaceDefMesh {
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
    })
}

/// A `FaceDefTransform` node of table `key`, or what is wrong with it.
fn read_def_transform(
    scene: &Scene,
    t: NodeId,
    key: TableKey,
    transforms: &HashMap<NodeId, usize>,
) -> Result<FaceDefTransform, String> {
    let target = scene.get_sfnode(t, "faceSceneGraphNode");
    let Some(name) = target
        .filter(|id| transforms.contains_key(id))
        .and_then(|id| scene.node(id).def_name.clone())
    else {
        return Err(format!(
            "{key}: FaceDefTransform.faceSceneGraphNode must be a Transform of the face"
        ));
    };
    let field_id = scene.get_sfint32(t, "fieldId").unwrap_or(1);
    let Some(field) = TransformField::from_field_id(field_id as i64) else {
        return Err(format!(
            "{key}: fieldId {field_id} is not 1 (rotation), 2 (scale) or 3 (translation)"
        ));
    };
    let r = scene
        .get_sfrotation(t, "rotationDef")
        .unwrap_or([0.0, 0.0, 1.0, 0.0]);
    Ok(FaceDefTransform {
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
    })
}
