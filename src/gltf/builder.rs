//! [`SceneBuilder`]: collects the scene, checking every value as it is added (so an error
//! points at the call that caused it), and builds the [`GltfDocument`].

use std::collections::HashSet;

use glam::Vec3;

use super::container::GltfDocument;
use super::document::assemble;
use super::{
    AnimationData, ChannelData, ChannelValues, MeshData, MeshId, MorphOffsets, MorphTargetData,
    NodeData, NodeId,
};
use crate::error::{Error, Result};

/// Collects meshes, nodes and animations, then [builds](SceneBuilder::build) a glTF document.
///
/// Every `add_*` method checks its input completely (finite numbers, counts, index ranges,
/// references to earlier handles) and returns [`super::GltfError::Scene`] naming the offending object.
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder<'a> {
    scene_name: String,
    meshes: Vec<MeshData<'a>>,
    nodes: Vec<NodeData>,
    animations: Vec<AnimationData>,
}

fn invalid(msg: String) -> Error {
    super::GltfError::Scene(msg).into()
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
        let mut seen = HashSet::new();
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
            self.check_channel_values(&who, node, c)?;
        }
        self.animations.push(animation);
        Ok(())
    }

    /// Keyframe times and values of channel `c` (called `who`) animating `node`.
    fn check_channel_values(&self, who: &str, node: &NodeData, c: &ChannelData) -> Result<()> {
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
        assemble(
            &self.scene_name,
            &self.meshes,
            &self.nodes,
            &self.animations,
        )
    }
}

fn too_many(what: &str) -> Error {
    invalid(format!("too many glTF {what}"))
}

fn all_finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Keyframe times: at least one, finite, from 0 on, strictly increasing.
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

/// Everything about a mesh glTF and its tools require: vertices, triangles in range, finite
/// numbers, matching attribute counts, material factors in 0..=1, well-formed morph targets.
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
        check_morph_target(t, n)
            .map_err(|what| invalid(format!("{who}: morph target `{}`: {what}", t.name)))?;
    }
    Ok(())
}

/// A morph target of a mesh with `n` vertices: finite default weight and offsets, one offset
/// per vertex (dense) or per listed vertex in range (sparse).
fn check_morph_target(t: &MorphTargetData, n: usize) -> std::result::Result<(), String> {
    if !t.default_weight.is_finite() {
        return Err("non-finite default weight".into());
    }
    match &t.offsets {
        MorphOffsets::Dense(o) => {
            if o.len() != n {
                return Err(format!("{} offsets for {n} vertices", o.len()));
            }
            if !o.iter().all(|&v| finite3(v)) {
                return Err("non-finite offset".into());
            }
        }
        MorphOffsets::Sparse { vertices, offsets } => {
            if vertices.len() != offsets.len() {
                return Err(format!(
                    "{} vertices but {} offsets",
                    vertices.len(),
                    offsets.len()
                ));
            }
            if let Some(v) = vertices.iter().find(|&&v| v as usize >= n) {
                return Err(format!("vertex {v} is past the {n} vertices"));
            }
            if !offsets.iter().all(|&v| finite3(v)) {
                return Err("non-finite offset".into());
            }
        }
    }
    Ok(())
}
