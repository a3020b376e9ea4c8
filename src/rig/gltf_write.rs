//! A rig written as glTF 2.0 morph targets, through the crate's glTF writer
//! ([`crate::gltf::SceneBuilder`]).
//!
//! One glTF mesh and one root node per rig mesh (both named after it), vertices in the rig's
//! order, polygons triangulated; every shape that moves the mesh becomes a sparse morph target
//! named in `extras.targetNames` with its default weight. Texture coordinates are written
//! when they are per vertex (indexed like the positions). [`super::gltf_read`] reads the
//! result back to an equal rig (same vertex order, names and deltas) for triangle meshes.

use std::borrow::Cow;

use crate::error::Result;
use crate::gltf::GltfDocument;
use crate::gltf::{MeshData, MorphOffsets, MorphTargetData, NodeData, SceneBuilder};

use super::Rig;

/// `rig` as a glTF document (no scaling: positions stay in the rig's units).
pub fn rig_to_gltf(rig: &Rig) -> Result<GltfDocument> {
    rig.check()?;
    let mut scene = SceneBuilder::new(rig.name.clone());
    for (mi, m) in rig.meshes.iter().enumerate() {
        let mesh = &m.mesh;
        let mut data = MeshData::new(
            m.name.clone(),
            Cow::Borrowed(mesh.positions.as_slice()),
            mesh.triangles(),
        );
        if mesh.uv_polygons.as_ref() == Some(&mesh.polygons)
            && mesh.uvs.len() == mesh.positions.len()
        {
            data = data.with_uvs(Cow::Borrowed(mesh.uvs.as_slice()));
        }
        if mesh.normal_polygons.as_ref() == Some(&mesh.polygons)
            && mesh.normals.len() == mesh.positions.len()
            && mesh
                .normals
                .iter()
                .all(|n| n.is_finite() && n.length_squared() > 1e-20)
        {
            data = data.with_normals(Cow::Borrowed(mesh.normals.as_slice()));
        }
        for s in &rig.shapes {
            let Some(d) = s.delta(mi) else {
                // A shape that moves nothing still keeps its name (on the first mesh).
                if mi == 0 && s.deltas.is_empty() {
                    data.morph_targets.push(MorphTargetData {
                        name: s.name.clone(),
                        offsets: MorphOffsets::Dense(Cow::Owned(vec![
                            glam::Vec3::ZERO;
                            mesh.positions.len()
                        ])),
                        default_weight: s.default_weight,
                    });
                }
                continue;
            };
            data.morph_targets.push(MorphTargetData {
                name: s.name.clone(),
                offsets: MorphOffsets::Sparse {
                    vertices: Cow::Borrowed(d.vertices.as_slice()),
                    offsets: Cow::Borrowed(d.offsets.as_slice()),
                },
                default_weight: s.default_weight,
            });
        }
        let id = scene.add_mesh(data)?;
        scene.add_node(NodeData::new(m.name.clone()).with_mesh(id))?;
    }
    scene.build()
}

/// Writes `rig` to `path` as `.glb` or `.gltf` (by extension), atomically.
pub fn write_rig_gltf(rig: &Rig, path: &std::path::Path) -> Result<()> {
    rig_to_gltf(rig)?.write(path)
}
