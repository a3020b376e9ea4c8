//! Head and eye rotations of a played stream on the user's own nodes: FAPs 48–50 (head
//! pitch, yaw, roll) turn the head node, 23–26 (eyeball yaw, pitch) the eye nodes, in the
//! standard's units (AU = 1e-5 rad) about the face frame's axes
//! ([`crate::spec::FapInfo::rotation_axis`]).
//!
//! Nodes are the ones the user names (`play --head-node`, `--eye-nodes`), else found by the
//! usual names (`Head`, `LeftEye`/`RightEye`, `eye.L`, Mixamo, CC, VRM 0 bone names) or by
//! the VRM humanoid bones (`VRMC_vrm` 1.0, `VRM` 0.x). A FAP the face's FAT has a table for
//! is left to that table (its morph targets): never a rotation and a morph for one motion.

use glam::{Mat4, Quat};
use serde_json::Value;

use crate::fat::eval::Activation;
use crate::fat::{Fat, TableKey};
use crate::gltf::source::GltfSource;
use crate::spec::FapId;

/// Nodes the user names for rotations (by node name).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RotationNodes {
    /// The head node (FAPs 48–50).
    pub head: Option<String>,
    /// The left and right eye nodes (FAPs 23–26); left is the face's own left.
    pub eyes: Option<(String, String)>,
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

/// World rotation of every node at rest (parents from `children`).
fn world_rotations(json: &Value) -> (Vec<Quat>, Vec<Option<usize>>) {
    let nodes = json["nodes"].as_array().cloned().unwrap_or_default();
    let mut parent = vec![None; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        for c in n["children"].as_array().into_iter().flatten() {
            if let Some(c) = c.as_u64().filter(|&c| (c as usize) < nodes.len()) {
                parent[c as usize] = Some(i);
            }
        }
    }
    let local: Vec<Quat> = nodes.iter().map(local_rotation).collect();
    let world = (0..nodes.len())
        .map(|i| {
            let mut q = local[i];
            let mut at = parent[i];
            let mut depth = 0;
            while let Some(p) = at {
                depth += 1;
                if depth > 256 {
                    break;
                }
                q = local[p] * q;
                at = parent[p];
            }
            q.normalize()
        })
        .collect();
    (world, parent)
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

/// The nodes `play` turns for `fat` in `source` (see the module docs). A node given by
/// `matrix` cannot be animated (glTF) and is skipped.
pub fn rotated_nodes(source: &GltfSource, fat: &Fat, names: &RotationNodes) -> Vec<RotatedNode> {
    let json = &source.json;
    let has_table = |f: u8| {
        fat.tables
            .iter()
            .any(|t| t.key == TableKey::LowLevel(FapId::new(f).expect("a FAP number")))
    };
    let (eye_l, eye_r) = match &names.eyes {
        Some((l, r)) => (Some(l.as_str()), Some(r.as_str())),
        None => (None, None),
    };
    let wanted: [(Option<usize>, &[u8]); 3] = [
        (
            find(json, names.head.as_deref(), HEAD_NAMES).or_else(|| {
                names
                    .head
                    .is_none()
                    .then(|| vrm_bone(json, "head"))
                    .flatten()
            }),
            &[49, 48, 50],
        ),
        (
            find(json, eye_l, LEFT_EYE_NAMES)
                .or_else(|| eye_l.is_none().then(|| vrm_bone(json, "leftEye")).flatten()),
            &[23, 25],
        ),
        (
            find(json, eye_r, RIGHT_EYE_NAMES).or_else(|| {
                eye_r
                    .is_none()
                    .then(|| vrm_bone(json, "rightEye"))
                    .flatten()
            }),
            &[24, 26],
        ),
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
        });
    }
    out
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
        let nodes = rotated_nodes(&source, &Fat::default(), &RotationNodes::default());
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
        // A FAT table for head yaw leaves yaw to the table.
        let mut fat = Fat::default();
        fat.tables.push(crate::fat::FaceDefTable {
            key: TableKey::LowLevel(FapId::new(49).unwrap()),
            meshes: vec![],
            transforms: vec![],
        });
        let nodes = rotated_nodes(&source, &fat, &RotationNodes::default());
        assert_eq!(nodes[0].faps.len(), 2);
        // Named nodes win over usual names.
        let named = RotationNodes {
            head: Some("Armature".into()),
            eyes: None,
        };
        assert_eq!(rotated_nodes(&source, &Fat::default(), &named)[0].node, 0);
    }
}
