//! Face transforms shown by the user's own glTF nodes: the eyeballs.
//!
//! A cloned face turns each eyeball by a transform of its own (FAPs 23–26). When the user's
//! document has eye nodes (`--eye-nodes`, the usual names such as `LeftEye`, or the VRM eye
//! bones, as [`super::gltf_rotations::eye_nodes`] finds them) that hold that eyeball's mesh
//! and nothing else of the face, the transform is shown by that node: its motion is animated
//! on the node, not baked into morph targets, and recorded in the document's FAT extras
//! (`userNode`, `specs/gltf-fat.md`) so the face reads back with the same eye motion.
//!
//! The node keeps its own rest transform and place in the user's hierarchy. A played frame
//! turns it by the transform's own motion in the face frame (the eyeball turned about its
//! centre, the transform's `center`, by the FAT's axis and angle), mapped into the node's
//! parent frame; when the node's origin is not that centre its translation moves with the
//! turn, so the mesh moves exactly as the FAT says.

use glam::{Affine3A, Mat4, Quat, Vec3};
use serde_json::Value;

use super::gltf_rotations::{descends, eye_nodes, node_parents, world_matrices, RotationNodes};
use crate::error::Diagnostic;
use crate::face::FaceModel;
use crate::gltf::source::GltfSource;
use crate::spec::FeaturePointId;

/// The face transforms of `face` that the user's eye nodes show, as `(transform, node)`.
/// Nodes already showing a transform (`taken`) are left as they are. An eye node whose
/// meshes are not one eyeball turned alone by the FAT (no pupil 3.5/3.6 on them, other
/// feature points or the other pupil on them, a skinned mesh, parts of other transforms, a
/// `matrix` node) is not used: a warning says why, and its motion stays in morph targets.
pub fn eye_transforms(
    face: &FaceModel,
    source: &GltfSource,
    names: &RotationNodes,
    taken: &[Option<usize>],
    warnings: &mut Vec<Diagnostic>,
) -> Vec<(usize, usize)> {
    let (left, right) = eye_nodes(source, names);
    let json = &source.json;
    let parents = node_parents(json);
    let mut out = Vec::new();
    for (node, pupil, other) in [
        (left, FeaturePointId::FP_3_5, FeaturePointId::FP_3_6),
        (right, FeaturePointId::FP_3_6, FeaturePointId::FP_3_5),
    ] {
        let Some(node) = node.filter(|n| !taken.contains(&Some(*n))) else {
            continue;
        };
        let label = json["nodes"][node]["name"]
            .as_str()
            .map_or_else(|| format!("#{node}"), str::to_string);
        let refuse = |why: String| {
            Diagnostic::warning(format!(
                "{}: eye node `{label}` is not turned ({why}); its eye motion stays in morph \
                 targets",
                source.path.display()
            ))
        };
        // The face meshes this node carries: its own and its descendants'.
        let under: Vec<usize> = face
            .meshes
            .iter()
            .enumerate()
            .filter(|(_, m)| {
                source
                    .part(&m.name)
                    .and_then(|p| p.node)
                    .is_some_and(|n| descends(&parents, n, node))
            })
            .map(|(i, _)| i)
            .collect();
        if under.is_empty() {
            // A bone skinned meshes follow, or an empty node: nothing of the face to turn.
            continue;
        }
        let Some(transform) = face.meshes[under[0]].transform else {
            continue;
        };
        if !face
            .fat
            .tables
            .iter()
            .flat_map(|t| &t.transforms)
            .any(|x| face.transform_index(&x.transform) == Some(transform))
        {
            // The FAT does not move it: nothing to animate.
            continue;
        }
        let pupil_on = face
            .fp_vertex(pupil)
            .is_some_and(|(m, _)| under.contains(&m));
        if !pupil_on {
            warnings.push(refuse(format!("its mesh holds no pupil {pupil}")));
            continue;
        }
        let skin_on = face
            .feature_points
            .iter()
            .filter(|p| p.id != pupil)
            .find(|p| {
                face.fp_vertex(p.id)
                    .is_some_and(|(m, _)| under.contains(&m))
            });
        if let Some(p) = skin_on {
            let what = if p.id == other {
                "it holds both eyes".to_string()
            } else {
                format!("its mesh carries skin: feature point {}", p.id)
            };
            warnings.push(refuse(what));
            continue;
        }
        if under.iter().any(|&m| {
            source
                .part(&face.meshes[m].name)
                .and_then(|p| p.node)
                .is_some_and(|n| json["nodes"][n].get("skin").is_some())
        }) {
            warnings.push(refuse("its mesh is skinned".into()));
            continue;
        }
        // The transform turns exactly these meshes (none of another part or of the skin).
        let moved_by = |m: usize| {
            let mut at = face.meshes[m].transform;
            let mut depth = 0;
            while let Some(t) = at {
                if t == transform {
                    return true;
                }
                depth += 1;
                if depth > face.transforms.len() {
                    break;
                }
                at = face.transforms.get(t).and_then(|x| x.parent);
            }
            false
        };
        let exact = (0..face.meshes.len()).all(|m| moved_by(m) == under.contains(&m));
        if !exact {
            warnings.push(refuse(
                "its meshes and the eyeball the face turns are not the same".into(),
            ));
            continue;
        }
        if json["nodes"][node].get("matrix").is_some() {
            warnings.push(refuse(
                "it is given by a matrix, which glTF cannot animate".into(),
            ));
            continue;
        }
        out.push((transform, node));
    }
    out
}

