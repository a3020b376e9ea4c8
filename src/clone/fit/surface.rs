//! Closest-point queries on a triangle surface (one parry3d BVH) filtered by slit side
//! ([`super::regions`]) and, optionally, by normal compatibility; plus the surface's
//! boundary, so hits on a border can be rejected. Searches skip whole subtrees the filter
//! rejects ([`super::filter_tree`]), with the same results as a filter applied per triangle.

use glam::Vec3;
use parry3d::math::Vector as PVec;
use parry3d::query::PointQuery;
use parry3d::shape::{CompositeShapeRef, TriMesh};

use super::filter_tree::{FilterTree, NormalTest};
use super::regions::TriMask;
use crate::clone::tri_filter::FilteredTriMesh;
pub(crate) use crate::mesh::geometry::{adjacency, barycentric, triangle_normals};

/// A closest-point hit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    /// Triangle index.
    pub triangle: u32,
    /// Barycentric weights of the hit in that triangle.
    pub weights: [f32; 3],
    /// The point.
    pub point: Vec3,
}

/// A surface ready for filtered closest-point queries.
pub(crate) struct QuerySurface {
    mesh: Option<TriMesh>,
    /// The mesh's BVH with per-node masks and normal cones (`None`: one triangle).
    tree: Option<FilterTree>,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    masks: Vec<TriMask>,
    normals: Vec<Vec3>,
    /// Per triangle, per corner k: the edge opposite corner k is a border.
    border: Vec<[bool; 3]>,
}

/// What a query may see.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Filter {
    /// Mask bit of the querying vertex's side.
    pub bit: TriMask,
    /// Unit normal of the querying vertex and the least cosine a triangle normal must reach;
    /// `None`: any orientation.
    pub normal: Option<(Vec3, f32)>,
    /// A second normal a triangle may match instead (the querying vertex sits on a crease:
    /// the incident face normal farthest from its vertex normal).
    pub crease: Option<Vec3>,
}

impl QuerySurface {
    /// Whether triangle `i` passes `filter` (side mask and normal compatibility).
    fn allowed(&self, filter: Filter, i: u32) -> bool {
        let i = i as usize;
        let mask_ok = self
            .masks
            .get(i)
            .is_none_or(|&m| super::regions::mask_passes(m, filter.bit));
        mask_ok
            && filter.normal.is_none_or(|(n, c)| {
                self.normals
                    .get(i)
                    .is_none_or(|t| t.dot(n) >= c || filter.crease.is_some_and(|m| t.dot(m) >= c))
            })
    }
}

/// Per triangle, which corners face a border edge (an edge of one triangle only).
fn border_edges(triangles: &[[u32; 3]]) -> Vec<[bool; 3]> {
    // Every (edge, triangle, corner), sorted by edge: an edge alone in its run is a border.
    let key = |a: u32, b: u32| (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
    let mut edges: Vec<(u64, u32, u8)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(i, t)| {
            (0..3u8).map(move |k| {
                let k = k as usize;
                (key(t[(k + 1) % 3], t[(k + 2) % 3]), i as u32, k as u8)
            })
        })
        .collect();
    edges.sort_unstable_by_key(|e| e.0);
    let mut border = vec![[false; 3]; triangles.len()];
    for (j, e) in edges.iter().enumerate() {
        let alone =
            (j == 0 || edges[j - 1].0 != e.0) && edges.get(j + 1).is_none_or(|next| next.0 != e.0);
        if alone {
            border[e.1 as usize][e.2 as usize] = true;
        }
    }
    border
}

