//! Writing a face: [`FaceModel`] → VRML scene, patching the face's own scene when it has one
//! or building a new `Face` (module docs of [`super`], "Writing").

use std::path::Path;

use glam::Vec3;

use super::bindings::{record_entries, replace_record};
use super::write_fat::{attach_tables, table_nodes};
use super::write_geometry::{build_geometry, patch_geometry};
use crate::error::Result;
use crate::face::FaceModel;
use crate::spec::FeaturePointId;
use crate::vrml::{FieldValue, Node, NodeId, NodeRef, Scene, Statement};

/// Writes a face as a VRML97 file (atomically).
pub fn write_face_file(path: &Path, face: &FaceModel) -> Result<()> {
    let scene = face_to_scene(face)?;
    crate::vrml::write_vrml_file(path, &scene)
}

/// The VRML text of a face.
pub fn write_face_string(face: &FaceModel) -> Result<String> {
    Ok(crate::vrml::write_vrml_string(&face_to_scene(face)?))
}

/// The VRML scene of a face: its own scene patched, or a new one.
pub fn face_to_scene(face: &FaceModel) -> Result<Scene> {
    face.check_structure()?;
    let mut scene = face.scene.clone().unwrap_or_default();
    let built_fresh = face.scene.is_none();
    // Names from other formats (a glTF primitive `Body.0`) become DEF names here.
    let renamed;
    let face = match built_fresh.then(|| with_vrml_names(face)).flatten() {
        Some(f) => {
            renamed = f;
            &renamed
        }
        None => face,
    };
    let geometry = if built_fresh {
        build_geometry(&mut scene, face)
    } else {
        patch_geometry(&mut scene, face)?
    };
    let coords = feature_point_coords(face);
    let record = record_entries(face);
    let tables = table_nodes(face, &geometry.meshes, &geometry.transforms)?;

    // The record goes before the face nodes so readers meet it first.
    let info = replace_record(&mut scene, record);
    let (face_node, fdp, new_face) = find_or_add_fdp(&mut scene);
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
            FieldValue::MFNode(geometry.roots),
        );
    }
    attach_tables(&mut scene, fdp, tables);
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

/// Whether `name` can be a VRML97 DEF name.
fn is_vrml_name(name: &str) -> bool {
    let mut c = name.chars();
    c.next().is_some_and(crate::vrml::lexer::is_id_first)
        && c.all(crate::vrml::lexer::is_id_rest)
        && !crate::vrml::lexer::KEYWORDS.contains(&name)
}

