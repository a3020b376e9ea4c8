//! Geometry on meshes as plain functions: triangulation, normals, bounds, validation.

use glam::{Vec2, Vec3};
use serde::Serialize;

use super::{Mesh, Polygons};

/// Polygons with more corners than this are fan-triangulated without ear clipping: ear clipping
/// is quadratic to cubic in the corner count and a hostile file could hold one huge face.
pub const MAX_EAR_CLIPPING_CORNERS: usize = 256;

/// Triangulates every polygon; returns the triangles and, for each, the index of the polygon it
/// came from. Polygons with fewer than three corners or an out-of-range index produce nothing
/// ([`validate`] reports them).
pub fn triangulate(positions: &[Vec3], polygons: &Polygons) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut triangles =
        Vec::with_capacity(polygons.corner_count().saturating_sub(2 * polygons.len()));
    let mut source = Vec::with_capacity(triangles.capacity());
    for (face, poly) in polygons.iter().enumerate() {
        if poly.len() < 3 || poly.iter().any(|&i| i as usize >= positions.len()) {
            continue;
        }
        let before = triangles.len();
        triangulate_polygon(positions, poly, &mut triangles);
        source.resize(triangles.len(), face as u32);
        debug_assert!(triangles.len() - before == poly.len() - 2);
    }
    (triangles, source)
}

/// Appends `poly.len() - 2` triangles covering one polygon (indices already checked in range),
/// keeping the polygon's winding.
///
/// Method: the polygon is projected onto the plane of its Newell normal
/// `N = Σ pᵢ × pᵢ₊₁` (robust for non-planar polygons; it points to the side from which the
/// polygon is counter-clockwise). If every corner turns left in that plane the polygon is convex
/// and is split as a fan from corner 0: `(0, i, i+1)`. Otherwise ear clipping: repeatedly cut off
/// a convex corner whose triangle contains no other remaining corner. Degenerate input (zero
/// normal, self-intersection leaving no ear) and polygons above [`MAX_EAR_CLIPPING_CORNERS`]
/// fall back to the fan, which always yields the right triangle count.
pub fn triangulate_polygon(positions: &[Vec3], poly: &[u32], out: &mut Vec<[u32; 3]>) {
    let n = poly.len();
    if n < 3 {
        return;
    }
    if n == 3 {
        out.push([poly[0], poly[1], poly[2]]);
        return;
    }
    let fan = |out: &mut Vec<[u32; 3]>, idx: &[u32]| {
        for i in 1..idx.len() - 1 {
            out.push([idx[0], idx[i], idx[i + 1]]);
        }
    };
    let p = |i: u32| positions[i as usize];
    let normal = newell_normal(poly.iter().map(|&i| p(i)));
    if n > MAX_EAR_CLIPPING_CORNERS || !normal.is_finite() || normal.length_squared() == 0.0 {
        fan(out, poly);
        return;
    }
    // Orthonormal frame (t, b) with t × b = n̂, so counter-clockwise about n̂ stays
    // counter-clockwise in 2D.
    let nh = normal.normalize();
    let t = nh.any_orthonormal_vector();
    let b = nh.cross(t);
    let pts: Vec<Vec2> = poly
        .iter()
        .map(|&i| {
            let q = p(i);
            Vec2::new(q.dot(t), q.dot(b))
        })
        .collect();
    let turn = |a: Vec2, o: Vec2, c: Vec2| (o - a).perp_dot(c - o);
    let convex = (0..n).all(|i| turn(pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]) >= 0.0);
    if convex {
        fan(out, poly);
        return;
    }
    let mut remaining: Vec<usize> = (0..n).collect();
    while remaining.len() > 3 {
        let m = remaining.len();
        let ear = (0..m).find(|&k| {
            let (a, o, c) = (
                remaining[(k + m - 1) % m],
                remaining[k],
                remaining[(k + 1) % m],
            );
            if turn(pts[a], pts[o], pts[c]) <= 0.0 {
                return false;
            }
            remaining
                .iter()
                .filter(|&&j| j != a && j != o && j != c)
                .all(|&j| !inside_triangle(pts[j], pts[a], pts[o], pts[c]))
        });
        match ear {
            Some(k) => {
                let (a, o, c) = (
                    remaining[(k + m - 1) % m],
                    remaining[k],
                    remaining[(k + 1) % m],
                );
                out.push([poly[a], poly[o], poly[c]]);
                remaining.remove(k);
            }
            None => {
                let rest: Vec<u32> = remaining.iter().map(|&j| poly[j]).collect();
                fan(out, &rest);
                return;
            }
        }
    }
    out.push([poly[remaining[0]], poly[remaining[1]], poly[remaining[2]]]);
}

