//! Lashes ride on their own lid's margin (module docs of [`super`], step 8). A row of lashes
//! floats in front of the lid; the skin point closest to it is often the lid's fold, which
//! moves far less than the margin the lashes grow from (the lashes followed a closing lid by
//! 12–28 % of its middle's drop). So a piece of lashes is tied to the margin instead.
//!
//! **The margins.** Per eye and lid, the margin runs from the outer eye corner through the
//! lid's middle feature point to the inner corner (left eye 3.7, 3.1 or 3.3, 3.11; right eye
//! 3.12, 3.2 or 3.4, 3.8): the shortest edge paths of the target's skin surface between
//! those points' vertices (around an eye opening they follow its rim). On a coarse skin
//! (fewer than [`MIN_INTERIOR`] vertices between a corner and the lid point, or a lid point
//! sharing its vertex with a corner) the path says nothing about the rim: the margin is then
//! the three feature points alone, each moving as its vertex.
//!
//! **Which pieces are lashes.** A connected piece holding no feature point whose points all
//! lie within [`REACH`] ES0 (pupil distance) of the nearer pupil, whose nearest point comes
//! within [`ROOT_GAP`] ES0 of that eye's upper or lower margin, and whose points lie, at
//! least [`ONE_SIDE`] of them, on one side of the line through the eye's corners: above it
//! an upper row, below it a lower row. A brow card is too far from the margin, an eye
//! occlusion or tear film straddles the corner line, both eyes' lashes in one piece reach
//! too far: none of them is a row of lashes.
//!
//! **The tie.** Each vertex of a row takes the motion of the margin point nearest it (two
//! neighbouring margin points, linearly): the row translates with the margin under every
//! table, so it keeps its offset in front of the lid, and a closing lid carries it around
//! the eyeball as it carries the rim. Where the margin moves straight (a coarse skin whose
//! lid point slides down), a lash that would end inside the eyeball (the target's eye part)
//! stops on its surface.

use glam::Vec3;

use std::collections::BTreeSet;

use super::{FaceParts, Part, Similarity, SkinSurface};
use crate::clone::{CloneSurface, SurfaceMotion};
use crate::face::FaceModel;
use crate::mesh::components::UnionFind;
use crate::spec::FeaturePointId;

/// Fewest surface vertices strictly between a corner and the lid point for the edge path to
/// stand for the rim.
pub(super) const MIN_INTERIOR: usize = 2;

/// Farthest a lash point may lie from its eye's pupil, in ES0.
pub(super) const REACH: f32 = 0.6;

/// Farthest the nearest point of a row may lie from its margin, in ES0.
pub(super) const ROOT_GAP: f32 = 0.2;

/// Least share of a row's points on its side of the corner line.
pub(super) const ONE_SIDE: f32 = 0.8;

/// A tie to the skin surface: three surface vertices and their weights.
pub(super) type Tie = ([u32; 3], [f32; 3]);

/// Share of the way from a lid point to each corner that is the margin's middle: it moves
/// as the lid point (the FAP defines that point's motion, and the lashes over the lid's
/// middle ride it), so `smooth` holds it and `lid_close` fades its change out over it.
pub(super) const MIDDLE: f32 = 0.5;

/// One lid's margin: points (the surface's frame), the surface vertex each moves as, and the
/// index of the lid's feature point among them.
#[derive(Clone, Debug)]
struct Lid {
    left: bool,
    upper: bool,
    points: Vec<Vec3>,
    vertices: Vec<u32>,
    mid: usize,
}

/// The lid margins of a skin surface, with the eyes' landmarks.
#[derive(Clone, Debug, Default)]
pub(super) struct LidMargins {
    lids: Vec<Lid>,
    /// Per eye (left, right): pupil, outer and inner corner.
    eyes: Vec<(bool, Vec3, Vec3, Vec3)>,
    /// Pupil distance (ES0 in the surface's frame).
    es: f32,
    /// The eyeballs (left eye or not, ball).
    balls: Vec<(bool, Ball)>,
}

