//! Upper and lower sides of the mouth and the eyes, so a closed mouth or eye does not weld
//! when points are matched between surfaces.
//!
//! Each slit (the mouth, each eye) has a split line through its corners and the midpoints of
//! its upper and lower feature points (xy in the face frame, piecewise linear in x). A vertex
//! strictly between the corners in x, not too far above or below the line and not too deep
//! behind the corners is [`Side::Upper`] above the line and [`Side::Lower`] below it; every
//! other vertex is [`Side::Other`]. The labels come from the feature points alone, so both
//! faces of a clone are cut the same anatomical way whatever their meshing.
//!
//! Queries from an upper vertex see only upper and other triangles, from a lower vertex only
//! lower and other ones. Triangles with both an upper and a lower vertex (bridging the slit:
//! CANDIDE-3 covers its eyes, iris vertices between the lids) are seen by every query, but a
//! target vertex that lands on one takes no motion from the corners of the other side
//! ([`own_side_weights`]): an upper lid never reads the lower lid's motion, and the iris
//! between them reads only the still iris and its own lid.

use glam::{Vec2, Vec3};

use crate::clone::CloneSurface;
use crate::spec::FeaturePointId;

/// A vertex's side of the mouth or eye slit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    /// Not near a slit.
    Other,
    /// Upper lip or upper eyelid.
    Upper,
    /// Lower lip or lower eyelid.
    Lower,
}

/// Which query sides may see a triangle: bit 0 upper, bit 1 lower, bit 2 other.
pub(crate) type TriMask = u8;

/// A triangle seen by every query.
pub(crate) const SEEN_BY_ALL: TriMask = 0b111;

/// Triangle bit: on a face piece ([`face_pieces`]). Query bit: sees only such triangles.
pub(crate) const FACE_PIECE: TriMask = 0b1000;

/// Triangle bit: seen by queries from the mouth interior (a corner inside,
/// [`crate::clone::mouth_interior`]). Query bit: a vertex inside the mouth.
pub(crate) const INTERIOR: TriMask = 0b1_0000;

/// Triangle bit: seen by queries from outside the mouth interior (a corner outside). Query
/// bit: a vertex outside. A triangle across the interior's border has both.
pub(crate) const EXTERIOR: TriMask = 0b10_0000;

/// Per vertex, whether it lies on a face piece: a connected piece of the surface holding a
/// skin feature point. The other pieces — ICT's eye occlusion and lacrimal shells, lashes,
/// a one-mesh source's eyeballs and teeth — may touch the skin (the occlusion shell lies
/// against the lid margin) but never stand for it: a lid vertex of the target that landed
/// on one took no lid motion at all.
pub(crate) fn face_pieces(s: &CloneSurface) -> Vec<bool> {
    let n = s.positions.len();
    let mut uf = crate::mesh::components::UnionFind::new(n);
    for t in &s.triangles {
        if t.iter().all(|&v| (v as usize) < n) {
            uf.union(t[0], t[1]);
            uf.union(t[1], t[2]);
        }
    }
    let (label, count) = uf.labels();
    let mut face = vec![false; count];
    for (&id, &v) in &s.fp_vertices {
        if crate::clone::face::Part::of_feature_point(id).is_none() {
            if let Some(&l) = label.get(v as usize) {
                face[l as usize] = true;
            }
        }
    }
    if !face.iter().any(|&f| f) {
        // No skin feature point on any piece: every piece is the face.
        return vec![true; n];
    }
    label.iter().map(|&l| face[l as usize]).collect()
}

/// One slit: the split line (sorted by x) and the box around it.
struct Slit {
    line: Vec<Vec2>,
    up: f32,
    down: f32,
    zmin: f32,
}