/// True if `q` lies inside or on the counter-clockwise triangle `(a, b, c)`.
fn inside_triangle(q: Vec2, a: Vec2, b: Vec2, c: Vec2) -> bool {
    let d1 = (b - a).perp_dot(q - a);
    let d2 = (c - b).perp_dot(q - b);
    let d3 = (a - c).perp_dot(q - c);
    d1 >= 0.0 && d2 >= 0.0 && d3 >= 0.0
}

/// Newell's polygon normal `Σ pᵢ × pᵢ₊₁`: twice the vector area of the (possibly non-planar)
/// polygon; its length is twice the area of a planar polygon.
pub fn newell_normal(points: impl Iterator<Item = Vec3> + Clone) -> Vec3 {
    let mut next = points.clone().cycle().skip(1);
    points.fold(Vec3::ZERO, |acc, p| acc + p.cross(next.next().unwrap_or(p)))
}

/// Area-weighted vertex normals: each triangle adds `(b − a) × (c − a)` — its normal scaled by
/// twice its area — to its three corners; the sums are normalised. Vertices on no (or only
/// degenerate) triangles get `Vec3::ZERO`. Triangles with out-of-range indices are skipped.
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [Some(&a), Some(&b), Some(&c)] = t.map(|i| positions.get(i as usize)) else {
            continue;
        };
        let w = (b - a).cross(c - a);
        for &i in t {
            sums[i as usize] += w;
        }
    }
    sums.into_iter().map(Vec3::normalize_or_zero).collect()
}

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Aabb {
    /// Smallest coordinate on each axis.
    pub min: Vec3,
    /// Largest coordinate on each axis.
    pub max: Vec3,
}

impl Aabb {
    /// Bounds of `points`; `None` if empty. Non-finite coordinates are skipped.
    pub fn of_points(points: &[Vec3]) -> Option<Aabb> {
        let mut it = points.iter().copied().filter(|p| p.is_finite());
        let first = it.next()?;
        Some(it.fold(
            Aabb {
                min: first,
                max: first,
            },
            |b, p| Aabb {
                min: b.min.min(p),
                max: b.max.max(p),
            },
        ))
    }

    /// Edge lengths.
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Centre point.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Length of the diagonal (a scale for tolerances).
    pub fn diagonal(&self) -> f32 {
        self.size().length()
    }
}

/// Findings of [`validate`]: counts of each kind of problem.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct MeshValidation {
    /// Position indices `>= positions.len()`.
    pub out_of_range_indices: usize,
    /// Polygons with fewer than three corners.
    pub short_faces: usize,
    /// Polygons repeating a vertex or with (near) zero area: `|N| ≤ 1e-7·L²` for Newell normal
    /// `N` and longest edge `L`. Legal but useless for geometry.
    pub degenerate_faces: usize,
    /// Positions with NaN or infinite coordinates.
    pub non_finite_positions: usize,
    /// uv polygons present but shaped differently from the polygons, or indices out of range.
    pub bad_uv_polygons: usize,
    /// normal polygons present but shaped differently from the polygons, or indices out of range.
    pub bad_normal_polygons: usize,
    /// `colors` is neither empty nor as long as `positions`.
    pub color_count_mismatch: bool,
    /// Face groups out of order or starting past the last face.
    pub bad_groups: usize,
}

impl MeshValidation {
    /// True if the mesh is structurally sound (degenerate faces are allowed).
    pub fn is_valid(&self) -> bool {
        self.out_of_range_indices == 0
            && self.short_faces == 0
            && self.non_finite_positions == 0
            && self.bad_uv_polygons == 0
            && self.bad_normal_polygons == 0
            && !self.color_count_mismatch
            && self.bad_groups == 0
    }
}

