//! The glTF document a face was read from, kept whole so that writing the face back patches
//! the user's file instead of generating a new one (see [`super::patch`]).
//!
//! The JSON is kept as a `serde_json::Value`: nodes, materials, skins, animations, cameras,
//! extensions and extras fbakit knows nothing about survive with their meaning intact. Each
//! face mesh read from the document remembers where it came from ([`SourcePart`]: node, mesh,
//! primitive) and the rest-pose matrix that placed its vertices in the file's world frame, so
//! motions computed in that frame can be mapped back into the mesh's own space.

use std::path::PathBuf;

use glam::{Mat3, Mat4, Vec3};

/// A glTF document as read: JSON, buffer bytes and the origin of every face mesh.
#[derive(Clone, PartialEq)]
pub struct GltfSource {
    /// The file it was read from (locates external images when the output is elsewhere).
    pub path: PathBuf,
    /// The whole JSON document.
    pub json: serde_json::Value,
    /// The bytes of each buffer, in `buffers` order (the GLB `BIN` chunk for a `.glb`).
    pub buffers: Vec<Vec<u8>>,
    /// One entry per face mesh read from the document, in reading order.
    pub parts: Vec<SourcePart>,
}

impl std::fmt::Debug for GltfSource {
    // The buffers are megabytes: their sizes say enough.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GltfSource")
            .field("path", &self.path)
            .field(
                "buffers",
                &self.buffers.iter().map(Vec::len).collect::<Vec<_>>(),
            )
            .field("parts", &self.parts)
            .finish_non_exhaustive()
    }
}

impl GltfSource {
    /// The part the face mesh named `name` came from.
    pub fn part(&self, name: &str) -> Option<&SourcePart> {
        self.parts.iter().find(|p| p.face_mesh == name)
    }

    /// Names of mesh `m`'s morph targets as the document gives them (empty when it names
    /// none); see [`target_names_value`].
    pub fn target_names(&self, m: usize) -> Vec<String> {
        target_names_value(&self.json["meshes"][m])
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect()
    }
}

/// The `targetNames` array of a glTF mesh object: in the mesh's extras, else in its first
/// primitive's (tools write either).
pub fn target_names_value(mesh: &serde_json::Value) -> Option<&Vec<serde_json::Value>> {
    mesh["extras"]["targetNames"]
        .as_array()
        .or_else(|| mesh["primitives"][0]["extras"]["targetNames"].as_array())
}

/// Where one face mesh came from in the document.
#[derive(Clone, Debug, PartialEq)]
pub struct SourcePart {
    /// Name of the face mesh (unique within the face).
    pub face_mesh: String,
    /// The node that instances the mesh (`None` for a file without nodes).
    pub node: Option<usize>,
    /// Index into `meshes`.
    pub mesh: usize,
    /// Index into the mesh's `primitives`.
    pub primitive: usize,
    /// Vertex count of the primitive (its `POSITION` count).
    pub vertex_count: usize,
    /// How the primitive's own coordinates were placed in the file's world frame.
    pub rest: RestPose,
}

/// The rest-pose placement of a primitive's vertices (mesh space → world).
#[derive(Clone, Debug, PartialEq)]
pub enum RestPose {
    /// One matrix for every vertex: the node's world matrix, or the common skin matrix.
    Matrix(Mat4),
    /// A skinned primitive whose joints do not move together: per vertex the blend of its
    /// joints' `world × inverseBind` matrices.
    PerVertex(Vec<Mat4>),
}

impl RestPose {
    /// The matrix placing vertex `v`.
    pub fn matrix(&self, v: usize) -> Mat4 {
        match self {
            RestPose::Matrix(m) => *m,
            RestPose::PerVertex(list) => list.get(v).copied().unwrap_or(Mat4::IDENTITY),
        }
    }

    /// A world-space displacement of vertex `v` in the primitive's own space (the inverse of
    /// the placement's linear part; a singular placement leaves the displacement as it is).
    pub fn to_local(&self, v: usize, world: Vec3) -> Vec3 {
        let linear = Mat3::from_mat4(self.matrix(v));
        let det = linear.determinant();
        if det.abs() < 1e-12 || !det.is_finite() {
            return world;
        }
        linear.inverse() * world
    }

    /// Whether the placement changes nothing.
    pub fn is_identity(&self) -> bool {
        matches!(self, RestPose::Matrix(m) if m.abs_diff_eq(Mat4::IDENTITY, 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displacements_map_back_through_the_placement() {
        let m = Mat4::from_scale(Vec3::splat(0.01)) * Mat4::from_rotation_x(-1.0);
        let rest = RestPose::Matrix(m);
        let local = Vec3::new(1.0, 2.0, 3.0);
        let world = Mat3::from_mat4(m) * local;
        assert!(rest.to_local(0, world).abs_diff_eq(local, 1e-4));
        let per = RestPose::PerVertex(vec![Mat4::IDENTITY, m]);
        assert_eq!(per.to_local(0, world), world);
        assert!(per.to_local(1, world).abs_diff_eq(local, 1e-4));
        assert!(RestPose::Matrix(Mat4::IDENTITY).is_identity());
        assert!(!rest.is_identity());
    }
}
