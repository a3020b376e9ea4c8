//! Nearest-vertex queries over a k-d tree, and detection of coincident (duplicated) vertices.

use glam::Vec3;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
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
pub fn find_coincident_vertices(positions: &[Vec3], epsilon: f32) -> CoincidentVertices {
    let index = VertexIndex::new(positions);
    let mut representative: Vec<u32> = (0..positions.len() as u32).collect();
    let mut assigned = vec![false; positions.len()];
    let mut clusters = Vec::new();
    for (i, p) in positions.iter().enumerate() {
        if assigned[i] || !p.is_finite() {
            continue;
        }
        assigned[i] = true;
        let mut cluster = vec![i as u32];
        for (j, _) in index.within(*p, epsilon) {
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
}