impl QuerySurface {
    /// Builds the BVH over `positions` / `triangles` with the triangles' side masks (empty:
    /// no slit filter).
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]], masks: Vec<TriMask>) -> Self {
        // parry's BVH on one core, the per-triangle tables on the other.
        let (mesh, (normals, border)) = rayon::join(
            || {
                let verts: Vec<PVec> = positions.iter().map(|p| PVec::new(p.x, p.y, p.z)).collect();
                if triangles.is_empty() {
                    None
                } else {
                    TriMesh::new(verts, triangles.to_vec()).ok()
                }
            },
            || {
                (
                    triangle_normals(positions, triangles),
                    border_edges(triangles),
                )
            },
        );
        let tree = mesh
            .as_ref()
            .and_then(|m| FilterTree::new(m, &masks, &normals));
        QuerySurface {
            mesh,
            tree,
            positions: positions.to_vec(),
            triangles: triangles.to_vec(),
            masks,
            normals,
            border,
        }
    }

    /// The closest point to `p` the filter allows.
    pub fn closest(&self, p: Vec3, filter: Filter) -> Option<Hit> {
        self.closest_within(p, filter, f32::MAX)
    }

    /// The closest point to `p` the filter allows, if one lies nearer than `max_dist`. The
    /// bound prunes the BVH search: a query whose nearby triangles the filter rejects stops
    /// at `max_dist` instead of searching the whole surface.
    pub fn closest_within(&self, p: Vec3, filter: Filter, max_dist: f32) -> Option<Hit> {
        self.closest_snapping(p, filter, 0.0, max_dist)
    }

    /// The closest point to `p` of the filter's side when it lies within `snap` of `p`
    /// (whatever the normals: a point on the surface matches there), else the closest point
    /// the whole filter allows nearer than `max_dist` (at least `snap`). One walk of the
    /// tree: the answer of a search of the side within `snap` followed by
    /// [`closest_within`](Self::closest_within).
    pub fn closest_snapping(
        &self,
        p: Vec3,
        filter: Filter,
        snap: f32,
        max_dist: f32,
    ) -> Option<Hit> {
        let mesh = self.mesh.as_ref()?;
        if !p.is_finite() {
            return None;
        }
        let allowed = |i| self.allowed(filter, i);
        let plain = Filter {
            normal: None,
            crease: None,
            ..filter
        };
        let on_side = |i| self.allowed(plain, i);
        let q = PVec::new(p.x, p.y, p.z);
        let max_dist = if snap > 0.0 {
            max_dist.max(snap)
        } else {
            max_dist
        };
        let (tri, proj, _) = match &self.tree {
            Some(tree) => {
                let normal = filter
                    .normal
                    .map(|(n, c)| NormalTest::new(n, filter.crease, c));
                tree.closest(
                    mesh,
                    q,
                    max_dist,
                    snap,
                    filter.bit,
                    normal.as_ref(),
                    allowed,
                    on_side,
                )?
            }
            None => {
                let side = CompositeShapeRef(&FilteredTriMesh {
                    mesh,
                    allowed: on_side,
                });
                let near = (snap > 0.0)
                    .then(|| side.project_local_point_and_get_location(q, snap * 1.001, false))
                    .flatten()
                    .filter(|h| (h.1.point - q).length() <= snap);
                match near {
                    Some(h) => h,
                    None => CompositeShapeRef(&FilteredTriMesh { mesh, allowed })
                        .project_local_point_and_get_location(q, max_dist, false)?,
                }
            }
        };
        let point = Vec3::new(proj.point.x, proj.point.y, proj.point.z);
        let t = self.triangles.get(tri as usize)?;
        let [a, b, c] = t.map(|v| self.positions[v as usize]);
        Some(Hit {
            triangle: tri,
            weights: barycentric(point, a, b, c),
            point,
        })
    }

    /// The closest point to `p` within triangle `tri` (its clamped barycentric weights):
    /// how a query that chose its triangle elsewhere reads the weights at `p` itself.
    pub fn within(&self, tri: u32, p: Vec3) -> Option<Hit> {
        let t = self.triangles.get(tri as usize)?;
        let [a, b, c] = t.map(|v| self.positions[v as usize]);
        let weights = barycentric(p, a, b, c);
        Some(Hit {
            triangle: tri,
            weights,
            point: a * weights[0] + b * weights[1] + c * weights[2],
        })
    }

    /// The distance from `p` to triangle `tri` if the filter allows it: an upper bound of
    /// [`closest`](Self::closest)'s distance, to bound that search (a warm start from the
    /// previous match).
    pub fn distance_to(&self, p: Vec3, filter: Filter, tri: u32) -> Option<f32> {
        let mesh = self.mesh.as_ref()?;
        if tri as usize >= self.triangles.len() || !self.allowed(filter, tri) {
            return None;
        }
        Some(
            mesh.triangle(tri)
                .distance_to_local_point(PVec::new(p.x, p.y, p.z), false),
        )
    }

    /// Whether any triangle of the surface passes `filter`, wherever it lies (a walk of the
    /// tree that skips the subtrees the filter rejects and stops at the first triangle).
    pub fn any_allowed(&self, filter: Filter) -> bool {
        let allowed = |i| self.allowed(filter, i);
        match &self.tree {
            Some(tree) => {
                let normal = filter
                    .normal
                    .map(|(n, c)| NormalTest::new(n, filter.crease, c));
                tree.any(filter.bit, normal.as_ref(), allowed)
            }
            None => self.mesh.is_some() && (0..self.triangles.len() as u32).any(allowed),
        }
    }

    /// Whether a hit lies on the surface's border (on a border edge of its triangle).
    pub fn on_border(&self, hit: &Hit) -> bool {
        self.border
            .get(hit.triangle as usize)
            .is_some_and(|b| (0..3).any(|k| b[k] && hit.weights[k] < 1e-4))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn border_edges_are_the_edges_of_one_triangle() {
        // Two triangles sharing edge 1-2, and a third sharing nothing.
        let b = border_edges(&[[0, 1, 2], [2, 1, 3], [4, 5, 6]]);
        assert_eq!(b, vec![[false, true, true], [true, true, false], [true; 3]]);
    }
}
