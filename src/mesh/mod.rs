//! Polygon meshes: the one model every face-geometry reader produces and every geometry
//! algorithm consumes.
//!
//! A [`Mesh`] keeps its faces exactly as the file gave them — polygons of any arity, vertex order
//! untouched — so that writers reproduce the input. Geometry work that needs triangles calls
//! [`Mesh::triangles`], which triangulates on demand ([`geometry`]). The layout is chosen for two
//! sources:
//!
//! - Wavefront OBJ ([`obj`]): global vertex/uv/normal arrays, per-corner index triples,
//!   `o`/`g`/`s`/`usemtl` state spans ([`FaceGroup`]).
//! - VRML97 `IndexedFaceSet`: `coord` + `coordIndex` (polygons separated by `-1`), `texCoord` +
//!   `texCoordIndex`, `normal` + `normalIndex`, and the `ccw`/`solid`/`creaseAngle` flags
//!   ([`SurfaceFlags`]). A `coordIndex` maps to [`Polygons`] one polygon per `-1`-terminated run.
//!
//! Positions are a flat `Vec<Vec3>` and faces a flat index buffer with offsets, so later stages
//! (FAT evaluation, ray casting, rendering) index straight into them.

pub mod components;
mod error;
pub mod geometry;
pub mod morton;
pub mod obj;
pub mod obj_patch;
pub mod orient;
pub mod rotation_fit;
pub mod spatial;
pub mod subdivide;
pub(crate) mod text;

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

pub use error::MeshError;
pub use geometry::{Aabb, MeshValidation};
pub use spatial::{find_coincident_vertices, CoincidentVertices, VertexIndex};

/// Polygons of any arity stored as one flat index buffer plus start offsets.
///
/// Polygon `i` is `indices[offsets[i]..offsets[i + 1]]`; `offsets` always starts with 0, so an
/// empty list has `offsets == [0]`. The indices point into whatever array the owner pairs them
/// with (positions, uvs or normals).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Polygons {
    indices: Vec<u32>,
    offsets: Vec<u32>,
}

impl Default for Polygons {
    fn default() -> Self {
        Polygons::new()
    }
}

impl Polygons {
    /// No polygons.
    pub fn new() -> Polygons {
        Polygons {
            indices: Vec::new(),
            offsets: vec![0],
        }
    }

    /// Polygons from triangles.
    pub fn from_triangles(triangles: &[[u32; 3]]) -> Polygons {
        let mut p = Polygons::new();
        for t in triangles {
            p.push(t);
        }
        p
    }

    /// Polygons from a list of index lists.
    pub fn from_lists<I, P>(lists: I) -> Polygons
    where
        I: IntoIterator<Item = P>,
        P: AsRef<[u32]>,
    {
        let mut p = Polygons::new();
        for l in lists {
            p.push(l.as_ref());
        }
        p
    }

    /// Appends one polygon. Arity is not checked here ([`Mesh::validate`] reports faces with
    /// fewer than three corners); readers reject them before pushing.
    ///
    /// # Panics
    /// If the total number of indices exceeds `u32::MAX` (4 G corners — beyond any input the
    /// bounded readers accept).
    pub fn push(&mut self, polygon: &[u32]) {
        self.indices.extend_from_slice(polygon);
        let end = u32::try_from(self.indices.len()).expect("more than u32::MAX polygon corners");
        self.offsets.push(end);
    }

    /// Number of polygons.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// True if there are no polygons.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Polygon `i`, if it exists.
    pub fn get(&self, i: usize) -> Option<&[u32]> {
        let start = *self.offsets.get(i)? as usize;
        let end = *self.offsets.get(i + 1)? as usize;
        Some(&self.indices[start..end])
    }

    /// All polygons in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[u32]> + Clone + '_ {
        self.offsets
            .windows(2)
            .map(|w| &self.indices[w[0] as usize..w[1] as usize])
    }

    /// The flat index buffer (all polygons' corners, in order).
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// Total number of corners over all polygons.
    pub fn corner_count(&self) -> usize {
        self.indices.len()
    }

    /// True if every polygon has exactly the same arity as the matching polygon of `other`
    /// (required of uv and normal polygons, which give one index per position corner).
    pub fn same_shape(&self, other: &Polygons) -> bool {
        self.offsets == other.offsets
    }
}

/// Per-mesh surface flags of VRML97 `IndexedFaceSet` (OBJ has none; defaults match VRML's).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFlags {
    /// Polygons are counter-clockwise seen from the front (VRML `ccw`, default true).
    pub ccw: bool,
    /// Back faces may be culled (VRML `solid`, default true).
    pub solid: bool,
    /// Polygons are convex (VRML `convex`, default true).
    pub convex: bool,
    /// Normals are smoothed across edges whose dihedral angle is below this (radians; VRML
    /// `creaseAngle`, default 0).
    pub crease_angle: f32,
}

