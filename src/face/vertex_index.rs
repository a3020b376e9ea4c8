//! Nearest-vertex queries over every mesh of a face at once, in the face frame — how feature
//! points given by position are bound to the face's vertices.

use glam::Vec3;

use super::vrml::FeaturePointMatch;
use super::FaceModel;
use crate::fdp::VertexBinding;
use crate::mesh::VertexIndex;
use crate::spec::FeaturePointId;

/// A spatial index over the neutral face-frame positions of all meshes of a face.
pub struct FaceVertexIndex {
    /// Index item → (mesh, vertex).
    owners: Vec<(usize, u32)>,
    index: VertexIndex,
}

impl FaceVertexIndex {
    /// Indexes every vertex of `face` at neutral, placed by its mesh's transform chain.
    pub fn new(face: &FaceModel) -> FaceVertexIndex {
        let all: Vec<usize> = (0..face.meshes.len()).collect();
        FaceVertexIndex::of_meshes(face, &all)
    }

    /// Indexes the vertices of the meshes `meshes` of `face` (indices; unknown ones skipped).
    /// A vertex no polygon of its mesh uses is left out (a mesh without polygons keeps all):
    /// it is never seen and never moves, as a UV sphere's unused pole copies, so a point
    /// bound to it would not follow its part.
    pub fn of_meshes(face: &FaceModel, meshes: &[usize]) -> FaceVertexIndex {
        let frames = face.frames();
        let mut owners = Vec::with_capacity(face.vertex_count());
        let mut world = Vec::with_capacity(face.vertex_count());
        for &mi in meshes {
            let Some(m) = face.meshes.get(mi) else {
                continue;
            };
            let indices = m.mesh.polygons.indices();
            let mut used = vec![indices.is_empty(); m.mesh.positions.len()];
            for &v in indices {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
            for (vi, p) in m.mesh.positions.iter().enumerate() {
                if !used[vi] {
                    continue;
                }
                owners.push((mi, vi as u32));
                world.push(frames.meshes[mi].transform_point3(*p));
            }
        }
        FaceVertexIndex {
            owners,
            index: VertexIndex::new(&world),
        }
    }

    /// The (mesh, vertex) nearest to `point` and its distance; `None` for an empty face or a
    /// non-finite point.
    pub fn nearest(&self, point: Vec3) -> Option<(usize, u32, f32)> {
        let (i, distance) = self.index.nearest_vertex(point)?;
        let (mesh, vertex) = self.owners[i as usize];
        Some((mesh, vertex, distance))
    }

    /// Feature point `id` at `point` bound to the nearest vertex of `face` (the face this
    /// index was built on): its binding and the match to report.
    pub fn bind(
        &self,
        face: &FaceModel,
        id: FeaturePointId,
        point: Vec3,
    ) -> Option<(VertexBinding, FeaturePointMatch)> {
        let (mesh, vertex, distance) = self.nearest(point)?;
        let name = face.meshes.get(mesh)?.name.clone();
        let binding = VertexBinding {
            mesh: Some(name.clone()),
            vertices: vec![vertex],
        };
        let found = FeaturePointMatch {
            id,
            mesh: name,
            vertex,
            distance,
        };
        Some((binding, found))
    }
}
