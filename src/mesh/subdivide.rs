//! Subdivision of triangle meshes, with the weights that carry any per-vertex quantity along.
//!
//! One round splits every triangle `(a, b, c)` into four through new vertices on its edges:
//! `(a, ab, ca)`, `(ab, b, bc)`, `(ca, bc, c)`, `(ab, bc, ca)` (orientation kept). Old
//! vertices keep their indices `0..n`; edge vertices follow in the order their edges are
//! first met. Every new position is a fixed weighted sum of old ones (a *stencil*), so
//! anything linear in the positions — morph-target displacements, colours — is carried by
//! the same sums ([`Subdivision::apply`]): a face's animation subdivides exactly.
//!
//! Schemes ([`Scheme`]):
//! - **Midpoint**: edge vertices at the edge's middle, old vertices unmoved. The surface is
//!   unchanged (a finer sampling of the same triangles).
//! - **Loop** (Loop 1987, with Warren's weights): an interior edge `ab` with opposite
//!   vertices `c`, `d` gets `3/8 (a + b) + 1/8 (c + d)`; an interior old vertex of valence
//!   `k` becomes `(1 − kβ) v + β Σ neighbours` with `β = 3/16` for `k = 3` and `3/(8k)`
//!   otherwise. Edges used by one triangle or by more than two (boundaries, non-manifold
//!   seams) are creases: their edge vertex is the midpoint, and an old vertex on exactly
//!   two crease edges becomes `3/4 v + 1/8 (n₁ + n₂)`; a vertex on one or on more than two
//!   crease edges (a corner) stays where it is. The limit surface is smooth and shrinks
//!   slightly towards the control mesh's inside.

use std::collections::HashMap;

use glam::Vec3;

/// How new positions are made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    /// Loop subdivision (smooth; module docs).
    #[default]
    Loop,
    /// Midpoint subdivision (same surface, more triangles).
    Midpoint,
}

/// One round of subdivision: the new triangles and, per new vertex, the old vertices and
/// weights it is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Subdivision {
    /// Old vertex count.
    pub old_count: usize,
    /// `(old vertex, weight)` per new vertex; weights sum to 1.
    pub stencils: Vec<Vec<(u32, f32)>>,
    /// The new triangles, four per old triangle in the old order.
    pub triangles: Vec<[u32; 3]>,
}

impl Subdivision {
    /// Number of vertices after the round.
    pub fn vertex_count(&self) -> usize {
        self.stencils.len()
    }

    /// Any per-vertex quantity (positions, displacements, colours) carried to the new
    /// vertices: `out[i] = Σ w · values[j]` over vertex `i`'s stencil. `values` must have one
    /// entry per old vertex; missing entries count as the default (zero).
    pub fn apply<T>(&self, values: &[T]) -> Vec<T>
    where
        T: Copy + Default + std::ops::Add<Output = T> + std::ops::Mul<f32, Output = T>,
    {
        self.stencils
            .iter()
            .map(|s| {
                s.iter().fold(T::default(), |acc, &(j, w)| {
                    acc + values.get(j as usize).copied().unwrap_or_default() * w
                })
            })
            .collect()
    }
}

/// One round of `scheme` over `triangles` on `vertex_count` vertices. Triangles with an
/// index out of range or a repeated corner are dropped (they have no edges to share).
pub fn subdivide(vertex_count: usize, triangles: &[[u32; 3]], scheme: Scheme) -> Subdivision {
    let n = vertex_count;
    let valid: Vec<[u32; 3]> = triangles
        .iter()
        .copied()
        .filter(|t| {
            t.iter().all(|&v| (v as usize) < n) && t[0] != t[1] && t[1] != t[2] && t[0] != t[2]
        })
        .collect();
    // Edge (low, high) → (new vertex, opposite corners, uses).
    struct Edge {
        vertex: u32,
        opposite: [u32; 2],
        uses: u32,
    }
    let mut edges: HashMap<(u32, u32), Edge> = HashMap::with_capacity(valid.len() * 3 / 2 + 1);
    let mut order: Vec<(u32, u32)> = Vec::with_capacity(valid.len() * 3 / 2 + 1);
    let mut out = Vec::with_capacity(valid.len() * 4);
    for t in &valid {
        let mut mid = [0u32; 3];
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let key = (a.min(b), a.max(b));
            let next = (n + order.len()) as u32;
            let e = edges.entry(key).or_insert_with(|| {
                order.push(key);
                Edge {
                    vertex: next,
                    opposite: [c, c],
                    uses: 0,
                }
            });
            if e.uses == 1 {
                e.opposite[1] = c;
            }
            e.uses += 1;
            mid[k] = e.vertex;
        }
        let [ab, bc, ca] = mid;
        out.push([t[0], ab, ca]);
        out.push([ab, t[1], bc]);
        out.push([ca, bc, t[2]]);
        out.push([ab, bc, ca]);
    }

    let mut stencils: Vec<Vec<(u32, f32)>> = Vec::with_capacity(n + order.len());
    match scheme {
        Scheme::Midpoint => stencils.extend((0..n as u32).map(|v| vec![(v, 1.0)])),
        Scheme::Loop => {
            // Neighbours and crease neighbours of every old vertex.
            let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
            let mut creases: Vec<Vec<u32>> = vec![Vec::new(); n];
            for &(a, b) in &order {
                let e = &edges[&(a, b)];
                neighbours[a as usize].push(b);
                neighbours[b as usize].push(a);
                if e.uses != 2 {
                    creases[a as usize].push(b);
                    creases[b as usize].push(a);
                }
            }
            for v in 0..n {
                let ring = &neighbours[v];
                let crease = &creases[v];
                let s = if ring.is_empty() || (!crease.is_empty() && crease.len() != 2) {
                    vec![(v as u32, 1.0)]
                } else if crease.len() == 2 {
                    vec![(v as u32, 0.75), (crease[0], 0.125), (crease[1], 0.125)]
                } else {
                    let k = ring.len() as f32;
                    let beta = if ring.len() == 3 {
                        3.0 / 16.0
                    } else {
                        3.0 / (8.0 * k)
                    };
                    let mut s = vec![(v as u32, 1.0 - k * beta)];
                    s.extend(ring.iter().map(|&u| (u, beta)));
                    s
                };
                stencils.push(s);
            }
        }
    }
    for key in &order {
        let e = &edges[key];
        let s = if scheme == Scheme::Loop && e.uses == 2 {
            vec![
                (key.0, 0.375),
                (key.1, 0.375),
                (e.opposite[0], 0.125),
                (e.opposite[1], 0.125),
            ]
        } else {
            vec![(key.0, 0.5), (key.1, 0.5)]
        };
        stencils.push(s);
    }
    Subdivision {
        old_count: n,
        stencils,
        triangles: out,
    }
}