/// An eyeball in the surface's frame: lashes resting outside it never enter it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Ball {
    centre: Vec3,
    radius: f32,
    /// Median distance of its points from the centre: the sphere of the eye's white, under a
    /// bulging cornea.
    inner: f32,
}

impl Ball {
    /// The ball around `points` (bounding-box centre, farthest point: a cornea bulging from
    /// the sphere counts), `None` without points.
    fn around(points: &[Vec3]) -> Option<Ball> {
        if points.is_empty() {
            return None;
        }
        let lo = points
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |a, &p| a.min(p));
        let hi = points
            .iter()
            .fold(Vec3::splat(f32::NEG_INFINITY), |a, &p| a.max(p));
        let centre = (lo + hi) / 2.0;
        let mut dist: Vec<f32> = points.iter().map(|p| p.distance(centre)).collect();
        dist.sort_by(f32::total_cmp);
        let radius = dist.last().copied().unwrap_or(0.0);
        let inner = dist[dist.len() / 2];
        (centre.is_finite() && radius > 0.0 && inner > 0.0).then_some(Ball {
            centre,
            radius,
            inner,
        })
    }

    /// Centre and median radius (the eye white's sphere).
    pub fn sphere(&self) -> (Vec3, f32) {
        (self.centre, self.inner)
    }

    /// Displacement `d` of a point resting at `rest`, cut short on the ball's surface where it
    /// would end inside (for a point resting outside): a lid carried around the eyeball by a
    /// straight translation (a coarse skin) takes its lashes around it too.
    pub fn keep_out(&self, rest: Vec3, d: Vec3) -> Vec3 {
        if rest.distance(self.centre) < self.radius {
            return d;
        }
        let r = rest + d - self.centre;
        let len = r.length();
        if len >= self.radius || len.is_nan() || len <= 0.0 {
            return d;
        }
        self.centre + r * (self.radius / len) - rest
    }
}

fn fp(s: &str) -> FeaturePointId {
    // The ids below are the standard's; parsing them cannot fail.
    s.parse().unwrap_or(FeaturePointId::FP_2_1)
}

impl LidMargins {
    /// One lid's margin (outer corner to inner): its neutral points and the surface vertex
    /// each moves as, if found.
    pub fn lid(&self, left: bool, upper: bool) -> Option<(&[Vec3], &[u32])> {
        self.lids
            .iter()
            .find(|l| l.left == left && l.upper == upper)
            .map(|l| (l.points.as_slice(), l.vertices.as_slice()))
    }

    /// One eye's outer and inner corner, if known.
    pub fn corners(&self, left: bool) -> Option<(Vec3, Vec3)> {
        self.eyes
            .iter()
            .find(|e| e.0 == left)
            .map(|&(_, _, o, i)| (o, i))
    }

    /// Per vertex of one lid's margin (in the order of [`Self::lid`]), how far it lies from
    /// the margin's middle ([`MIDDLE`]): 0 at the lid point, rising smoothly (by length along
    /// the margin) to 1 at `MIDDLE` of the way to each corner and beyond.
    pub fn middle_weights(&self, left: bool, upper: bool) -> Vec<f32> {
        let Some(l) = self
            .lids
            .iter()
            .find(|l| l.left == left && l.upper == upper)
        else {
            return Vec::new();
        };
        let mut run = vec![0.0f32];
        for w in l.points.windows(2) {
            run.push(run[run.len() - 1] + w[0].distance(w[1]));
        }
        let (at, last) = (run[l.mid], run[run.len() - 1]);
        run.iter()
            .map(|&r| {
                let span = MIDDLE * if r <= at { at } else { last - at };
                if span <= 0.0 {
                    return 1.0;
                }
                let x = ((r - at).abs() / span).min(1.0);
                x * x * (3.0 - 2.0 * x)
            })
            .collect()
    }

