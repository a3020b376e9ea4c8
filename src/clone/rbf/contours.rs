//! Step 1: eye and inner-lip contour extraction by greedy mesh walks from feature points.

use std::collections::HashSet;

use glam::{Vec2, Vec3};

use crate::spec::FeaturePointId;

use super::super::CloneSurface;
use super::mesh::VertexTriangles;
use crate::error::Diagnostic;

/// The extracted contours of one face (vertex paths). A contour that could not be walked is
/// `None` and the reason is in the warnings.
#[derive(Clone, Debug, Default)]
pub(crate) struct Contours {
    /// Right eye loop 3.2 ⇒ 3.8 ⇒ 3.4 ⇒ 3.12: top, inner corner, bottom, outer corner
    /// (closed; the start is not repeated).
    pub right_eye: Option<Vec<u32>>,
    /// Left eye loop 3.1 ⇒ 3.11 ⇒ 3.3 ⇒ 3.7 (the right eye's loop mirrored: top, inner
    /// corner, bottom, outer corner, so a symmetric face gets mirror-image contours).
    pub left_eye: Option<Vec<u32>>,
    /// Upper inner lip, 2.5 ⇒ 2.4 (both corners included).
    pub upper_lip: Option<Vec<u32>>,
    /// Lower inner lip, 2.5 ⇒ 2.4.
    pub lower_lip: Option<Vec<u32>>,
}

fn fp_vertex(surface: &CloneSurface, id: FeaturePointId) -> Option<u32> {
    surface.fp_vertices.get(&id).copied()
}

/// Extracts all four contours; failures become warnings (`what: reason`).
pub(crate) fn extract(
    surface: &CloneSurface,
    adj: &[Vec<u32>],
    incidence: &VertexTriangles,
    face: &str,
    warnings: &mut Vec<Diagnostic>,
) -> Contours {
    let pos = &surface.positions;
    let mut eye = |labels: [FeaturePointId; 4], name: &str| -> Option<Vec<u32>> {
        let fps: Option<Vec<u32>> = labels.iter().map(|&l| fp_vertex(surface, l)).collect();
        let Some(fps) = fps else {
            warnings.push(Diagnostic::warning(format!(
                "{face}: {name} contour skipped: feature points {} are not all surface vertices",
                labels.map(|l| l.to_string()).join(", ")
            )));
            return None;
        };
        match eye_loop(pos, adj, &fps) {
            Ok(c) => Some(c),
            Err(e) => {
                warnings.push(Diagnostic::warning(format!(
                    "{face}: {name} contour skipped: {e}"
                )));
                None
            }
        }
    };
    let right_eye = eye(
        [
            FeaturePointId::FP_3_2,
            FeaturePointId::FP_3_8,
            FeaturePointId::FP_3_4,
            FeaturePointId::FP_3_12,
        ],
        "right eye",
    );
    let left_eye = eye(
        [
            FeaturePointId::FP_3_1,
            FeaturePointId::FP_3_11,
            FeaturePointId::FP_3_3,
            FeaturePointId::FP_3_7,
        ],
        "left eye",
    );
    let (mut upper_lip, mut lower_lip) = (None, None);
    match (
        fp_vertex(surface, FeaturePointId::FP_2_5),
        fp_vertex(surface, FeaturePointId::FP_2_4),
    ) {
        (Some(s), Some(e)) => {
            let mesh = (incidence, surface.triangles.as_slice());
            for (upper, mid, slot) in [
                (true, FeaturePointId::FP_2_2, &mut upper_lip),
                (false, FeaturePointId::FP_2_3, &mut lower_lip),
            ] {
                let mid = fp_vertex(surface, mid).filter(|&m| m != s && m != e);
                match lip_contour(pos, adj, mesh, (s, mid, e), upper) {
                    Ok(c) => *slot = Some(c),
                    Err(err) => warnings.push(Diagnostic::warning(format!(
                        "{face}: {} inner lip contour skipped: {err}",
                        if upper { "upper" } else { "lower" }
                    ))),
                }
            }
        }
        _ => warnings.push(Diagnostic::warning(format!(
            "{face}: lip contours skipped: feature points 2.4 and 2.5 are not both surface vertices"
        ))),
    }
    Contours {
        right_eye,
        left_eye,
        upper_lip,
        lower_lip,
    }
}

