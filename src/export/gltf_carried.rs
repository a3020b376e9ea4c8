//! How much of a face vertex a node of the user's document carries: for a skinned primitive,
//! the vertex's skin weight on that joint and the joints below it; for a plain one, all of it
//! when the node is the primitive's node or one of its ancestors, else nothing.
//!
//! `play` hands the jaw FAPs to a jaw node only when it carries the chin (2.1), and the head
//! rotations to a head node only when it carries the nose tip (9.3): a `Jaw` bone no chin
//! vertex is weighted to (an unused bone of a generic rig, a helper empty) would take
//! `open_jaw` from the morph targets and move nothing.

use gltf::mesh::Semantic;
use serde::Deserialize;

use super::gltf_rotations::{descends, node_parents};
use crate::face::vertex_index::FaceVertexIndex;
use crate::face::FaceModel;
use crate::gltf::source::GltfSource;
use crate::rig::gltf_accessor::{AccessorData, Want};
use crate::spec::FeaturePointId;

/// Whether `node` (playing the `role`, e.g. "jaw") carries the vertex of feature point `fp`
/// at least half (see [`carried_share`]; a point given by position takes the face's nearest
/// vertex), else why not, in words.
pub fn carries_point(
    source: &GltfSource,
    face: &FaceModel,
    node: usize,
    role: &str,
    fp: FeaturePointId,
) -> Result<(), String> {
    let name = source.json["nodes"][node]["name"].as_str().unwrap_or("");
    let Some((mesh, vertex)) = face.fp_vertex(fp).or_else(|| {
        let at = face.feature_points.position(fp)?;
        let (m, v, _) = FaceVertexIndex::new(face).nearest(at)?;
        Some((m, v))
    }) else {
        return Err(format!(
            "{role} node `{name}`: the face has no feature point {fp} to check it by"
        ));
    };
    let mesh_name = &face.meshes[mesh].name;
    let Some(part) = source.part(mesh_name) else {
        return Err(format!(
            "{role} node `{name}`: the mesh `{mesh_name}` of feature point {fp} is not in the document"
        ));
    };
    match carried_share(
        source,
        part.node,
        part.mesh,
        part.primitive,
        vertex as usize,
        node,
    ) {
        Some(s) if s >= 0.5 => Ok(()),
        Some(s) => Err(format!(
            "{role} node `{name}` carries feature point {fp} by {:.0} % only",
            s * 100.0
        )),
        None => Err(format!(
            "{role} node `{name}`: the skin weights of feature point {fp} cannot be read"
        )),
    }
}

/// The share (0–1) of vertex `vertex` of the document's `mesh`/`primitive`, instanced by
/// `mesh_node`, that `node` moves; `None` when the document cannot say (unreadable weights).
pub fn carried_share(
    source: &GltfSource,
    mesh_node: Option<usize>,
    mesh: usize,
    primitive: usize,
    vertex: usize,
    node: usize,
) -> Option<f32> {
    match primitive_shares(source, mesh_node, mesh, primitive, node)? {
        Shares::All(s) => Some(s),
        Shares::PerVertex(list) => list.get(vertex).copied(),
    }
}

/// How much of each vertex of a primitive a node moves ([`primitive_shares`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Shares {
    /// The same share for every vertex (a plain mesh: 1 under the node, else 0).
    All(f32),
    /// Per vertex, from the skin weights.
    PerVertex(Vec<f32>),
}

impl Shares {
    /// The shares of the first `count` vertices.
    pub fn of(&self, count: usize) -> Vec<f32> {
        match self {
            Shares::All(s) => vec![*s; count],
            Shares::PerVertex(list) => list.iter().copied().take(count).collect(),
        }
    }
}

/// The share (0–1) of every vertex of the document's `mesh`/`primitive`, instanced by
/// `mesh_node`, that `node` moves: its skin weight on `node` and the joints below it, or all
/// or nothing for a plain mesh; `None` when the document cannot say (unreadable weights).
/// One look-up: [`ShareReader`] answers many from one parse of the document.
pub fn primitive_shares(
    source: &GltfSource,
    mesh_node: Option<usize>,
    mesh: usize,
    primitive: usize,
    node: usize,
) -> Option<Shares> {
    ShareReader::new(source).shares(mesh_node, mesh, primitive, node)
}

/// [`primitive_shares`] for many primitives and nodes of one document: the node tree is read
/// once, and the document parsed for its accessors once, when a skinned primitive first asks
/// (a plain mesh needs only the tree).
pub struct ShareReader<'a> {
    source: &'a GltfSource,
    parents: Vec<Option<usize>>,
    doc: std::cell::OnceCell<Option<gltf::Document>>,
}