    /// The middle of one lid's margin: its vertices short of [`MIDDLE`] of the way from the
    /// lid point to either corner.
    pub fn middle(&self, left: bool, upper: bool) -> Vec<u32> {
        let Some((_, vertices)) = self.lid(left, upper) else {
            return Vec::new();
        };
        vertices
            .iter()
            .zip(self.middle_weights(left, upper))
            .filter(|(_, w)| *w < 1.0)
            .map(|(&v, _)| v)
            .collect()
    }

    /// Pupil distance (ES0 in the surface's frame).
    pub fn es(&self) -> f32 {
        self.es
    }

    /// The surface vertices on every lid's margin.
    pub fn margin_vertices(&self) -> impl Iterator<Item = u32> + '_ {
        self.lids.iter().flat_map(|l| l.vertices.iter().copied())
    }

    /// The margins of `surf`'s lids (those whose corner, lid and pupil points it knows).
    pub fn of(surf: &CloneSurface) -> LidMargins {
        let pos = |id: &str| surf.fp(fp(id));
        let (Some(pl), Some(pr)) = (pos("3.5"), pos("3.6")) else {
            return LidMargins::default();
        };
        let es = pl.distance(pr);
        if es.is_nan() || es <= 0.0 {
            return LidMargins::default();
        }
        let graph = EdgeGraph::of(surf);
        let mut out = LidMargins {
            es,
            ..LidMargins::default()
        };
        for (left, pupil, outer, inner, lids) in [
            (true, pl, "3.7", "3.11", [("3.1", true), ("3.3", false)]),
            (false, pr, "3.12", "3.8", [("3.2", true), ("3.4", false)]),
        ] {
            let (Some(o), Some(i)) = (pos(outer), pos(inner)) else {
                continue;
            };
            out.eyes.push((left, pupil, o, i));
            for (mid, upper) in lids {
                let ids = [outer, mid, inner].map(fp);
                if let Some((points, vertices, mid)) = margin(surf, &graph, ids) {
                    out.lids.push(Lid {
                        left,
                        upper,
                        points,
                        vertices,
                        mid,
                    });
                }
            }
        }
        out
    }

    /// The same with the target's eyeballs (`parts`' eye meshes of `face`, put in the
    /// surface's `frame`), which lashes stay out of.
    pub fn with_eyeballs(
        mut self,
        face: &FaceModel,
        parts: &FaceParts,
        frame: &Similarity,
    ) -> Self {
        let frames = face.frames();
        for (part, left) in [(Part::LeftEye, true), (Part::RightEye, false)] {
            let points: Vec<Vec3> = parts
                .parts
                .get(&part)
                .into_iter()
                .flatten()
                .flat_map(|&mi| face.mesh_world(&frames, mi))
                .map(|p| frame.point(p))
                .collect();
            if let Some(b) = Ball::around(&points) {
                self.balls.push((left, b));
            }
        }
        self
    }

    /// The eyeballs (left eye or not, ball).
    pub fn balls(&self) -> &[(bool, Ball)] {
        &self.balls
    }

    /// The eyeball of lid `lid`'s eye, if known.
    pub fn ball(&self, lid: usize) -> Option<Ball> {
        let left = self.lids.get(lid)?.left;
        self.balls.iter().find(|b| b.0 == left).map(|b| b.1)
    }

    /// The lid a piece (`points` in the surface's frame) rides on as a row of lashes (module
    /// docs), as an index for [`Self::tie`].
    pub fn row_lid(&self, points: &[Vec3]) -> Option<usize> {
        if points.is_empty() || self.lids.is_empty() {
            return None;
        }
        let c = points.iter().copied().sum::<Vec3>() / points.len() as f32;
        let &(left, pupil, o, i) = self
            .eyes
            .iter()
            .min_by(|a, b| a.1.distance(c).total_cmp(&b.1.distance(c)))?;
        if points.iter().any(|p| p.distance(pupil) > REACH * self.es) {
            return None;
        }
        // Side of the corner line, in the face's vertical.
        let side = |p: &Vec3| {
            let t = if (i.x - o.x).abs() > 0.0 {
                ((p.x - o.x) / (i.x - o.x)).clamp(0.0, 1.0)
            } else {
                0.5
            };
            p.y - (o.y + t * (i.y - o.y))
        };
        let above = points.iter().filter(|p| side(p) > 0.0).count() as f32;
        let n = points.len() as f32;
        let upper = if above >= ONE_SIDE * n {
            true
        } else if n - above >= ONE_SIDE * n {
            false
        } else {
            return None;
        };
        let k = self
            .lids
            .iter()
            .position(|l| l.left == left && l.upper == upper)?;
        let gap = points
            .iter()
            .map(|&p| nearest_on(&self.lids[k].points, p).2)
            .fold(f32::INFINITY, f32::min);
        (gap <= ROOT_GAP * self.es).then_some(k)
    }

    /// The tie of point `p` (the surface's frame) to lid `lid`'s margin: the margin point
    /// nearest it, between two margin vertices.
    pub fn tie(&self, lid: usize, p: Vec3) -> Tie {
        let l = &self.lids[lid];
        let (a, t, _) = nearest_on(&l.points, p);
        let b = (a + 1).min(l.vertices.len() - 1);
        (
            [l.vertices[a], l.vertices[b], l.vertices[a]],
            [1.0 - t, t, 0.0],
        )
    }
}

