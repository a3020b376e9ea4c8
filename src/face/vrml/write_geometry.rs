//! Writing the face's geometry: a new scene graph of `Transform`s and `Shape`s for a face
//! without a scene, or the face's transforms and meshes written into the nodes of its own.

use glam::{Quat, Vec3};

use super::write::{add, set_field};
use super::write_insert::{insert_meshes, insert_transforms};
use crate::error::Result;
use crate::face::{FaceError, FaceMesh, FaceModel, FaceTransform};
use crate::mesh::{Mesh, Polygons, SurfaceFlags};
use crate::vrml::{FieldValue, Node, NodeId, NodeRef, Scene};

/// The nodes the face's geometry was written to.
pub(super) struct GeometryNodes {
    /// The `IndexedFaceSet` of each mesh.
    pub(super) meshes: Vec<NodeId>,
    /// The `Transform` of each transform.
    pub(super) transforms: Vec<NodeId>,
    /// Roots of a newly built scene graph (`FDP.faceSceneGraph`); empty when patching.
    pub(super) roots: Vec<NodeRef>,
}

/// Builds the face's scene graph as new nodes: a `Transform` per transform, a `Shape` with an
/// `IndexedFaceSet` (and its material) per mesh.
pub(super) fn build_geometry(scene: &mut Scene, face: &FaceModel) -> GeometryNodes {
    let mut mesh_nodes: Vec<NodeId> = Vec::with_capacity(face.meshes.len());
    let mut transform_nodes: Vec<NodeId> = Vec::with_capacity(face.transforms.len());
    let mut geometry_roots: Vec<NodeRef> = Vec::new();
    // Children list: a transform's own shapes first, then its child transforms, so the
    // depth-first reading order gives back the model's order (parents-first models).
    let mut children: Vec<Vec<NodeRef>> = vec![Vec::new(); face.transforms.len()];
    let mut child_transforms: Vec<Vec<NodeRef>> = vec![Vec::new(); face.transforms.len()];
    let mut root_transforms = Vec::new();
    for t in &face.transforms {
        let mut node = Node::new("Transform");
        node.def_name = Some(t.name.clone());
        write_transform_fields(&mut node, t);
        let r = add(scene, node);
        transform_nodes.push(r.id);
        match t.parent {
            Some(p) => child_transforms[p].push(r),
            None => root_transforms.push(r),
        }
    }
    for m in &face.meshes {
        let (shape, ifs) = add_shape(scene, m);
        mesh_nodes.push(ifs);
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
    GeometryNodes {
        meshes: mesh_nodes,
        transforms: transform_nodes,
        roots: geometry_roots,
    }
}

/// Adds a `Shape` for mesh `m`: its material when it has a colour and a DEF'd
/// `IndexedFaceSet`. Returns the shape and the `IndexedFaceSet`.
fn add_shape(scene: &mut Scene, m: &FaceMesh) -> (NodeRef, NodeId) {
    let mut shape = Node::new("Shape");
    if let Some(c) = m.color {
        let mut mat = Node::new("Material");
        mat.fields
            .push(("diffuseColor".into(), FieldValue::SFColor(c)));
        let mat = add(scene, mat);
        let mut app = Node::new("Appearance");
        app.fields
            .push(("material".into(), FieldValue::SFNode(Some(mat))));
        let app = add(scene, app);
        shape
            .fields
            .push(("appearance".into(), FieldValue::SFNode(Some(app))));
    }
    let shape = add(scene, shape);
    let mut ifs = Node::new("IndexedFaceSet");
    ifs.def_name = Some(m.name.clone());
    let ifs = add(scene, ifs);
    set_field(
        &mut scene.nodes[shape.id.0],
        "geometry",
        FieldValue::SFNode(Some(ifs)),
    );
    write_mesh_fields(scene, ifs.id, &m.mesh);
    (shape, ifs.id)
}

/// Writes the face's transforms and meshes into the nodes of the same DEF names in its own
/// scene. A mesh or transform the scene lacks is added where its content sits (see
/// [`insert_meshes`] and [`insert_transforms`]).
pub(super) fn patch_geometry(scene: &mut Scene, face: &FaceModel) -> Result<GeometryNodes> {
    let mut found: Vec<Option<NodeId>> = face
        .transforms
        .iter()
        .map(|t| find_def_of_type(scene, &t.name, "Transform"))
        .collect();
    let mut found_meshes: Vec<Option<NodeId>> = face
        .meshes
        .iter()
        .map(|m| find_def_of_type(scene, &m.name, "IndexedFaceSet"))
        .collect();
    if found_meshes.iter().any(Option::is_none) {
        insert_meshes(scene, face, &mut found_meshes, &found, |scene, m| {
            add_shape(scene, &face.meshes[m])
        });
    }
    let mut mesh_nodes: Vec<NodeId> = Vec::with_capacity(face.meshes.len());
    for (m, id) in face.meshes.iter().zip(found_meshes) {
        // `insert_meshes` fills every gap; kept as an error rather than a panic.
        mesh_nodes.push(id.ok_or_else(|| FaceError::MeshNotInScene {
            name: m.name.clone(),
        })?);
    }
    if found.iter().any(Option::is_none) {
        insert_transforms(scene, face, &mut found, &mesh_nodes);
    }
    let mut transform_nodes: Vec<NodeId> = Vec::with_capacity(face.transforms.len());
    for (t, id) in face.transforms.iter().zip(found) {
        // `insert_transforms` fills every gap; kept as an error rather than a panic.
        let id = id.ok_or_else(|| FaceError::TransformNotInScene {
            name: t.name.clone(),
        })?;
        write_transform_fields(&mut scene.nodes[id.0], t);
        transform_nodes.push(id);
    }
    for (m, &id) in face.meshes.iter().zip(&mesh_nodes) {
        write_mesh_fields(scene, id, &m.mesh);
    }
    Ok(GeometryNodes {
        meshes: mesh_nodes,
        transforms: transform_nodes,
        roots: Vec::new(),
    })
}

/// The first node named `name` of type `type_name`.
fn find_def_of_type(scene: &Scene, name: &str, type_name: &str) -> Option<NodeId> {
    scene
        .nodes
        .iter()
        .position(|n| n.def_name.as_deref() == Some(name) && n.type_name == type_name)
        .map(NodeId)
}

/// Polygons as a `-1`-terminated index list.
fn index_list(polys: &Polygons) -> Vec<i32> {
    let mut out = Vec::with_capacity(polys.corner_count() + polys.len());
    for p in polys.iter() {
        out.extend(p.iter().map(|&i| i as i32));
        out.push(-1);
    }
    out
}

/// Vectors as `MFVec3f` values.
pub(super) fn vec3s(v: &[Vec3]) -> Vec<[f32; 3]> {
    v.iter().map(|p| p.to_array()).collect()
}

/// The node in `ifs`'s SFNode field `field`, or a new `type_name` node set there.
fn child_node(scene: &mut Scene, ifs: NodeId, field: &str, type_name: &str) -> NodeId {
    match scene.get_sfnode(ifs, field) {
        Some(c) => c,
        None => {
            let c = add(scene, Node::new(type_name));
            set_field(&mut scene.nodes[ifs.0], field, FieldValue::SFNode(Some(c)));
            c.id
        }
    }
}

/// Fills an `IndexedFaceSet` node's geometry fields from a mesh (adding `Coordinate`,
/// `TextureCoordinate` and `Normal` nodes where the node has none).
fn write_mesh_fields(scene: &mut Scene, ifs: NodeId, mesh: &Mesh) {
    let coord = child_node(scene, ifs, "coord", "Coordinate");
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
        let tc = child_node(scene, ifs, "texCoord", "TextureCoordinate");
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
        let n = child_node(scene, ifs, "normal", "Normal");
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
    write_surface_flags(&mut scene.nodes[ifs.0], mesh.flags);
}

/// Writes `ccw`, `solid`, `convex` and `creaseAngle` where they differ from the VRML default
/// or the node already has them.
fn write_surface_flags(node: &mut Node, f: SurfaceFlags) {
    let d = SurfaceFlags::default();
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

/// Writes a transform's five fields into a `Transform` node.
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

/// A quaternion as a VRML `SFRotation`; `0 0 1 0` for no rotation.
fn quat_rotation(q: Quat) -> [f32; 4] {
    let (axis, angle) = q.to_axis_angle();
    if angle == 0.0 || !axis.is_finite() {
        [0.0, 0.0, 1.0, 0.0]
    } else {
        [axis.x, axis.y, axis.z, angle]
    }
}
