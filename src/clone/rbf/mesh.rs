//! Mesh helpers for the RBF cloning method: vertex adjacency, vertex normals, barycentric
//! coordinates, groups of coincident vertices and region-filtered ray/closest-point queries
//! (parry3d BVHs).

use std::collections::HashMap;

use glam::Vec3;
use parry3d::math::Vector as PVec;
use parry3d::query::Ray;
use parry3d::shape::{CompositeShapeRef, TriMesh};

use super::regions::{Region, TriRegion};
use crate::clone::tri_filter::FilteredTriMesh;
pub(crate) use crate::mesh::geometry::{adjacency, barycentric, triangle_normals};

/// The triangles around each vertex (compressed rows), to find the triangles on either side
/// of an edge without a hash map over all edges.
pub(crate) struct VertexTriangles {
    start: Vec<u32>,
    tris: Vec<u32>,
}

impl VertexTriangles {
    pub fn new(vertex_count: usize, triangles: &[[u32; 3]]) -> Self {
        let mut start = vec![0u32; vertex_count + 1];
        for t in triangles {
            for &v in t {
                start[v as usize + 1] += 1;
            }
        }
        for i in 0..vertex_count {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut tris = vec![0u32; start[vertex_count] as usize];
        for (k, t) in triangles.iter().enumerate() {
            for &v in t {
                tris[fill[v as usize] as usize] = k as u32;
                fill[v as usize] += 1;
            }
        }
        VertexTriangles { start, tris }
    }

    /// The triangles having vertex `v`.
    pub fn around(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let range = self
            .start
            .get(v as usize)
            .zip(self.start.get(v as usize + 1))
            .map_or(0..0, |(&a, &b)| a as usize..b as usize);
        self.tris[range].iter().copied()
    }

    /// Third vertices of the triangles that have edge `a–b`.
    pub fn opposites<'a>(
        &'a self,
        triangles: &'a [[u32; 3]],
        a: u32,
        b: u32,
    ) -> impl Iterator<Item = u32> + 'a {
        let range = self.start[a as usize] as usize..self.start[a as usize + 1] as usize;
        self.tris[range].iter().filter_map(move |&k| {
            let t = triangles[k as usize];
            if t.contains(&b) {
                t.iter().copied().find(|&w| w != a && w != b)
            } else {
                None
            }
        })
    }
}