/// The eye loop through four feature-point vertices, one greedy path per quarter. Vertices
/// of earlier quarters are not revisited (except the loop's start at the very end).
pub(crate) fn eye_loop(pos: &[Vec3], adj: &[Vec<u32>], fps: &[u32]) -> Result<Vec<u32>, String> {
    let mut visited: HashSet<u32> = HashSet::new();
    let mut contour = vec![fps[0]];
    visited.insert(fps[0]);
    for k in 0..fps.len() {
        let (start, end) = (fps[k], fps[(k + 1) % fps.len()]);
        let before = visited.clone();
        let path = match greedy_path(pos, adj, start, end, &mut visited) {
            Ok(p) => p,
            // The greedy step can corner itself on irregular meshes (triangulated quads
            // next to triangles); the shortest edge path through unused vertices joins the
            // same feature points.
            Err(e) => {
                visited = before;
                let p = shortest_path(pos, adj, start, end, |v| visited.contains(&v)).ok_or(e)?;
                visited.extend(p.iter().copied());
                p
            }
        };
        contour.extend(path);
    }
    // The last quarter ends at the start vertex again.
    contour.pop();
    Ok(contour)
}

/// One inner lip, corner 2.5 ⇒ corner 2.4 (`ends = (2.5, midpoint, 2.4)`). With the lip's
/// midpoint (2.2 upper, 2.3 lower) known, it is walked from each corner to the midpoint and
/// the halves joined, so a mirror-symmetric face gets a mirror-symmetric contour (one walk
/// from corner to corner is not: the greedy choice depends on the walking direction). A half
/// whose greedy walk dead-ends (the xy angle rule has no forward neighbour where a lip curls
/// into the mouth, common on meshes of mixed quads and triangles) is the shortest edge path
/// instead.
pub(crate) fn lip_contour(
    pos: &[Vec3],
    adj: &[Vec<u32>],
    mesh: (&VertexTriangles, &[[u32; 3]]),
    (start, mid, end): (u32, Option<u32>, u32),
    upper: bool,
) -> Result<Vec<u32>, String> {
    let half = |a: u32, b: u32| -> Result<Vec<u32>, String> {
        lip_walk(pos, adj, mesh, a, b, upper).or_else(|e| {
            let rest = shortest_path(pos, adj, a, b, |_| false).ok_or(e)?;
            Ok(std::iter::once(a).chain(rest).collect())
        })
    };
    let Some(mid) = mid else {
        return half(start, end);
    };
    let mut contour = half(start, mid)?;
    let back = half(end, mid)?;
    contour.extend(back.iter().rev().skip(1));
    let mut seen = HashSet::new();
    if !contour.iter().all(|v| seen.insert(*v)) {
        // The halves crossed: one walk from corner to corner is the better contour.
        return half(start, end);
    }
    Ok(contour)
}