/// Counts the structural problems of `mesh` (see [`MeshValidation`]).
pub fn validate(mesh: &Mesh) -> MeshValidation {
    let np = mesh.positions.len();
    let mut v = MeshValidation {
        non_finite_positions: mesh.positions.iter().filter(|p| !p.is_finite()).count(),
        color_count_mismatch: !mesh.colors.is_empty() && mesh.colors.len() != np,
        ..MeshValidation::default()
    };
    for poly in mesh.polygons.iter() {
        let bad = poly.iter().filter(|&&i| i as usize >= np).count();
        v.out_of_range_indices += bad;
        if poly.len() < 3 {
            v.short_faces += 1;
            continue;
        }
        if bad > 0 {
            continue;
        }
        let repeated = (0..poly.len()).any(|i| poly[i + 1..].contains(&poly[i]));
        let pts = poly.iter().map(|&i| mesh.positions[i as usize]);
        let longest = (0..poly.len())
            .map(|i| {
                let a = mesh.positions[poly[i] as usize];
                let b = mesh.positions[poly[(i + 1) % poly.len()] as usize];
                a.distance_squared(b)
            })
            .fold(0.0f32, f32::max);
        let area2 = newell_normal(pts).length();
        if repeated || area2.is_nan() || area2 <= 1e-7 * longest {
            v.degenerate_faces += 1;
        }
    }
    let check_attr = |polys: &Option<Polygons>, len: usize| -> usize {
        match polys {
            None => 0,
            Some(p) if !p.same_shape(&mesh.polygons) => 1.max(p.len()),
            Some(p) => p
                .iter()
                .filter(|f| f.iter().any(|&i| i as usize >= len))
                .count(),
        }
    };
    v.bad_uv_polygons = check_attr(&mesh.uv_polygons, mesh.uvs.len());
    v.bad_normal_polygons = check_attr(&mesh.normal_polygons, mesh.normals.len());
    let faces = mesh.polygons.len() as u64;
    let mut prev = 0u64;
    for g in &mesh.groups {
        let f = u64::from(g.first_face);
        if f < prev || f > faces {
            v.bad_groups += 1;
        }
        prev = prev.max(f);
    }
    v
}

/// Unit normals of triangles (zero for degenerate ones and for triangles with an index out of
/// range).
pub fn triangle_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions.get(v as usize).copied().unwrap_or(Vec3::ZERO));
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect()
}

/// Barycentric weights of `p` (on or near triangle `a b c`), clamped to the triangle and
/// summing to one; a degenerate triangle gives its nearest corner weight one.
pub fn barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
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

