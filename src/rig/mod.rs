//! Blendshape rigs: a neutral face plus named blend shapes (morph targets), the form real faces
//! come in (ARKit-named glTF morph targets, folders of OBJs such as the ICT-FaceKit).
//!
//! A [`Rig`] holds the neutral meshes in world space (node transforms already applied), their
//! material groups, and for every named [`BlendShape`] the per-mesh vertex deltas at weight 1,
//! stored sparsely (only moved vertices). Readers:
//!
//! - [`gltf_read`]: glTF 2.0 (`.glb`, `.gltf` with external or data-URI buffers) through the
//!   `gltf` crate; targets named by `mesh.extras.targetNames`.
//! - [`obj_folder`]: a neutral OBJ plus one full-mesh OBJ per shape (the ICT-FaceKit layout),
//!   read in parallel.
//!
//! [`read_rig`] picks the reader from the path; [`Rig::to_face`] gives the neutral as a
//! [`FaceModel`] (meshes, no FAT), and [`gltf_write`] writes a rig back as glTF morph targets.
//! Shapes with the same name on several meshes (a head and its teeth both moving under
//! `jawOpen`) are one shape.
//!
//! The ARKit bridge: [`arkit_names`] (the 52 shapes and which rig shapes play them),
//! [`weights_csv`] (capture-app weight curves), [`bounded_ls`] (the box-constrained least
//! squares both directions solve), [`arkit_weights`] (weights ⇄ FAP values on a rig and its
//! FAT), [`arkit_amplitudes`] (FAP values per ARKit shape, measured) and [`arkit_export`]
//! (any FAT face as ARKit-named shapes).

pub mod arkit_amplitudes;
pub mod arkit_export;
pub mod arkit_names;
pub mod arkit_weights;
pub mod bounded_ls;
pub mod capture;
mod error;
pub mod fap_map;
pub mod fat_build;
pub(crate) mod gltf_accessor;
#[cfg(test)]
mod gltf_encodings_tests;
pub mod gltf_read;
pub mod gltf_write;
pub mod obj_folder;
pub mod trim;
pub mod weights_csv;

pub use error::RigError;

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;
use serde::Serialize;

use crate::error::{Diagnostic, Error, Result};
use crate::face::{FaceMesh, FaceModel};
use crate::mesh::Mesh;

/// Most vertices a rig may have over all its meshes (refused before allocating more).
pub const MAX_RIG_VERTICES: usize = 32 << 20;

/// Most blend shapes a rig may have.
pub const MAX_RIG_SHAPES: usize = 4096;

/// One neutral mesh of a rig, in world space.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RigMesh {
    /// Unique name within the rig.
    pub name: String,
    /// Geometry: positions, polygons, uvs, normals and material groups ([`Mesh::groups`]).
    pub mesh: Mesh,
}

/// The motion of one mesh under one blend shape at weight 1.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShapeDelta {
    /// Index into [`Rig::meshes`].
    pub mesh: usize,
    /// Moved vertices, increasing.
    pub vertices: Vec<u32>,
    /// Displacement of each moved vertex (world space, same units as the mesh).
    pub offsets: Vec<Vec3>,
}

/// A named blend shape (morph target).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlendShape {
    /// Name as the rig gives it (`jawOpen`, `eyeBlink_L`, `aa`, ...).
    pub name: String,
    /// Weight in the rig's rest pose (glTF `weights`); usually 0.
    pub default_weight: f32,
    /// Per-mesh deltas (meshes the shape does not move are absent).
    pub deltas: Vec<ShapeDelta>,
}

impl BlendShape {
    /// The delta of mesh `mesh`, if the shape moves it.
    pub fn delta(&self, mesh: usize) -> Option<&ShapeDelta> {
        self.deltas.iter().find(|d| d.mesh == mesh)
    }

    /// Number of moved vertices over all meshes.
    pub fn moved_vertex_count(&self) -> usize {
        self.deltas.iter().map(|d| d.vertices.len()).sum()
    }

    /// Displacement of vertex `vertex` of mesh `mesh` at weight 1 (zero if it does not move).
    pub fn offset(&self, mesh: usize, vertex: u32) -> Vec3 {
        self.delta(mesh)
            .and_then(|d| d.vertices.binary_search(&vertex).ok().map(|k| d.offsets[k]))
            .unwrap_or(Vec3::ZERO)
    }
}

/// A blendshape rig: neutral meshes plus named shapes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rig {
    /// A name for messages and outputs (file stem or folder name).
    pub name: String,
    /// The neutral meshes, world space.
    pub meshes: Vec<RigMesh>,
    /// The blend shapes, in file order.
    pub shapes: Vec<BlendShape>,
    /// Things the reader skipped or worked around (printed as warnings).
    pub warnings: Vec<Diagnostic>,
    /// The glTF document the rig was read from (kept so outputs patch it), if any.
    #[serde(skip)]
    pub source: Option<std::sync::Arc<crate::gltf::source::GltfSource>>,
}

impl Rig {
    /// Index of the shape named `name` (exact match).
    pub fn shape_index(&self, name: &str) -> Option<usize> {
        self.shapes.iter().position(|s| s.name == name)
    }

    /// The shape named `name` (exact match).
    pub fn shape(&self, name: &str) -> Option<&BlendShape> {
        self.shapes.iter().find(|s| s.name == name)
    }

    /// Total vertex count over all meshes.
    pub fn vertex_count(&self) -> usize {
        self.meshes.iter().map(|m| m.mesh.vertex_count()).sum()
    }