/// Positions and triangles after `rounds` rounds of `scheme`.
pub fn subdivide_positions(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    scheme: Scheme,
    rounds: usize,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut p, mut t) = (positions.to_vec(), triangles.to_vec());
    for _ in 0..rounds {
        let s = subdivide(p.len(), &t, scheme);
        p = s.apply(&p);
        t = s.triangles;
    }
    (p, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular octahedron (every vertex valence 4, closed).
    fn octahedron() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (p, t)
    }

    #[test]
    fn counts_and_orientation() {
        let (p, t) = octahedron();
        let s = subdivide(p.len(), &t, Scheme::Loop);
        // V + E new vertices, 4F triangles; Euler characteristic stays 2.
        assert_eq!(s.vertex_count(), 6 + 12);
        assert_eq!(s.triangles.len(), 32);
        let q = s.apply(&p);
        for tri in &s.triangles {
            let [a, b, c] = tri.map(|i| q[i as usize]);
            let n = (b - a).cross(c - a);
            // Outward: same side as the centroid from the origin.
            assert!(n.dot(a + b + c) > 0.0, "{tri:?}");
        }
        for st in &s.stencils {
            let sum: f32 = st.iter().map(|&(_, w)| w).sum();
            assert!((sum - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn loop_weights_on_the_octahedron() {
        let (p, t) = octahedron();
        let s = subdivide(p.len(), &t, Scheme::Loop);
        let q = s.apply(&p);
        // Valence 4: β = 3/32, old vertex X → (1 − 4β) X + β (Y − Y + Z − Z) = 5/8 X.
        assert!((q[0] - Vec3::X * 0.625).length() < 1e-6, "{}", q[0]);
        // Edge X–Y with opposite Z and −Z: 3/8 (X + Y).
        let xy = s
            .stencils
            .iter()
            .position(|st| {
                st.len() == 4 && st.iter().any(|&(v, _)| v == 0) && st.iter().any(|&(v, _)| v == 2)
            })
            .unwrap();
        assert!((q[xy] - (Vec3::X + Vec3::Y) * 0.375).length() < 1e-6);
    }

    #[test]
    fn boundaries_are_creases_and_midpoint_keeps_the_surface() {
        // One quad as two triangles: a flat square with a border all round.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let t = vec![[0, 1, 2], [0, 2, 3]];
        let s = subdivide(4, &t, Scheme::Loop);
        let q = s.apply(&p);
        // Corner 1 has two crease edges: 3/4 X + 1/8 (0 + (1,1)) = (0.875, 0.125).
        assert!((q[1] - Vec3::new(0.875, 0.125, 0.0)).length() < 1e-6);
        // A flat mesh stays flat.
        assert!(q.iter().all(|v| v.z.abs() < 1e-7));
        let (m, mt) = subdivide_positions(&p, &t, Scheme::Midpoint, 2);
        assert_eq!(mt.len(), 32);
        assert_eq!(&m[..4], &p[..]);
        let area = |pts: &[Vec3], tris: &[[u32; 3]]| -> f32 {
            tris.iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| pts[i as usize]);
                    (b - a).cross(c - a).length() / 2.0
                })
                .sum()
        };
        assert!((area(&m, &mt) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn bad_triangles_are_dropped_and_values_carried() {
        let s = subdivide(3, &[[0, 1, 2], [0, 0, 1], [0, 1, 9]], Scheme::Midpoint);
        assert_eq!(s.triangles.len(), 4);
        let d = s.apply(&[1.0f32, 3.0, 5.0]);
        assert_eq!(d.len(), 6);
        assert_eq!(d[3], 2.0);
        // Fewer values than vertices: the missing ones are zero.
        assert_eq!(s.apply(&[2.0f32])[3], 1.0);
    }
}