/// The point of polyline `line` nearest `p`: segment start, parameter along the segment,
/// distance. A single point is a segment of length zero.
pub(super) fn nearest_on(line: &[Vec3], p: Vec3) -> (usize, f32, f32) {
    let mut best = (0, 0.0, f32::INFINITY);
    let last = line.len().saturating_sub(1);
    for a in 0..line.len() {
        let b = (a + 1).min(last);
        let (pa, pb) = (line[a], line[b]);
        let ab = pb - pa;
        let len2 = ab.length_squared();
        let t = if len2 > 0.0 {
            ((p - pa).dot(ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = p.distance(pa + ab * t);
        if d < best.2 {
            best = (a, t, d);
        }
        if b == a {
            break;
        }
    }
    best
}

/// A feature point's vertex on the surface: its own, else the vertex nearest its position.
fn fp_vertex(surf: &CloneSurface, id: FeaturePointId) -> Option<u32> {
    if let Some(&v) = surf.fp_vertices.get(&id) {
        return Some(v);
    }
    let q = surf.fp(id)?;
    (0..surf.positions.len() as u32).min_by(|&a, &b| {
        surf.positions[a as usize]
            .distance(q)
            .total_cmp(&surf.positions[b as usize].distance(q))
    })
}

/// The margin through the feature points `ids` (outer corner, lid, inner corner): its points,
/// the vertex each moves as (module docs) and the lid point's index among them.
fn margin(
    surf: &CloneSurface,
    graph: &EdgeGraph,
    ids: [FeaturePointId; 3],
) -> Option<(Vec<Vec3>, Vec<u32>, usize)> {
    let vs = ids.map(|id| fp_vertex(surf, id));
    let [Some(a), Some(m), Some(b)] = vs else {
        return None;
    };
    let pos = ids.map(|id| surf.fp(id));
    let [Some(pa), Some(pm), Some(pb)] = pos else {
        return None;
    };
    let first = graph.path(surf, a, m);
    let second = graph.path(surf, m, b);
    let dense = |p: &Option<Vec<u32>>| p.as_ref().is_some_and(|p| p.len() >= MIN_INTERIOR + 2);
    if a != m && m != b && dense(&first) && dense(&second) {
        let mut vertices = first?;
        let mid = vertices.len() - 1;
        vertices.extend(second?.into_iter().skip(1));
        let points = vertices
            .iter()
            .map(|&v| surf.positions[v as usize])
            .collect();
        return Some((points, vertices, mid));
    }
    Some((vec![pa, pm, pb], vec![a, m, b], 1))
}

/// The surface's edges (CSR adjacency with lengths).
struct EdgeGraph {
    start: Vec<usize>,
    next: Vec<u32>,
}

impl EdgeGraph {
    fn of(surf: &CloneSurface) -> EdgeGraph {
        let n = surf.positions.len();
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(surf.triangles.len() * 6);
        for t in &surf.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if (a as usize) < n && (b as usize) < n && a != b {
                    pairs.push((a, b));
                    pairs.push((b, a));
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut start = vec![0; n + 1];
        for &(a, _) in &pairs {
            start[a as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        EdgeGraph {
            start,
            next: pairs.into_iter().map(|p| p.1).collect(),
        }
    }

    /// The shortest edge path from `a` to `b` (both included), by Dijkstra; `None` when they
    /// are not connected.
    fn path(&self, surf: &CloneSurface, a: u32, b: u32) -> Option<Vec<u32>> {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let n = surf.positions.len();
        let mut dist = vec![f32::INFINITY; n];
        let mut prev = vec![u32::MAX; n];
        let mut heap = BinaryHeap::new();
        dist[a as usize] = 0.0;
        // Non-negative finite distances order as their bit patterns.
        heap.push(Reverse((0u32, a)));
        while let Some(Reverse((bits, v))) = heap.pop() {
            let d = f32::from_bits(bits);
            if d > dist[v as usize] {
                continue;
            }
            if v == b {
                break;
            }
            let pv = surf.positions[v as usize];
            for &w in &self.next[self.start[v as usize]..self.start[v as usize + 1]] {
                let nd = d + pv.distance(surf.positions[w as usize]);
                if nd.is_finite() && nd < dist[w as usize] {
                    dist[w as usize] = nd;
                    prev[w as usize] = v;
                    heap.push(Reverse((nd.to_bits(), w)));
                }
            }
        }
        if !dist[b as usize].is_finite() {
            return None;
        }
        let mut path = vec![b];
        let mut v = b;
        while v != a {
            v = prev[v as usize];
            if v == u32::MAX || path.len() > n {
                return None;
            }
            path.push(v);
        }
        path.reverse();
        Some(path)
    }
}

/// Rows of lashes inside the skin meshes (a one-mesh head's lashes): the surface vertices
/// they own and their ties.
#[derive(Clone, Debug, Default)]
pub(super) struct SkinRows {
    vertices: Vec<u32>,
    ties: Vec<Tie>,
    /// Per vertex: its rest position and the eyeball it stays out of.
    outside: Vec<Option<(Ball, Vec3)>>,
}

impl SkinRows {
    /// The rows among the pieces of `skin`'s meshes (polygon connectivity alone: ICT's lash
    /// roots coincide with its lid vertices, and welding joins them to the face). Every piece
    /// but the largest is tried (module docs); a row takes the surface vertices only it has
    /// (its roots, welded to the lid, move as the lid), and is left alone when one of them is
    /// a feature point.
    pub fn of(face: &FaceModel, skin: &SkinSurface, margins: &LidMargins) -> SkinRows {
        let n = skin.welded.len();
        let mut uf = UnionFind::new(n);
        for (k, &mi) in skin.meshes.iter().enumerate() {
            let start = skin.starts[k] as u32;
            for poly in face.meshes[mi].mesh.polygons.iter() {
                for w in poly.windows(2) {
                    if ((start + w[0]) as usize) < n && ((start + w[1]) as usize) < n {
                        uf.union(start + w[0], start + w[1]);
                    }
                }
            }
        }
        let (label, count) = uf.labels();
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); count];
        for (c, &k) in label.iter().enumerate() {
            members[k as usize].push(c as u32);
        }
        let core = (0..count).max_by_key(|&k| members[k].len());
        let surf = &skin.surface;
        let fps: BTreeSet<u32> = surf.fp_vertices.values().copied().collect();
        let mut out = SkinRows::default();
        for (k, cs) in members.iter().enumerate() {
            if Some(k) == core || cs.len() < 2 {
                continue;
            }
            let mut ws: Vec<u32> = cs.iter().map(|&c| skin.welded[c as usize]).collect();
            ws.sort_unstable();
            ws.dedup();
            let pts: Vec<Vec3> = ws.iter().map(|&w| surf.positions[w as usize]).collect();
            let own: Vec<(u32, Vec3)> = ws
                .iter()
                .zip(&pts)
                .filter(|(&w, _)| {
                    skin.duplicates(w)
                        .iter()
                        .all(|&c| label[c as usize] as usize == k)
                })
                .map(|(&w, &p)| (w, p))
                .collect();
            if own.is_empty() || own.iter().any(|(w, _)| fps.contains(w)) {
                continue;
            }
            let Some(lid) = margins.row_lid(&pts) else {
                continue;
            };
            let ball = margins.ball(lid);
            for (w, p) in own {
                out.vertices.push(w);
                out.ties.push(margins.tie(lid, p));
                out.outside.push(ball.map(|b| (b, p)));
            }
        }
        out
    }

    /// Whether there are any.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// Each motion's offsets on the rows replaced by their margins' motion.
    pub fn carry(&self, motions: &mut [SurfaceMotion]) {
        if self.is_empty() {
            return;
        }
        let mut on_row = self.vertices.clone();
        on_row.sort_unstable();
        for m in motions.iter_mut() {
            let new: Vec<(u32, Vec3)> = self
                .vertices
                .iter()
                .zip(&self.ties)
                .zip(&self.outside)
                .map(|((&v, (c, w)), out)| {
                    let d = (0..3).map(|k| m.offset_at(c[k]) * w[k]).sum::<Vec3>();
                    (v, out.map_or(d, |(b, rest)| b.keep_out(rest, d)))
                })
                .filter(|(_, d)| *d != Vec3::ZERO)
                .collect();
            m.offsets.retain(|(v, _)| on_row.binary_search(v).is_err());
            m.offsets.extend(new);
            m.offsets.sort_unstable_by_key(|o| o.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fdp::{Fapu, FapuDistances};
    use std::collections::BTreeMap;

    /// A flat strip of skin with an eye's corners and upper lid on its lower edge, and a
    /// floating row above it.
    fn strip() -> CloneSurface {
        let mut positions = Vec::new();
        for j in 0..2 {
            for i in 0..=8 {
                positions.push(Vec3::new(i as f32 * 0.5, j as f32, 0.0));
            }
        }
        let mut triangles = Vec::new();
        for i in 0..8u32 {
            triangles.push([i, i + 1, i + 10]);
            triangles.push([i, i + 10, i + 9]);
        }
        // A lash card over the middle, 0.2 in front of the strip.
        let base = positions.len() as u32;
        for (x, y) in [(1.5, 0.1), (2.5, 0.1), (1.5, 0.5), (2.5, 0.5)] {
            positions.push(Vec3::new(x, y, 0.2));
        }
        triangles.push([base, base + 1, base + 3]);
        triangles.push([base, base + 3, base + 2]);
        let mut fp_vertices = BTreeMap::new();
        let mut fp_positions = BTreeMap::new();
        for (id, v) in [("3.7", 0u32), ("3.1", 4), ("3.11", 8)] {
            fp_vertices.insert(fp(id), v);
            fp_positions.insert(fp(id), positions[v as usize]);
        }
        fp_positions.insert(fp("3.5"), Vec3::new(2.0, -0.5, 0.0));
        fp_positions.insert(fp("3.6"), Vec3::new(-4.0, -0.5, 0.0));
        let d = FapuDistances {
            irisd0: 1.0,
            es0: 6.0,
            ens0: 4.0,
            mns0: 2.0,
            mw0: 5.0,
        };
        CloneSurface {
            positions,
            triangles,
            fp_vertices,
            fp_positions,
            fapu: Fapu::from_distances(d).unwrap(),
        }
    }

    #[test]
    fn a_floating_row_takes_its_margin_motion() {
        let surf = strip();
        let margins = LidMargins::of(&surf);
        let card: Vec<u32> = (18..22).collect();
        let pts: Vec<Vec3> = card.iter().map(|&v| surf.positions[v as usize]).collect();
        let lid = margins.row_lid(&pts).unwrap();
        let rows = SkinRows {
            vertices: card.clone(),
            ties: pts.iter().map(|&p| margins.tie(lid, p)).collect(),
            outside: vec![None; 4],
        };
        // The lid's middle goes down, its neighbours half as far; the strip's upper row
        // (the fold, closer to the card's top) stays.
        let mut m = [SurfaceMotion {
            key: crate::fat::TableKey::LowLevel(crate::spec::FapId::new(19).unwrap()),
            value: 1.0,
            offsets: vec![
                (3, Vec3::new(0.0, -0.5, 0.0)),
                (4, Vec3::new(0.0, -1.0, 0.0)),
                (5, Vec3::new(0.0, -0.5, 0.0)),
            ],
        }];
        rows.carry(&mut m);
        let d = |v: u32| m[0].offset_at(v);
        // x = 1.5 and 2.5 are margin vertices 3 and 5.
        assert_eq!(d(18), Vec3::new(0.0, -0.5, 0.0));
        assert_eq!(d(19), Vec3::new(0.0, -0.5, 0.0));
        assert_eq!(d(20), d(18));
        assert_eq!(d(4), Vec3::new(0.0, -1.0, 0.0));
    }

    #[test]
    fn a_row_below_the_corners_is_not_an_upper_row_and_a_far_card_none() {
        let surf = strip();
        let margins = LidMargins::of(&surf);
        // Straddling the corner line.
        let straddle = [Vec3::new(1.0, 0.3, 0.1), Vec3::new(1.0, -0.3, 0.1)];
        assert_eq!(margins.row_lid(&straddle), None);
        // Above, but far from the margin (a brow).
        let brow = [Vec3::new(1.0, 1.5, 0.0), Vec3::new(3.0, 1.5, 0.0)];
        assert_eq!(margins.row_lid(&brow), None);
        // Above and at the margin.
        let row = [Vec3::new(1.0, 0.05, 0.1), Vec3::new(3.0, 0.3, 0.1)];
        assert_eq!(margins.row_lid(&row), Some(0));
    }

    #[test]
    fn the_margin_middle_fades_in_from_the_lid_point_to_half_way() {
        let surf = strip();
        let margins = LidMargins::of(&surf);
        // Vertices 0..=8 along x, the lid point 3.1 at 4: half way to each corner is two
        // vertices out.
        let w = margins.middle_weights(true, true);
        assert_eq!(w.len(), 9);
        assert_eq!(w[4], 0.0);
        assert!(
            (w[3] - 0.5).abs() < 1e-6 && (w[5] - 0.5).abs() < 1e-6,
            "{w:?}"
        );
        assert!(w[..=2].iter().chain(&w[6..]).all(|&x| x == 1.0), "{w:?}");
        assert_eq!(margins.middle(true, true), [3, 4, 5]);
        assert!(margins.middle(false, true).is_empty());
    }

    #[test]
    fn a_coarse_skin_uses_the_feature_points_alone() {
        let mut surf = strip();
        // The lid point on the corner's vertex, as on the coarse test avatar.
        surf.fp_vertices.insert(fp("3.1"), 8);
        let margins = LidMargins::of(&surf);
        assert_eq!(margins.lids[0].vertices, [0, 8, 8]);
        assert_eq!(margins.lids[0].points[1], Vec3::new(2.0, 0.0, 0.0));
    }
}
