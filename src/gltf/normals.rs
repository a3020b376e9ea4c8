//! Vertex normals for glTF, which requires unit-length normals: the one area-weighted rule of
//! [`crate::mesh::geometry::vertex_normals`], with +Z where a vertex has none.

use glam::Vec3;

/// Area-weighted vertex normals; a vertex on no (non-degenerate) triangle gets +Z.
pub fn area_weighted_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    crate::mesh::geometry::vertex_normals(positions, triangles)
        .into_iter()
        .map(|n| if n == Vec3::ZERO { Vec3::Z } else { n })
        .collect()
}
