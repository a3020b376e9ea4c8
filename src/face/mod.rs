//! A complete MPEG-4 face model: scene graph (meshes under transforms), feature points (FDP)
//! and Facial Animation Tables (FAT).
//!
//! [`FaceModel`] is what cloning and playing work on. Every face enters through one front
//! door, [`read()`] (any format, by extension or content, or a bundled face by name), and
//! leaves through [`write()`] (VRML, gzip VRML, OBJ; glTF is [`crate::export::gltf`]). Faces
//! are also built from OBJ morph sets ([`morphs`]) and from CANDIDE-3 ([`candide`]);
//! [`summary`] describes one and [`validate`] checks one.
//!
//! Frames: mesh positions and FAT displacements are in each mesh's local frame (its
//! `Coordinate` node); [`FaceModel::frames`] places them in the face frame (MPEG-4: +x the
//! face's own left, +y up, +z forward), where feature points and FAPUs live.

pub mod attach;
pub mod bundled;
pub mod candide;
mod error;
pub mod format;
mod from_rig;
pub mod gltf_fat;
pub mod morphs;
pub mod mouth;
pub mod parts;
pub mod pose;
pub mod read;
pub mod snap;
pub mod subdivide;
pub mod summary;
pub mod units;
pub mod validate;
pub mod vertex_index;
pub mod visemes;
pub mod vrml;
pub mod write;

pub use bundled::BundledFace;
pub use error::FaceError;
pub use format::FaceFormat;
pub use pose::FacePose;
pub use read::{read, read_bytes, read_with, FaceReadOptions};
pub use vrml::FaceReadReport;
pub use write::write;

use std::collections::HashMap;

use glam::{Affine3A, Quat, Vec3};
use serde::Serialize;

use crate::error::Result;
use crate::fat::eval::FatEvaluator;
use crate::fat::Fat;
use crate::fdp::{Fapu, FeaturePointSet};
use crate::mesh::Mesh;
use crate::spec::FeaturePointId;

/// A `Transform` node of the face.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaceTransform {
    /// `DEF` name (unique within the face).
    pub name: String,
    /// Enclosing transform, if any.
    pub parent: Option<usize>,
    /// `translation`.
    pub translation: Vec3,
    /// `rotation`.
    pub rotation: Quat,
    /// `scale`.
    pub scale: Vec3,
    /// `scaleOrientation`.
    pub scale_orientation: Quat,
    /// `center`: the centre of rotation and scaling.
    pub center: Vec3,
}

impl FaceTransform {
    /// A neutral transform with the given name, parent and centre.
    pub fn new(name: impl Into<String>, parent: Option<usize>, center: Vec3) -> Self {
        FaceTransform {
            name: name.into(),
            parent,
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
            scale_orientation: Quat::IDENTITY,
            center,
        }
    }

    /// The local matrix with a FAT change applied: the FAT rotation turns the neutral
    /// rotation further in the parent's axes (`ΔR · R`), translation and scale changes add, and
    /// the whole turns about `center`. Every consumer (player, morph export, cloning
    /// evaluation) poses transforms through this one rule.
    pub fn animated_matrix(&self, d: &crate::fat::eval::TransformDelta) -> Affine3A {
        if *d == crate::fat::eval::TransformDelta::IDENTITY {
            return self.local_matrix();
        }
        local_matrix(
            self.translation + d.translation,
            d.rotation * self.rotation,
            self.scale + d.scale,
            self.scale_orientation,
            self.center,
        )
    }

    /// The VRML97 local matrix `T · C · R · SR · S · SR⁻¹ · C⁻¹`.
    pub fn local_matrix(&self) -> Affine3A {
        local_matrix(
            self.translation,
            self.rotation,
            self.scale,
            self.scale_orientation,
            self.center,
        )
    }
}

/// The VRML97 `Transform` matrix from its fields.
pub fn local_matrix(t: Vec3, r: Quat, s: Vec3, so: Quat, c: Vec3) -> Affine3A {
    Affine3A::from_translation(t + c)
        * Affine3A::from_quat(r)
        * Affine3A::from_quat(so)
        * Affine3A::from_scale(s)
        * Affine3A::from_quat(so.inverse())
        * Affine3A::from_translation(-c)
}

/// One `IndexedFaceSet` of the face with its appearance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaceMesh {
    /// `DEF` name of the `IndexedFaceSet` (unique within the face; FATs refer to it).
    pub name: String,
    /// Enclosing transform, if any.
    pub transform: Option<usize>,
    /// Geometry in the mesh's local frame.
    pub mesh: Mesh,
    /// `Material.diffuseColor`, if given.
    pub color: Option<[f32; 3]>,
}

