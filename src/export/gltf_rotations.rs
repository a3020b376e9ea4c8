//! Head and eye rotations of a played stream on the user's own nodes: FAPs 48–50 (head
//! pitch, yaw, roll) turn the head node, 23–26 (eyeball yaw, pitch) the eye nodes, in the
//! standard's units (AU = 1e-5 rad) about the face frame's axes
//! ([`crate::spec::FapInfo::rotation_axis`]) — the face's own, which are turned from the
//! file's for a face modelled facing −z as VRM 0.x avatars are
//! ([`crate::fdp::FeaturePointSet::upright_turn`]).
//!
//! Nodes are the ones the user names (`play --head-node`, `--eye-nodes`), else found by the
//! usual names (`Head`, `LeftEye`/`RightEye`, `eye.L`, Mixamo, CC, VRM 0 bone names) or by
//! the VRM humanoid bones (`VRMC_vrm` 1.0, `VRM` 0.x). A FAP the face's FAT has a table for
//! is left to that table (its morph targets): never a rotation and a morph for one motion.
//! A cloned face's eyeball transforms are shown by eye nodes that move the eyeball alone
//! (holding its mesh, or its skin weights: [`super::gltf_user_nodes`]), and its head
//! transform by the head node: their tables then turn those nodes through the transform.
//!
//! The jaw is the other way round ([`jaw_node`]): a skinned jaw joint carries the chin, the
//! lower teeth and the lower lip with it, so when the document has one (`play --jaw-node`,
//! or a node named `Jaw`/`jaw`, the VRM humanoid `jaw` bone), `open_jaw` turns it about the
//! face's +x through the joint, `thrust_jaw` and `shift_jaw` move it, and the FAT's targets
//! for these three FAPs are held at zero in the animation (they stay in the document).

use glam::{Mat3, Mat4, Quat, Vec3};
use serde_json::Value;

use crate::fat::eval::Activation;
use crate::fat::TableKey;
use crate::gltf::source::GltfSource;
use crate::spec::FapId;

/// Nodes the user names for rotations (by node name).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RotationNodes {
    /// The head node (FAPs 48–50).
    pub head: Option<String>,
    /// The left and right eye nodes (FAPs 23–26); left is the face's own left.
    pub eyes: Option<(String, String)>,
    /// The jaw node (FAPs 3, 14, 15: `open_jaw`, `thrust_jaw`, `shift_jaw`).
    pub jaw: Option<String>,
}

/// One node to turn: its index, the FAPs that turn it, and how a face-frame rotation maps
/// into its parent's frame.
#[derive(Clone, Debug)]
pub struct RotatedNode {
    /// Node index.
    pub node: usize,
    /// The FAPs (yaw, pitch, roll as they apply).
    pub faps: Vec<FapId>,
    /// The node's rest rotation.
    rest: Quat,
    /// The parent's world rotation (world deltas are conjugated by it).
    parent: Quat,
    /// The face's own axes in the file (columns: x, y, z; identity for an upright face).
    axes: Mat3,
}

impl RotatedNode {
    /// The node's rotation for `activations`.
    pub fn rotation(&self, activations: &[Activation]) -> Quat {
        let mut world = Quat::IDENTITY;
        for &fap in &self.faps {
            let Some(axis) = fap.info().rotation_axis() else {
                continue;
            };
            let value: f64 = activations
                .iter()
                .filter(|a| a.key == TableKey::LowLevel(fap) && a.value.is_finite())
                .map(|a| a.value)
                .sum();
            let axis = (self.axes * axis).normalize();
            world = Quat::from_axis_angle(axis, (value * 1e-5) as f32) * world;
        }
        ((self.parent.inverse() * world * self.parent) * self.rest).normalize()
    }
}