/// The shortest path along mesh edges (Dijkstra, edge length) from `start` to `end` through
/// vertices not `blocked` (`end` always allowed). Returns it without `start`, ending at
/// `end`; `None` when `end` cannot be reached.
pub(crate) fn shortest_path(
    pos: &[Vec3],
    adj: &[Vec<u32>],
    start: u32,
    end: u32,
    blocked: impl Fn(u32) -> bool,
) -> Option<Vec<u32>> {
    use std::cmp::Reverse;
    use std::collections::{BinaryHeap, HashMap};
    // Non-negative f64s order like their bit patterns.
    let mut dist: HashMap<u32, f64> = HashMap::from([(start, 0.0)]);
    let mut prev: HashMap<u32, u32> = HashMap::new();
    let mut heap = BinaryHeap::from([Reverse((0u64, start))]);
    while let Some(Reverse((bits, v))) = heap.pop() {
        let d = f64::from_bits(bits);
        if v == end {
            let mut path = vec![end];
            let mut w = end;
            while let Some(&p) = prev.get(&w) {
                if p == start {
                    break;
                }
                path.push(p);
                w = p;
            }
            path.reverse();
            return Some(path);
        }
        if dist.get(&v).is_some_and(|&best| d > best) {
            continue;
        }
        for &n in adj.get(v as usize)? {
            if n == start || (n != end && blocked(n)) {
                continue;
            }
            let nd = d + f64::from(pos[v as usize].distance(pos[n as usize]));
            if dist.get(&n).is_none_or(|&best| nd < best) {
                dist.insert(n, nd);
                prev.insert(n, v);
                heap.push(Reverse((nd.to_bits(), n)));
            }
        }
    }
    None
}

/// The paper's greedy walk from `start` to `end`: from `v` step to the neighbour `n` whose
/// direction `(n − v)/‖n − v‖` points best towards `end`. The paper minimises
/// `‖v + n̂ − end‖` with a unit step, which depends on the model's unit of length; we use its
/// scale-free limit (largest cosine between `n − v` and `end − v`, ties to the neighbour
/// nearer `end`), and step to `end` directly when it is a neighbour. Visited vertices are
/// never re-entered and the walk is capped at the vertex count, so it always terminates;
/// it fails when it runs into a dead end. Returns the path without `start`, ending at `end`.
pub(crate) fn greedy_path(
    pos: &[Vec3],
    adj: &[Vec<u32>],
    start: u32,
    end: u32,
    visited: &mut HashSet<u32>,
) -> Result<Vec<u32>, String> {
    let mut path = Vec::new();
    let mut v = start;
    let target = pos[end as usize];
    while v != end {
        if path.len() > pos.len() {
            return Err(format!("walk {start}⇒{end} exceeded the step cap"));
        }
        let here = pos[v as usize];
        let next = if adj[v as usize].contains(&end) {
            Some(end)
        } else {
            let to_end = (target - here).normalize_or_zero();
            adj[v as usize]
                .iter()
                .copied()
                .filter(|n| !visited.contains(n))
                .filter_map(|n| {
                    let d = pos[n as usize] - here;
                    let len = d.length();
                    (len > 0.0).then(|| (n, d.dot(to_end) / len, pos[n as usize].distance(target)))
                })
                .max_by(|a, b| a.1.total_cmp(&b.1).then(b.2.total_cmp(&a.2)))
                .map(|c| c.0)
        };
        let Some(n) = next else {
            return Err(format!(
                "walk {start}⇒{end} reached a dead end at vertex {v}"
            ));
        };
        visited.insert(n);
        path.push(n);
        v = n;
    }
    Ok(path)
}

fn cross2(a: Vec2, b: Vec2) -> f32 {
    a.x * b.y - a.y * b.x
}