/// `face` with every mesh and transform name that cannot be a DEF name made one (characters
/// VRML does not allow become `_`, a leading digit gets a `_` before it; a repeat gets `_2`,
/// `_3`), and the FAT's and feature
/// points' references renamed with them; `None` when every name already is one.
fn with_vrml_names(face: &FaceModel) -> Option<FaceModel> {
    let names = face
        .meshes
        .iter()
        .map(|m| &m.name)
        .chain(face.transforms.iter().map(|t| &t.name));
    if names.clone().all(|n| is_vrml_name(n)) {
        return None;
    }
    let mut taken: std::collections::HashSet<String> =
        names.filter(|n| is_vrml_name(n)).cloned().collect();
    let mut fix = |name: &str| -> String {
        if is_vrml_name(name) {
            return name.to_string();
        }
        let mut base: String = name
            .chars()
            .map(|c| {
                if crate::vrml::lexer::is_id_rest(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        // A leading digit, sign or keyword is kept behind a `_`.
        if !is_vrml_name(&base) {
            base.insert(0, '_');
        }
        let mut out = base.clone();
        let mut k = 2;
        while taken.contains(&out) {
            out = format!("{base}_{k}");
            k += 1;
        }
        taken.insert(out.clone());
        out
    };
    let mut out = face.clone();
    let mut meshes = std::collections::HashMap::new();
    for m in out.meshes.iter_mut() {
        let new = fix(&m.name);
        if m.mesh.name == m.name {
            m.mesh.name = new.clone();
        }
        meshes.insert(std::mem::replace(&mut m.name, new.clone()), new);
    }
    let mut transforms = std::collections::HashMap::new();
    for t in out.transforms.iter_mut() {
        let new = fix(&t.name);
        transforms.insert(std::mem::replace(&mut t.name, new.clone()), new);
    }
    for table in out.fat.tables.iter_mut() {
        for m in table.meshes.iter_mut() {
            if let Some(n) = meshes.get(&m.mesh) {
                m.mesh = n.clone();
            }
        }
        for x in table.transforms.iter_mut() {
            if let Some(n) = transforms.get(&x.transform) {
                x.transform = n.clone();
            }
        }
    }
    let mut points = crate::fdp::FeaturePointSet::new();
    for p in face.feature_points.iter() {
        let mut p = p.clone();
        if let Some(b) = p.binding.as_mut() {
            if let Some(n) = b.mesh.as_ref().and_then(|m| meshes.get(m)) {
                b.mesh = Some(n.clone());
            }
        }
        points.insert(p);
    }
    out.feature_points = points;
    Some(out)
}

/// All 84 feature points in label order, missing ones at the mean of the present ones
/// (`featurePointsCoord` must list them all).
fn feature_point_coords(face: &FaceModel) -> Vec<[f32; 3]> {
    let with_pos: Vec<Vec3> = face
        .feature_points
        .iter()
        .filter_map(|p| p.position)
        .collect();
    let fill = if with_pos.is_empty() {
        Vec3::ZERO
    } else {
        with_pos.iter().sum::<Vec3>() / with_pos.len() as f32
    };
    FeaturePointId::all()
        .map(|id| face.feature_points.position(id).unwrap_or(fill).to_array())
        .collect()
}

/// The scene's `Face` node (if any) and its `FDP` (or a bare `FDP`); without one, a new
/// `Face { fdp FDP {} }` is added and returned as the third value, not yet a root statement.
fn find_or_add_fdp(scene: &mut Scene) -> (Option<NodeId>, NodeId, Option<NodeRef>) {
    let face_node = scene.nodes_of_type("Face").next();
    let fdp = face_node
        .and_then(|f| scene.get_sfnode(f, "fdp"))
        .or_else(|| scene.nodes_of_type("FDP").next());
    match fdp {
        Some(f) => (face_node, f, None),
        None => {
            let fdp = add(scene, Node::new("FDP"));
            let mut face_n = Node::new("Face");
            face_n
                .fields
                .push(("fdp".into(), FieldValue::SFNode(Some(fdp))));
            let face_ref = add(scene, face_n);
            (face_node, fdp.id, Some(face_ref))
        }
    }
}

/// Sets field `name` of `node`, replacing its value or appending it.
pub(super) fn set_field(node: &mut Node, name: &str, value: FieldValue) {
    match node.fields.iter_mut().find(|(n, _)| n == name) {
        Some((_, v)) => *v = value,
        None => node.fields.push((name.to_string(), value)),
    }
}

/// Adds `node` to the scene, referenced by its DEF (not a USE).
pub(super) fn add(scene: &mut Scene, node: Node) -> NodeRef {
    NodeRef {
        id: scene.add_node(node),
        is_use: false,
    }
}

/// A `USE` of node `id`.
pub(super) fn use_of(id: NodeId) -> NodeRef {
    NodeRef { id, is_use: true }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// alma with a mesh and a transform renamed as glTF names them (`Body.0`, `1st`) is
    /// written with DEF names VRML allows and reads back with its FAT on the renamed parts.
    #[test]
    fn names_vrml_does_not_allow_are_made_def_names() {
        let mut face = crate::synth::alma().to_face_model();
        let (mesh, transform) = (face.meshes[0].name.clone(), face.transforms[0].name.clone());
        for m in face.meshes.iter_mut() {
            if m.name == mesh {
                m.name = "Body.0".into();
            }
        }
        face.transforms[0].name = "1st".into();
        for t in face.fat.tables.iter_mut() {
            for m in t.meshes.iter_mut().filter(|m| m.mesh == mesh) {
                m.mesh = "Body.0".into();
            }
            for x in t.transforms.iter_mut().filter(|x| x.transform == transform) {
                x.transform = "1st".into();
            }
        }
        let mut points = crate::fdp::FeaturePointSet::new();
        for p in face.feature_points.iter() {
            let mut p = p.clone();
            if let Some(b) = p
                .binding
                .as_mut()
                .filter(|b| b.mesh.as_deref() == Some(&mesh))
            {
                b.mesh = Some("Body.0".into());
            }
            points.insert(p);
        }
        face.feature_points = points;
        face.scene = None;
        let text = write_face_string(&face).unwrap();
        assert!(text.contains("DEF Body_0 ") && text.contains("DEF _1st "));
        let scene = crate::vrml::parse_vrml(&text, Path::new("t.wrl")).unwrap();
        let (back, _) = super::super::face_from_scene(scene, "t").unwrap();
        assert!(back.mesh_index("Body_0").is_some());
        assert_eq!(back.fat.tables.len(), face.fat.tables.len());
        let moved = |f: &FaceModel| {
            f.fat
                .tables
                .iter()
                .map(|t| t.meshes.len() + t.transforms.len())
                .sum::<usize>()
        };
        assert_eq!(moved(&back), moved(&face));
    }
}