impl Slit {
    /// The split line's y at `x`, if `x` lies strictly between the corners.
    fn y_at(&self, x: f32) -> Option<f32> {
        let (first, last) = (self.line.first()?, self.line.last()?);
        if !(x > first.x && x < last.x) {
            return None;
        }
        self.line.windows(2).find_map(|w| {
            let (a, b) = (w[0], w[1]);
            if x < a.x || x > b.x {
                return None;
            }
            let t = if b.x > a.x {
                (x - a.x) / (b.x - a.x)
            } else {
                0.5
            };
            Some(a.y + (b.y - a.y) * t)
        })
    }

    fn side(&self, p: Vec3) -> Side {
        if p.z < self.zmin {
            return Side::Other;
        }
        let Some(y) = self.y_at(p.x) else {
            return Side::Other;
        };
        if p.y >= y && p.y <= y + self.up {
            Side::Upper
        } else if p.y < y && p.y >= y - self.down {
            Side::Lower
        } else {
            Side::Other
        }
    }
}

fn fp(s: &CloneSurface, group: u8, index: u8) -> Option<Vec3> {
    s.fp(FeaturePointId::new(group, index)?)
}

/// First available of several feature points.
fn first(s: &CloneSurface, ids: &[(u8, u8)]) -> Option<Vec3> {
    ids.iter().find_map(|&(g, i)| fp(s, g, i))
}

/// A slit from its two corners and pairs of (upper, lower) points across it.
fn slit(corners: [Vec3; 2], pairs: &[(Vec3, Vec3)], up: f32, down: f32, depth: f32) -> Slit {
    let mut line: Vec<Vec2> = corners.iter().map(|c| c.truncate()).collect();
    let (lo, hi) = (
        corners[0].x.min(corners[1].x),
        corners[0].x.max(corners[1].x),
    );
    for (u, l) in pairs {
        let m = (*u + *l) * 0.5;
        if m.x > lo && m.x < hi {
            line.push(m.truncate());
        }
    }
    line.sort_by(|a, b| a.x.total_cmp(&b.x));
    line.dedup_by(|a, b| a.x == b.x);
    let zmin = corners[0].z.min(corners[1].z) - depth;
    Slit {
        line,
        up,
        down,
        zmin,
    }
}

/// The mouth and eye slits a surface's feature points define.
fn slits(s: &CloneSurface) -> Vec<Slit> {
    let d = &s.fapu.distances;
    let (mns0, es0, mw0) = (d.mns0 as f32, d.es0 as f32, d.mw0 as f32);
    let mut out = Vec::new();
    if !(mns0 > 0.0 && es0 > 0.0 && mw0 > 0.0) {
        return out;
    }
    // Mouth: inner corners if known, else outer ones.
    let lc = first(s, &[(2, 4), (8, 3)]);
    let rc = first(s, &[(2, 5), (8, 4)]);
    if let (Some(lc), Some(rc)) = (lc, rc) {
        let pairs: Vec<(Vec3, Vec3)> = [((2, 2), (2, 3)), ((2, 6), (2, 8)), ((2, 7), (2, 9))]
            .iter()
            .filter_map(|&((a, b), (c, e))| Some((fp(s, a, b)?, fp(s, c, e)?)))
            .collect();
        if !pairs.is_empty() {
            out.push(slit([lc, rc], &pairs, 0.9 * mns0, 1.3 * mns0, 0.5 * mw0));
        }
    }
    // Eyes: (outer corner, inner corner, upper lid, lower lid) per side.
    for (outer, inner, top, bottom) in [
        ((3, 7), (3, 11), (3, 1), (3, 3)),
        ((3, 8), (3, 12), (3, 2), (3, 4)),
    ] {
        let pts = (
            fp(s, outer.0, outer.1),
            fp(s, inner.0, inner.1),
            fp(s, top.0, top.1),
            fp(s, bottom.0, bottom.1),
        );
        if let (Some(o), Some(i), Some(t), Some(b)) = pts {
            out.push(slit([o, i], &[(t, b)], 0.3 * es0, 0.3 * es0, 0.25 * es0));
        }
    }
    out
}

