//! Nearest-vertex queries over a k-d tree, and detection of coincident (duplicated) vertices.

use glam::{DVec3, Vec3};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;
use serde::Serialize;

/// A k-d tree over vertex positions answering nearest-vertex and radius queries.
///
/// Non-finite positions are left out of the tree (they are never the answer).
pub struct VertexIndex {
    tree: Option<ImmutableKdTree<f32, u32, 3, 32>>,
    /// Tree item → original vertex index (identity unless non-finite points were skipped).
    ids: Vec<u32>,
}

impl VertexIndex {
    /// Builds the index over `positions` (O(n log n)).
    pub fn new(positions: &[Vec3]) -> VertexIndex {
        let (points, ids): (Vec<[f32; 3]>, Vec<u32>) = positions
            .iter()
            .enumerate()
            .filter(|(_, p)| p.is_finite())
            .map(|(i, p)| (p.to_array(), i as u32))
            .unzip();
        let tree = (!points.is_empty()).then(|| ImmutableKdTree::new_from_slice(&points));
        VertexIndex { tree, ids }
    }

    /// Number of indexed vertices.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// True if no vertex is indexed.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The vertex closest to `point` and its Euclidean distance; `None` if the index is empty or
    /// `point` is not finite. Ties go to any of the closest vertices.
    pub fn nearest_vertex(&self, point: Vec3) -> Option<(u32, f32)> {
        let tree = self.tree.as_ref()?;
        if !point.is_finite() {
            return None;
        }
        let n = tree.nearest_one::<SquaredEuclidean>(&point.to_array());
        Some((self.ids[n.item as usize], n.distance.sqrt()))
    }

    /// All vertices within distance `radius` of `point` (inclusive), nearest first, with their
    /// distances.
    pub fn within(&self, point: Vec3, radius: f32) -> Vec<(u32, f32)> {
        let Some(tree) = self.tree.as_ref() else {
            return Vec::new();
        };
        if !point.is_finite() || !radius.is_finite() || radius < 0.0 {
            return Vec::new();
        }
        // kiddo's `within` is exclusive of the bound; nudge it up one ulp to include it.
        let r2 = radius * radius;
        let bound = f32::from_bits(r2.to_bits() + 1);
        tree.within::<SquaredEuclidean>(&point.to_array(), bound)
            .into_iter()
            .filter(|n| n.distance <= r2)
            .map(|n| (self.ids[n.item as usize], n.distance.sqrt()))
            .collect()
    }
}

/// Result of [`find_coincident_vertices`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct CoincidentVertices {
    /// For each vertex, the vertex it coincides with that has the smallest index (itself if
    /// none): a merge map usable to re-index faces.
    pub representative: Vec<u32>,
    /// The clusters of two or more coincident vertices, each sorted, in order of their smallest
    /// member.
    pub clusters: Vec<Vec<u32>>,
}

/// Finds vertices lying within `epsilon` of each other (e.g. duplicated seam vertices).
///
/// Greedy clustering in index order: the lowest unassigned vertex claims every unassigned vertex
/// within `epsilon` of it. Clusters are therefore balls around their representative, so two
/// vertices `2·epsilon` apart may land in different clusters — fine for exact or near-exact
/// duplicates, which is the use case. Non-finite positions are never merged.
///
/// The pairs within `epsilon` come from a grid of cells `CELL` × `epsilon` wide (a point
/// looks only into the cells its `epsilon` box touches: nearly always its own), in parallel;
/// a k-d tree, several times slower on a head's tens of thousands of vertices (a clone
/// calls this a dozen times), stands in when the cells cannot be numbered (`epsilon` 0,
/// or coordinates beyond 10¹⁵ cells).
pub fn find_coincident_vertices(positions: &[Vec3], epsilon: f32) -> CoincidentVertices {
    let mut pairs =
        grid_pairs(positions, epsilon).unwrap_or_else(|| tree_pairs(positions, epsilon));
    pairs.sort_unstable();
    let mut representative: Vec<u32> = (0..positions.len() as u32).collect();
    let mut assigned = vec![false; positions.len()];
    let mut clusters = Vec::new();
    let mut k = 0;
    for (i, p) in positions.iter().enumerate() {
        let first = k;
        while pairs.get(k).is_some_and(|e| e.0 as usize == i) {
            k += 1;
        }
        if assigned[i] || !p.is_finite() {
            continue;
        }
        assigned[i] = true;
        if first == k {
            continue;
        }
        let mut cluster = vec![i as u32];
        for &(_, j) in &pairs[first..k] {
            let ju = j as usize;
            if !assigned[ju] {
                assigned[ju] = true;
                representative[ju] = i as u32;
                cluster.push(j);
            }
        }
        if cluster.len() > 1 {
            cluster.sort_unstable();
            clusters.push(cluster);
        }
    }
    CoincidentVertices {
        representative,
        clusters,
    }
}

