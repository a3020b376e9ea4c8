//! Step 4 — interpolation from a 2D triangle mesh (the paper's "Interpolation from 2D triangle
//! mesh" section): bounding-box test (a uniform grid of triangle boxes), barycentric coordinates,
//! overlap resolution by the smallest interpolated depth, and the closest-triangle rule with
//! clamped, renormalised coordinates for points outside every triangle.

use glam::DVec2;

/// Tolerance on the sum of excess barycentric coordinates under which a point counts as
/// inside (points on shared edges and vertices must be inside both neighbours).
const INSIDE_EPS: f64 = 1e-9;

/// Depth differences below this are the same surface (shared edges), not an overlap.
const DEPTH_EPS: f64 = 1e-9;

/// How many allowed triangles, nearest bounding box first, the closest-triangle rule examines.
/// The paper's measure (sum of excess barycentrics) is not a Euclidean distance, so an exact
/// minimum needs every triangle; the few nearest boxes always contain the closest triangle on
/// a mesh whose triangles are of similar size, and keep the search logarithmic.
const OUTSIDE_CANDIDATES: usize = 16;

/// Barycentric coordinates of `p` in triangle `(a, b, c)`, `None` for a degenerate triangle.
pub(crate) fn barycentric(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> Option<[f64; 3]> {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let det = v0.x * v1.y - v1.x * v0.y;
    let scale = v0.length_squared().max(v1.length_squared());
    // Relative test: |det| / edge² is the sine of the angle at `a`; NaN fails it too.
    if det.abs().partial_cmp(&(1e-12 * scale)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let b1 = (v2.x * v1.y - v1.x * v2.y) / det;
    let b2 = (v0.x * v2.y - v2.x * v0.y) / det;
    Some([1.0 - b1 - b2, b1, b2])
}

/// The paper's distance of a point to a triangle: the sum of the barycentric coordinates'
/// excess below 0 and above 1.
pub(crate) fn excess(b: [f64; 3]) -> f64 {
    b.iter()
        .map(|&x| {
            if x < 0.0 {
                -x
            } else if x > 1.0 {
                x - 1.0
            } else {
                0.0
            }
        })
        .sum()
}

/// The paper's closest point on the triangle: coordinates truncated to [0, 1] and divided by
/// their sum (never zero: coordinates sum to 1, so one of them is positive).
pub(crate) fn clamp(b: [f64; 3]) -> [f64; 3] {
    let c = b.map(|x| x.clamp(0.0, 1.0));
    let s: f64 = c.iter().sum();
    c.map(|x| x / s)
}

/// Triangle bounding boxes bucketed in a uniform grid: the boxes containing a point, and the
/// boxes nearest a point in order. Cells are about one mean box across, so a point's cell
/// holds a handful of boxes on a mesh of similar-sized triangles.
struct BoxGrid {
    boxes: Vec<(DVec2, DVec2)>,
    origin: DVec2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// Compressed rows: the boxes of cell `k` are `items[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Box-to-point squared distance (0 inside).
fn box_distance2((lo, hi): (DVec2, DVec2), p: DVec2) -> f64 {
    let d = (lo - p).max(p - hi).max(DVec2::ZERO);
    d.length_squared()
}

impl BoxGrid {
    fn new(boxes: Vec<(DVec2, DVec2)>) -> BoxGrid {
        let (lo, hi) = boxes.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
        );
        let n = boxes.len().max(1) as f64;
        let mean = boxes.iter().map(|b| (b.1 - b.0).max_element()).sum::<f64>() / n;
        let extent = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
        // About one box per cell, and never more cells than 4 per box (long thin boxes).
        let floor = (extent.x * extent.y / (4.0 * n)).sqrt();
        let cell = mean.max(floor).max(extent.max_element() * 1e-6);
        let cells = |e: f64| ((e / cell).floor() as usize + 1).min(1 << 15);
        let (nx, ny) = if boxes.is_empty() {
            (1, 1)
        } else {
            (cells(extent.x), cells(extent.y))
        };
        let origin = if boxes.is_empty() { DVec2::ZERO } else { lo };
        let mut grid = BoxGrid {
            boxes,
            origin,
            cell,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: Vec::new(),
        };
        for pass in 0..2 {
            let mut fill = grid.start.clone();
            for (k, &b) in grid.boxes.iter().enumerate() {
                let ([i0, j0], [i1, j1]) = (grid.index(b.0), grid.index(b.1));
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        let c = j * nx + i;
                        if pass == 0 {
                            grid.start[c + 1] += 1;
                        } else {
                            grid.items[fill[c] as usize] = k as u32;
                            fill[c] += 1;
                        }
                    }
                }
            }
            if pass == 0 {
                for c in 0..nx * ny {
                    grid.start[c + 1] += grid.start[c];
                }
                grid.items = vec![0; grid.start[nx * ny] as usize];
            }
        }
        grid
    }

    /// The cell holding `p`, clamped to the grid.
    fn index(&self, p: DVec2) -> [usize; 2] {
        let q = (p - self.origin) / self.cell;
        let clamp = |x: f64, n: usize| (x.max(0.0) as usize).min(n - 1);
        [clamp(q.x, self.nx), clamp(q.y, self.ny)]
    }

    fn cell_items(&self, i: usize, j: usize) -> &[u32] {
        let c = j * self.nx + i;
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// Boxes containing `p` (borders included).
    fn containing(&self, p: DVec2) -> impl Iterator<Item = u32> + '_ {
        let [i, j] = self.index(p);
        self.cell_items(i, j)
            .iter()
            .copied()
            .filter(move |&k| box_distance2(self.boxes[k as usize], p) == 0.0)
    }

    /// Up to `count` boxes passing `keep`, nearest to `p` first (ties by index): rings of
    /// cells grow around `p` until no unvisited cell can hold a nearer box.
    ///
    /// Only the `count` best so far are kept (sorted, so the stopping test is one look), and
    /// boxes met in several cells are skipped by a per-thread visit stamp: a point far outside
    /// the grid (the back of a whole head) visits most of it, and a hash set and a sort per
    /// ring made that most of fmc's time.
    fn nearest(&self, p: DVec2, count: usize, keep: impl Fn(u32) -> bool) -> Vec<u32> {
        if count == 0 || self.boxes.is_empty() {
            return Vec::new();
        }
        thread_local! {
            /// Per box, the visit number that last saw it; and the current visit number.
            static STAMPS: std::cell::RefCell<(Vec<u32>, u32)> =
                const { std::cell::RefCell::new((Vec::new(), 0)) };
        }
        STAMPS.with(|cell| {
            let mut guard = cell.borrow_mut();
            let (stamps, visit) = &mut *guard;
            if stamps.len() < self.boxes.len() {
                stamps.resize(self.boxes.len(), 0);
            }
            *visit = visit.wrapping_add(1);
            if *visit == 0 {
                stamps.iter_mut().for_each(|s| *s = 0);
                *visit = 1;
            }
            self.nearest_stamped(p, count, keep, stamps, *visit)
        })
    }

    fn nearest_stamped(
        &self,
        p: DVec2,
        count: usize,
        keep: impl Fn(u32) -> bool,
        stamps: &mut [u32],
        visit: u32,
    ) -> Vec<u32> {
        let [ci, cj] = self.index(p);
        // The best `count` so far, by (squared distance, index).
        let mut best: Vec<(f64, u32)> = Vec::with_capacity(count + 1);
        let before = |a: &(f64, u32), b: &(f64, u32)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
        for r in 0.. {
            let (i0, i1) = (ci.saturating_sub(r), (ci + r).min(self.nx - 1));
            let (j0, j1) = (cj.saturating_sub(r), (cj + r).min(self.ny - 1));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    // Only the ring's border cells are new.
                    if r > 0 && i > i0 && i < i1 && j > j0 && j < j1 {
                        continue;
                    }
                    for &k in self.cell_items(i, j) {
                        let stamp = &mut stamps[k as usize];
                        if *stamp == visit {
                            continue;
                        }
                        *stamp = visit;
                        if !keep(k) {
                            continue;
                        }
                        let item = (box_distance2(self.boxes[k as usize], p), k);
                        if best.len() < count || before(&item, &best[count - 1]).is_lt() {
                            let at = best.partition_point(|b| before(b, &item).is_lt());
                            best.insert(at, item);
                            best.truncate(count);
                        }
                    }
                }
            }
            // Distance from `p` to the cells not yet visited (through the sides of the
            // visited block that are not the grid's edge).
            let x = |i: usize| self.origin.x + i as f64 * self.cell;
            let y = |j: usize| self.origin.y + j as f64 * self.cell;
            let mut bound = f64::INFINITY;
            if i0 > 0 {
                bound = bound.min((p.x - x(i0)).max(0.0));
            }
            if i1 + 1 < self.nx {
                bound = bound.min((x(i1 + 1) - p.x).max(0.0));
            }
            if j0 > 0 {
                bound = bound.min((p.y - y(j0)).max(0.0));
            }
            if j1 + 1 < self.ny {
                bound = bound.min((y(j1 + 1) - p.y).max(0.0));
            }
            let done =
                bound.is_infinite() || best.len() >= count && best[count - 1].0 <= bound * bound;
            if done {
                break;
            }
        }
        best.into_iter().map(|f| f.1).collect()
    }
}

