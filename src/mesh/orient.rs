//! Consistent triangle winding: flips triangles so that neighbours agree, then turns each
//! connected piece outwards.
//!
//! Models such as CANDIDE-3 list their triangles with mixed winding; a renderer that shades
//! back faces differently (or a normal computation that averages face normals) then shows
//! a patchwork of facets. Two triangles sharing an edge agree when they traverse it in
//! opposite directions; a breadth-first walk over shared edges flips each disagreeing
//! neighbour. Edges with more than two triangles (non-manifold) are not walked across. A
//! piece that cannot be oriented (a Möbius-like strip) keeps the first orientation reached.
//!
//! Outwards: the area-weighted normals of a piece should point away from its centroid —
//! true for closed solids (eyeballs, teeth) and for open shells curved around their inside
//! (a face mask, whose centroid lies behind the skin). Otherwise the piece is flipped.

use std::collections::HashMap;

use glam::Vec3;

/// `triangles` with consistent, outward winding (see the module docs). Triangles with an
/// index out of range are kept as they are.
pub fn orient_outwards(triangles: &[[u32; 3]], positions: &[Vec3]) -> Vec<[u32; 3]> {
    let n = positions.len() as u32;
    let mut out = triangles.to_vec();
    let valid =
        |t: &[u32; 3]| t.iter().all(|&i| i < n) && t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    // Undirected edge → the triangles using it.
    let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(triangles.len() * 2);
    for (ti, t) in triangles.iter().enumerate() {
        if !valid(t) {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(ti as u32);
        }
    }
    let mut seen = vec![false; triangles.len()];
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..triangles.len() {
        if seen[seed] || !valid(&triangles[seed]) {
            continue;
        }
        seen[seed] = true;
        queue.push_back(seed);
        let mut piece = Vec::new();
        while let Some(ti) = queue.pop_front() {
            piece.push(ti);
            let t = out[ti];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let Some(users) = edges.get(&(a.min(b), a.max(b))) else {
                    continue;
                };
                if users.len() != 2 {
                    continue;
                }
                for &u in users {
                    let u = u as usize;
                    if u == ti || seen[u] {
                        continue;
                    }
                    seen[u] = true;
                    // The neighbour agrees when it runs the shared edge b → a.
                    if runs(&out[u], a, b) {
                        out[u].swap(1, 2);
                    }
                    queue.push_back(u);
                }
            }
        }
        if outward_score(&piece, &out, positions) < 0.0 {
            for &ti in &piece {
                out[ti].swap(1, 2);
            }
        }
    }
    out
}

/// Whether triangle `t` traverses the directed edge `a → b`.
fn runs(t: &[u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
}

/// Sum over the piece of (area-weighted normal) · (triangle centroid − piece centroid):
/// positive when the piece faces away from its centroid.
fn outward_score(piece: &[usize], triangles: &[[u32; 3]], positions: &[Vec3]) -> f64 {
    let corner = |t: &[u32; 3]| t.map(|i| positions[i as usize].as_dvec3());
    let mut sum = glam::DVec3::ZERO;
    let mut weight = 0.0;
    for &ti in piece {
        let [a, b, c] = corner(&triangles[ti]);
        let area = (b - a).cross(c - a).length();
        if area.is_finite() {
            sum += (a + b + c) / 3.0 * area;
            weight += area;
        }
    }
    if weight <= 0.0 {
        return 0.0;
    }
    let centre = sum / weight;
    piece
        .iter()
        .map(|&ti| {
            let [a, b, c] = corner(&triangles[ti]);
            let n = (b - a).cross(c - a);
            let d = n.dot((a + b + c) / 3.0 - centre);
            if d.is_finite() {
                d
            } else {
                0.0
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube's 12 triangles, outward.
    fn cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        (p, t)
    }

    fn signed_volume(p: &[Vec3], t: &[[u32; 3]]) -> f32 {
        t.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn mixed_winding_becomes_consistent_and_outward() {
        let (p, t) = cube();
        assert!(
            (signed_volume(&p, &t) - 1.0).abs() < 1e-6,
            "fixture is outward"
        );
        let mut mixed = t.clone();
        for (i, tri) in mixed.iter_mut().enumerate() {
            if i % 3 == 0 {
                tri.swap(0, 1);
            }
        }
        let fixed = orient_outwards(&mixed, &p);
        assert!((signed_volume(&p, &fixed) - 1.0).abs() < 1e-6);
        // All reversed: turned back outwards.
        let inward: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        assert!((signed_volume(&p, &orient_outwards(&inward, &p)) - 1.0).abs() < 1e-6);
        // Already right: unchanged.
        assert_eq!(orient_outwards(&t, &p), t);
    }

    #[test]
    fn open_shell_faces_away_from_its_inside() {
        // A bowl (half an octahedron) opening towards −z: its outside faces +z.
        let p = vec![
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
        ];
        let t = vec![[0, 1, 2], [0, 3, 2], [0, 3, 4], [0, 1, 4]];
        let fixed = orient_outwards(&t, &p);
        for tri in &fixed {
            let [a, b, c] = tri.map(|i| p[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "{tri:?}");
        }
    }

    #[test]
    fn bad_triangles_are_kept() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let t = vec![[0, 1, 9], [0, 0, 1], [0, 1, 2]];
        let out = orient_outwards(&t, &p);
        assert_eq!(out[0], [0, 1, 9]);
        assert_eq!(out[1], [0, 0, 1]);
        assert_eq!(out.len(), 3);
    }
}
