//! Assembling the glTF JSON document from checked scene data: meshes with their primitive,
//! morph targets and material, the node tree, the scene and the animations, all laid out in
//! one buffer by [`Layout`].

use glam::{Quat, Vec3};
use serde_json::json;

use super::container::GltfDocument;
use super::json::{self, Accessor, Root};
use super::layout::Layout;
use super::{
    area_weighted_normals, AnimationData, ChannelValues, Interpolation, MeshData, MorphOffsets,
    MorphTargetData, NodeData,
};
use crate::error::Result;

/// The document of a checked scene: every mesh is shown by a node, every reference is valid.
pub(super) fn assemble(
    scene_name: &str,
    meshes: &[MeshData],
    nodes: &[NodeData],
    animations: &[AnimationData],
) -> Result<GltfDocument> {
    let mut out = Layout::default();
    let mut root = Root {
        asset: json::Asset {
            version: "2.0".into(),
            generator: Some("fbakit".into()),
        },
        scene: Some(0),
        ..Default::default()
    };
    for (i, m) in meshes.iter().enumerate() {
        let (mesh, material) = mesh_json(&mut out, m, i as u32);
        root.meshes.push(mesh);
        root.materials.push(material);
    }
    let mut roots = Vec::new();
    for (i, n) in nodes.iter().enumerate() {
        root.nodes.push(node_json(n));
        match n.parent {
            Some(p) => root.nodes[p.index()].children.push(i as u32),
            None => roots.push(i as u32),
        }
    }
    root.scenes.push(json::Scene {
        name: name_opt(scene_name),
        nodes: roots,
        extras: None,
    });
    for a in animations {
        root.animations.push(animation_json(&mut out, a));
    }
    let byte_length = u32::try_from(out.bin.len()).map_err(|_| super::GltfError::BufferTooLarge)?;
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

/// `Some(name)`, or `None` for an empty name (glTF names are optional).
fn name_opt(name: &str) -> Option<String> {
    (!name.is_empty()).then(|| name.to_string())
}

/// A node's JSON; identity transform parts are left out.
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

/// Mesh `index` as one triangle primitive with its morph targets, and its material.
fn mesh_json(out: &mut Layout, m: &MeshData, index: u32) -> (json::Mesh, json::Material) {
    let n = m.positions.len() as u32;
    let mut attributes = vec![(
        "POSITION".to_string(),
        out.vec3s(&m.positions, Some(json::ARRAY_BUFFER), true),
    )];
    let base_normals = area_weighted_normals(&m.positions, &m.triangles);
    let normals: Vec<Vec3> = match &m.normals {
        Some(given) => given.iter().map(|v| v.normalize()).collect(),
        None => base_normals.clone(),
    };
    attributes.push((
        "NORMAL".into(),
        out.vec3s(&normals, Some(json::ARRAY_BUFFER), false),
    ));
    if let Some(uvs) = &m.uvs {
        let arrays: Vec<[f32; 2]> = uvs.iter().map(|v| v.to_array()).collect();
        attributes.push((
            "TEXCOORD_0".into(),
            out.floats(&arrays, Some(json::ARRAY_BUFFER), false),
        ));
    }
    let flat: Vec<u32> = m.triangles.iter().flatten().copied().collect();
    let (view, component_type) = out.uints(&flat, n - 1, Some(json::ELEMENT_ARRAY_BUFFER));
    let indices = out.accessor(Accessor {
        buffer_view: Some(view),
        component_type,
        count: flat.len() as u32,
        kind: "SCALAR".into(),
        ..Default::default()
    });
    let mut targets = Vec::with_capacity(m.morph_targets.len());
    for t in &m.morph_targets {
        targets.push(morph_target_json(out, m, t, &base_normals));
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
    (mesh, material_json(m))
}

/// One morph target's attributes: the `POSITION` displacement, and with
/// [`MeshData::morph_normals`] the `NORMAL` delta against `base_normals`.
fn morph_target_json(
    out: &mut Layout,
    m: &MeshData,
    t: &MorphTargetData,
    base_normals: &[Vec3],
) -> json::Attributes {
    let n = m.positions.len() as u32;
    let (vertices, offsets) = sparse_offsets(&t.offsets);
    let mut attrs = vec![(
        "POSITION".to_string(),
        out.displacement(n, &vertices, &offsets),
    )];
    if m.morph_normals {
        let mut moved = m.positions.to_vec();
        for (&v, &o) in vertices.iter().zip(&offsets) {
            moved[v as usize] += o;
        }
        let (nv, no): (Vec<u32>, Vec<Vec3>) = area_weighted_normals(&moved, &m.triangles)
            .iter()
            .zip(base_normals)
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .map(|(i, (a, b))| (i as u32, *a - *b))
            .unzip();
        attrs.push((
            "NORMAL".to_string(),
            out.displacement_no_bounds(n, &nv, &no),
        ));
    }
    attrs
}

/// The mesh's PBR material (`BLEND` when its alpha is below 1).
fn material_json(m: &MeshData) -> json::Material {
    let mat = &m.material;
    json::Material {
        name: name_opt(&m.name),
        pbr_metallic_roughness: json::PbrMetallicRoughness {
            base_color_factor: mat.base_color,
            metallic_factor: mat.metallic,
            roughness_factor: mat.roughness,
        },
        alpha_mode: (mat.base_color[3] < 1.0).then(|| "BLEND".to_string()),
        double_sided: mat.double_sided,
    }
}

/// An animation: one sampler and one channel per [`ChannelData`](super::ChannelData).
fn animation_json(out: &mut Layout, a: &AnimationData) -> json::Animation {
    let mut anim = json::Animation {
        name: name_opt(&a.name),
        ..Default::default()
    };
    for c in &a.channels {
        let input = out.time_accessor(&c.times);
        let output = match &c.values {
            ChannelValues::Weights(w) => {
                let arrays: Vec<[f32; 1]> = w.iter().map(|&x| [x]).collect();
                out.floats(&arrays, None, false)
            }
            ChannelValues::Rotation(r) => {
                let arrays: Vec<[f32; 4]> = r.iter().map(|q| q.normalize().to_array()).collect();
                out.floats(&arrays, None, false)
            }
            ChannelValues::Translation(v) | ChannelValues::Scale(v) => out.vec3s(v, None, false),
        };
        anim.samplers.push(json::AnimationSampler {
            input,
            interpolation: match c.interpolation {
                Interpolation::Linear => None,
                Interpolation::Step => Some("STEP".into()),
            },
            output,
        });
        anim.channels.push(json::Channel {
            sampler: (anim.samplers.len() - 1) as u32,
            target: json::ChannelTarget {
                node: c.node.0,
                path: c.values.path().into(),
            },
        });
    }
    anim
}
