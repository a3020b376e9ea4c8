//! Plain-data scene description and its conversion into a [`GltfDocument`].
//!
//! Callers describe meshes ([`MeshData`]), nodes ([`NodeData`]) and animations
//! ([`AnimationData`]) with `glam` vectors and slices; [`SceneBuilder`] checks every value as it
//! is added (so an error points at the call that caused it) and [`SceneBuilder::build`] lays
//! the data out in one binary buffer with the accessors, buffer views and JSON objects glTF
//! needs. Nothing here knows about FATs or FAPs: the face model and the player fill these
//! structs.

use std::borrow::Cow;
use std::collections::HashMap;

use glam::{Quat, Vec2, Vec3};
use serde_json::json;

use super::container::GltfDocument;
use super::json::{self, Accessor, BufferView, Root};
use crate::error::{Error, Result};

/// Handle of a mesh added to a [`SceneBuilder`]; meshes are written in the order added.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(pub(super) u32);

impl MeshId {
    /// Index of the mesh in the written `meshes` array.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Handle of a node added to a [`SceneBuilder`]; nodes are written in the order added.
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

/// Collects meshes, nodes and animations, then [builds](SceneBuilder::build) a glTF document.
///
/// Every `add_*` method checks its input completely (finite numbers, counts, index ranges,
/// references to earlier handles) and returns [`Error::Invalid`] naming the offending object.
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder<'a> {
    scene_name: String,
    meshes: Vec<MeshData<'a>>,
    nodes: Vec<NodeData>,
    animations: Vec<AnimationData>,
}

fn invalid(msg: String) -> Error {
    Error::Invalid(msg)
}

fn finite3(v: Vec3) -> bool {
    v.is_finite()
}

impl<'a> SceneBuilder<'a> {
    /// An empty scene called `scene_name`.
    pub fn new(scene_name: impl Into<String>) -> Self {
        SceneBuilder {
            scene_name: scene_name.into(),
            ..Default::default()
        }
    }

    /// Adds a mesh after checking it; it must be placed on a node before [`build`](Self::build).
    pub fn add_mesh(&mut self, mesh: MeshData<'a>) -> Result<MeshId> {
        check_mesh(&mesh)?;
        let id = MeshId(u32::try_from(self.meshes.len()).map_err(|_| too_many("meshes"))?);
        self.meshes.push(mesh);
        Ok(id)
    }

    /// Adds a node after checking its transform and references.
    pub fn add_node(&mut self, node: NodeData) -> Result<NodeId> {
        let who = format!("glTF node `{}`", node.name);
        if let Some(p) = node.parent {
            if p.index() >= self.nodes.len() {
                return Err(invalid(format!("{who}: parent is not an earlier node")));
            }
        }
        if let Some(m) = node.mesh {
            if m.index() >= self.meshes.len() {
                return Err(invalid(format!("{who}: unknown mesh")));
            }
        }
        if !finite3(node.translation) || !finite3(node.scale) || !node.rotation.is_finite() {
            return Err(invalid(format!("{who}: non-finite transform")));
        }
        if node.rotation.length_squared() < 1e-12 {
            return Err(invalid(format!("{who}: zero-length rotation quaternion")));
        }
        let id = NodeId(u32::try_from(self.nodes.len()).map_err(|_| too_many("nodes"))?);
        self.nodes.push(node);
        Ok(id)
    }

    /// Adds an animation after checking every channel against the nodes and meshes so far.
    pub fn add_animation(&mut self, animation: AnimationData) -> Result<()> {
        let who = format!("glTF animation `{}`", animation.name);
        if animation.channels.is_empty() {
            return Err(invalid(format!("{who}: no channels")));
        }
        let mut seen = std::collections::HashSet::new();
        for (i, c) in animation.channels.iter().enumerate() {
            let who = format!("{who}, channel {i}");
            let node = self
                .nodes
                .get(c.node.index())
                .ok_or_else(|| invalid(format!("{who}: unknown node")))?;
            if !seen.insert((c.node, c.values.path())) {
                return Err(invalid(format!(
                    "{who}: node `{}` already has a {} channel",
                    node.name,
                    c.values.path()
                )));
            }
            check_times(&c.times).map_err(|e| invalid(format!("{who}: {e}")))?;
            let n = c.times.len();
            let (len, finite) = match &c.values {
                ChannelValues::Weights(w) => {
                    let targets = node
                        .mesh
                        .map(|m| self.meshes[m.index()].morph_targets.len())
                        .unwrap_or(0);
                    if targets == 0 {
                        return Err(invalid(format!(
                            "{who}: weights channel on node `{}`, which has no morph targets",
                            node.name
                        )));
                    }
                    (w.len() / targets, w.len() % targets == 0 && all_finite(w))
                }
                ChannelValues::Rotation(r) => (
                    r.len(),
                    r.iter()
                        .all(|q| q.is_finite() && q.length_squared() > 1e-12),
                ),
                ChannelValues::Translation(v) | ChannelValues::Scale(v) => {
                    (v.len(), v.iter().all(|&v| finite3(v)))
                }
            };
            if len != n {
                return Err(invalid(format!(
                    "{who}: {} values do not match {n} keyframe times",
                    c.values.path()
                )));
            }
            if !finite {
                return Err(invalid(format!(
                    "{who}: non-finite (or zero-length rotation) {} value",
                    c.values.path()
                )));
            }
        }
        self.animations.push(animation);
        Ok(())
    }

