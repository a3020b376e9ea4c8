//! The plain-data scene description callers fill: meshes ([`MeshData`]) with materials and
//! morph targets, nodes ([`NodeData`]) and animations ([`AnimationData`]), with `glam`
//! vectors and borrowed or owned slices. Nothing here knows about FATs or FAPs.

use std::borrow::Cow;

use glam::{Quat, Vec2, Vec3};

/// Handle of a mesh added to a [`SceneBuilder`](super::SceneBuilder); meshes are written in the order added.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(pub(super) u32);

impl MeshId {
    /// Index of the mesh in the written `meshes` array.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Handle of a node added to a [`SceneBuilder`](super::SceneBuilder); nodes are written in the order added.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NodeId(pub(super) u32);

impl NodeId {
    /// Index of the node in the written `nodes` array.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// The PBR material written for one mesh (no textures).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialData {
    /// Linear RGBA base colour, each component in 0..=1. Alpha below 1 makes the material
    /// `BLEND`.
    pub base_color: [f32; 4],
    /// Metalness 0..=1.
    pub metallic: f32,
    /// Roughness 0..=1.
    pub roughness: f32,
    /// Render back faces too (for open meshes such as a face mask).
    pub double_sided: bool,
}

impl Default for MaterialData {
    /// Light grey, non-metallic, fairly rough, single-sided.
    fn default() -> Self {
        MaterialData {
            base_color: [0.8, 0.8, 0.8, 1.0],
            metallic: 0.0,
            roughness: 0.7,
            double_sided: false,
        }
    }
}

/// Vertex displacements of one morph target.
#[derive(Clone, Debug, PartialEq)]
pub enum MorphOffsets<'a> {
    /// One offset per vertex of the mesh.
    Dense(Cow<'a, [Vec3]>),
    /// Offsets of the listed vertices only (all others stay). Repeated vertices add up.
    Sparse {
        /// Moved vertices (indices into the mesh's positions).
        vertices: Cow<'a, [u32]>,
        /// Offset of each listed vertex (same length as `vertices`).
        offsets: Cow<'a, [Vec3]>,
    },
}

/// One morph target (a glTF "target" plus its name and default weight).
#[derive(Clone, Debug, PartialEq)]
pub struct MorphTargetData<'a> {
    /// Name written to `mesh.extras.targetNames` (three.js and Blender show it).
    pub name: String,
    /// Position displacements at weight 1.
    pub offsets: MorphOffsets<'a>,
    /// Weight in `mesh.weights` (the rest pose); usually 0.
    pub default_weight: f32,
}

/// A triangle mesh with its material and morph targets.
///
/// Written as one glTF mesh with one triangle primitive. Normals are computed (area-weighted)
/// when not given; indices are stored as `u16` when the vertex count allows it.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshData<'a> {
    /// Mesh name.
    pub name: String,
    /// Vertex positions (at least one).
    pub positions: Cow<'a, [Vec3]>,
    /// Counter-clockwise triangles (at least one), as indices into `positions`.
    pub triangles: Cow<'a, [[u32; 3]]>,
    /// Per-vertex normals (normalised when written); computed when `None`.
    pub normals: Option<Cow<'a, [Vec3]>>,
    /// Per-vertex texture coordinates (`TEXCOORD_0`).
    pub uvs: Option<Cow<'a, [Vec2]>>,
    /// The mesh's material.
    pub material: MaterialData,
    /// Morph targets, in output order.
    pub morph_targets: Vec<MorphTargetData<'a>>,
    /// Also write `NORMAL` deltas for each target (recomputed normals of the displaced mesh
    /// minus those of the neutral mesh), so lighting follows the deformation.
    pub morph_normals: bool,
}

impl<'a> MeshData<'a> {
    /// A mesh with default material, computed normals and no morph targets.
    pub fn new(
        name: impl Into<String>,
        positions: impl Into<Cow<'a, [Vec3]>>,
        triangles: impl Into<Cow<'a, [[u32; 3]]>>,
    ) -> Self {
        MeshData {
            name: name.into(),
            positions: positions.into(),
            triangles: triangles.into(),
            normals: None,
            uvs: None,
            material: MaterialData::default(),
            morph_targets: Vec::new(),
            morph_normals: false,
        }
    }

    /// Sets explicit normals.
    pub fn with_normals(mut self, normals: impl Into<Cow<'a, [Vec3]>>) -> Self {
        self.normals = Some(normals.into());
        self
    }