/// The inner-lip walk from 2.5 to 2.4 (paper: at each step the neighbour with the smallest
/// [upper] or greatest [lower] xy-plane angle to `v_direction = end − start`, within
/// (−π/2, π/2)).
///
/// Taken literally the rule fails at the corners: there the lower lip's first vertex has the
/// smallest angle, and on a closed mouth the upper and lower candidates coincide. We keep the
/// angle rule, measured towards "up" (so the sign does not depend on which way x points), but
/// rank the candidate edges first by topology: (0) edges whose triangles all lie on the lip's
/// own side — the border of the mouth opening, which on an open or closed (slit) mouth is the
/// inner lip contour; (1) edges with some triangle on that side; (2) the rest. "The lip's own
/// side" of an edge `v → n` is left of it for the upper lip when walking towards +x (above
/// the edge), right of it for the lower lip. Coincident upper/lower vertices of a closed
/// mouth are therefore told apart by topology, not by position. Ties go to the vertex nearer
/// the end; zero-length edges are skipped, visited vertices never re-entered, and the walk
/// is capped at the vertex count, so it always terminates.
pub(crate) fn lip_walk(
    pos: &[Vec3],
    adj: &[Vec<u32>],
    (incidence, triangles): (&VertexTriangles, &[[u32; 3]]),
    start: u32,
    end: u32,
    upper: bool,
) -> Result<Vec<u32>, String> {
    let xy = |i: u32| pos[i as usize].truncate();
    let dir = xy(end) - xy(start);
    if dir.x == 0.0 {
        return Err("lip corners 2.4 and 2.5 have the same x".into());
    }
    let dir = dir.normalize();
    // +1 when "left of the walking direction" is up (+y).
    let up = dir.x.signum();
    let mut visited: HashSet<u32> = HashSet::from([start]);
    let mut contour = vec![start];
    let mut v = start;
    while v != end {
        if contour.len() > pos.len() {
            return Err("lip walk exceeded the step cap".into());
        }
        let cands: Vec<(u32, f32, u8)> = adj[v as usize]
            .iter()
            .copied()
            .filter(|n| !visited.contains(n))
            .filter_map(|n| {
                let d = xy(n) - xy(v);
                if d.length() == 0.0 {
                    return None;
                }
                let a = cross2(dir, d).atan2(dir.dot(d)) * up;
                if a.abs() >= std::f32::consts::FRAC_PI_2 {
                    return None;
                }
                let ws: Vec<u32> = incidence.opposites(triangles, v, n).collect();
                let own_side = |w: &u32| {
                    let s = cross2(d, xy(*w) - xy(v)) * up;
                    if upper {
                        s > 0.0
                    } else {
                        s < 0.0
                    }
                };
                let on_side = ws.iter().filter(|w| own_side(w)).count();
                // Tier 0: the edge borders the mouth (triangles on the lip's side only);
                // tier 1: some triangle on the lip's side; tier 2: anything else.
                let tier = if on_side > 0 && on_side == ws.len() {
                    0
                } else if on_side > 0 {
                    1
                } else {
                    2
                };
                Some((n, a, tier))
            })
            .collect();
        let target = pos[end as usize];
        let pick = cands
            .iter()
            .min_by(|a, b| {
                let (ka, kb) = if upper { (a.1, b.1) } else { (-a.1, -b.1) };
                a.2.cmp(&b.2).then(ka.total_cmp(&kb)).then(
                    pos[a.0 as usize]
                        .distance(target)
                        .total_cmp(&pos[b.0 as usize].distance(target)),
                )
            })
            .map(|c| c.0);
        let Some(n) = pick else {
            return Err(format!("lip walk reached a dead end at vertex {v}"));
        };
        visited.insert(n);
        contour.push(n);
        v = n;
    }
    Ok(contour)
}

/// The point nearest `p` on a polyline (closed: also the segment last → first).
pub(crate) fn nearest_on_polyline(p: Vec3, pts: &[Vec3], closed: bool) -> Option<Vec3> {
    let segs = if closed {
        pts.len()
    } else {
        pts.len().saturating_sub(1)
    };
    let mut best: Option<(f32, Vec3)> = None;
    if pts.len() == 1 {
        return Some(pts[0]);
    }
    for i in 0..segs {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 {
            ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = a + ab * t;
        let d = q.distance_squared(p);
        if best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, q));
        }
    }
    best.map(|b| b.1)
}

#[cfg(test)]
mod tests {
    use super::super::mesh::adjacency;
    use super::*;