/// Every vertex's side, and how many slits were found (0 to 3). A vertex is judged by the
/// mean of its neighbours (`adj`), not by itself: on a closed mouth or eye the upper and
/// lower vertices of the slit coincide, and only their neighbours tell them apart.
pub(crate) fn classify(s: &CloneSurface, adj: &[Vec<u32>]) -> (Vec<Side>, usize) {
    let slits = slits(s);
    let sides =
        s.positions
            .iter()
            .enumerate()
            .map(|(v, &p)| {
                let ring = adj.get(v).filter(|r| !r.is_empty()).map(|r| {
                    r.iter().map(|&w| s.positions[w as usize]).sum::<Vec3>() / r.len() as f32
                });
                let q = Vec3::new(p.x, ring.map_or(p.y, |c| c.y), p.z);
                slits
                    .iter()
                    .map(|sl| sl.side(q))
                    .find(|&sd| sd != Side::Other)
                    .unwrap_or(Side::Other)
            })
            .collect();
    (sides, slits.len())
}

/// Triangle masks from vertex sides (module docs), face pieces (`face`, per vertex) and
/// the mouth interior (`inside`, per vertex; empty when the face has none).
pub(crate) fn triangle_masks(
    sides: &[Side],
    face: &[bool],
    inside: &[bool],
    triangles: &[[u32; 3]],
) -> Vec<TriMask> {
    triangles
        .iter()
        .map(|t| {
            let piece = if face.get(t[0] as usize).copied().unwrap_or(true) {
                FACE_PIECE
            } else {
                0
            };
            let is_in = |v: &u32| inside.get(*v as usize).copied().unwrap_or(false);
            let mouth = if t.iter().any(is_in) { INTERIOR } else { 0 }
                | if t.iter().all(is_in) { 0 } else { EXTERIOR };
            let piece = piece | mouth;
            let has = |w: Side| t.iter().any(|&v| sides.get(v as usize) == Some(&w));
            piece
                | match (has(Side::Upper), has(Side::Lower)) {
                    // A triangle bridging the slit (a mesh that covers the eye, a mouth not cut
                    // open) is seen from both sides; a query from one side then takes none of
                    // the other side's corners (`own_side_weights`).
                    (true, true) => SEEN_BY_ALL,
                    (true, false) => 0b101,
                    (false, true) => 0b110,
                    (false, false) => SEEN_BY_ALL,
                }
        })
        .collect()
}

/// Weights `w` of a hit in triangle `tri` seen from a query of side `query`: the corners
/// of the opposite slit side get none, the others share it (unchanged when no corner or
/// every corner is opposite).
pub(crate) fn own_side_weights(
    query: Side,
    tri: [u32; 3],
    w: [f32; 3],
    sides: &[Side],
) -> [f32; 3] {
    let opposite = match query {
        Side::Upper => Side::Lower,
        Side::Lower => Side::Upper,
        Side::Other => return w,
    };
    let keep: [bool; 3] = tri.map(|v| sides.get(v as usize) != Some(&opposite));
    let total: f32 = (0..3).filter(|&k| keep[k]).map(|k| w[k]).sum();
    if keep.iter().all(|&k| k) || !keep.iter().any(|&k| k) {
        return w;
    }
    if total <= 1e-6 {
        // The hit lies on the opposite corners' edge: the nearest own corner takes it all.
        let k = (0..3).find(|&k| keep[k]).unwrap_or(0);
        let mut out = [0.0; 3];
        out[k] = 1.0;
        return out;
    }
    std::array::from_fn(|k| if keep[k] { w[k] / total } else { 0.0 })
}

