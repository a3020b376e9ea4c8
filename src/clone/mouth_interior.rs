//! The hidden interior of a face's mouth: a rig head's mouth socket, the lips' inner faces
//! behind the contact line — the skin no one sees from the front.
//!
//! Two steps read it. `fit` keeps the interiors of the two faces to themselves: a source
//! socket matched onto a target without one is dragged onto the target's inner lips, and
//! those lips then read the socket's motion (ICT-FaceKit onto MediaPipe's canonical face:
//! every inner-lip vertex landed on socket triangles 3–6 cm behind ICT's lips, and
//! `stretch_r_cornerlip` moved its lip corner 0.6 % of its FAPU). The `mouth` step of
//! [`crate::clone::face`] moves the target's interior as a smooth extension of the lips.
//!
//! # The region
//!
//! In the aligned frame (+z forward), with `y_l` the lip line (mean y of 2.2 and 2.3), `z_l`
//! the lips' front (the smaller z of the two), MNS0 and MW0 the face's units: a vertex is
//! *inside* when it lies in the mouth box ([`Extent`]: for the `mouth` step |x − x_l| ≤ 0.9
//! MW0, y_l − 1.5 MNS0 ≤ y ≤ y_l + 0.8 MNS0; for matching, the whole socket), at least [`BEHIND`] × MNS0 behind the lips' front, hidden from the front (some
//! triangle lies at least [`HIDDEN`] × MNS0 in front of it along +z: a depth buffer of the
//! surface over the box), and reached from the inner lip contour (not a hidden fold elsewhere
//! in the box, under the jaw's angle). Cheeks beside the mouth corners are in front and stay
//! out; a face without a mouth interior (CANDIDE-3, MediaPipe's canonical face) has no such
//! vertex. Feature points never are inside (they keep what the FAP defines).

use std::collections::{BTreeSet, VecDeque};

use glam::Vec3;

use super::CloneSurface;
use crate::spec::FeaturePointId as F;

/// How far behind the lips' front (MNS0) a vertex must lie to be inside.
const BEHIND: f32 = 0.15;
/// How far in front of it (MNS0) the surface must lie for a vertex to be hidden.
const HIDDEN: f32 = 0.1;
/// The inner lip contour and the lip corners, from which the interior is reached.
const INNER_LIP: [F; 8] = [
    F::FP_2_2,
    F::FP_2_3,
    F::FP_2_4,
    F::FP_2_5,
    F::FP_2_6,
    F::FP_2_7,
    F::FP_2_8,
    F::FP_2_9,
];
/// Edge rings around the inner lip contour searched for the interior's first vertices.
const SEED_RINGS: u8 = 4;

/// How far from the lips an interior reaches: across (MW0 from the middle), below and
/// above the lip line (MNS0).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Extent {
    across: f32,
    below: f32,
    above: f32,
    /// How deep (MNS0 behind the lips' front) the interior must reach to count at all.
    depth: f32,
}

impl Extent {
    /// Behind the lips: what the `mouth` step fills.
    pub(crate) const LIPS: Extent = Extent {
        across: 0.9,
        below: 1.5,
        above: 0.8,
        depth: 0.0,
    };
    /// The whole socket: a rig head's reaches a lip height above the lip line and round the
    /// corners into the cheeks (ICT-FaceKit's: 2.5 cm above its lips, 6 cm deep), and all of
    /// it must stay apart from a face without one when two faces are matched. The lips'
    /// inner faces alone (MediaPipe's canonical face: half an MNS0 behind the lips' front)
    /// are no socket: they are lips, and match lips.
    pub(crate) const SOCKET: Extent = Extent {
        across: 1.5,
        below: 3.0,
        above: 2.0,
        depth: 1.0,
    };
}

/// The landmarks the region is measured from (aligned frame).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Mouth {
    /// Middle of the lip line, across.
    pub x: f32,
    /// Height of the lip line.
    pub y: f32,
    /// The lips' front (the smaller depth of 2.2 and 2.3).
    pub z: f32,
    /// MNS0.
    pub mns: f32,
    /// MW0.
    pub mw: f32,
}

impl Mouth {
    /// The mouth of `s` (`None` without 2.2, 2.3 or a mouth FAPU).
    pub(crate) fn of(s: &CloneSurface) -> Option<Mouth> {
        let (u, l) = (s.fp(F::FP_2_2)?, s.fp(F::FP_2_3)?);
        let d = s.fapu.distances;
        let (mns, mw) = (d.mns0 as f32, d.mw0 as f32);
        (mns > 0.0 && mw > 0.0).then_some(Mouth {
            x: 0.5 * (u.x + l.x),
            y: 0.5 * (u.y + l.y),
            z: u.z.min(l.z),
            mns,
            mw,
        })
    }

    fn in_box(&self, p: Vec3, e: Extent) -> bool {
        (p.x - self.x).abs() <= e.across * self.mw
            && p.y >= self.y - e.below * self.mns
            && p.y <= self.y + e.above * self.mns
    }
}

/// A face's mouth interior: its landmarks and, per surface vertex, whether it is inside.
pub(crate) struct MouthInterior {
    /// Where it was measured from.
    pub mouth: Mouth,
    /// Per surface vertex: inside (module docs).
    pub inside: Vec<bool>,
}

