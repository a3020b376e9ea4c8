//! Face transforms shown by the user's own glTF nodes: the eyeballs.
//!
//! A cloned face turns each eyeball by a transform of its own (FAPs 23–26). When the user's
//! document has eye nodes (`--eye-nodes`, the usual names such as `LeftEye`, or the VRM eye
//! bones, as [`super::gltf_rotations::eye_nodes`] finds them) that move that eyeball's mesh
//! and nothing else of the face — the mesh under the node, or skinned to it as an eye joint
//! (`world × inverseBind` of the joint places the eyeball, so turning the joint turns it) —
//! the transform is shown by that node: its motion is animated
//! on the node, not baked into morph targets, and recorded in the document's FAT extras
//! (`userNode`, `specs/gltf-fat.md`) so the face reads back with the same eye motion.
//!
//! The node keeps its own rest transform and place in the user's hierarchy. A played frame
//! turns it by the transform's own motion in the face frame (the eyeball turned about its
//! centre, the transform's `center`, by the FAT's axis and angle), mapped into the node's
//! parent frame; when the node's origin is not that centre its translation moves with the
//! turn, so the mesh moves exactly as the FAT says.
//!
//! The eye's transform may also hold meshes the node does not move at all: an eye white on
//! a node of its own or in another mesh, beside the iris under the eye node. The node then
//! shows the turn of what it holds, and those meshes take the same turn as per-vertex
//! targets ([`EyeNode::apart`]), recorded above the transform so the file reads back with
//! their motion once.

use glam::{Affine3A, Mat4, Quat, Vec3};
use serde_json::Value;

use super::gltf_carried::ShareReader;
use super::gltf_rotations::{eye_nodes, world_matrices, RotationNodes};
use crate::error::Diagnostic;
use crate::face::FaceModel;
use crate::fat::TableKey;
use crate::gltf::source::GltfSource;
use crate::spec::FeaturePointId;

/// Least share of an eyeball's skin weight on its eye joint (and the joints below it) for
/// the joint to turn it: a few stray weights are tolerated.
const EYEBALL_CARRIED: f32 = 0.95;
/// Largest share of a vertex the eye node may move when it is not the eyeball's: more would
/// turn skin (a lid weighted to the eye bone) with the eye.
const STRAY_SHARE: f32 = 1e-3;

/// The warning for an eye node of `source` that does not turn its eyeball, and `why`.
pub(super) fn eye_node_refusal(source: &GltfSource, node: usize, why: &str) -> Diagnostic {
    let label = source.json["nodes"][node]["name"]
        .as_str()
        .map_or_else(|| format!("#{node}"), str::to_string);
    Diagnostic::warning(format!(
        "{}: eye node `{label}` is not turned ({why}); its eye motion stays in morph targets",
        source.path.display()
    ))
}