/// Groups of vertices at the same position (within `eps`): `class[v]` is the smallest vertex
/// index of `v`'s group. A closed mouth has such pairs (upper and lower inner lip).
pub(crate) fn coincidence_classes(positions: &[Vec3], eps: f32) -> Vec<u32> {
    let cell = |p: Vec3| -> [i64; 3] { (p / eps).floor().to_array().map(|x| x as i64) };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut class: Vec<u32> = (0..positions.len() as u32).collect();
    for (i, &p) in positions.iter().enumerate() {
        let c = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &j in list {
                            if positions[j as usize].distance(p) <= eps {
                                found = Some(class[j as usize]);
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        if let Some(k) = found {
            class[i] = k;
        }
        grid.entry(c).or_default().push(i as u32);
    }
    class
}

fn pvec(v: Vec3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

fn gvec(v: PVec) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// A surface hit: triangle and point on it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    /// Surface triangle index.
    pub triangle: u32,
    /// The point on that triangle.
    pub point: Vec3,
}

/// Ray and closest-point queries on a surface (one parry3d BVH), restricted by lip region: a
/// query for an upper-lip vertex never sees lower-lip (or mixed) triangles, and vice versa.
pub(crate) struct RegionBvh {
    mesh: Option<TriMesh>,
    regions: Vec<TriRegion>,
}

/// Whether a triangle of `regions` is seen from `query`: a query from one lip never sees
/// the other lip's triangles.
fn region_allows(regions: &[TriRegion], query: Region, triangle: u32) -> bool {
    let Some(r) = regions.get(triangle as usize) else {
        return true;
    };
    match query {
        Region::Other => true,
        Region::Upper => matches!(r, TriRegion::Other | TriRegion::Upper),
        Region::Lower => matches!(r, TriRegion::Other | TriRegion::Lower),
    }
}

impl RegionBvh {
    /// Builds the BVH; `tri_regions` empty means no lip separation.
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]], tri_regions: &[TriRegion]) -> Self {
        let verts = positions.iter().map(|&p| pvec(p)).collect();
        RegionBvh {
            mesh: TriMesh::new(verts, triangles.to_vec()).ok(),
            regions: tri_regions.to_vec(),
        }
    }

    /// The surface as seen from `region`: the same BVH, the other lip's triangles skipped.
    fn view(&self, region: Region) -> Option<FilteredTriMesh<'_, impl Fn(u32) -> bool + '_>> {
        let regions = &self.regions;
        Some(FilteredTriMesh {
            mesh: self.mesh.as_ref()?,
            allowed: move |i| region_allows(regions, region, i),
        })
    }

    /// The nearest surface point along `±dir` from `origin` within `length`.
    #[cfg(test)]
    pub fn ray_both_ways(
        &self,
        region: Region,
        origin: Vec3,
        dir: Vec3,
        length: f32,
    ) -> Option<Hit> {
        self.ray_both_ways_where(region, origin, dir, length, |_| true)
    }

    /// Like [`RegionBvh::ray_both_ways`], but only hits on triangles that `accept` are
    /// taken: a ray that meets a rejected triangle goes on through it (at most a few times).
    pub fn ray_both_ways_where(
        &self,
        region: Region,
        origin: Vec3,
        dir: Vec3,
        length: f32,
        accept: impl Fn(u32) -> bool,
    ) -> Option<Hit> {
        if dir == Vec3::ZERO || !origin.is_finite() || !dir.is_finite() {
            return None;
        }
        if let Some(h) = self.cast_both_ways(region, origin, dir, length, &accept) {
            return Some(h);
        }
        // A ray exactly through a vertex or along an edge can slip between its triangles;
        // which of two mirror-image rays slips is a rounding accident, so retry from four
        // origins a hair to the sides (the hit moves by as little).
        let (t1, t2) = dir.normalize_or_zero().any_orthonormal_pair();
        let hair = length.max(f32::MIN_POSITIVE) * 1e-4;
        [t1, -t1, t2, -t2]
            .into_iter()
            .filter_map(|t| {
                let h = self.cast_both_ways(region, origin + t * hair, dir, length, &accept)?;
                Some((h.point.distance(origin), h))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, h)| Hit {
                point: h.point,
                ..h
            })
    }

    fn cast_both_ways(
        &self,
        region: Region,
        origin: Vec3,
        dir: Vec3,
        length: f32,
        accept: &impl Fn(u32) -> bool,
    ) -> Option<Hit> {
        let view = self.view(region)?;
        // Past a rejected hit by a hair, so the same triangle is not met again.
        let nudge = length.max(f32::MIN_POSITIVE) * 1e-5;
        let mut best: Option<(f32, u32, Vec3)> = None;
        for d in [dir, -dir] {
            let mut from = 0.0f32;
            for _ in 0..8 {
                let ray = Ray::new(pvec(origin + d * from), pvec(d));
                let Some((tri, t)) =
                    CompositeShapeRef(&view).cast_local_ray(&ray, length - from, false)
                else {
                    break;
                };
                let at = from + t;
                // A hit at the origin is the ray's own surface, whichever way it faces.
                if at <= nudge || accept(tri) {
                    if best.is_none_or(|(bt, _, _)| at < bt) {
                        best = Some((at, tri, d));
                    }
                    break;
                }
                from = at + nudge;
                if from >= length {
                    break;
                }
            }
        }
        best.map(|(t, triangle, d)| Hit {
            triangle,
            point: origin + d * t,
        })
    }

    /// The closest surface point to `p`.
    pub fn closest(&self, region: Region, p: Vec3) -> Option<Hit> {
        let view = self.view(region)?;
        if !p.is_finite() {
            return None;
        }
        let (tri, proj, _) = CompositeShapeRef(&view).project_local_point_and_get_location(
            pvec(p),
            f32::MAX,
            false,
        )?;
        Some(Hit {
            triangle: tri,
            point: gvec(proj.point),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::geometry::vertex_normals;

    #[test]
    fn barycentric_reproduces_points_and_clamps() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let w = barycentric(Vec3::new(0.25, 0.5, 0.0), a, b, c);
        assert!(
            (w[0] - 0.25).abs() < 1e-6 && (w[1] - 0.25).abs() < 1e-6 && (w[2] - 0.5).abs() < 1e-6
        );
        let back = a * w[0] + b * w[1] + c * w[2];
        assert!(back.distance(Vec3::new(0.25, 0.5, 0.0)) < 1e-6);
        assert_eq!(barycentric(b, a, b, c), [0.0, 1.0, 0.0]);
        // Slightly outside: clamped, still sums to one.
        let w = barycentric(Vec3::new(-1e-4, 0.5, 0.0), a, b, c);
        assert!(w.iter().all(|&x| x >= 0.0) && (w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // Degenerate triangle: nearest vertex.
        assert_eq!(
            barycentric(Vec3::X * 0.9, a, Vec3::X, Vec3::X * 2.0)[1],
            1.0
        );
    }

    #[test]
    fn adjacency_normals_and_classes() {
        let pos = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::X,
        ];
        let tris = vec![[0, 1, 2], [1, 3, 2]];
        let adj = adjacency(pos.len(), &tris);
        assert_eq!(adj[1], vec![0, 2, 3]);
        assert!(adj[4].is_empty());
        let n = vertex_normals(&pos, &tris);
        assert!(n[0].distance(Vec3::Z) < 1e-6 && n[4] == Vec3::ZERO);
        assert_eq!(coincidence_classes(&pos, 1e-6), vec![0, 1, 2, 3, 1]);
        let vt = VertexTriangles::new(pos.len(), &tris);
        assert_eq!(vt.opposites(&tris, 1, 2).collect::<Vec<_>>(), vec![0, 3]);
        assert_eq!(vt.opposites(&tris, 0, 3).count(), 0);
    }

    #[test]
    fn rays_hit_through_vertices_or_fall_back() {
        let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let tris = vec![[0, 1, 2], [1, 3, 2]];
        let bvh = RegionBvh::new(&pos, &tris, &[]);
        let h = bvh
            .ray_both_ways(Region::Other, Vec3::new(0.2, 0.2, -0.5), Vec3::Z, 1.0)
            .unwrap();
        assert_eq!(h.triangle, 0);
        assert!(h.point.distance(Vec3::new(0.2, 0.2, 0.0)) < 1e-6);
        // Backwards along the direction too.
        let h = bvh
            .ray_both_ways(Region::Other, Vec3::new(0.8, 0.8, 0.5), Vec3::Z, 1.0)
            .unwrap();
        assert_eq!(h.triangle, 1);
        assert!(bvh
            .ray_both_ways(Region::Other, Vec3::new(0.8, 0.8, 5.0), Vec3::Z, 1.0)
            .is_none());
        let c = bvh
            .closest(Region::Other, Vec3::new(2.0, 0.5, 0.3))
            .unwrap();
        assert!(c.point.distance(Vec3::new(1.0, 0.5, 0.0)) < 1e-6);
    }
}