/// A user's node showing a face transform: its rest frames in the file.
#[derive(Clone, Debug)]
pub struct UserNode {
    /// The node's world matrix at rest.
    world: Mat4,
    /// Its parent's world matrix at rest.
    parent_world: Mat4,
    /// Its rest translation (the animation's base).
    rest_translation: Vec3,
}

impl UserNode {
    /// The frames of node `node` of `json`.
    pub fn new(json: &Value, node: usize) -> Option<UserNode> {
        let (world, parent) = world_matrices(json);
        let w = *world.get(node)?;
        let parent_world = parent[node].map_or(Mat4::IDENTITY, |p| world[p]);
        if parent_world.determinant().abs() < 1e-20 || !parent_world.is_finite() {
            return None;
        }
        let (_, _, rest_translation) = (parent_world.inverse() * w).to_scale_rotation_translation();
        Some(UserNode {
            world: w,
            parent_world,
            rest_translation,
        })
    }

    /// The node's local rotation and translation when its mesh moves by `delta`, a motion in
    /// the file's world frame.
    pub fn local(&self, delta: Affine3A) -> (Quat, Vec3) {
        let local = self.parent_world.inverse() * Mat4::from(delta) * self.world;
        let (_, r, t) = local.to_scale_rotation_translation();
        (r.normalize(), t)
    }

    /// The rest translation.
    pub fn rest_translation(&self) -> Vec3 {
        self.rest_translation
    }
}

/// The world-frame motion (face frame, lengths × `unit`) of a transform alone, its parents
/// at rest: `parent` is the parent's world matrix, `rest` the transform's local matrix and
/// `animated` the local matrix of a played frame.
pub fn world_delta(parent: Affine3A, rest: Affine3A, animated: Affine3A, unit: f32) -> Affine3A {
    let d = parent * animated * rest.inverse() * parent.inverse();
    let s = Affine3A::from_scale(Vec3::splat(unit));
    s * d * s.inverse()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A world-frame turn about a pivot off the node's origin, under a turned and scaled
    /// parent, comes back as the node's local rotation and translation: the node's world
    /// matrix is the turn applied to its rest one.
    #[test]
    fn a_world_turn_becomes_the_nodes_local_pose() {
        let parent = Quat::from_rotation_x(-1.2);
        let json = serde_json::json!({"nodes": [
            {"scale": [0.01, 0.01, 0.01], "rotation": parent.to_array(), "children": [1]},
            {"translation": [3.0, 1.0, 2.0], "rotation": Quat::from_rotation_z(0.3).to_array()}
        ]});
        let node = UserNode::new(&json, 1).unwrap();
        assert!(
            node.local(Affine3A::IDENTITY)
                .0
                .angle_between(Quat::from_rotation_z(0.3))
                < 1e-3
        );
        let pivot = Vec3::new(0.02, 0.0, 0.05);
        let turn = Affine3A::from_translation(pivot)
            * Affine3A::from_rotation_y(0.2)
            * Affine3A::from_translation(-pivot);
        let (r, t) = node.local(turn);
        let local = Mat4::from_rotation_translation(r, t);
        let (world, _) = world_matrices(&json);
        let got = world[0] * local;
        let want = Mat4::from(turn) * world[1];
        assert!(got.abs_diff_eq(want, 1e-5), "{got} vs {want}");
        assert!(descends(&[None, Some(0)], 1, 0) && !descends(&[None, Some(0)], 0, 1));
    }
}