/// The mask bits a query from a vertex of side `s` needs (`face`: the vertex lies on a
/// face piece, and sees only face-piece triangles; `inside`: the vertex lies in the mouth
/// interior, and sees only triangles with a corner there — else only triangles with a
/// corner outside).
pub(crate) fn query_bit(s: Side, face: bool, inside: bool) -> TriMask {
    let side = match s {
        Side::Upper => 0b001,
        Side::Lower => 0b010,
        Side::Other => 0b100,
    };
    let piece = if face { FACE_PIECE } else { 0 };
    side | piece | if inside { INTERIOR } else { EXTERIOR }
}

/// Whether a triangle of mask `mask` passes a query of bits `bit` ([`query_bit`]).
pub(crate) fn mask_passes(mask: TriMask, bit: TriMask) -> bool {
    mask & bit & SEEN_BY_ALL != 0
        && (bit & FACE_PIECE == 0 || mask & FACE_PIECE != 0)
        && mask & bit & (INTERIOR | EXTERIOR) != 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_query_takes_no_motion_from_the_other_side_of_a_slit() {
        let sides = [Side::Upper, Side::Lower, Side::Other];
        let w = [0.2, 0.5, 0.3];
        // An upper query keeps the upper and other corners, renormalised.
        let up = own_side_weights(Side::Upper, [0, 1, 2], w, &sides);
        assert!((up[0] - 0.4).abs() < 1e-6 && up[1] == 0.0 && (up[2] - 0.6).abs() < 1e-6);
        // A lower query at the upper corner keeps its own corner.
        let low = own_side_weights(Side::Lower, [0, 1, 2], [1.0, 0.0, 0.0], &sides);
        assert_eq!(low, [0.0, 1.0, 0.0]);
        // Other queries and one-sided triangles are unchanged.
        assert_eq!(own_side_weights(Side::Other, [0, 1, 2], w, &sides), w);
        assert_eq!(own_side_weights(Side::Upper, [0, 0, 2], w, &sides), w);
    }

    #[test]
    fn bridging_triangles_are_seen_from_both_sides_and_pieces_stay_apart() {
        let sides = [Side::Upper, Side::Lower, Side::Other, Side::Upper];
        let face = [true, true, true, false];
        let masks = triangle_masks(&sides, &face, &[], &[[0, 1, 2], [3, 3, 3], [0, 2, 2]]);
        // Bridging: every side, on the face.
        assert!(mask_passes(masks[0], query_bit(Side::Upper, true, false)));
        assert!(mask_passes(masks[0], query_bit(Side::Lower, true, false)));
        // Off the face: not for a face vertex, fine for another piece's vertex.
        assert!(!mask_passes(masks[1], query_bit(Side::Upper, true, false)));
        assert!(mask_passes(masks[1], query_bit(Side::Upper, false, false)));
        // Upper only: not for a lower query.
        assert!(!mask_passes(masks[2], query_bit(Side::Lower, true, false)));
        assert!(mask_passes(masks[2], query_bit(Side::Other, false, false)));
    }

    #[test]
    fn the_mouth_interior_and_the_outside_see_only_their_own_triangles() {
        let sides = [Side::Other; 4];
        let face = [true; 4];
        // 0 and 1 inside the mouth, 2 and 3 outside.
        let inside = [true, true, false, false];
        let masks = triangle_masks(&sides, &face, &inside, &[[0, 1, 0], [0, 1, 2], [2, 3, 2]]);
        let (q_in, q_out) = (
            query_bit(Side::Other, true, true),
            query_bit(Side::Other, true, false),
        );
        // Wholly inside: only for inside queries.
        assert!(mask_passes(masks[0], q_in) && !mask_passes(masks[0], q_out));
        // Across the border: for both.
        assert!(mask_passes(masks[1], q_in) && mask_passes(masks[1], q_out));
        // Wholly outside: only for outside queries.
        assert!(!mask_passes(masks[2], q_in) && mask_passes(masks[2], q_out));
        // A face without an interior: every triangle is outside.
        let none = triangle_masks(&sides, &face, &[], &[[0, 1, 2]]);
        assert!(!mask_passes(none[0], q_in) && mask_passes(none[0], q_out));
    }
}