impl MouthInterior {
    /// The interior of `s` (module docs) within `extent` of the lips, `adj` its vertex
    /// adjacency (the callers have it already); `None` when it has none.
    pub(crate) fn of(s: &CloneSurface, adj: &[Vec<u32>], extent: Extent) -> Option<MouthInterior> {
        let mouth = Mouth::of(s)?;
        let n = s.positions.len();
        let depth = DepthBuffer::new(s, &mouth, extent);
        let pinned: BTreeSet<u32> = s.fp_vertices.values().copied().collect();
        let candidate: Vec<bool> = s
            .positions
            .iter()
            .enumerate()
            .map(|(v, p)| {
                mouth.in_box(*p, extent)
                    && !pinned.contains(&(v as u32))
                    && p.z <= mouth.z - BEHIND * mouth.mns
                    && depth.front(*p) >= p.z + HIDDEN * mouth.mns
            })
            .collect();
        if !candidate.iter().any(|&c| c) {
            return None;
        }
        let mut inside = vec![false; n];
        let mut queue: VecDeque<(u32, u8)> = INNER_LIP
            .iter()
            .filter_map(|id| s.fp_vertices.get(id))
            .map(|&v| (v, 0))
            .collect();
        let mut seen = vec![false; n];
        while let Some((v, rings)) = queue.pop_front() {
            let Some(done) = seen.get_mut(v as usize) else {
                continue;
            };
            if std::mem::replace(done, true) {
                continue;
            }
            if candidate[v as usize] {
                inside[v as usize] = true;
            } else if rings >= SEED_RINGS {
                continue;
            }
            for &w in adj.get(v as usize).map_or(&[][..], Vec::as_slice) {
                if !seen.get(w as usize).copied().unwrap_or(true) {
                    let r = if candidate[v as usize] { 0 } else { rings + 1 };
                    queue.push_back((w, r));
                }
            }
        }
        let deepest = s
            .positions
            .iter()
            .zip(&inside)
            .filter(|(_, &i)| i)
            .map(|(p, _)| (mouth.z - p.z) / mouth.mns)
            .fold(f32::NEG_INFINITY, f32::max);
        (deepest >= extent.depth && deepest > 0.0).then_some(MouthInterior { mouth, inside })
    }
}

/// The front-most surface depth over the mouth box, on a grid.
struct DepthBuffer {
    x0: f32,
    y0: f32,
    cell: f32,
    nx: usize,
    ny: usize,
    z: Vec<f32>,
}

impl DepthBuffer {
    fn new(s: &CloneSurface, mouth: &Mouth, e: Extent) -> DepthBuffer {
        let cell = mouth.mns / 40.0;
        let across = (e.across + 0.1) * mouth.mw;
        let (x0, x1) = (mouth.x - across, mouth.x + across);
        let (y0, y1) = (
            mouth.y - (e.below + 0.1) * mouth.mns,
            mouth.y + (e.above + 0.1) * mouth.mns,
        );
        let nx = ((x1 - x0) / cell).ceil() as usize + 1;
        let ny = ((y1 - y0) / cell).ceil() as usize + 1;
        let mut z = vec![f32::NEG_INFINITY; nx * ny];
        for t in &s.triangles {
            let Some([a, b, c]) = corners(t, &s.positions) else {
                continue;
            };
            let lo = a.min(b).min(c);
            let hi = a.max(b).max(c);
            if hi.x < x0 || lo.x > x1 || hi.y < y0 || lo.y > y1 {
                continue;
            }
            let i0 = ((lo.x - x0) / cell).floor().max(0.0) as usize;
            let i1 = (((hi.x - x0) / cell).ceil().max(0.0) as usize).min(nx - 1);
            let j0 = ((lo.y - y0) / cell).floor().max(0.0) as usize;
            let j1 = (((hi.y - y0) / cell).ceil().max(0.0) as usize).min(ny - 1);
            let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if det.abs() < 1e-12 * cell * cell {
                continue;
            }
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let (px, py) = (x0 + i as f32 * cell, y0 + j as f32 * cell);
                    let wb = ((px - a.x) * (c.y - a.y) - (c.x - a.x) * (py - a.y)) / det;
                    let wc = ((b.x - a.x) * (py - a.y) - (px - a.x) * (b.y - a.y)) / det;
                    let wa = 1.0 - wb - wc;
                    if wa >= -1e-4 && wb >= -1e-4 && wc >= -1e-4 {
                        let depth = wa * a.z + wb * b.z + wc * c.z;
                        let slot = &mut z[j * nx + i];
                        *slot = slot.max(depth);
                    }
                }
            }
        }
        DepthBuffer {
            x0,
            y0,
            cell,
            nx,
            ny,
            z,
        }
    }

    /// The front-most depth over `p`'s cell and its neighbours.
    fn front(&self, p: Vec3) -> f32 {
        let i = ((p.x - self.x0) / self.cell).round();
        let j = ((p.y - self.y0) / self.cell).round();
        if i < 0.0 || j < 0.0 {
            return f32::NEG_INFINITY;
        }
        let (i, j) = (i as usize, j as usize);
        let mut best = f32::NEG_INFINITY;
        for jj in j.saturating_sub(1)..=(j + 1).min(self.ny - 1) {
            for ii in i.saturating_sub(1)..=(i + 1).min(self.nx - 1) {
                best = best.max(self.z[jj * self.nx + ii]);
            }
        }
        best
    }
}

/// A triangle's corner positions, `None` when an index is out of range.
fn corners(t: &[u32; 3], positions: &[Vec3]) -> Option<[Vec3; 3]> {
    Some([
        *positions.get(t[0] as usize)?,
        *positions.get(t[1] as usize)?,
        *positions.get(t[2] as usize)?,
    ])
}
