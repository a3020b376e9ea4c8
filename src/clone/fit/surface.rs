//! Closest-point queries on a triangle surface (one parry3d BVH) filtered by slit side
//! ([`super::regions`]) and, optionally, by normal compatibility; plus the surface's
//! boundary, so hits on a border can be rejected.

use std::collections::HashMap;

use glam::Vec3;
use parry3d::math::Vector as PVec;
use parry3d::shape::{CompositeShapeRef, TriMesh};

use super::regions::TriMask;
use crate::clone::tri_filter::FilteredTriMesh;

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
}

impl QuerySurface {
    /// Whether triangle `i` passes `filter` (side mask and normal compatibility).
    fn allowed(&self, filter: Filter, i: u32) -> bool {
        let i = i as usize;
        let mask_ok = self.masks.get(i).is_none_or(|m| m & filter.bit != 0);
        mask_ok
            && filter
                .normal
                .is_none_or(|(n, c)| self.normals.get(i).is_none_or(|t| t.dot(n) >= c))
    }
}

/// Unit normals of triangles (zero for degenerate ones).
pub(crate) fn triangle_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect()
}

/// Per triangle, which corners face a border edge (an edge of one triangle only).
fn border_edges(triangles: &[[u32; 3]]) -> Vec<[bool; 3]> {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut count: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 2);
    for t in triangles {
        for k in 0..3 {
            *count
                .entry(key(t[(k + 1) % 3], t[(k + 2) % 3]))
                .or_default() += 1;
        }
    }
    triangles
        .iter()
        .map(|t| std::array::from_fn(|k| count[&key(t[(k + 1) % 3], t[(k + 2) % 3])] == 1))
        .collect()
}

impl QuerySurface {
    /// Builds the BVH over `positions` / `triangles` with the triangles' side masks (empty:
    /// no slit filter).
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]], masks: Vec<TriMask>) -> Self {
        let verts: Vec<PVec> = positions.iter().map(|p| PVec::new(p.x, p.y, p.z)).collect();
        let mesh = if triangles.is_empty() {
            None
        } else {
            TriMesh::new(verts, triangles.to_vec()).ok()
        };
        QuerySurface {
            mesh,
            positions: positions.to_vec(),
            triangles: triangles.to_vec(),
            masks,
            normals: triangle_normals(positions, triangles),
            border: border_edges(triangles),
        }
    }

    /// The closest point to `p` the filter allows.
    pub fn closest(&self, p: Vec3, filter: Filter) -> Option<Hit> {
        let mesh = self.mesh.as_ref()?;
        if !p.is_finite() {
            return None;
        }
        let view = FilteredTriMesh {
            mesh,
            allowed: |i| self.allowed(filter, i),
        };
        let (tri, proj, _) = CompositeShapeRef(&view).project_local_point_and_get_location(
            PVec::new(p.x, p.y, p.z),
            f32::MAX,
            false,
        )?;
        let point = Vec3::new(proj.point.x, proj.point.y, proj.point.z);
        let t = self.triangles.get(tri as usize)?;
        let [a, b, c] = t.map(|v| self.positions[v as usize]);
        Some(Hit {
            triangle: tri,
            weights: barycentric(point, a, b, c),
            point,
        })
    }

    /// Whether a hit lies on the surface's border (on a border edge of its triangle).
    pub fn on_border(&self, hit: &Hit) -> bool {
        self.border
            .get(hit.triangle as usize)
            .is_some_and(|b| (0..3).any(|k| b[k] && hit.weights[k] < 1e-4))
    }
}

/// Barycentric weights of `p` (on or near triangle `a b c`), clamped to the triangle and
/// summing to one; a degenerate triangle gives its nearest corner weight one.
pub(crate) fn barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let (e0, e1, ep) = ((b - a).as_dvec3(), (c - a).as_dvec3(), (p - a).as_dvec3());
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (ep.dot(e0), ep.dot(e1));
    let denom = d00 * d11 - d01 * d01;
    let scale = d00.max(d11);
    if denom.is_nan() || denom <= 1e-12 * scale * scale {
        let d = [p.distance(a), p.distance(b), p.distance(c)];
        let k = (0..3).min_by(|&i, &j| d[i].total_cmp(&d[j])).unwrap_or(0);
        let mut w = [0.0; 3];
        w[k] = 1.0;
        return w;
    }
    let v = (d11 * d20 - d01 * d21) / denom;
    let w = (d00 * d21 - d01 * d20) / denom;
    let out = [(1.0 - v - w).max(0.0), v.max(0.0), w.max(0.0)];
    let s: f64 = out.iter().sum();
    if s.is_nan() || s <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    out.map(|x| (x / s) as f32)
}

/// Sorted, de-duplicated neighbours of every vertex.
pub(crate) fn adjacency(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut adj = vec![Vec::new(); vertex_count];
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b && (a as usize) < vertex_count && (b as usize) < vertex_count {
                adj[a as usize].push(b);
                adj[b as usize].push(a);
            }
        }
    }
    for n in &mut adj {
        n.sort_unstable();
        n.dedup();
    }
    adj
}