/// A face: meshes, transforms, feature points and FAT.
///
/// Equality compares the content (transforms, meshes, feature points, FAT), not the name or
/// the kept scene, so a face equals itself after a write → read round trip.
#[derive(Clone, Debug)]
pub struct FaceModel {
    /// A name for messages and outputs.
    pub name: String,
    /// Transforms, parents before children.
    pub transforms: Vec<FaceTransform>,
    /// Meshes.
    pub meshes: Vec<FaceMesh>,
    /// Feature points: positions in the face frame, bound to mesh vertices where known.
    pub feature_points: FeaturePointSet,
    /// The Facial Animation Tables (empty for a plain target face).
    pub fat: Fat,
    /// The VRML scene it was read from, kept so writing preserves every other node.
    pub scene: Option<crate::vrml::Scene>,
    /// The OBJ text it was read from, kept so OBJ outputs keep the user's file (groups,
    /// materials, `vt`, `vn`, comments) and rewrite only its `v` lines ([`crate::mesh::obj_patch`]).
    pub obj_source: Option<std::sync::Arc<str>>,
    /// The OBJ file it was read from: its material libraries and textures are found beside
    /// it when OBJ outputs copy them.
    pub obj_path: Option<std::path::PathBuf>,
    /// The glTF document it was read from, kept so glTF outputs patch it (mesh names match
    /// [`crate::gltf::source::SourcePart::face_mesh`]).
    pub gltf_source: Option<std::sync::Arc<crate::gltf::source::GltfSource>>,
}

impl PartialEq for FaceModel {
    fn eq(&self, other: &Self) -> bool {
        self.transforms == other.transforms
            && self.meshes == other.meshes
            && self.feature_points == other.feature_points
            && self.fat == other.fat
    }
}

/// The face frame of each transform and mesh, computed once.
#[derive(Clone, Debug, Default)]
pub struct FaceFrames {
    /// World matrix of each transform.
    pub transforms: Vec<Affine3A>,
    /// World matrix of each mesh (its transform's, or identity).
    pub meshes: Vec<Affine3A>,
}

impl FaceModel {
    /// An empty face.
    pub fn new(name: impl Into<String>) -> Self {
        FaceModel {
            name: name.into(),
            transforms: Vec::new(),
            meshes: Vec::new(),
            feature_points: FeaturePointSet::new(),
            fat: Fat::default(),
            scene: None,
            obj_source: None,
            obj_path: None,
            gltf_source: None,
        }
    }

    /// A face of one untransformed mesh named `name` (the mesh takes the name too), as OBJ
    /// files, morph sets and CANDIDE-3 make them.
    pub fn single_mesh(name: impl Into<String>, mut mesh: Mesh) -> Self {
        let name = name.into();
        mesh.name = name.clone();
        let mut face = FaceModel::new(name.clone());
        face.meshes.push(FaceMesh {
            name,
            transform: None,
            mesh,
            color: None,
        });
        face
    }

    /// Index of the mesh named `name`.
    pub fn mesh_index(&self, name: &str) -> Option<usize> {
        self.meshes.iter().position(|m| m.name == name)
    }

    /// Index of the mesh a feature-point file names: a mesh name as the face has it, or
    /// for a face read from glTF (whose meshes are named after their node, else their glTF
    /// mesh, else `mesh{index}`, with `.{primitive}` when the mesh has several primitives)
    /// `Name/p` for primitive `p` of the node or mesh `Name`, and `#m/p` for primitive `p`
    /// of glTF mesh `m` when it and its node are unnamed. Names a glTF file repeats get a
    /// `_2`, `_3` suffix on the face and are named that way.
    pub fn resolve_mesh_spec(&self, spec: &str) -> Option<usize> {
        if let Some(i) = self.mesh_index(spec) {
            return Some(i);
        }
        let (base, p) = match spec.rsplit_once('/') {
            Some((base, p)) => (base, p.trim().parse::<usize>().ok()?),
            None => (spec, 0),
        };
        if let Some(i) = self.resolve_gltf_spec(base, p) {
            return Some(i);
        }
        let base = match base.strip_prefix('#') {
            Some(m) => format!("mesh{}", m.trim().parse::<usize>().ok()?),
            None => base.to_string(),
        };
        self.mesh_index(&format!("{base}.{p}"))
            .or_else(|| (p == 0).then(|| self.mesh_index(&base)).flatten())
    }

    /// Primitive `p` of the glTF node or mesh named `base` (or of mesh `#m`) in the document
    /// the face was read from: the face mesh it became, first instance first.
    fn resolve_gltf_spec(&self, base: &str, p: usize) -> Option<usize> {
        let doc = self.gltf_source.as_deref()?;
        let name_of = |list: &str, i: usize| doc.json[list][i]["name"].as_str();
        let index = base
            .strip_prefix('#')
            .and_then(|m| m.trim().parse::<usize>().ok());
        let part = doc.parts.iter().find(|s| {
            s.primitive == p
                && match index {
                    Some(m) => s.mesh == m,
                    None => {
                        name_of("meshes", s.mesh) == Some(base)
                            || s.node.and_then(|n| name_of("nodes", n)) == Some(base)
                    }
                }
        })?;
        self.mesh_index(&part.face_mesh)
    }

    /// Index of the transform named `name`.
    pub fn transform_index(&self, name: &str) -> Option<usize> {
        self.transforms.iter().position(|t| t.name == name)
    }