/// Width of [`find_coincident_vertices`]' grid cells in `epsilon`s: wide enough that a point's
/// `epsilon` box nearly always lies in its own cell, narrow enough that a cell of a mesh holds
/// a vertex or two (`epsilon` is a millionth of a face's size there).
const CELL: f64 = 1024.0;

/// Squared distance as the k-d tree measures it (same operations in the same order), so a
/// pair is within `epsilon` for the grid exactly when it is for the tree.
fn squared_distance(a: Vec3, b: Vec3) -> f32 {
    let d = a - b;
    d.x * d.x + d.y * d.y + d.z * d.z
}

/// Every ordered pair `(i, j)`, `i ≠ j`, of finite points within `epsilon` (squared distance
/// ≤ `epsilon²`), by a grid; `None` when the cells cannot be numbered. The points are sorted
/// by a hash of their cell: a cell's points lie side by side (with those of any cell sharing
/// its hash, which the distance test then turns away), and a point whose `epsilon` box
/// crosses into other cells finds theirs by a binary search.
fn grid_pairs(positions: &[Vec3], epsilon: f32) -> Option<Vec<(u32, u32)>> {
    if !(epsilon > 0.0 && epsilon.is_finite()) {
        return None;
    }
    let cell = epsilon as f64 * CELL;
    let coordinate = |x: f64| {
        let c = (x / cell).floor();
        (c.abs() < 1e15).then_some(c as i64)
    };
    let key = |p: DVec3| -> Option<[i64; 3]> {
        Some([coordinate(p.x)?, coordinate(p.y)?, coordinate(p.z)?])
    };
    let hash = |c: [i64; 3]| {
        (c[0] as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (c[1] as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ (c[2] as u64).wrapping_mul(0x1656_67B1_9E37_79F9)
    };
    let mut keyed: Vec<(u64, u32)> = Vec::with_capacity(positions.len());
    for (i, p) in positions.iter().enumerate() {
        if p.is_finite() {
            keyed.push((hash(key(p.as_dvec3())?), i as u32));
        }
    }
    keyed.par_sort_unstable();
    let keyed = &keyed;
    // The points of the cells with hash `h`.
    let run = |h: u64| {
        let a = keyed.partition_point(|e| e.0 < h);
        let b = a + keyed[a..].partition_point(|e| e.0 == h);
        &keyed[a..b]
    };
    // The box searched: a little wider than `epsilon`, beyond any rounding of the squared
    // distance test.
    let reach = epsilon as f64 * (1.0 + 1e-3);
    let r2 = epsilon * epsilon;
    let pairs = (0..keyed.len())
        .into_par_iter()
        .flat_map_iter(|k| {
            let (h, i) = keyed[k];
            let p = positions[i as usize];
            let q = p.as_dvec3();
            let mut out = Vec::new();
            let mut take = |near: &[(u64, u32)]| {
                for &(_, j) in near {
                    if j != i && squared_distance(p, positions[j as usize]) <= r2 {
                        out.push((i, j));
                    }
                }
            };
            match (key(q - reach), key(q + reach)) {
                (Some(lo), Some(hi)) if lo == hi => {
                    // Within its own cell: the run around it.
                    let a = keyed[..k].iter().rev().take_while(|e| e.0 == h).count();
                    let b = keyed[k..].iter().take_while(|e| e.0 == h).count();
                    take(&keyed[k - a..k + b]);
                }
                (Some(lo), Some(hi)) => {
                    for x in lo[0]..=hi[0] {
                        for y in lo[1]..=hi[1] {
                            for z in lo[2]..=hi[2] {
                                take(run(hash([x, y, z])));
                            }
                        }
                    }
                }
                _ => {}
            }
            out.into_iter()
        })
        .collect::<Vec<_>>();
    let mut pairs = pairs;
    // Two cells of one box sharing a hash list their points twice.
    pairs.sort_unstable();
    pairs.dedup();
    Some(pairs)
}

/// [`grid_pairs`] by the k-d tree.
fn tree_pairs(positions: &[Vec3], epsilon: f32) -> Vec<(u32, u32)> {
    let index = VertexIndex::new(positions);
    let mut pairs = Vec::new();
    for (i, p) in positions.iter().enumerate() {
        if !p.is_finite() {
            continue;
        }
        for (j, _) in index.within(*p, epsilon) {
            if j as usize != i {
                pairs.push((i as u32, j));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_vertex_matches_brute_force() {
        // A deterministic pseudo-random cloud.
        let mut s = 12345u32;
        let mut r = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32
        };
        let pts: Vec<Vec3> = (0..500).map(|_| Vec3::new(r(), r(), r())).collect();
        let idx = VertexIndex::new(&pts);
        assert_eq!(idx.len(), 500);
        for _ in 0..50 {
            let q = Vec3::new(r(), r(), r());
            let (i, d) = idx.nearest_vertex(q).unwrap();
            let best = pts
                .iter()
                .map(|p| p.distance(q))
                .fold(f32::INFINITY, f32::min);
            assert!((d - best).abs() < 1e-6);
            assert!((pts[i as usize].distance(q) - best).abs() < 1e-6);
        }
    }

    #[test]
    fn empty_and_non_finite_are_handled() {
        assert_eq!(VertexIndex::new(&[]).nearest_vertex(Vec3::ZERO), None);
        let idx = VertexIndex::new(&[Vec3::NAN, Vec3::new(1.0, 0.0, 0.0)]);
        assert_eq!(idx.nearest_vertex(Vec3::ZERO), Some((1, 1.0)));
        assert_eq!(idx.nearest_vertex(Vec3::NAN), None);
        assert_eq!(
            idx.within(Vec3::ZERO, 1.0),
            vec![(1, 1.0)],
            "bound is inclusive"
        );
        assert!(idx.within(Vec3::ZERO, 0.99).is_empty());
    }

    #[test]
    fn coincident_vertices_are_clustered_to_the_lowest_index() {
        let pts = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.0, 0.0, 1e-7),
            Vec3::X,
            Vec3::Y,
            Vec3::ZERO,
        ];
        let c = find_coincident_vertices(&pts, 1e-6);
        assert_eq!(c.representative, vec![0, 1, 0, 1, 4, 0]);
        assert_eq!(c.clusters, vec![vec![0, 2, 5], vec![1, 3]]);
        // Many identical points (a bucket full of equal keys) do not trouble the tree.
        let same = vec![Vec3::ONE; 1000];
        let c = find_coincident_vertices(&same, 0.0);
        assert_eq!(c.clusters.len(), 1);
        assert_eq!(c.clusters[0].len(), 1000);
    }

    /// The greedy clustering of the docs, pair by pair over every two points.
    fn brute_force(positions: &[Vec3], epsilon: f32) -> CoincidentVertices {
        let n = positions.len();
        let mut representative: Vec<u32> = (0..n as u32).collect();
        let mut assigned = vec![false; n];
        let mut clusters = Vec::new();
        for i in 0..n {
            if assigned[i] || !positions[i].is_finite() {
                continue;
            }
            assigned[i] = true;
            let mut cluster = vec![i as u32];
            for j in 0..n {
                let close = positions[j].is_finite()
                    && squared_distance(positions[i], positions[j]) <= epsilon * epsilon;
                if !assigned[j] && close {
                    assigned[j] = true;
                    representative[j] = i as u32;
                    cluster.push(j as u32);
                }
            }
            if cluster.len() > 1 {
                clusters.push(cluster);
            }
        }
        CoincidentVertices {
            representative,
            clusters,
        }
    }

    #[test]
    fn grid_and_tree_cluster_as_the_brute_force_does() {
        let mut s = 99u32;
        let mut r = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32
        };
        let eps = 1e-3;
        let mut pts: Vec<Vec3> = (0..400).map(|_| Vec3::new(r(), r(), r()) * 3.0).collect();
        // Exact copies, copies within and just beyond epsilon, chains of points 0.6 ε apart
        // (the greedy order decides those), copies across a cell border, a NaN.
        for k in 0..60 {
            let p = pts[k * 5];
            let step = [0.0, 0.5, 0.99, 1.01, 0.6, 1.2][k % 6] * eps;
            pts.push(p + Vec3::new(step, 0.0, 0.0));
            pts.push(p + Vec3::new(0.0, step, step) / 2f32.sqrt());
        }
        let border = (CELL * eps as f64) as f32;
        pts.push(Vec3::splat(border - 0.3 * eps));
        pts.push(Vec3::splat(border + 0.2 * eps));
        pts.push(Vec3::new(f32::NAN, 0.0, 0.0));
        pts.push(Vec3::new(-2.0, -5.0, 7.0));
        pts.push(Vec3::new(-2.0, -5.0, 7.0));
        for e in [eps, 0.5 * eps, 2.0 * eps] {
            let want = brute_force(&pts, e);
            assert!(want.clusters.len() > 10, "{}", want.clusters.len());
            assert_eq!(find_coincident_vertices(&pts, e), want, "grid, ε {e}");
            let mut pairs = tree_pairs(&pts, e);
            pairs.sort_unstable();
            let mut grid = grid_pairs(&pts, e).unwrap();
            grid.sort_unstable();
            assert_eq!(grid, pairs, "ε {e}");
        }
        // ε 0 takes the tree: exact copies only.
        assert!(grid_pairs(&pts, 0.0).is_none());
        assert_eq!(find_coincident_vertices(&pts, 0.0), brute_force(&pts, 0.0));
    }
}