    /// Checks the invariants every reader guarantees: unique mesh and shape names, deltas
    /// pointing at existing meshes and vertices (increasing), finite numbers.
    pub fn check(&self) -> Result<()> {
        let mut names = HashMap::new();
        for m in &self.meshes {
            if names.insert(m.name.as_str(), ()).is_some() {
                return Err(RigError::DuplicateMesh {
                    rig: self.name.clone(),
                    mesh: m.name.clone(),
                }
                .into());
            }
        }
        let mut names = HashMap::new();
        for s in &self.shapes {
            if s.name.is_empty() {
                return Err(RigError::UnnamedShape {
                    rig: self.name.clone(),
                }
                .into());
            }
            if names.insert(s.name.as_str(), ()).is_some() {
                return Err(RigError::DuplicateShape {
                    rig: self.name.clone(),
                    shape: s.name.clone(),
                }
                .into());
            }
            if !s.default_weight.is_finite() {
                return Err(RigError::NonFiniteWeight {
                    rig: self.name.clone(),
                    shape: s.name.clone(),
                }
                .into());
            }
            for d in &s.deltas {
                let rig = || self.name.clone();
                let shape = || s.name.clone();
                let Some(m) = self.meshes.get(d.mesh) else {
                    return Err(RigError::ShapeUnknownMesh {
                        rig: rig(),
                        shape: shape(),
                        mesh: d.mesh,
                    }
                    .into());
                };
                if d.vertices.len() != d.offsets.len()
                    || d.vertices.windows(2).any(|w| w[0] >= w[1])
                    || d.vertices
                        .last()
                        .is_some_and(|&v| v as usize >= m.mesh.vertex_count())
                {
                    return Err(RigError::BadVertexList {
                        rig: rig(),
                        shape: shape(),
                        mesh: m.name.clone(),
                    }
                    .into());
                }
                if !d.offsets.iter().all(|o| o.is_finite()) {
                    return Err(RigError::NonFiniteOffset {
                        rig: rig(),
                        shape: shape(),
                        mesh: m.name.clone(),
                    }
                    .into());
                }
            }
        }
        Ok(())
    }

    /// Fails unless the rig has at least one shape (`file` names the source in the message).
    pub fn require_shapes(&self, file: &Path) -> Result<()> {
        if self.shapes.is_empty() {
            return Err(RigError::NoShapes {
                file: file.to_path_buf(),
            }
            .into());
        }
        Ok(())
    }

    /// World positions of mesh `mesh` with the shapes at `weights` (`(shape index, weight)`).
    pub fn posed_positions(&self, mesh: usize, weights: &[(usize, f32)]) -> Vec<Vec3> {
        let mut out = self.meshes[mesh].mesh.positions.clone();
        for &(s, w) in weights {
            if let Some(d) = self.shapes.get(s).and_then(|s| s.delta(mesh)) {
                for (&v, &o) in d.vertices.iter().zip(&d.offsets) {
                    out[v as usize] += o * w;
                }
            }
        }
        out
    }

    /// The neutral as a face with a FAT realised through `map` and calibrated on
    /// `feature_points` (see [`fat_build`]), with the report of what was realised.
    pub fn to_face_with_fat(
        &self,
        feature_points: Option<crate::fdp::FeaturePointSet>,
        map: &fap_map::FapMap,
    ) -> Result<(FaceModel, fat_build::RigFatReport)> {
        fat_build::face_from_rig(self, feature_points, map)
    }

    /// The neutral as a face: one [`FaceMesh`] per rig mesh (world space, no transforms), no
    /// feature points, no FAT. Part names a cloner recognises (eyes, teeth) come from the mesh
    /// names.
    pub fn to_face(&self) -> FaceModel {
        let mut face = FaceModel::new(self.name.clone());
        face.meshes = self
            .meshes
            .iter()
            .map(|m| FaceMesh {
                name: m.name.clone(),
                transform: None,
                mesh: m.mesh.clone(),
                color: None,
            })
            .collect();
        face.gltf_source = self.source.clone();
        face
    }
}

/// Sparse delta of `shape` against `neutral` (equal lengths): every vertex that moved at all.
pub fn sparse_delta(mesh: usize, neutral: &[Vec3], shape: &[Vec3]) -> ShapeDelta {
    let mut vertices = Vec::new();
    let mut offsets = Vec::new();
    for (i, (s, n)) in shape.iter().zip(neutral).enumerate() {
        let d = *s - *n;
        if d != Vec3::ZERO {
            vertices.push(i as u32);
            offsets.push(d);
        }
    }
    ShapeDelta {
        mesh,
        vertices,
        offsets,
    }
}

/// Reads a rig: `.glb` / `.gltf` through [`gltf_read`], a folder or a neutral `.obj` through
/// [`obj_folder`]. A rig without blend shapes is an error.
pub fn read_rig(path: &Path) -> Result<Rig> {
    let rig = if path.is_dir() {
        obj_folder::read_obj_rig(path)?
    } else {
        match extension(path).as_deref() {
            Some("glb" | "gltf") => gltf_read::read_gltf(path)?,
            Some("obj") => obj_folder::read_obj_rig(path)?,
            _ => {
                return Err(Error::Unsupported(format!(
                    "{}: a rig is a .glb/.gltf file, a folder of OBJs or a neutral .obj",
                    path.display()
                )))
            }
        }
    };
    rig.require_shapes(path)?;
    Ok(rig)
}

/// Lower-case extension of `path`.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
}

/// Rig name from a path: file stem or folder name.
fn rig_name(path: &Path) -> String {
    let p = if path.is_dir() {
        path.file_name()
    } else {
        path.file_stem()
    };
    p.map_or_else(|| "rig".to_string(), |s| s.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests;