    /// Lays out the scene as a glTF document (one buffer, one scene).
    ///
    /// Fails if a mesh is not shown by any node (glTF tools flag unused objects).
    pub fn build(&self) -> Result<GltfDocument> {
        let mut used = vec![false; self.meshes.len()];
        for n in &self.nodes {
            if let Some(m) = n.mesh {
                used[m.index()] = true;
            }
        }
        if let Some(i) = used.iter().position(|u| !u) {
            return Err(invalid(format!(
                "glTF mesh `{}` is not shown by any node",
                self.meshes[i].name
            )));
        }
        let mut out = Layout::default();
        let mut root = Root {
            asset: json::Asset {
                version: "2.0".into(),
                generator: Some("fbakit".into()),
            },
            scene: Some(0),
            ..Default::default()
        };
        for (i, m) in self.meshes.iter().enumerate() {
            let (mesh, material) = out.mesh(m, i as u32);
            root.meshes.push(mesh);
            root.materials.push(material);
        }
        let mut roots = Vec::new();
        for (i, n) in self.nodes.iter().enumerate() {
            root.nodes.push(node_json(n));
            match n.parent {
                Some(p) => root.nodes[p.index()].children.push(i as u32),
                None => roots.push(i as u32),
            }
        }
        root.scenes.push(json::Scene {
            name: name_opt(&self.scene_name),
            nodes: roots,
        });
        for a in &self.animations {
            root.animations.push(out.animation(a));
        }
        let byte_length = u32::try_from(out.bin.len())
            .map_err(|_| invalid("glTF buffer exceeds 4 GiB".to_string()))?;
        if byte_length > 0 {
            root.buffers.push(json::Buffer {
                byte_length,
                uri: None,
            });
        }
        root.accessors = out.accessors;
        root.buffer_views = out.views;
        Ok(GltfDocument { root, bin: out.bin })
    }
}

fn too_many(what: &str) -> Error {
    invalid(format!("too many glTF {what}"))
}

fn all_finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn name_opt(name: &str) -> Option<String> {
    (!name.is_empty()).then(|| name.to_string())
}

fn check_times(times: &[f32]) -> std::result::Result<(), String> {
    if times.is_empty() {
        return Err("no keyframes".into());
    }
    if !all_finite(times) || times[0] < 0.0 {
        return Err("keyframe times must be finite and >= 0".into());
    }
    if times.windows(2).any(|w| w[1] <= w[0]) {
        return Err("keyframe times must be strictly increasing".into());
    }
    Ok(())
}

