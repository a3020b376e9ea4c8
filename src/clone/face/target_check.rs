//! Damage in the target that cloning survives but the user should know about: holes,
//! duplicated vertices, non-manifold edges and flipped polygons in its skin, feature points
//! off the mesh or on top of each other. Each finding is one warning naming the mesh and a
//! few places; the clone goes on (welding and the surface methods cope, the result is
//! checked for non-finite numbers at the end).

use std::collections::HashMap;

use glam::Vec3;

use super::FaceParts;
use crate::error::Diagnostic;
use crate::face::FaceModel;
use crate::mesh::components::UnionFind;

/// Boundary loops with at most this many edges count as holes: a face's own openings (neck,
/// mouth, eyes, nostrils) are longer.
const HOLE_EDGES: usize = 12;

/// Feature points that meet in a neutral face with its mouth closed: the inner lip contours
/// and the teeth tips.
const MEET_WHEN_CLOSED: [(&str, &str); 4] = [
    ("2.2", "2.3"),
    ("2.6", "2.8"),
    ("2.7", "2.9"),
    ("9.10", "9.11"),
];

/// Places named per finding.
const SHOWN: usize = 3;

/// Adds a warning for each kind of damage found in `target` (its skin meshes and feature
/// points).
pub(super) fn check_target(target: &FaceModel, tparts: &FaceParts, warnings: &mut Vec<Diagnostic>) {
    for &m in &tparts.skin {
        check_mesh(target, m, warnings);
    }
    check_feature_points(target, warnings);
}

/// `N things (e.g. a, b, c)`.
fn listed(n: usize, what: &str, places: &[String]) -> String {
    format!("{n} {what} (e.g. {})", places.join(", "))
}

fn at(p: Vec3) -> String {
    format!("({:.1}, {:.1}, {:.1})", p.x, p.y, p.z)
}

fn check_mesh(target: &FaceModel, m: usize, warnings: &mut Vec<Diagnostic>) {
    let fm = &target.meshes[m];
    let mesh = &fm.mesh;
    let np = mesh.positions.len();
    let prefix = format!("target mesh `{}`", fm.name);

    // Duplicated vertices: the same position twice (compared by bits, -0 as 0).
    let mut first: HashMap<[u32; 3], usize> = HashMap::new();
    let mut dups = Vec::new();
    for (i, p) in mesh.positions.iter().enumerate() {
        let key = (*p + Vec3::ZERO).to_array().map(f32::to_bits);
        if let Some(&j) = first.get(&key) {
            dups.push(format!("vertex {i} = {j} at {}", at(*p)));
        } else {
            first.insert(key, i);
        }
    }
    // A short seam of coincident vertices is deliberate (closed lips that open); many mean a
    // mesh whose polygons were never joined.
    if dups.len() > (np / 50).max(16) {
        warnings.push(Diagnostic::warning(format!(
            "{prefix}: {}; the surface is welded there",
            listed(
                dups.len(),
                &format!(
                    "duplicated vertices ({:.0} % of the mesh)",
                    100.0 * dups.len() as f64 / np as f64
                ),
                &dups[..dups.len().min(SHOWN)]
            )
        )));
    }

    // Edges: how often each is used, and in which direction. Edge → (uses a→b, uses b→a),
    // in a fixed order so the places named are stable.
    let sorted = edge_uses(&mesh.polygons, np);
    let place = |(a, b): (u32, u32)| format!("edge {a}-{b}");
    let non_manifold: Vec<String> = sorted
        .iter()
        .filter(|(_, (f, r))| f + r > 2)
        .map(|&(e, _)| place(e))
        .collect();
    if !non_manifold.is_empty() {
        warnings.push(Diagnostic::warning(format!(
            "{prefix}: {}; motion is not carried across them",
            listed(
                non_manifold.len(),
                "non-manifold edges (more than two polygons)",
                &non_manifold[..non_manifold.len().min(SHOWN)]
            )
        )));
    }
    let flipped: Vec<String> = sorted
        .iter()
        .filter(|(_, uses)| *uses == (2, 0) || *uses == (0, 2))
        .map(|&(e, _)| place(e))
        .collect();
    if !flipped.is_empty() {
        warnings.push(Diagnostic::warning(format!(
            "{prefix}: {}; normals there point the wrong way",
            listed(
                flipped.len(),
                "edges between polygons wound opposite ways (flipped polygons)",
                &flipped[..flipped.len().min(SHOWN)]
            )
        )));
    }

    // Holes: small loops of boundary edges (edges of one polygon).
    let mut loops = UnionFind::new(np);
    let mut boundary_edges = 0usize;
    for &((a, b), (f, r)) in &sorted {
        if f + r == 1 {
            loops.union(a, b);
            boundary_edges += 1;
        }
    }
    if boundary_edges > 0 {
        let mut size: HashMap<u32, (usize, u32)> = HashMap::new();
        for &((a, _), (f, r)) in &sorted {
            if f + r == 1 {
                let e = size.entry(loops.find(a)).or_insert((0, a));
                e.0 += 1;
                e.1 = e.1.min(a);
            }
        }
        let mut holes: Vec<u32> = size
            .values()
            .filter(|(n, _)| *n <= HOLE_EDGES)
            .map(|&(_, v)| v)
            .collect();
        holes.sort_unstable();
        if !holes.is_empty() {
            let places: Vec<String> = holes
                .iter()
                .take(SHOWN)
                .map(|&v| format!("at vertex {v} {}", at(mesh.positions[v as usize])))
                .collect();
            warnings.push(Diagnostic::warning(format!(
                "{prefix}: {}; the motion across them is interpolated",
                listed(holes.len(), "holes", &places)
            )));
        }
    }
}