/// Sorted, de-duplicated neighbours of every vertex (the edges of `triangles`; indices out of
/// range are skipped).
pub fn adjacency(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let edges = || {
        triangles.iter().flat_map(|t| {
            (0..3).map(|k| (t[k], t[(k + 1) % 3])).filter(|&(a, b)| {
                a != b && (a as usize) < vertex_count && (b as usize) < vertex_count
            })
        })
    };
    // Each list allocated once, with room for every edge end before de-duplication: growing
    // tens of thousands of small lists cost more than filling them.
    let mut degree = vec![0usize; vertex_count];
    for (a, b) in edges() {
        degree[a as usize] += 1;
        degree[b as usize] += 1;
    }
    let mut adj: Vec<Vec<u32>> = degree.into_iter().map(Vec::with_capacity).collect();
    for (a, b) in edges() {
        adj[a as usize].push(b);
        adj[b as usize].push(a);
    }
    for n in &mut adj {
        n.sort_unstable();
        n.dedup();
    }
    adj
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(positions: &[Vec3], tris: &[[u32; 3]]) -> f32 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                (b - a).cross(c - a).length() / 2.0
            })
            .sum()
    }

    #[test]
    fn convex_quad_is_a_fan() {
        let pos = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let mut out = Vec::new();
        triangulate_polygon(&pos, &[0, 1, 2, 3], &mut out);
        assert_eq!(out, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn concave_polygon_is_ear_clipped_with_exact_area() {
        // An L shape starting next to its reflex corner (1, 1): a fan from corner 0 would
        // produce the triangle (2,1)-(1,2)-(0,2), which lies partly outside.
        let pos: Vec<Vec3> = [
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
            (0.0, 0.0),
            (2.0, 0.0),
        ]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, 0.0))
        .collect();
        let poly = [0, 1, 2, 3, 4, 5];
        let mut out = Vec::new();
        triangulate_polygon(&pos, &poly, &mut out);
        assert_eq!(out.len(), 4);
        // Area of the L: 2×2 square minus the 1×1 notch.
        assert!((area(&pos, &out) - 3.0).abs() < 1e-5, "{out:?}");
        // Winding kept: every triangle faces +z like the polygon.
        for t in &out {
            let [a, b, c] = t.map(|i| pos[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0);
        }
        // Same polygon wound clockwise: still 3 triangles, all facing -z.
        let rev: Vec<u32> = poly.iter().rev().copied().collect();
        let mut out = Vec::new();
        triangulate_polygon(&pos, &rev, &mut out);
        assert!((area(&pos, &out) - 3.0).abs() < 1e-5);
        for t in &out {
            let [a, b, c] = t.map(|i| pos[i as usize]);
            assert!((b - a).cross(c - a).z < 0.0);
        }
    }

    #[test]
    fn degenerate_polygons_still_give_n_minus_2_triangles() {
        let pos = [Vec3::ZERO; 5];
        let mut out = Vec::new();
        triangulate_polygon(&pos, &[0, 1, 2, 3, 4], &mut out);
        assert_eq!(out.len(), 3);
    }

    #[test]
    fn vertex_normals_of_a_flat_square_point_up() {
        let pos = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
            Vec3::Z,
        ];
        let n = vertex_normals(&pos, &[[0, 1, 2], [0, 2, 3]]);
        for v in &n[..4] {
            assert!((*v - Vec3::Z).length() < 1e-6);
        }
        assert_eq!(n[4], Vec3::ZERO, "unused vertex");
    }

    #[test]
    fn area_weighting_favours_the_larger_face() {
        // Vertex 0 shared by a big triangle facing +z and a small one facing +x.
        let pos = vec![
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(0.0, 10.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let n = vertex_normals(&pos, &[[0, 1, 2], [0, 3, 4]]);
        // Weights 100 (+z) and 1 (+x): normalised (1, 0, 100)/|..|.
        let expected = Vec3::new(1.0, 0.0, 100.0).normalize();
        assert!((n[0] - expected).length() < 1e-6);
    }

    #[test]
    fn bounds_skip_nothing_finite() {
        let b = Aabb::of_points(&[Vec3::new(1.0, -2.0, 3.0), Vec3::new(-1.0, 5.0, 0.0)]).unwrap();
        assert_eq!(b.min, Vec3::new(-1.0, -2.0, 0.0));
        assert_eq!(b.max, Vec3::new(1.0, 5.0, 3.0));
        assert_eq!(b.center(), Vec3::new(0.0, 1.5, 1.5));
        assert!(Aabb::of_points(&[]).is_none());
    }

    #[test]
    fn validation_counts_each_problem() {
        let mut m = Mesh::from_triangles(
            "v",
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            &[[0, 1, 2], [0, 0, 1], [0, 1, 7]],
        );
        m.polygons.push(&[0, 1]);
        let v = m.validate();
        assert_eq!(v.out_of_range_indices, 1);
        assert_eq!(v.degenerate_faces, 1);
        assert_eq!(v.short_faces, 1);
        assert!(!v.is_valid());
        let ok = Mesh::from_triangles("ok", vec![Vec3::ZERO, Vec3::X, Vec3::Y], &[[0, 1, 2]]);
        assert!(ok.validate().is_valid());
        assert_eq!(ok.validate(), MeshValidation::default());
        let mut bad_uv = ok.clone();
        bad_uv.uv_polygons = Some(Polygons::from_lists([[0u32, 1, 2, 3]]));
        assert_eq!(bad_uv.validate().bad_uv_polygons, 1);
    }
}