    /// Sets texture coordinates.
    pub fn with_uvs(mut self, uvs: impl Into<Cow<'a, [Vec2]>>) -> Self {
        self.uvs = Some(uvs.into());
        self
    }

    /// Sets the material.
    pub fn with_material(mut self, material: MaterialData) -> Self {
        self.material = material;
        self
    }

    /// Adds a morph target with one offset per vertex (default weight 0).
    pub fn with_dense_target(
        mut self,
        name: impl Into<String>,
        offsets: impl Into<Cow<'a, [Vec3]>>,
    ) -> Self {
        self.morph_targets.push(MorphTargetData {
            name: name.into(),
            offsets: MorphOffsets::Dense(offsets.into()),
            default_weight: 0.0,
        });
        self
    }

    /// Adds a morph target moving only `vertices` (default weight 0).
    pub fn with_sparse_target(
        mut self,
        name: impl Into<String>,
        vertices: impl Into<Cow<'a, [u32]>>,
        offsets: impl Into<Cow<'a, [Vec3]>>,
    ) -> Self {
        self.morph_targets.push(MorphTargetData {
            name: name.into(),
            offsets: MorphOffsets::Sparse {
                vertices: vertices.into(),
                offsets: offsets.into(),
            },
            default_weight: 0.0,
        });
        self
    }
}

/// A scene node: a local transform (translation, then rotation, then scale, applied to the
/// child) under an optional parent, optionally showing a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeData {
    /// Node name (animation tools address nodes by it).
    pub name: String,
    /// Parent node; `None` for a scene root. Parents must be added before their children, which
    /// also rules out cycles.
    pub parent: Option<NodeId>,
    /// Local translation.
    pub translation: Vec3,
    /// Local rotation (normalised when written).
    pub rotation: Quat,
    /// Local scale.
    pub scale: Vec3,
    /// Mesh shown at this node.
    pub mesh: Option<MeshId>,
}

impl NodeData {
    /// A root node with identity transform and no mesh.
    pub fn new(name: impl Into<String>) -> Self {
        NodeData {
            name: name.into(),
            parent: None,
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
            mesh: None,
        }
    }

    /// Sets the parent.
    pub fn with_parent(mut self, parent: NodeId) -> Self {
        self.parent = Some(parent);
        self
    }

    /// Sets the mesh.
    pub fn with_mesh(mut self, mesh: MeshId) -> Self {
        self.mesh = Some(mesh);
        self
    }

    /// Sets the translation.
    pub fn with_translation(mut self, t: Vec3) -> Self {
        self.translation = t;
        self
    }

    /// Sets the rotation.
    pub fn with_rotation(mut self, r: Quat) -> Self {
        self.rotation = r;
        self
    }

    /// Sets the scale.
    pub fn with_scale(mut self, s: Vec3) -> Self {
        self.scale = s;
        self
    }
}

/// How values between keyframes are obtained.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Interpolation {
    /// Linear (spherical-linear for rotations).
    #[default]
    Linear,
    /// Hold each keyframe's value until the next.
    Step,
}

/// Keyframe values of one channel; the variant is the animated property (`target.path`).
#[derive(Clone, Debug, PartialEq)]
pub enum ChannelValues {
    /// Morph weights: `times.len() × target count` floats, keyframe-major (all weights of
    /// keyframe 0, then keyframe 1, ...).
    Weights(Vec<f32>),
    /// Rotations, one per keyframe (normalised when written).
    Rotation(Vec<Quat>),
    /// Translations, one per keyframe.
    Translation(Vec<Vec3>),
    /// Scales, one per keyframe.
    Scale(Vec<Vec3>),
}

impl ChannelValues {
    /// The glTF `target.path` name.
    pub fn path(&self) -> &'static str {
        match self {
            ChannelValues::Weights(_) => "weights",
            ChannelValues::Rotation(_) => "rotation",
            ChannelValues::Translation(_) => "translation",
            ChannelValues::Scale(_) => "scale",
        }
    }
}

/// One animated property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelData {
    /// The animated node (for weights: a node showing a mesh with morph targets).
    pub node: NodeId,
    /// Keyframe times in seconds: finite, >= 0, strictly increasing, at least one.
    pub times: Vec<f32>,
    /// Keyframe values.
    pub values: ChannelValues,
    /// Interpolation between keyframes.
    pub interpolation: Interpolation,
}

/// A named animation (a clip in three.js, an action in Blender).
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationData {
    /// Animation name.
    pub name: String,
    /// Channels (at least one; at most one per node and property).
    pub channels: Vec<ChannelData>,
}