impl<'a> ShareReader<'a> {
    /// A reader of `source`'s shares.
    pub fn new(source: &'a GltfSource) -> ShareReader<'a> {
        ShareReader {
            source,
            parents: node_parents(&source.json),
            doc: std::cell::OnceCell::new(),
        }
    }

    /// [`primitive_shares`] of this document.
    pub fn shares(
        &self,
        mesh_node: Option<usize>,
        mesh: usize,
        primitive: usize,
        node: usize,
    ) -> Option<Shares> {
        let source = self.source;
        let json = &source.json;
        let parents = &self.parents;
        let Some(mesh_node) = mesh_node else {
            return Some(Shares::All(0.0));
        };
        let Some(skin) = json["nodes"][mesh_node]["skin"].as_u64() else {
            let carried = descends(parents, mesh_node, node);
            return Some(Shares::All(if carried { 1.0 } else { 0.0 }));
        };
        let joints: Vec<usize> = json["skins"][skin as usize]["joints"]
            .as_array()?
            .iter()
            .filter_map(|j| j.as_u64().map(|j| j as usize))
            .collect();
        let doc = self
            .doc
            .get_or_init(|| {
                let root = gltf::json::Root::deserialize(json).ok()?;
                Some(gltf::Document::from_json_without_validation(root))
            })
            .as_ref()?;
        let prim = doc.meshes().nth(mesh)?.primitives().nth(primitive)?;
        // The skin's accessors checked before the reader trusts them (a short or mistyped one
        // would make it stop or panic).
        let data = AccessorData {
            file: &source.path,
            buffers: &source.buffers,
        };
        for (semantic, want) in [
            (Semantic::Joints(0), Want::Joints),
            (Semantic::Weights(0), Want::Weights),
        ] {
            let acc = prim.get(&semantic)?;
            data.check(&acc, "skin", want, None).ok()?;
        }
        // Which joint slots `node` moves.
        let on_node: Vec<bool> = joints.iter().map(|&n| descends(parents, n, node)).collect();
        let reader = prim.reader(|b| source.buffers.get(b.index()).map(Vec::as_slice));
        let js = reader.read_joints(0)?.into_u16();
        let ws = reader.read_weights(0)?.into_f32();
        let shares = js
            .zip(ws)
            .map(|(js, ws)| {
                // fold from +0: an empty f32 `sum` is −0, which prints as "-0 %".
                let total = ws
                    .iter()
                    .filter(|w| w.is_finite())
                    .fold(0.0f32, |a, w| a + w);
                if total <= 0.0 {
                    return 0.0;
                }
                let on = js
                    .iter()
                    .zip(ws)
                    .filter(|(j, w)| {
                        w.is_finite() && on_node.get(usize::from(**j)).copied().unwrap_or(false)
                    })
                    .fold(0.0f32, |a, (_, w)| a + w);
                on / total
            })
            .collect();
        Some(Shares::PerVertex(shares))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(json: serde_json::Value, buffers: Vec<Vec<u8>>) -> GltfSource {
        GltfSource {
            path: "a.glb".into(),
            json,
            buffers,
            parts: Vec::new(),
        }
    }

    #[test]
    fn plain_meshes_are_carried_by_their_ancestors_only() {
        let s = source(
            serde_json::json!({"nodes": [
                {"name": "Head", "children": [1, 2]},
                {"name": "Jaw", "children": [3]},
                {"name": "Face", "mesh": 0},
                {"name": "Teeth", "mesh": 1}
            ]}),
            Vec::new(),
        );
        assert_eq!(carried_share(&s, Some(2), 0, 0, 0, 1), Some(0.0));
        assert_eq!(carried_share(&s, Some(3), 1, 0, 0, 1), Some(1.0));
        assert_eq!(carried_share(&s, Some(2), 0, 0, 0, 0), Some(1.0));
    }

    #[test]
    fn skinned_vertices_are_carried_by_their_weights_below_the_node() {
        // Two vertices; joints [Head, Jaw, JawTip]: vertex 0 all Head, vertex 1 a quarter
        // Jaw and half JawTip (below Jaw), a quarter Head.
        let mut bin = Vec::new();
        for p in [[0.0f32, 0.0, 0.0], [0.0, -1.0, 0.0]] {
            for c in p {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        let joints_at = bin.len();
        bin.extend_from_slice(&[0, 0, 0, 0, 1, 2, 0, 0]);
        let weights_at = bin.len();
        for w in [[1.0f32, 0.0, 0.0, 0.0], [0.25, 0.5, 0.25, 0.0]] {
            for c in w {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        let json = serde_json::json!({
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": bin.len()}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 24},
                {"buffer": 0, "byteOffset": joints_at, "byteLength": 8},
                {"buffer": 0, "byteOffset": weights_at, "byteLength": 32}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 2, "type": "VEC3",
                 "min": [0, -1, 0], "max": [0, 0, 0]},
                {"bufferView": 1, "componentType": 5121, "count": 2, "type": "VEC4"},
                {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC4"}
            ],
            "meshes": [{"primitives": [{"attributes":
                {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}}]}],
            "skins": [{"joints": [0, 1, 2]}],
            "nodes": [
                {"name": "Head", "children": [1, 3]},
                {"name": "Jaw", "children": [2]},
                {"name": "JawTip"},
                {"name": "Face", "mesh": 0, "skin": 0}
            ]
        });
        let mut float_joints = json.clone();
        float_joints["accessors"][1]["componentType"] = 5126.into();
        let s = source(json, vec![bin.clone()]);
        assert_eq!(carried_share(&s, Some(3), 0, 0, 0, 1), Some(0.0));
        assert_eq!(carried_share(&s, Some(3), 0, 0, 1, 1), Some(0.75));
        assert_eq!(carried_share(&s, Some(3), 0, 0, 1, 0), Some(1.0));
        assert_eq!(carried_share(&s, Some(3), 0, 0, 9, 1), None);
        // The whole primitive at once, as the eye joints are checked.
        assert_eq!(
            primitive_shares(&s, Some(3), 0, 0, 1),
            Some(Shares::PerVertex(vec![0.0, 0.75]))
        );
        assert_eq!(
            primitive_shares(&s, Some(3), 0, 0, 1).unwrap().of(1),
            vec![0.0]
        );
        // Float joints (not glTF) are refused, never read.
        let s = source(float_joints, vec![bin]);
        assert_eq!(carried_share(&s, Some(3), 0, 0, 1, 1), None);
    }
}