    /// A 5×5 grid of vertices (x, y in 0..4) with a slit mouth along y = 2 between the
    /// corners (0,2) and (4,2): the middle row is duplicated (upper copies 25..=27 for
    /// x = 1..3), so upper and lower lip vertices coincide, as on a closed-mouth face.
    fn slit_grid() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut pos: Vec<Vec3> = (0..25)
            .map(|i| Vec3::new((i % 5) as f32, (i / 5) as f32, 0.0))
            .collect();
        for x in 1..4 {
            pos.push(Vec3::new(x as f32, 2.0, 0.0));
        }
        let id = |x: u32, y: u32, from_above: bool| -> u32 {
            if y == 2 && (1..4).contains(&x) && from_above {
                24 + x
            } else {
                y * 5 + x
            }
        };
        let mut tris = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                // Cells above the slit use the upper copies of row 2.
                let above = y == 2;
                let (a, b) = (id(x, y, above), id(x + 1, y, above));
                let (c, d) = (id(x + 1, y + 1, above), id(x, y + 1, above));
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        (pos, tris)
    }

    #[test]
    fn lip_walks_separate_a_closed_slit_mouth() {
        let (pos, tris) = slit_grid();
        let adj = adjacency(pos.len(), &tris);
        let vt = VertexTriangles::new(pos.len(), &tris);
        let opp = (&vt, tris.as_slice());
        // Start 2.5 at x = 0 (right corner, −x side), end 2.4 at x = 4.
        let upper = lip_walk(&pos, &adj, opp, 10, 14, true).unwrap();
        let lower = lip_walk(&pos, &adj, opp, 10, 14, false).unwrap();
        assert_eq!(upper, vec![10, 25, 26, 27, 14]);
        assert_eq!(lower, vec![10, 11, 12, 13, 14]);
    }

    #[test]
    fn a_dead_end_lip_walk_becomes_the_shortest_path() {
        // The start's neighbours both lie behind it (as where a lip of a mixed quad/triangle
        // mesh curls into the mouth), so the xy angle rule has nowhere to go.
        let pos = vec![
            Vec3::ZERO,
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(1.0, 3.0, 0.0),
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(-1.0, -1.0, 0.0),
        ];
        let tris = vec![[0, 1, 4], [1, 3, 2]];
        let adj = adjacency(pos.len(), &tris);
        let vt = VertexTriangles::new(pos.len(), &tris);
        let mesh = (&vt, tris.as_slice());
        assert!(lip_walk(&pos, &adj, mesh, 0, 3, true).is_err());
        assert_eq!(
            lip_contour(&pos, &adj, mesh, (0, None, 3), true).unwrap(),
            vec![0, 1, 3]
        );
        // An end that cannot be reached at all is an error, never a panic.
        let lone = adjacency(pos.len(), &tris[..1]);
        assert!(lip_contour(&pos, &lone, mesh, (0, None, 3), true).is_err());
    }

    #[test]
    fn greedy_eye_loop_walks_around_a_ring() {
        // An octagon ring around a centre vertex 8, plus the centre.
        let mut pos: Vec<Vec3> = (0..8)
            .map(|k| {
                let a = k as f32 * std::f32::consts::FRAC_PI_4;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        pos.push(Vec3::ZERO);
        let tris: Vec<[u32; 3]> = (0..8).map(|k| [8, k, (k + 1) % 8]).collect();
        let adj = adjacency(pos.len(), &tris);
        // UP (2) ⇒ LEFT (4) ⇒ DOWN (6) ⇒ RIGHT (0).
        let c = eye_loop(&pos, &adj, &[2, 4, 6, 0]).unwrap();
        assert_eq!(c, vec![2, 3, 4, 5, 6, 7, 0, 1]);
        // A dead end is an error, not a hang: an isolated end vertex.
        pos.push(Vec3::new(5.0, 5.0, 0.0));
        let adj = adjacency(pos.len(), &tris);
        assert!(eye_loop(&pos, &adj, &[2, 9, 6, 0]).is_err());
    }

    #[test]
    fn nearest_point_on_polyline() {
        let pts = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)];
        let q = nearest_on_polyline(Vec3::new(0.5, -1.0, 0.0), &pts, false).unwrap();
        assert!(q.distance(Vec3::new(0.5, 0.0, 0.0)) < 1e-6);
        let q = nearest_on_polyline(Vec3::new(0.2, 0.8, 0.0), &pts, true).unwrap();
        assert!(q.distance(Vec3::new(0.5, 0.5, 0.0)) < 1e-6);
    }
}
