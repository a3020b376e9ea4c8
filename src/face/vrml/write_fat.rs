//! Writing the FAT as the FDP's `FaceDefTables`, each entry a `USE` of the mesh or transform
//! it moves.

use std::collections::HashMap;

use super::write::{add, set_field, use_of};
use super::write_geometry::vec3s;
use crate::error::Result;
use crate::face::{FaceError, FaceModel};
use crate::fat::{FaceDefMesh, FaceDefTransform, TableKey};
use crate::vrml::{FieldValue, Node, NodeId, NodeRef, Scene};

/// One table's nodes, not yet in the scene.
pub(super) struct DefTableNodes {
    table: Node,
    meshes: Vec<Node>,
    transforms: Vec<Node>,
}

/// The nodes of every table of the face's FAT; `mesh_nodes` and `transform_nodes` are the
/// nodes the face's meshes and transforms were written to.
pub(super) fn table_nodes(
    face: &FaceModel,
    mesh_nodes: &[NodeId],
    transform_nodes: &[NodeId],
) -> Result<Vec<DefTableNodes>> {
    let mesh_node_of: HashMap<&str, NodeId> = face
        .meshes
        .iter()
        .zip(mesh_nodes)
        .map(|(m, &id)| (m.name.as_str(), id))
        .collect();
    let transform_node_of: HashMap<&str, NodeId> = face
        .transforms
        .iter()
        .zip(transform_nodes)
        .map(|(t, &id)| (t.name.as_str(), id))
        .collect();
    // A face read from VRML keeps its file's table order; a generated file has the
    // canonical one, so equal FATs in any order write the same bytes.
    let canonical;
    let in_order = if face.scene.is_some() {
        &face.fat.tables
    } else {
        canonical = face.fat.canonical_tables();
        &canonical
    };
    let mut tables = Vec::with_capacity(in_order.len());
    for table in in_order {
        let (fap_id, select) = table.key.node_fields();
        let mut node = Node::new("FaceDefTables");
        node.fields
            .push(("fapID".into(), FieldValue::SFInt32(fap_id as i32)));
        node.fields
            .push(("highLevelSelect".into(), FieldValue::SFInt32(select as i32)));
        let mut mesh_refs = Vec::new();
        for m in &table.meshes {
            let target =
                *mesh_node_of
                    .get(m.mesh.as_str())
                    .ok_or_else(|| FaceError::FatMeshNotInScene {
                        key: table.key,
                        mesh: m.mesh.clone(),
                    })?;
            mesh_refs.push(def_mesh_node(m, target, table.key)?);
        }
        let mut transform_refs = Vec::new();
        for t in &table.transforms {
            let target = *transform_node_of.get(t.transform.as_str()).ok_or_else(|| {
                FaceError::FatTransformNotInScene {
                    key: table.key,
                    transform: t.transform.clone(),
                }
            })?;
            transform_refs.push(def_transform_node(t, target));
        }
        tables.push(DefTableNodes {
            table: node,
            meshes: mesh_refs,
            transforms: transform_refs,
        });
    }
    Ok(tables)
}

/// A `FaceDefMesh` node moving the `IndexedFaceSet` `target`.
fn def_mesh_node(m: &FaceDefMesh, target: NodeId, key: TableKey) -> Result<Node> {
    let borders = m
        .interval_borders
        .iter()
        .map(|&b| border_i32(b, key))
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
    Ok(n)
}

/// A `FaceDefTransform` node moving the `Transform` `target`.
fn def_transform_node(t: &FaceDefTransform, target: NodeId) -> Node {
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
    n
}

/// Adds the tables to the scene as the FDP's `faceDefTables`, replacing any it had.
pub(super) fn attach_tables(scene: &mut Scene, fdp: NodeId, tables: Vec<DefTableNodes>) {
    let mut table_refs = Vec::with_capacity(tables.len());
    for DefTableNodes {
        table,
        meshes,
        transforms,
    } in tables
    {
        let t = add(scene, table);
        let m: Vec<NodeRef> = meshes.into_iter().map(|n| add(scene, n)).collect();
        let x: Vec<NodeRef> = transforms.into_iter().map(|n| add(scene, n)).collect();
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
}

/// An interval border as the `MFInt32` value VRML stores; a fractional or huge border is an
/// error.
fn border_i32(b: f64, key: TableKey) -> Result<i32> {
    if b.fract() != 0.0 || !b.is_finite() || b.abs() > i32::MAX as f64 {
        return Err(FaceError::NonIntegerBorder { key, border: b }.into());
    }
    Ok(b as i32)
}