/// Every edge `(a, b)`, `a < b`, of the polygons (those with an index out of range left out)
/// with how often it runs a→b and b→a, sorted by edge. Gathered per lower end, as an
/// adjacency list is (a hash map of a head's edges cost several times more).
fn edge_uses(polygons: &crate::mesh::Polygons, np: usize) -> Vec<((u32, u32), (u32, u32))> {
    let valid = |poly: &[u32]| poly.len() >= 3 && poly.iter().all(|&v| (v as usize) < np);
    fn sides(poly: &[u32]) -> impl Iterator<Item = (u32, u32)> + '_ {
        (0..poly.len())
            .map(|k| (poly[k], poly[(k + 1) % poly.len()]))
            .filter(|(a, b)| a != b)
    }
    let mut start = vec![0usize; np + 1];
    for poly in polygons.iter().filter(|p| valid(p)) {
        for (a, b) in sides(poly) {
            start[a.min(b) as usize + 1] += 1;
        }
    }
    for v in 0..np {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    // (upper end, runs a→b)
    let mut ends = vec![(0u32, false); start[np]];
    for poly in polygons.iter().filter(|p| valid(p)) {
        for (a, b) in sides(poly) {
            let lo = a.min(b) as usize;
            ends[fill[lo]] = (a.max(b), a < b);
            fill[lo] += 1;
        }
    }
    let mut out = Vec::new();
    for a in 0..np {
        let run = &mut ends[start[a]..start[a + 1]];
        run.sort_unstable_by_key(|e| e.0);
        for e in run.chunk_by(|x, y| x.0 == y.0) {
            let forward = e.iter().filter(|x| x.1).count() as u32;
            out.push(((a as u32, e[0].0), (forward, e.len() as u32 - forward)));
        }
    }
    out
}

/// Feature points far from every vertex, and feature points at the same place.
fn check_feature_points(target: &FaceModel, warnings: &mut Vec<Diagnostic>) {
    let frames = target.frames();
    let world: Vec<Vec3> = target
        .meshes
        .iter()
        .zip(&frames.meshes)
        .flat_map(|(m, f)| m.mesh.positions.iter().map(|p| f.transform_point3(*p)))
        .filter(|p| p.is_finite())
        .collect();
    let (lo, hi) = world.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let size = (hi - lo).length();
    if world.is_empty() || !size.is_finite() || size <= 0.0 {
        return;
    }
    let points: Vec<(String, Vec3)> = target
        .feature_points
        .iter()
        .filter_map(|p| Some((p.id.to_string(), target.feature_points.position(p.id)?)))
        .filter(|(_, p)| p.is_finite())
        .collect();
    // Off the mesh: farther than 5 % of the face's size from its nearest vertex. A linear
    // scan: at most 84 points.
    let off: Vec<String> = points
        .iter()
        .filter_map(|(id, p)| {
            let d = world
                .iter()
                .map(|v| v.distance_squared(*p))
                .fold(f32::INFINITY, f32::min)
                .sqrt();
            (d > 0.05 * size).then(|| {
                // Four decimals and the share: a face in metres is off by hundredths.
                format!(
                    "{id} ({d:.4} from the nearest vertex, {:.1} % of the face size)",
                    100.0 * d / size
                )
            })
        })
        .collect();
    if !off.is_empty() {
        warnings.push(Diagnostic::warning(format!(
            "target feature points off the mesh: {}; the clone aligns and scales by them as \
             they are",
            off.join(", ")
        )));
    }
    let mut same = Vec::new();
    for (i, (a, pa)) in points.iter().enumerate() {
        for (b, pb) in &points[i + 1..] {
            let closed_mouth = MEET_WHEN_CLOSED.iter().any(|&(x, y)| {
                (x, y) == (a.as_str(), b.as_str()) || (y, x) == (a.as_str(), b.as_str())
            });
            if !closed_mouth && pa.distance(*pb) <= 1e-5 * size {
                same.push(format!("{a} and {b} at {}", at(*pa)));
            }
        }
    }
    if !same.is_empty() {
        warnings.push(Diagnostic::warning(format!(
            "target feature points coincide: {}; distances measured between them are zero",
            same.join(", ")
        )));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Polygons;

    #[test]
    fn edge_uses_count_each_direction_per_edge_in_order() {
        let mut polygons = Polygons::new();
        // Two triangles sharing 1-2 the right way and a third on it (non-manifold), two
        // wound the same way along 3-4 (flipped), a quad, a degenerate corner and an index
        // out of range.
        for p in [
            &[0u32, 1, 2][..],
            &[2, 1, 3],
            &[2, 3, 4],
            &[3, 4, 6],
            &[1, 2, 5],
            &[5, 6, 7, 4],
            &[6, 6, 7],
            &[0, 1, 99],
        ] {
            polygons.push(p);
        }
        let np = 8;
        let mut want: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for poly in polygons.iter() {
            if poly.len() < 3 || poly.iter().any(|&v| v as usize >= np) {
                continue;
            }
            for k in 0..poly.len() {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                if a != b {
                    let e = want.entry((a.min(b), a.max(b))).or_default();
                    if a < b {
                        e.0 += 1;
                    } else {
                        e.1 += 1;
                    }
                }
            }
        }
        let mut want: Vec<_> = want.into_iter().collect();
        want.sort_unstable();
        let got = edge_uses(&polygons, np);
        assert_eq!(got, want);
        assert!(got.contains(&((1, 2), (2, 1))) && got.contains(&((3, 4), (2, 0))));
    }
}