fn check_mesh(m: &MeshData) -> Result<()> {
    let who = format!("glTF mesh `{}`", m.name);
    let err = |what: String| Err(invalid(format!("{who}: {what}")));
    let n = m.positions.len();
    if n == 0 {
        return err("no vertices (empty meshes cannot be exported)".into());
    }
    if u32::try_from(n).is_err() {
        return err("more than 2^32 vertices".into());
    }
    if m.triangles.is_empty() {
        return err("no triangles (empty meshes cannot be exported)".into());
    }
    if !m.positions.iter().all(|&p| finite3(p)) {
        return err("non-finite vertex position".into());
    }
    if let Some(t) = m
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return err(format!("triangle {t:?} refers past the {n} vertices"));
    }
    if let Some(normals) = &m.normals {
        if normals.len() != n {
            return err(format!("{} normals for {n} vertices", normals.len()));
        }
        if !normals
            .iter()
            .all(|&v| finite3(v) && v.length_squared() > 1e-20)
        {
            return err("non-finite or zero-length normal".into());
        }
    }
    if let Some(uvs) = &m.uvs {
        if uvs.len() != n {
            return err(format!("{} UVs for {n} vertices", uvs.len()));
        }
        if !uvs.iter().all(|uv| uv.is_finite()) {
            return err("non-finite UV".into());
        }
    }
    let mat = &m.material;
    if !mat
        .base_color
        .iter()
        .chain([&mat.metallic, &mat.roughness])
        .all(|x| (0.0..=1.0).contains(x))
    {
        return err("material factors must lie in 0..=1".into());
    }
    for t in &m.morph_targets {
        let err = |what: String| err(format!("morph target `{}`: {what}", t.name));
        if !t.default_weight.is_finite() {
            return err("non-finite default weight".into());
        }
        match &t.offsets {
            MorphOffsets::Dense(o) => {
                if o.len() != n {
                    return err(format!("{} offsets for {n} vertices", o.len()));
                }
                if !o.iter().all(|&v| finite3(v)) {
                    return err("non-finite offset".into());
                }
            }
            MorphOffsets::Sparse { vertices, offsets } => {
                if vertices.len() != offsets.len() {
                    return err(format!(
                        "{} vertices but {} offsets",
                        vertices.len(),
                        offsets.len()
                    ));
                }
                if let Some(v) = vertices.iter().find(|&&v| v as usize >= n) {
                    return err(format!("vertex {v} is past the {n} vertices"));
                }
                if !offsets.iter().all(|&v| finite3(v)) {
                    return err("non-finite offset".into());
                }
            }
        }
    }
    Ok(())
}

fn node_json(n: &NodeData) -> json::Node {
    let r = n.rotation.normalize();
    json::Node {
        name: name_opt(&n.name),
        children: Vec::new(),
        mesh: n.mesh.map(|m| m.0),
        translation: (n.translation != Vec3::ZERO).then(|| n.translation.to_array()),
        rotation: (r != Quat::IDENTITY).then(|| r.to_array()),
        scale: (n.scale != Vec3::ONE).then(|| n.scale.to_array()),
    }
}

/// Area-weighted vertex normals; a vertex on no (non-degenerate) triangle gets +Z.
pub fn area_weighted_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let (Some(&pa), Some(&pb), Some(&pc)) =
            (positions.get(a), positions.get(b), positions.get(c))
        else {
            continue;
        };
        // The cross product's length is twice the triangle's area: that is the weighting.
        let n = (pb - pa).cross(pc - pa);
        acc[a] += n;
        acc[b] += n;
        acc[c] += n;
    }
    acc.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Z))
        .collect()
}

/// A morph target's non-zero offsets, sorted by vertex, duplicates summed.
fn sparse_offsets(offsets: &MorphOffsets) -> (Vec<u32>, Vec<Vec3>) {
    let mut pairs: Vec<(u32, Vec3)> = match offsets {
        MorphOffsets::Dense(o) => o
            .iter()
            .enumerate()
            .filter(|(_, &o)| o != Vec3::ZERO)
            .map(|(i, &o)| (i as u32, o))
            .collect(),
        MorphOffsets::Sparse { vertices, offsets } => {
            let mut p: Vec<(u32, Vec3)> = vertices
                .iter()
                .copied()
                .zip(offsets.iter().copied())
                .collect();
            p.sort_by_key(|&(v, _)| v);
            let mut merged: Vec<(u32, Vec3)> = Vec::with_capacity(p.len());
            for (v, o) in p {
                match merged.last_mut() {
                    Some(last) if last.0 == v => last.1 += o,
                    _ => merged.push((v, o)),
                }
            }
            merged.retain(|&(_, o)| o != Vec3::ZERO);
            merged
        }
    };
    pairs.shrink_to_fit();
    pairs.into_iter().unzip()
}

/// The growing binary buffer with its views and accessors.
#[derive(Default)]
struct Layout {
    bin: Vec<u8>,
    views: Vec<BufferView>,
    accessors: Vec<Accessor>,
    /// Keyframe-time accessors by bit pattern, so channels with equal times share one.
    times: HashMap<Vec<u32>, u32>,
}

fn bounds<const N: usize>(items: impl Iterator<Item = [f32; N]>) -> (Vec<f32>, Vec<f32>) {
    let mut min = [f32::INFINITY; N];
    let mut max = [f32::NEG_INFINITY; N];
    for v in items {
        for k in 0..N {
            min[k] = min[k].min(v[k]);
            max[k] = max[k].max(v[k]);
        }
    }
    (min.to_vec(), max.to_vec())
}

impl Layout {
    /// Appends a 4-byte-aligned buffer view filled by `fill`.
    fn view(&mut self, target: Option<u32>, fill: impl FnOnce(&mut Vec<u8>)) -> u32 {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let start = self.bin.len();
        fill(&mut self.bin);
        self.views.push(BufferView {
            buffer: 0,
            byte_offset: start as u32,
            byte_length: (self.bin.len() - start) as u32,
            target,
        });
        (self.views.len() - 1) as u32
    }

