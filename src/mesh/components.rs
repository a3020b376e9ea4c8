//! Connected pieces of a mesh: vertices joined by polygon edges (and, optionally, vertices
//! that coincide in space), by union-find. Used to find a rig's eyeball, the skin among a
//! scan's loose parts and the eyes and teeth inside a one-mesh head.

use super::Mesh;

/// Disjoint sets over `0..n` with path halving.
#[derive(Clone, Debug)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// The representative of `x`'s set.
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    /// Joins the sets of `a` and `b`.
    pub fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra as usize] = rb;
        }
    }

    /// The set of every element, numbered densely in order of first appearance, and the
    /// number of sets.
    pub fn labels(&mut self) -> (Vec<u32>, usize) {
        let n = self.parent.len();
        let mut label = vec![u32::MAX; n];
        let mut count = 0u32;
        let mut out = vec![0u32; n];
        for v in 0..n as u32 {
            let r = self.find(v) as usize;
            if label[r] == u32::MAX {
                label[r] = count;
                count += 1;
            }
            out[v as usize] = label[r];
        }
        (out, count as usize)
    }
}

/// The piece of every vertex of `mesh` (vertices sharing a polygon are in one piece; indices
/// out of range are ignored) and the number of pieces. `joined` lists extra pairs to join
/// (e.g. coincident vertices).
pub fn connected_components(mesh: &Mesh, joined: &[(u32, u32)]) -> (Vec<u32>, usize) {
    let n = mesh.positions.len();
    let mut sets = UnionFind::new(n);
    for poly in mesh.polygons.iter() {
        let Some((&first, rest)) = poly.split_first() else {
            continue;
        };
        if first as usize >= n {
            continue;
        }
        for &v in rest.iter().filter(|&&v| (v as usize) < n) {
            sets.union(first, v);
        }
    }
    for &(a, b) in joined {
        if (a as usize) < n && (b as usize) < n {
            sets.union(a, b);
        }
    }
    sets.labels()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn pieces_and_joins() {
        // Two triangles apart, and a lone vertex.
        let positions = vec![Vec3::ZERO; 7];
        let mesh = Mesh::from_triangles("m", positions, &[[0, 1, 2], [3, 4, 5]]);
        let (label, count) = connected_components(&mesh, &[]);
        assert_eq!(count, 3);
        assert_eq!(label, vec![0, 0, 0, 1, 1, 1, 2]);
        let (label, count) = connected_components(&mesh, &[(2, 3), (6, 99)]);
        assert_eq!(count, 2);
        assert_eq!(label[5], label[0]);
    }
}