impl Default for SurfaceFlags {
    fn default() -> Self {
        SurfaceFlags {
            ccw: true,
            solid: true,
            convex: true,
            crease_angle: 0.0,
        }
    }
}

/// A run of faces sharing the OBJ grouping state (`o`, `g`, `s`, `usemtl`).
///
/// A group applies from face `first_face` up to the next group's `first_face` (or the end).
/// Kept so an OBJ writer can reproduce the file's structure; geometry ignores it.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FaceGroup {
    /// Index of the first polygon of the run.
    pub first_face: u32,
    /// Current object name (`o`), if any.
    pub object: Option<String>,
    /// Current group names (`g`); empty for the default group.
    pub groups: Vec<String>,
    /// Current smoothing group (`s`); `None` for `s off` / `s 0` or none given.
    pub smoothing: Option<u32>,
    /// Current material (`usemtl`), if any.
    pub material: Option<String>,
}

/// A polygon mesh.
///
/// Invariants checked by [`Mesh::validate`] (not enforced by construction, so builders can fill
/// the fields directly): every index is in range of its array; `uv_polygons` and
/// `normal_polygons`, when present, have exactly the shape of `polygons`; `colors` is empty or
/// as long as `positions`; `groups` have non-decreasing `first_face`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Mesh {
    /// Name (OBJ: file stem; VRML: DEF name of the shape, if any).
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex RGB colours (0..1), empty if the source had none.
    pub colors: Vec<Vec3>,
    /// Faces as the source gave them: indices into `positions`, original arity and order.
    pub polygons: Polygons,
    /// Texture coordinates.
    pub uvs: Vec<Vec2>,
    /// Per-corner indices into `uvs`, same shape as `polygons`; `None` without texture
    /// coordinates. (VRML without `texCoordIndex` uses `coordIndex`: store a copy of it.)
    pub uv_polygons: Option<Polygons>,
    /// Normals.
    pub normals: Vec<Vec3>,
    /// Per-corner indices into `normals`, same shape as `polygons`; `None` without normals.
    pub normal_polygons: Option<Polygons>,
    /// OBJ object/group/material spans over the faces (empty: one default group).
    pub groups: Vec<FaceGroup>,
    /// VRML surface flags.
    pub flags: SurfaceFlags,
}

impl Mesh {
    /// A mesh of triangles over `positions`.
    pub fn from_triangles(
        name: impl Into<String>,
        positions: Vec<Vec3>,
        triangles: &[[u32; 3]],
    ) -> Mesh {
        Mesh {
            name: name.into(),
            positions,
            polygons: Polygons::from_triangles(triangles),
            ..Mesh::default()
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of polygons (faces as stored, not triangles).
    pub fn face_count(&self) -> usize {
        self.polygons.len()
    }

    /// The faces triangulated (see [`geometry::triangulate_polygon`]); polygons are untouched.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        geometry::triangulate(&self.positions, &self.polygons).0
    }

    /// Area-weighted vertex normals (see [`geometry::vertex_normals`]).
    pub fn vertex_normals(&self) -> Vec<Vec3> {
        geometry::vertex_normals(&self.positions, &self.triangles())
    }

    /// Axis-aligned bounds of the positions; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<Aabb> {
        Aabb::of_points(&self.positions)
    }

    /// Structural checks (see [`MeshValidation`]).
    pub fn validate(&self) -> MeshValidation {
        geometry::validate(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_store_any_arity_in_order() {
        let p = Polygons::from_lists([vec![0, 1, 2], vec![3, 4, 5, 6], vec![7, 8, 9, 10, 11]]);
        assert_eq!(p.len(), 3);
        assert_eq!(p.get(1), Some(&[3, 4, 5, 6][..]));
        assert_eq!(p.get(3), None);
        assert_eq!(p.corner_count(), 12);
        let arities: Vec<usize> = p.iter().map(|f| f.len()).collect();
        assert_eq!(arities, [3, 4, 5]);
        assert!(Polygons::new().is_empty());
        assert!(p.same_shape(&Polygons::from_lists([
            [9, 9, 9].as_slice(),
            &[0; 4],
            &[1; 5]
        ])));
        assert!(!p.same_shape(&Polygons::from_triangles(&[[0, 1, 2]])));
    }

    #[test]
    fn mesh_from_triangles_counts() {
        let m = Mesh::from_triangles("t", vec![Vec3::ZERO, Vec3::X, Vec3::Y], &[[0, 1, 2]]);
        assert_eq!((m.vertex_count(), m.face_count()), (3, 1));
        assert_eq!(m.triangles(), vec![[0, 1, 2]]);
        assert!(m.flags.ccw && m.flags.solid);
    }
}