    fn accessor(&mut self, a: Accessor) -> u32 {
        self.accessors.push(a);
        (self.accessors.len() - 1) as u32
    }

    fn floats<const N: usize>(
        &mut self,
        data: &[[f32; N]],
        target: Option<u32>,
        with_bounds: bool,
    ) -> u32 {
        let view = self.view(target, |b| {
            b.reserve(data.len() * N * 4);
            for v in data {
                for x in v {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
        });
        let (min, max) = if with_bounds {
            bounds(data.iter().copied())
        } else {
            (Vec::new(), Vec::new())
        };
        self.accessor(Accessor {
            buffer_view: Some(view),
            component_type: json::FLOAT,
            count: data.len() as u32,
            kind: ["SCALAR", "VEC2", "VEC3", "VEC4"][N - 1].into(),
            min,
            max,
            sparse: None,
        })
    }

    fn vec3s(&mut self, data: &[Vec3], target: Option<u32>, with_bounds: bool) -> u32 {
        let arrays: Vec<[f32; 3]> = data.iter().map(|v| v.to_array()).collect();
        self.floats(&arrays, target, with_bounds)
    }

    /// Unsigned integers as u8 / u16 / u32 (the smallest allowed by `max_value`).
    fn uints(&mut self, data: &[u32], max_value: u32, target: Option<u32>) -> (u32, u32) {
        let (ty, size) = if target.is_none() && max_value <= u8::MAX as u32 {
            (json::UNSIGNED_BYTE, 1)
        } else if max_value < u16::MAX as u32 || (target.is_none() && max_value == 65535) {
            // 65535 is the primitive-restart value of u16 *vertex* indices.
            (json::UNSIGNED_SHORT, 2)
        } else {
            (json::UNSIGNED_INT, 4)
        };
        let view = self.view(target, |b| {
            b.reserve(data.len() * size);
            for &i in data {
                match size {
                    1 => b.push(i as u8),
                    2 => b.extend_from_slice(&(i as u16).to_le_bytes()),
                    _ => b.extend_from_slice(&i.to_le_bytes()),
                }
            }
        });
        (view, ty)
    }

    /// A morph-target displacement accessor over `count` vertices: sparse when that is
    /// smaller than dense, all-zero (no data) when nothing moves.
    fn displacement(&mut self, count: u32, vertices: &[u32], offsets: &[Vec3]) -> u32 {
        let nnz = vertices.len();
        let index_size = if count <= 256 {
            1
        } else if count <= 65536 {
            2
        } else {
            4
        };
        if nnz * (12 + index_size) >= count as usize * 12 {
            let mut dense = vec![Vec3::ZERO; count as usize];
            for (&v, &o) in vertices.iter().zip(offsets) {
                dense[v as usize] = o;
            }
            return self.vec3s(&dense, Some(json::ARRAY_BUFFER), true);
        }
        let zeros = (nnz < count as usize).then_some([0.0f32; 3]);
        let (min, max) = bounds(offsets.iter().map(|o| o.to_array()).chain(zeros));
        let sparse = (nnz > 0).then(|| {
            let (indices, component_type) = self.uints(vertices, count - 1, None);
            let values = self.view(None, |b| {
                for o in offsets {
                    for x in o.to_array() {
                        b.extend_from_slice(&x.to_le_bytes());
                    }
                }
            });
            json::Sparse {
                count: nnz as u32,
                indices: json::SparseIndices {
                    buffer_view: indices,
                    component_type,
                },
                values: json::SparseValues {
                    buffer_view: values,
                },
            }
        });
        self.accessor(Accessor {
            buffer_view: None,
            component_type: json::FLOAT,
            count,
            kind: "VEC3".into(),
            min,
            max,
            sparse,
        })
    }

    fn mesh(&mut self, m: &MeshData, index: u32) -> (json::Mesh, json::Material) {
        let n = m.positions.len() as u32;
        let mut attributes = vec![(
            "POSITION".to_string(),
            self.vec3s(&m.positions, Some(json::ARRAY_BUFFER), true),
        )];
        let base_normals = area_weighted_normals(&m.positions, &m.triangles);
        let normals: Vec<Vec3> = match &m.normals {
            Some(given) => given.iter().map(|v| v.normalize()).collect(),
            None => base_normals.clone(),
        };
        attributes.push((
            "NORMAL".into(),
            self.vec3s(&normals, Some(json::ARRAY_BUFFER), false),
        ));
        if let Some(uvs) = &m.uvs {
            let arrays: Vec<[f32; 2]> = uvs.iter().map(|v| v.to_array()).collect();
            attributes.push((
                "TEXCOORD_0".into(),
                self.floats(&arrays, Some(json::ARRAY_BUFFER), false),
            ));
        }
        let flat: Vec<u32> = m.triangles.iter().flatten().copied().collect();
        let (view, component_type) = self.uints(&flat, n - 1, Some(json::ELEMENT_ARRAY_BUFFER));
        let indices = self.accessor(Accessor {
            buffer_view: Some(view),
            component_type,
            count: flat.len() as u32,
            kind: "SCALAR".into(),
            ..Default::default()
        });
        let mut targets = Vec::with_capacity(m.morph_targets.len());
        for t in &m.morph_targets {
            let (vertices, offsets) = sparse_offsets(&t.offsets);
            let mut attrs = vec![(
                "POSITION".to_string(),
                self.displacement(n, &vertices, &offsets),
            )];
            if m.morph_normals {
                let mut moved = m.positions.to_vec();
                for (&v, &o) in vertices.iter().zip(&offsets) {
                    moved[v as usize] += o;
                }
                let (nv, no): (Vec<u32>, Vec<Vec3>) = area_weighted_normals(&moved, &m.triangles)
                    .iter()
                    .zip(&base_normals)
                    .enumerate()
                    .filter(|(_, (a, b))| a != b)
                    .map(|(i, (a, b))| (i as u32, *a - *b))
                    .unzip();
                attrs.push((
                    "NORMAL".to_string(),
                    self.displacement_no_bounds(n, &nv, &no),
                ));
            }
            targets.push(attrs);
        }
        let mesh = json::Mesh {
            name: name_opt(&m.name),
            primitives: vec![json::Primitive {
                attributes,
                indices: Some(indices),
                material: Some(index),
                mode: None,
                targets,
            }],
            weights: m.morph_targets.iter().map(|t| t.default_weight).collect(),
            extras: (!m.morph_targets.is_empty()).then(|| {
                json!({ "targetNames": m.morph_targets.iter().map(|t| &t.name).collect::<Vec<_>>() })
            }),
        };
        let mat = &m.material;
        let material = json::Material {
            name: name_opt(&m.name),
            pbr_metallic_roughness: json::PbrMetallicRoughness {
                base_color_factor: mat.base_color,
                metallic_factor: mat.metallic,
                roughness_factor: mat.roughness,
            },
            alpha_mode: (mat.base_color[3] < 1.0).then(|| "BLEND".to_string()),
            double_sided: mat.double_sided,
        };
        (mesh, material)
    }

    /// [`Layout::displacement`] without `min`/`max` (only `POSITION` needs them).
    fn displacement_no_bounds(&mut self, count: u32, vertices: &[u32], offsets: &[Vec3]) -> u32 {
        let a = self.displacement(count, vertices, offsets);
        let acc = &mut self.accessors[a as usize];
        acc.min.clear();
        acc.max.clear();
        a
    }

    fn animation(&mut self, a: &AnimationData) -> json::Animation {
        let mut out = json::Animation {
            name: name_opt(&a.name),
            ..Default::default()
        };
        for c in &a.channels {
            let key: Vec<u32> = c.times.iter().map(|t| t.to_bits()).collect();
            let input = match self.times.get(&key) {
                Some(&i) => i,
                None => {
                    let arrays: Vec<[f32; 1]> = c.times.iter().map(|&t| [t]).collect();
                    let i = self.floats(&arrays, None, true);
                    self.times.insert(key, i);
                    i
                }
            };
            let output = match &c.values {
                ChannelValues::Weights(w) => {
                    let arrays: Vec<[f32; 1]> = w.iter().map(|&x| [x]).collect();
                    self.floats(&arrays, None, false)
                }
                ChannelValues::Rotation(r) => {
                    let arrays: Vec<[f32; 4]> =
                        r.iter().map(|q| q.normalize().to_array()).collect();
                    self.floats(&arrays, None, false)
                }
                ChannelValues::Translation(v) | ChannelValues::Scale(v) => {
                    self.vec3s(v, None, false)
                }
            };
            out.samplers.push(json::AnimationSampler {
                input,
                interpolation: match c.interpolation {
                    Interpolation::Linear => None,
                    Interpolation::Step => Some("STEP".into()),
                },
                output,
            });
            out.channels.push(json::Channel {
                sampler: (out.samplers.len() - 1) as u32,
                target: json::ChannelTarget {
                    node: c.node.0,
                    path: c.values.path().into(),
                },
            });
        }
        out
    }
}