/// The face transforms of `face` that the user's eye nodes show.
/// Nodes already showing a transform (`taken`) are left as they are. An eye node shows an
/// eyeball when it moves that eyeball alone: a plain mesh under it, or a skinned mesh
/// weighted to it (or the joints below it) by at least 95 % (the usual VRM, Mixamo or
/// ReadyPlayerMe eye bone). An eye node whose meshes are not one eyeball turned alone by the
/// FAT (no pupil 3.5/3.6 on them, other feature points or the other pupil on them, an
/// eyeball partly weighted to it, skin weighted to it, parts of other transforms, a `matrix`
/// node) is not used: a warning says why, and its motion stays in morph targets. An eyeball
/// that is vertices of a bigger mesh (no transform of its own: the FAT moves it vertex by
/// vertex) is left to [`super::gltf_eye_parts::eye_parts`].
pub fn eye_transforms(
    face: &FaceModel,
    source: &GltfSource,
    names: &RotationNodes,
    taken: &[Option<usize>],
    warnings: &mut Vec<Diagnostic>,
) -> Vec<EyeNode> {
    let (left, right) = eye_nodes(source, names);
    let json = &source.json;
    let reader = ShareReader::new(source);
    let mut out = Vec::new();
    for (node, pupil, other, faps) in [
        (
            left,
            FeaturePointId::FP_3_5,
            FeaturePointId::FP_3_6,
            [23, 25, 27],
        ),
        (
            right,
            FeaturePointId::FP_3_6,
            FeaturePointId::FP_3_5,
            [24, 26, 28],
        ),
    ] {
        let Some(node) = node.filter(|n| !taken.contains(&Some(*n))) else {
            continue;
        };
        let refuse = |why: String| eye_node_refusal(source, node, &why);
        // How much of each face mesh's vertices the node moves (its own meshes and its
        // descendants', or skin weights on it and the joints below it).
        let mut unreadable = None;
        let shares: Vec<Vec<f32>> = face
            .meshes
            .iter()
            .map(|m| {
                let n = m.mesh.vertex_count();
                let Some(part) = source.part(&m.name) else {
                    return vec![0.0; n];
                };
                match reader.shares(part.node, part.mesh, part.primitive, node) {
                    Some(s) => s.of(n),
                    None => {
                        unreadable.get_or_insert_with(|| m.name.clone());
                        vec![0.0; n]
                    }
                }
            })
            .collect();
        let under: Vec<usize> = (0..face.meshes.len())
            .filter(|&m| shares[m].iter().any(|&s| s > STRAY_SHARE))
            .collect();
        if under.is_empty() {
            if let Some(m) = unreadable {
                warnings.push(refuse(format!(
                    "the skin weights of mesh `{m}` cannot be read"
                )));
            }
            // A bone no face vertex follows, or an empty node: nothing of the face to turn.
            continue;
        }
        let pupil_mesh = face
            .fp_vertex(pupil)
            .map(|(m, _)| m)
            .filter(|m| under.contains(m));
        let Some(transform) = face.meshes[pupil_mesh.unwrap_or(under[0])].transform else {
            // No transform of its own: an eyeball that is vertices of a bigger mesh (a
            // one-primitive eyes mesh cut apart and baked by the cloner) is left to
            // `gltf_eye_parts`.
            continue;
        };
        let moves = |eye: bool| {
            face.fat
                .tables
                .iter()
                .filter(|t| {
                    !eye || matches!(t.key, TableKey::LowLevel(f) if faps.contains(&f.number()))
                })
                .flat_map(|t| &t.transforms)
                .any(|x| face.transform_index(&x.transform) == Some(transform))
        };
        if !moves(false) {
            // The FAT does not move it: nothing to animate.
            continue;
        }
        if pupil_mesh.is_none() {
            warnings.push(refuse(format!("its mesh holds no pupil {pupil}")));
            continue;
        }
        if !moves(true) {
            // Not the eye's own transform (the mesh hangs under the head's): its eyeball is
            // vertices of the mesh, left to `gltf_eye_parts`.
            continue;
        }
        let skin_on = face
            .feature_points
            .iter()
            .filter(|p| p.id != pupil)
            .find(|p| {
                face.fp_vertex(p.id).is_some_and(|(m, v)| {
                    shares[m].get(v as usize).is_some_and(|&s| s > STRAY_SHARE)
                })
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
        if let Some(m) = (0..face.meshes.len()).find(|&m| !moved_by(m) && under.contains(&m)) {
            let skinned = source
                .part(&face.meshes[m].name)
                .and_then(|p| p.node)
                .is_some_and(|n| json["nodes"][n].get("skin").is_some());
            warnings.push(refuse(if skinned {
                format!(
                    "mesh `{}` is weighted to it too, not only the eyeball",
                    face.meshes[m].name
                )
            } else {
                "its meshes and the eyeball the face turns are not the same".into()
            }));
            continue;
        }
        // Meshes of the eyeball the node does not move at all (an eye white beside an iris
        // under the eye node): the node shows the turn of its own meshes, and theirs is
        // baked into per-vertex targets with the same motion.
        let apart: Vec<usize> = (0..face.meshes.len())
            .filter(|&m| moved_by(m) && shares[m].iter().all(|&s| s <= STRAY_SHARE))
            .collect();
        let partly = (0..face.meshes.len())
            .filter(|&m| moved_by(m) && !apart.contains(&m))
            .find_map(|m| {
                let s = &shares[m];
                let mean = s.iter().sum::<f32>() / s.len().max(1) as f32;
                (mean < EYEBALL_CARRIED).then_some((m, mean))
            });
        if let Some((m, mean)) = partly {
            warnings.push(refuse(if mean <= STRAY_SHARE {
                "its meshes and the eyeball the face turns are not the same".into()
            } else {
                format!(
                    "mesh `{}` of the eyeball is weighted to it by {:.0} % only, not {:.0} %",
                    face.meshes[m].name,
                    mean * 100.0,
                    EYEBALL_CARRIED * 100.0
                )
            }));
            continue;
        }
        if json["nodes"][node].get("matrix").is_some() {
            warnings.push(refuse(
                "it is given by a matrix, which glTF cannot animate".into(),
            ));
            continue;
        }
        out.push(EyeNode {
            transform,
            node,
            apart,
        });
    }
    out
}

/// A face transform shown by a user's eye node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EyeNode {
    /// The face transform.
    pub transform: usize,
    /// The glTF node showing it.
    pub node: usize,
    /// Face meshes the transform moves that the node does not (an eye white beside the iris
    /// it holds): their share of the motion is baked into per-vertex targets.
    pub apart: Vec<usize>,
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

    /// The node's origin in the file's world frame at rest.
    pub fn world_origin(&self) -> Vec3 {
        self.world.w_axis.truncate()
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
    use crate::export::gltf_rotations::descends;

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