    /// World (face-frame) matrices of all transforms and meshes at neutral.
    pub fn frames(&self) -> FaceFrames {
        let locals: Vec<Affine3A> = self.transforms.iter().map(|t| t.local_matrix()).collect();
        self.frames_with(&locals)
    }

    /// World matrices given each transform's local matrix (e.g. animated ones). Transforms
    /// must come parents first, which readers and builders guarantee.
    pub fn frames_with(&self, locals: &[Affine3A]) -> FaceFrames {
        let mut frames = FaceFrames::default();
        self.frames_into(locals, &mut frames);
        frames
    }

    /// Face-frame positions of every vertex of mesh `mesh` at neutral (empty for an unknown
    /// mesh).
    pub fn mesh_world(&self, frames: &FaceFrames, mesh: usize) -> Vec<Vec3> {
        let Some(m) = self.meshes.get(mesh) else {
            return Vec::new();
        };
        let w = frames.meshes[mesh];
        m.mesh
            .positions
            .iter()
            .map(|&p| w.transform_point3(p))
            .collect()
    }

    /// Face-frame position of vertex `vertex` of mesh `mesh` at neutral.
    pub fn vertex_world(&self, frames: &FaceFrames, mesh: usize, vertex: u32) -> Option<Vec3> {
        let p = *self.meshes.get(mesh)?.mesh.positions.get(vertex as usize)?;
        Some(frames.meshes[mesh].transform_point3(p))
    }

    /// Re-derives every feature point bound to mesh vertices from the current geometry (the
    /// mean of its vertices, in the face frame). Points bound to unknown meshes or vertices
    /// are an error naming them all.
    pub fn resolve_feature_points(&mut self) -> Result<()> {
        let frames = self.frames();
        let names: HashMap<&str, usize> = self
            .meshes
            .iter()
            .enumerate()
            .map(|(i, m)| (m.name.as_str(), i))
            .collect();
        let meshes = &self.meshes;
        let lookup = |mesh: Option<&str>, v: u32| -> Option<Vec3> {
            let mi = match mesh {
                Some(n) => *names.get(n)?,
                None if meshes.len() == 1 => 0,
                None => return None,
            };
            let p = *meshes[mi].mesh.positions.get(v as usize)?;
            Some(frames.meshes[mi].transform_point3(p))
        };
        self.feature_points.resolve_positions(lookup).map(|_| ())
    }

    /// The face's FAP units measured on its feature points.
    pub fn fapu(&self) -> Result<Fapu> {
        Fapu::from_feature_points(&self.feature_points)
    }

    /// `(mesh name, vertex count)` pairs, the form FAT evaluation and validation take.
    pub fn mesh_sizes(&self) -> Vec<(&str, usize)> {
        self.meshes
            .iter()
            .map(|m| (m.name.as_str(), m.mesh.vertex_count()))
            .collect()
    }

    /// Transform names in order.
    pub fn transform_names(&self) -> Vec<&str> {
        self.transforms.iter().map(|t| t.name.as_str()).collect()
    }

    /// A FAT evaluator bound to this face's meshes and transforms.
    pub fn evaluator(&self) -> Result<FatEvaluator> {
        FatEvaluator::new(&self.fat, &self.mesh_sizes(), &self.transform_names())
    }

    /// Total vertex count over all meshes.
    pub fn vertex_count(&self) -> usize {
        self.meshes.iter().map(|m| m.mesh.vertex_count()).sum()
    }

    /// Checks names are unique and transforms come parents first (what every reader and
    /// builder must produce).
    pub fn check_structure(&self) -> Result<()> {
        let mut seen = HashMap::new();
        for m in &self.meshes {
            if seen.insert(m.name.as_str(), ()).is_some() {
                return Err(FaceError::DuplicateMesh {
                    name: m.name.clone(),
                }
                .into());
            }
        }
        let mut seen = HashMap::new();
        for (i, t) in self.transforms.iter().enumerate() {
            if seen.insert(t.name.as_str(), ()).is_some() {
                return Err(FaceError::DuplicateTransform {
                    name: t.name.clone(),
                }
                .into());
            }
            if t.parent.is_some_and(|p| p >= i) {
                return Err(FaceError::TransformBeforeParent {
                    name: t.name.clone(),
                }
                .into());
            }
        }
        if let Some(m) = self
            .meshes
            .iter()
            .find(|m| m.transform.is_some_and(|t| t >= self.transforms.len()))
        {
            return Err(FaceError::MissingTransform {
                mesh: m.name.clone(),
            }
            .into());
        }
        Ok(())
    }

    /// The mesh and vertex a feature point is bound to (first vertex of its binding).
    pub fn fp_vertex(&self, id: FeaturePointId) -> Option<(usize, u32)> {
        let b = self.feature_points.get(id)?.binding.as_ref()?;
        let mesh = match &b.mesh {
            Some(name) => self.mesh_index(name)?,
            None if self.meshes.len() == 1 => 0,
            None => return None,
        };
        Some((mesh, *b.vertices.first()?))
    }
}

#[cfg(test)]
mod tests;