/// Normalised name: lower case, letters and digits only.
fn norm(s: &str) -> String {
    s.chars()
        .filter(char::is_ascii_alphanumeric)
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

const HEAD_NAMES: &[&str] = &[
    "head",
    "jbipchead",
    "mixamorighead",
    "ccbasehead",
    "bip01head",
];
const LEFT_EYE_NAMES: &[&str] = &[
    "lefteye",
    "eyel",
    "leye",
    "eyeleft",
    "jadjlfaceeye",
    "mixamoriglefteye",
    "ccbaseleye",
];
const RIGHT_EYE_NAMES: &[&str] = &[
    "righteye",
    "eyer",
    "reye",
    "eyeright",
    "jadjrfaceeye",
    "mixamorigrighteye",
    "ccbasereye",
];

/// Index of the node named `name` exactly, else the first whose normalised name is in `usual`.
fn find(json: &Value, name: Option<&str>, usual: &[&str]) -> Option<usize> {
    let nodes = json["nodes"].as_array()?;
    if let Some(name) = name {
        return nodes.iter().position(|n| n["name"].as_str() == Some(name));
    }
    nodes.iter().position(|n| {
        n["name"]
            .as_str()
            .is_some_and(|s| usual.contains(&norm(s).as_str()))
    })
}

/// The node of VRM humanoid bone `bone` (1.0 `VRMC_vrm`, then 0.x `VRM`).
fn vrm_bone(json: &Value, bone: &str) -> Option<usize> {
    let ext = &json["extensions"];
    if let Some(n) = ext["VRMC_vrm"]["humanoid"]["humanBones"][bone]["node"].as_u64() {
        return Some(n as usize);
    }
    ext["VRM"]["humanoid"]["humanBones"]
        .as_array()?
        .iter()
        .find(|b| b["bone"] == bone)?["node"]
        .as_u64()
        .map(|n| n as usize)
}

/// The head node `play` turns for FAPs 48–50: the node named `names.head`, else the first
/// with a usual head name, else the VRM humanoid `head` bone.
pub fn head_node(source: &GltfSource, names: &RotationNodes) -> Option<usize> {
    find(&source.json, names.head.as_deref(), HEAD_NAMES).or_else(|| {
        names
            .head
            .is_none()
            .then(|| vrm_bone(&source.json, "head"))
            .flatten()
    })
}

/// The left and right eye nodes (FAPs 23/25 and 24/26): the nodes named `names.eyes`, else
/// the first with a usual eye name, else the VRM humanoid `leftEye`/`rightEye` bones.
pub fn eye_nodes(source: &GltfSource, names: &RotationNodes) -> (Option<usize>, Option<usize>) {
    let json = &source.json;
    let (l, r) = match &names.eyes {
        Some((l, r)) => (Some(l.as_str()), Some(r.as_str())),
        None => (None, None),
    };
    let one = |name: Option<&str>, usual: &[&str], bone: &str| {
        find(json, name, usual).or_else(|| name.is_none().then(|| vrm_bone(json, bone)).flatten())
    };
    (
        one(l, LEFT_EYE_NAMES, "leftEye"),
        one(r, RIGHT_EYE_NAMES, "rightEye"),
    )
}

/// The head rotation FAPs (pitch, yaw, roll).
pub const HEAD_FAPS: [u8; 3] = [48, 49, 50];

/// World rotation of every node at rest (parents from `children`).
fn world_rotations(json: &Value) -> (Vec<Quat>, Vec<Option<usize>>) {
    let (world, parent) = compose_at_rest(json, local_rotation);
    (world.into_iter().map(Quat::normalize).collect(), parent)
}

/// Every node's local value (`local`) composed with its ancestors' (parent first), and each
/// node's parent. A cycle in a broken `children` graph stops after 256 steps.
fn compose_at_rest<T: Copy + std::ops::Mul<Output = T>>(
    json: &Value,
    local: fn(&Value) -> T,
) -> (Vec<T>, Vec<Option<usize>>) {
    let nodes = json["nodes"].as_array().map_or(&[][..], Vec::as_slice);
    let parent = node_parents(json);
    let local: Vec<T> = nodes.iter().map(local).collect();
    let world = (0..nodes.len())
        .map(|i| {
            let mut m = local[i];
            let mut at = parent[i];
            let mut depth = 0;
            while let Some(p) = at {
                depth += 1;
                if depth > 256 {
                    break;
                }
                m = local[p] * m;
                at = parent[p];
            }
            m
        })
        .collect();
    (world, parent)
}

/// Each node's parent (from `children`).
pub(crate) fn node_parents(json: &Value) -> Vec<Option<usize>> {
    let nodes = json["nodes"].as_array().map_or(&[][..], Vec::as_slice);
    let mut parent = vec![None; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        for c in n["children"].as_array().into_iter().flatten() {
            if let Some(c) = c.as_u64().filter(|&c| (c as usize) < nodes.len()) {
                parent[c as usize] = Some(i);
            }
        }
    }
    parent
}

/// Whether node `n` is `ancestor` or below it (`parents` from [`node_parents`]; a cycle in a
/// broken graph ends the walk).
pub(crate) fn descends(parents: &[Option<usize>], n: usize, ancestor: usize) -> bool {
    let mut at = Some(n);
    let mut depth = 0;
    while let Some(i) = at {
        if i == ancestor {
            return true;
        }
        depth += 1;
        if depth > parents.len() {
            return false;
        }
        at = parents.get(i).copied().flatten();
    }
    false
}

fn local_rotation(n: &Value) -> Quat {
    if let Some(m) = n["matrix"].as_array() {
        let v: Vec<f32> = m.iter().map(|x| x.as_f64().unwrap_or(0.0) as f32).collect();
        if v.len() == 16 {
            let (_, r, _) = Mat4::from_cols_slice(&v).to_scale_rotation_translation();
            return r;
        }
    }
    match n["rotation"].as_array() {
        Some(r) if r.len() == 4 => {
            let f = |i: usize| r[i].as_f64().unwrap_or(0.0) as f32;
            Quat::from_xyzw(f(0), f(1), f(2), f(3)).normalize()
        }
        _ => Quat::IDENTITY,
    }
}

/// The face's own axes in its file as the columns of a matrix (face frame → file): the
/// identity for a face modelled upright, quarter turns for one modelled turned.
pub(super) fn face_axes(face: &crate::face::FaceModel) -> Mat3 {
    face.feature_points
        .upright_turn()
        .map_or(Mat3::IDENTITY, |t| t.transpose())
}

/// The nodes `play` turns for `face`'s FAT in `source` (see the module docs). A node given by
/// `matrix` cannot be animated (glTF) and is skipped.
pub fn rotated_nodes(
    source: &GltfSource,
    face: &crate::face::FaceModel,
    names: &RotationNodes,
) -> Vec<RotatedNode> {
    let fat = &face.fat;
    let axes = face_axes(face);
    let json = &source.json;
    let has_table = |f: u8| {
        fat.tables
            .iter()
            .any(|t| t.key == TableKey::LowLevel(FapId::new(f).expect("a FAP number")))
    };
    let (eye_l, eye_r) = eye_nodes(source, names);
    let wanted: [(Option<usize>, &[u8]); 3] = [
        (head_node(source, names), &[49, 48, 50]),
        (eye_l, &[23, 25]),
        (eye_r, &[24, 26]),
    ];
    let (world, parent) = world_rotations(json);
    let mut out = Vec::new();
    for (node, faps) in wanted {
        let Some(node) = node else { continue };
        if json["nodes"][node].get("matrix").is_some() {
            continue;
        }
        let faps: Vec<FapId> = faps
            .iter()
            .filter(|&&f| !has_table(f))
            .filter_map(|&f| FapId::new(f))
            .collect();
        if faps.is_empty() {
            continue;
        }
        out.push(RotatedNode {
            node,
            faps,
            rest: local_rotation(&json["nodes"][node]),
            parent: parent[node].map_or(Quat::IDENTITY, |p| world[p]),
            axes,
        });
    }
    out
}

const JAW_NAMES: &[&str] = &[
    "jaw",
    "jawbone",
    "jawroot",
    "mixamorigjaw",
    "ccbasejawroot",
    "jbipcjaw",
    "lowerjaw",
];

/// The FAPs the jaw node takes over from the FAT: `open_jaw`, `thrust_jaw`, `shift_jaw`.
pub const JAW_FAPS: [u8; 3] = [3, 14, 15];

/// The jaw joint `play` moves for `open_jaw` (a turn), `thrust_jaw` and `shift_jaw` (moves).
#[derive(Clone, Debug)]
pub struct JawNode {
    /// Node index.
    pub node: usize,
    rest_rotation: Quat,
    rest_translation: Vec3,
    /// The parent's world rotation (world turns are conjugated by it).
    parent_rotation: Quat,
    /// The inverse of the parent's world linear part (world moves into its frame).
    parent_inverse: Mat3,
    /// The face's own x axis in the file (what `open_jaw` turns about).
    face_x: Vec3,
    /// Radians per unit of `open_jaw`, signed so that the chin goes down.
    open_per_unit: f64,
    /// World move per unit of `thrust_jaw` and of `shift_jaw` (file units).
    thrust_per_unit: Vec3,
    shift_per_unit: Vec3,
}

fn fap_value(activations: &[Activation], fap: u8) -> f64 {
    let Some(id) = FapId::new(fap) else {
        return 0.0;
    };
    activations
        .iter()
        .filter(|a| a.key == TableKey::LowLevel(id) && a.value.is_finite())
        .map(|a| a.value)
        .sum()
}

impl JawNode {
    /// The node's rotation for `activations`.
    pub fn rotation(&self, activations: &[Activation]) -> Quat {
        let angle = fap_value(activations, 3) * self.open_per_unit;
        let world = Quat::from_axis_angle(self.face_x, angle as f32);
        ((self.parent_rotation.inverse() * world * self.parent_rotation) * self.rest_rotation)
            .normalize()
    }

    /// The node's translation for `activations`.
    pub fn translation(&self, activations: &[Activation]) -> Vec3 {
        let world = self.thrust_per_unit * fap_value(activations, 14) as f32
            + self.shift_per_unit * fap_value(activations, 15) as f32;
        self.rest_translation + self.parent_inverse * world
    }

    /// Whether `key` is one of the FAPs the jaw node takes over.
    pub fn takes(key: TableKey) -> bool {
        matches!(key, TableKey::LowLevel(f) if JAW_FAPS.contains(&f.number()))
    }
}

/// World matrix of every node at rest (parents from `children`).
pub(crate) fn world_matrices(json: &Value) -> (Vec<Mat4>, Vec<Option<usize>>) {
    compose_at_rest(json, local_matrix)
}

fn vec3_of(v: &Value, default: Vec3) -> Vec3 {
    match v.as_array() {
        Some(a) if a.len() == 3 => {
            let f = |i: usize| a[i].as_f64().unwrap_or(0.0) as f32;
            Vec3::new(f(0), f(1), f(2))
        }
        _ => default,
    }
}

fn local_matrix(n: &Value) -> Mat4 {
    if let Some(m) = n["matrix"].as_array() {
        let v: Vec<f32> = m.iter().map(|x| x.as_f64().unwrap_or(0.0) as f32).collect();
        if v.len() == 16 {
            return Mat4::from_cols_slice(&v);
        }
    }
    Mat4::from_scale_rotation_translation(
        vec3_of(&n["scale"], Vec3::ONE),
        local_rotation(n),
        vec3_of(&n["translation"], Vec3::ZERO),
    )
}

/// The jaw node `play` moves in `source` (see the module docs): the node named `name`, else
/// the first with a usual jaw name, else the VRM humanoid `jaw` bone. The turn per unit of
/// `open_jaw` is the chin's (feature point 2.1) drop of one MNS over its distance from the
/// joint in the face's side view; `thrust_jaw` and `shift_jaw` move it by MNS and MW along
/// the standard's directions. `unit` is the file's length per face unit. `Err` says why a
/// node that was found cannot be used (a `matrix` node, no feature points, no FAP units, the
/// chin on the joint, or a node the FAT's own transform tables drive: `skip`).
pub fn jaw_node(
    source: &GltfSource,
    face: &crate::face::FaceModel,
    name: Option<&str>,
    unit: f32,
    skip: &[usize],
) -> Result<Option<JawNode>, String> {
    let json = &source.json;
    let node = find(json, name, JAW_NAMES)
        .or_else(|| name.is_none().then(|| vrm_bone(json, "jaw")).flatten());
    let Some(node) = node else {
        return match name {
            Some(n) => Err(format!("no node named `{n}`")),
            None => Ok(None),
        };
    };
    let label = json["nodes"][node]["name"]
        .as_str()
        .unwrap_or("")
        .to_string();
    if skip.contains(&node) {
        // The FAT's own transform (a face fbakit wrote) already moves it.
        return Ok(None);
    }
    if json["nodes"][node].get("matrix").is_some() {
        return Err(format!(
            "jaw node `{label}` is given by a matrix, which glTF cannot animate"
        ));
    }
    let fapu = face
        .fapu()
        .map_err(|e| format!("jaw node `{label}` needs the face's FAP units: {e}"))?;
    let chin = face
        .feature_points
        .position(crate::spec::FeaturePointId::FP_2_1)
        .ok_or_else(|| format!("jaw node `{label}` needs the chin's feature point 2.1"))?
        * unit;
    let (world, parent) = world_matrices(json);
    let pivot = world[node].w_axis.truncate();
    // In the face's own axes (turned from the file's for a face modelled facing −z).
    let axes = face_axes(face);
    let r = axes.transpose() * (chin - pivot);
    let radius = (r.y * r.y + r.z * r.z).sqrt();
    if !radius.is_finite() || radius <= 1e-6 * (chin.length() + 1.0) {
        return Err(format!(
            "jaw node `{label}` sits on the chin (2.1): it cannot turn the jaw open"
        ));
    }
    let mns = fapu.unit(crate::spec::FapuKind::Mns) * f64::from(unit);
    let mw = fapu.unit(crate::spec::FapuKind::Mw) * f64::from(unit);
    // A turn θ about +x moves the chin by (0, −r.z θ, r.y θ): down when r.z θ > 0.
    let open_per_unit = mns / f64::from(radius) * f64::from(r.z.signum());
    let dir = |f: u8| {
        FapId::new(f)
            .and_then(|f| f.info().direction())
            .unwrap_or(Vec3::ZERO)
    };
    let parent_world = parent[node].map_or(Mat4::IDENTITY, |p| world[p]);
    let parent_linear = Mat3::from_mat4(parent_world);
    let det = parent_linear.determinant();
    if det.abs() < 1e-12 || !det.is_finite() {
        return Err(format!("jaw node `{label}` has a degenerate parent"));
    }
    let (_, parent_rotation, _) = parent_world.to_scale_rotation_translation();
    Ok(Some(JawNode {
        node,
        rest_rotation: local_rotation(&json["nodes"][node]),
        rest_translation: vec3_of(&json["nodes"][node]["translation"], Vec3::ZERO),
        parent_rotation,
        parent_inverse: parent_linear.inverse(),
        open_per_unit,
        thrust_per_unit: axes * dir(14) * mns as f32,
        shift_per_unit: axes * dir(15) * mw as f32,
        face_x: axes.x_axis,
    }))
}

/// Keys in one hemisphere, so LINEAR (slerp) takes the short way.
pub fn same_hemisphere(values: &mut [Quat]) {
    let mut prev = Quat::IDENTITY;
    for q in values {
        if q.dot(prev) < 0.0 {
            *q = -*q;
        }
        prev = *q;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::face::FaceModel;
    use glam::Vec3;

    #[test]
    fn usual_names_are_found_and_rotations_are_in_the_face_frame() {
        let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let json = serde_json::json!({
            "nodes": [
                {"name": "Armature", "rotation": turn.to_array(), "children": [1]},
                {"name": "mixamorig:Head", "children": [2]},
                {"name": "eye.L"}
            ]
        });
        let source = GltfSource {
            path: "a.glb".into(),
            json,
            buffers: vec![],
            parts: vec![],
        };
        let bare = FaceModel::new("face");
        let nodes = rotated_nodes(&source, &bare, &RotationNodes::default());
        assert_eq!(nodes.iter().map(|n| n.node).collect::<Vec<_>>(), [1, 2]);
        // Head yaw of 0.1 rad turns about the world's +y whatever the armature's turn.
        let a = [Activation {
            key: TableKey::LowLevel(FapId::new(49).unwrap()),
            value: 10_000.0,
        }];
        let local = nodes[0].rotation(&a);
        let world = turn * local;
        let want = Quat::from_axis_angle(Vec3::Y, 0.1) * turn;
        assert!(world.abs_diff_eq(want, 1e-5) || world.abs_diff_eq(-want, 1e-5));
        // A face facing −z (turned round in its file): its yaw turns about the world's +y
        // still, its pitch about the world's −x (its own +x).
        let mut round = FaceModel::new("face");
        for (id, p) in [
            ("3.5", Vec3::new(-3.2, 0.0, 0.0)),
            ("3.6", Vec3::new(3.2, 0.0, 0.0)),
            ("2.2", Vec3::new(0.0, -6.0, -1.2)),
            ("2.3", Vec3::new(0.0, -6.4, -1.1)),
            ("9.3", Vec3::new(0.0, -3.5, -2.5)),
        ] {
            round
                .feature_points
                .insert(crate::fdp::FeaturePoint::at(id.parse().unwrap(), p));
        }
        let nodes = rotated_nodes(&source, &round, &RotationNodes::default());
        let world = turn * nodes[0].rotation(&a);
        assert!(world.abs_diff_eq(want, 1e-5) || world.abs_diff_eq(-want, 1e-5));
        let pitch = [Activation {
            key: TableKey::LowLevel(FapId::new(48).unwrap()),
            value: 10_000.0,
        }];
        let world = turn * nodes[0].rotation(&pitch);
        let want = Quat::from_axis_angle(-Vec3::X, 0.1) * turn;
        assert!(world.abs_diff_eq(want, 1e-5) || world.abs_diff_eq(-want, 1e-5));
        // A FAT table for head yaw leaves yaw to the table.
        let mut with_table = FaceModel::new("face");
        with_table.fat.tables.push(crate::fat::FaceDefTable {
            key: TableKey::LowLevel(FapId::new(49).unwrap()),
            meshes: vec![],
            transforms: vec![],
        });
        let nodes = rotated_nodes(&source, &with_table, &RotationNodes::default());
        assert_eq!(nodes[0].faps.len(), 2);
        // Named nodes win over usual names.
        let named = RotationNodes {
            head: Some("Armature".into()),
            ..RotationNodes::default()
        };
        assert_eq!(rotated_nodes(&source, &bare, &named)[0].node, 0);
    }
}