/// Where a point fell: the chosen triangle and the coordinates to interpolate with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Hit {
    /// Index into [`TriMesh2::triangles`].
    pub tri: u32,
    /// Barycentric coordinates (clamped and renormalised when `outside`).
    pub bary: [f64; 3],
    /// The point was outside every allowed triangle (closest-triangle rule).
    pub outside: bool,
    /// The point was inside several allowed triangles at different depths.
    pub overlap: bool,
}

/// Input points with depths and a triangulation, indexed for point location.
pub(crate) struct TriMesh2 {
    /// Input points P_i.
    pub points: Vec<DVec2>,
    /// Depth of each point; smaller is in front.
    pub depth: Vec<f64>,
    /// The non-degenerate triangles, as given (degenerate ones are dropped).
    pub triangles: Vec<[u32; 3]>,
    /// For each kept triangle, its index in the caller's list.
    pub original: Vec<u32>,
    grid: BoxGrid,
}

impl TriMesh2 {
    /// Indexes `triangles` over `points`. Triangles with zero area, an out-of-range index or
    /// a horizontal extent over `max_width` (a cylinder seam) are left out.
    pub fn new(
        points: Vec<DVec2>,
        depth: Vec<f64>,
        triangles: &[[u32; 3]],
        max_width: f64,
    ) -> TriMesh2 {
        let mut kept = Vec::with_capacity(triangles.len());
        let mut original = Vec::with_capacity(triangles.len());
        let mut boxes = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            if t.iter().any(|&v| v as usize >= points.len()) {
                continue;
            }
            let [a, b, c] = t.map(|v| points[v as usize]);
            if barycentric(a, a, b, c).is_none() {
                continue;
            }
            let lo = a.min(b).min(c);
            let hi = a.max(b).max(c);
            if hi.x - lo.x > max_width {
                continue;
            }
            boxes.push((lo, hi));
            kept.push(*t);
            original.push(i as u32);
        }
        TriMesh2 {
            points,
            depth,
            triangles: kept,
            original,
            grid: BoxGrid::new(boxes),
        }
    }

    fn coords(&self, tri: u32, p: DVec2) -> [f64; 3] {
        let [a, b, c] = self.triangles[tri as usize].map(|v| self.points[v as usize]);
        // Kept triangles are non-degenerate, so this is always `Some`.
        barycentric(p, a, b, c).unwrap_or([1.0 / 3.0; 3])
    }

    fn depth_at(&self, tri: u32, b: [f64; 3]) -> f64 {
        let t = self.triangles[tri as usize];
        (0..3).map(|k| b[k] * self.depth[t[k] as usize]).sum()
    }

    /// Locates `p` among the triangles for which `allowed(kept index)` holds: the front-most
    /// (smallest interpolated depth) containing triangle — or, with `near = Some(d)`, the one
    /// whose interpolated depth is closest to `d` — else the closest one by the excess
    /// measure with clamped coordinates. `None` only when no triangle is allowed.
    pub fn locate(
        &self,
        p: DVec2,
        near: Option<f64>,
        allowed: impl Fn(u32) -> bool,
    ) -> Option<Hit> {
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for tri in self.grid.containing(p) {
            if !allowed(tri) {
                continue;
            }
            let b = self.coords(tri, p);
            if excess(b) > INSIDE_EPS {
                continue;
            }
            let raw = self.depth_at(tri, b);
            (lo, hi) = (lo.min(raw), hi.max(raw));
            let d = near.map_or(raw, |n| (raw - n).abs());
            // Ties (shared edges) go to the lower index, for determinism.
            let better = best.is_none_or(|(bd, bt, _)| {
                d < bd - DEPTH_EPS || ((d - bd).abs() <= DEPTH_EPS && tri < bt)
            });
            if better {
                best = Some((d, tri, b));
            }
        }
        let overlap = hi - lo > DEPTH_EPS;
        if let Some((_, tri, bary)) = best {
            return Some(Hit {
                tri,
                bary,
                outside: false,
                overlap,
            });
        }
        let mut closest: Option<(f64, u32, [f64; 3])> = None;
        for tri in self.grid.nearest(p, OUTSIDE_CANDIDATES, &allowed) {
            let b = self.coords(tri, p);
            let e = excess(b);
            if closest.is_none_or(|(ce, ct, _)| e < ce || (e == ce && tri < ct)) {
                closest = Some((e, tri, b));
            }
        }
        closest.map(|(_, tri, b)| Hit {
            tri,
            bary: clamp(b),
            outside: true,
            overlap: false,
        })
    }

    /// The input-point indices and weights of a hit.
    pub fn weights(&self, hit: &Hit) -> [(u32, f64); 3] {
        let t = self.triangles[hit.tri as usize];
        [
            (t[0], hit.bary[0]),
            (t[1], hit.bary[1]),
            (t[2], hit.bary[2]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> TriMesh2 {
        // Two triangles of the unit square, plus a small triangle in front overlapping the
        // upper-right corner of the square.
        let points = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(0.6, 0.6),
            DVec2::new(1.2, 0.6),
            DVec2::new(0.6, 1.2),
        ];
        let depth = vec![1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
        TriMesh2::new(points, depth, &[[0, 1, 2], [0, 2, 3], [4, 5, 6]], 10.0)
    }

    #[test]
    fn barycentric_matches_hand_computation() {
        let b = barycentric(
            DVec2::new(0.25, 0.5),
            DVec2::ZERO,
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
        )
        .unwrap();
        assert!((b[0] - 0.25).abs() < 1e-12 && (b[1] - 0.25).abs() < 1e-12);
        assert!((b[2] - 0.5).abs() < 1e-12);
        assert!(barycentric(DVec2::ZERO, DVec2::ZERO, DVec2::X, DVec2::X * 2.0).is_none());
    }

    #[test]
    fn inside_point_interpolates_its_triangle() {
        let m = square();
        let h = m.locate(DVec2::new(0.75, 0.25), None, |_| true).unwrap();
        assert!(!h.outside && !h.overlap);
        assert_eq!(m.triangles[h.tri as usize], [0, 1, 2]);
        // P = 0.25·A + 0.5·B + 0.25·C for A(0,0) B(1,0) C(1,1).
        let w = h.bary;
        assert!((w[0] - 0.25).abs() < 1e-12 && (w[1] - 0.5).abs() < 1e-12);
        assert!((w[2] - 0.25).abs() < 1e-12);
    }

    #[test]
    fn overlap_goes_to_the_smallest_depth() {
        let m = square();
        let h = m.locate(DVec2::new(0.8, 0.8), None, |_| true).unwrap();
        assert!(h.overlap);
        assert_eq!(m.triangles[h.tri as usize], [4, 5, 6]);
        // With the front triangle excluded, the square behind is used.
        let h = m.locate(DVec2::new(0.8, 0.8), None, |t| t != 2).unwrap();
        assert_eq!(m.triangles[h.tri as usize], [0, 1, 2]);
        assert!(!h.overlap);
    }

    #[test]
    fn outside_point_uses_closest_triangle_with_clamped_coordinates() {
        let m = TriMesh2::new(
            vec![DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)],
            vec![0.0; 3],
            &[[0, 1, 2]],
            10.0,
        );
        // P(1.5, -0.5): b = (0, 1.5, -0.5); excess 1.0; clamped (0, 1, 0).
        let p = DVec2::new(1.5, -0.5);
        let b = barycentric(p, DVec2::ZERO, DVec2::X, DVec2::Y).unwrap();
        assert!((excess(b) - 1.0).abs() < 1e-12);
        let h = m.locate(p, None, |_| true).unwrap();
        assert!(h.outside);
        assert_eq!(h.bary, [0.0, 1.0, 0.0]);
        // P(0.8, 0.8): b = (-0.6, 0.8, 0.8); clamped (0, 0.8, 0.8) / 1.6 = (0, 0.5, 0.5).
        let h = m.locate(DVec2::new(0.8, 0.8), None, |_| true).unwrap();
        assert!(h.outside);
        assert!((h.bary[1] - 0.5).abs() < 1e-12 && (h.bary[2] - 0.5).abs() < 1e-12);
        assert!(m.locate(p, None, |_| false).is_none());
    }

    #[test]
    fn closest_triangle_is_chosen_by_excess() {
        let m = square();
        // Left of the square: only triangle [0,2,3] is close by the excess measure.
        let h = m.locate(DVec2::new(-0.2, 0.7), None, |t| t != 2).unwrap();
        assert!(h.outside);
        assert_eq!(m.triangles[h.tri as usize], [0, 2, 3]);
    }
}
