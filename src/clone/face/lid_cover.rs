//! The `lid_cover` step (module docs of [`super`], with [`CloneOptions::lid_cover`]): where
//! the source's blink closes its eye, the target's closed lids cover its eye from the front
//! (issue 21 §1) — by default only where the source's own closed lids do ("When" below).
//!
//! `lid_close` and `lid_seam` make the target's margins meet, but only in height: the lids
//! move as the source's FAT moves its own. Alma's closed lids lie behind her protruding
//! eyes, so on ICT's real head they came down straight behind its cornea: at alma's closing
//! value 512 the cornea lay 0.0008 (0.06 eye-white radii) in front of where the lids meet,
//! and 69 / 70 eye vertices per eye were seen from the front through the closed lids (ICT's
//! own blink: none).
//!
//! It runs after `eyeball` and `smooth`'s second pass: `smooth` took back the closing of a
//! single margin vertex (a spike to it), which reopened the slit over the eye (one eye
//! vertex seen per eye); `bound`, last, holds the margins. Per eye with both lid FAPs,
//! whose source blink closes (as `lid_close` finds its closing value `v`, in both tables'
//! first interval, borders `b_t`, `b_b`), and with an eyeball part on the target:
//!
//! 1. The eye's front `H(x, y)`: the largest z of the eyeball part's triangles over `(x, y)`
//!    (the cornea where it bulges), seen along the face's z (towards the viewer).
//! 2. The slit where it is left open over the eye: the margins posed at `v`, per margin
//!    vertex over the eye (`H` defined there) the gap `g` to the other margin at its place
//!    along the corner line; where `g > 0` its height changes by its FAP's share of
//!    `g + `[`OVERLAP`] IRISD0 (`s` of the source's closing for the upper lid, `1 − s` for
//!    the lower, as `lid_close` shares it), spread along the margin as a Wendland bump over
//!    [`ALONG`] of the corner line (each vertex at least its own), through its lid's FAP at
//!    its border (`× b / v`), and into the lid by `lid_close`'s bump, no vertex closing past
//!    its lid point.
//!    Where the lids already meet or cross nothing changes.
//! 3. The lid vertices: skin within [`NEAR`] eye-white radii `r` of the eyeball's centre `c`
//!    that rest in front of the eye (`z ≥ H − `[`BEHIND`]` r`; outside the eye's outline:
//!    in front of its centre), the upper lid's (its margin row and whatever lies above the
//!    corner line) and the lower lid's; the corners (on both rows) are kept.
//! 4. At `x = v` and then at `x = far = min(b_t, b_b)` (the FAT's full closing), posed with
//!    both lid FAPs at `x`, a lid vertex `p` whose eye front lies in front of it
//!    (`p.z < H(p.x, p.y)`: the eye is seen through the lid there) needs to come forward by
//!    `need = H + `[`CLEAR`]` r − p.z`. A vertex in front of the eye needs nothing.
//! 5. Each lid vertex `k` comes forward by `max_j need_j · bump(|k − j| / (`[`SPREAD`]` r))`
//!    over the needing vertices `j` of its own lid (rest places; `lid_close`'s Wendland
//!    bump: each vertex at least its own need, the push smooth into the lid), at most
//!    [`MAX_PUSH`] `r`, straight forward (+z: in front of the cornea, where the lids close,
//!    the eyeball's normal; its level turn towards the corners shifted the margins sideways
//!    and made the lids cross 0.03 IRISD0 deeper at alma's closing value): no height
//!    changes, so step 2's closed line stays closed and the lid points keep their FAPs'
//!    vertical motion.
//! 6. The push is added to the top FAP's motion at its first border (upper lid) or the
//!    bottom FAP's (lower lid), times `b / x`: the FAT interpolates its first interval
//!    linearly, so at values short of closing (the eye open) the lids move only by that
//!    interpolation, and at `far` step 4 measures what is still missing once `v`'s push is
//!    in.
//!
//! A clone whose closed lids meet over the eye and lie in front of it (a self-clone of a
//! source whose own blink covers its eye) is not changed. The cover is full (no eye vertex
//! seen), not down to the source's share: which part of the eye to leave showing has no
//! answer in the source's.
//!
//! Measured, alma → ICT (per eye, at alma's closing value 512; ICT's own blink at its own
//! closing value in brackets): eye vertices seen through the closed lids 69 / 70 → 0 (0),
//! gaps along the closed line −0.041…0.060 → −0.041…0.021 IRISD0 (−0.177…0.032),
//! roughness 0.172 → 0.117 (0.083), at 1024 0.345 → 0.234 (0.172); `close_t` at 512 turns
//! 101° → 119° (ICT's own 97°); the blink's depth into the eye white 0.161 → 0.163 radii
//! (0.109); about 5 ms.
//!
//! # When
//!
//! [`CloneOptions::lid_cover`]: `On` covers every eye the source's blink closes (self-clones
//! of a cartoon whose own blink leaves its eye showing change: alma → alma's lid FAPs 4.6 % /
//! 3.7 % off the truth), `Off` never runs the step, and `Auto`, the default, covers an eye
//! only where what the clone's closed lids leave of it differs from what the source's own
//! closed lids leave of the source's. Measured per eye, on the source at its closing value
//! `v` (its skin posed with both lid FAPs at `v`) and on the clone before the step, on a
//! 40 × 40 grid over the eye's box: of the places where the eye's front `H` shows with the
//! lids open (no skin in front of it at rest), the **share** still seen closed, and how far
//! the eye stands out there in front of the closed lids (**depth**: the median of `H` less
//! the skin's front, in half widths of the eye). A one-mesh source's eyeballs (pieces of its
//! skin) are found as [`super::split_embedded_parts`] finds them; a source without an eyeball
//! shows none. `Auto` covers where
//!
//! - the clone's share exceeds the source's by more than [`MARGIN`] (0.1): it shows more of
//!   its eye than the source's closed lids show (candide, no eyeball, → ICT: 18 %), or
//! - the clone's eye shows but stands out less than [`DEPTH`] (half) as far as the source's:
//!   a sliver left by lids that nearly cover it, where the source's whole eye stands out past
//!   its closed lids — the source's style, which the target's geometry does not carry
//!   (alma → ICT: 20 % standing out 0.033 against alma's own 58 % standing out 0.137;
//!   bruno → ICT 16 %, 0.029 against 47 %, 0.097).
//!
//! A self-clone sees the same on both sides and is kept exactly (alma 58 %, 0.137; bruno
//! 47 %, 0.097); alma → bruno (46 %, 0.084: 0.61 of alma's depth) and bruno → alma (55 %,
//! 0.127: +0.075 share) are kept too, as each cartoon's own blink leaves its eye showing.
//! The thresholds lie between those: the share margin above the cartoon pairs' +0.075, the
//! depth ratio between the cartoons' smallest 0.61 and the real head's largest 0.30. A
//! share of eye *vertices* seen (the first rule tried) cannot tell: alma's blink shows 59 of
//! her 338 (17 %), ICT's cornea under it 69 of its 1570 (4 %), and as a share of what the
//! open eye shows ICT's is still the smaller (20 % against 58 %) — alma's eye stands out as
//! a whole past her closed lids, only ICT's cornea past its. The report says per eye what
//! was measured and done ([`CloneReport::lid_cover`]).
//!
//! [`CloneOptions::lid_cover`]: super::CloneOptions::lid_cover
//! [`CloneReport::lid_cover`]: super::CloneReport::lid_cover

use std::collections::{BTreeMap, HashSet};

use glam::Vec3;

use super::align::Similarity;
use super::lid_close::{
    along, eye_closings, first_motion, height, posed, spread, store_changed, RowSets, REACH,
};
use super::lid_margin::LidMargins;
use super::options::LidCover;
use super::parts::{FaceParts, Part};
use super::report::LidCoverEye;
use super::rescale::bump;
use super::skin_surface::SkinSurface;
use super::smooth::dense_field;
use crate::clone::{CloneSurface, SurfaceMotion};
use crate::face::FaceModel;
use crate::fat::Fat;

/// Skin within this many eye-white radii of an eyeball's centre may be a lid covering it.
pub(super) const NEAR: f32 = 1.6;

/// How far (eye-white radii) in front of the eye a lid that was seen through ends.
pub(super) const CLEAR: f32 = 0.02;

/// A vertex resting further than this (eye-white radii) behind the eye's front is no lid
/// (the socket behind the eyeball), and is neither measured nor moved.
pub(super) const BEHIND: f32 = 0.02;

/// How far (eye-white radii) each vertex's push spreads into its lid.
pub(super) const SPREAD: f32 = 0.5;

/// Longest push, in eye-white radii.
pub(super) const MAX_PUSH: f32 = 0.5;

/// How far (IRISD0) the margins of a slit left open over the eye come to overlap.
pub(super) const OVERLAP: f32 = 0.02;

/// How far (of the corner line, outer corner 0 to inner 1) a margin vertex's closing
/// spreads along its margin.
pub(super) const ALONG: f32 = 0.06;

/// Grid cells per side of an eye front's lookup.
const CELLS: usize = 24;

/// [`LidCover::Auto`] covers an eye when the share of it seen through the clone's closed
/// lids exceeds the source's own share by more than this (module docs, "When").
pub(super) const MARGIN: f32 = 0.1;

/// [`LidCover::Auto`] covers an eye that stands out in front of the clone's closed lids by
/// less than this share of how far the source's stands out in front of its own.
pub(super) const DEPTH: f32 = 0.5;

/// Samples per side of the grid over an eye's front that measures the share seen.
const SAMPLES: usize = 40;

/// An eyeball part's front as the viewer sees it (step 1): its triangles binned on a grid
/// over their x, y box.
pub(super) struct EyeFront {
    left: bool,
    tris: Vec<[Vec3; 3]>,
    lo: Vec3,
    cell: (f32, f32),
    bins: Vec<Vec<u32>>,
}

impl EyeFront {
    /// The front of eye `left` from triangles `tris` (the surface's frame); `None` without
    /// any.
    pub(super) fn new(left: bool, tris: Vec<[Vec3; 3]>) -> Option<EyeFront> {
        let (lo, hi) = tris
            .iter()
            .flatten()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        if !(lo.is_finite() && hi.is_finite()) || hi.x <= lo.x || hi.y <= lo.y {
            return None;
        }
        let cell = ((hi.x - lo.x) / CELLS as f32, (hi.y - lo.y) / CELLS as f32);
        let mut bins = vec![Vec::new(); CELLS * CELLS];
        let index = |v: f32, lo: f32, size: f32| (((v - lo) / size) as usize).min(CELLS - 1);
        for (k, t) in tris.iter().enumerate() {
            let (tl, th) = t
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
                    (a.min(*p), b.max(*p))
                });
            for i in index(tl.x, lo.x, cell.0)..=index(th.x, lo.x, cell.0) {
                for j in index(tl.y, lo.y, cell.1)..=index(th.y, lo.y, cell.1) {
                    bins[j * CELLS + i].push(k as u32);
                }
            }
        }
        Some(EyeFront {
            left,
            tris,
            lo,
            cell,
            bins,
        })
    }

    /// The fronts of `face`'s eyeball parts (`parts`' eye meshes put in the surface's frame
    /// by `frame`, as [`LidMargins::with_eyeballs`] puts them).
    pub(super) fn of(face: &FaceModel, parts: &FaceParts, frame: &Similarity) -> Vec<EyeFront> {
        let frames = face.frames();
        [(Part::LeftEye, true), (Part::RightEye, false)]
            .into_iter()
            .filter_map(|(part, left)| {
                let mut tris = Vec::new();
                for &mi in parts.parts.get(&part).into_iter().flatten() {
                    let pos: Vec<Vec3> = face
                        .mesh_world(&frames, mi)
                        .into_iter()
                        .map(|p| frame.point(p))
                        .collect();
                    for poly in face.meshes[mi].mesh.polygons.iter() {
                        for k in 1..poly.len().saturating_sub(1) {
                            let t = [poly[0], poly[k], poly[k + 1]];
                            if let Some(q) = t
                                .iter()
                                .map(|&v| pos.get(v as usize).copied())
                                .collect::<Option<Vec<Vec3>>>()
                            {
                                tris.push([q[0], q[1], q[2]]);
                            }
                        }
                    }
                }
                EyeFront::new(left, tris)
            })
            .collect()
    }

    /// The corners (low x, y; high x, y) of the box its lookup covers.
    fn bounds(&self) -> ((f32, f32), (f32, f32)) {
        let n = CELLS as f32;
        (
            (self.lo.x, self.lo.y),
            (self.lo.x + n * self.cell.0, self.lo.y + n * self.cell.1),
        )
    }

    /// The front of the triangles of `surf` (its vertices at `positions`) over this eye's
    /// box, but those wholly of `skip`'s vertices (an eyeball in the surface): the skin the
    /// eye is seen through.
    fn skin_over(
        &self,
        surf: &CloneSurface,
        positions: &[Vec3],
        skip: &HashSet<u32>,
    ) -> Option<EyeFront> {
        let ((x0, y0), (x1, y1)) = self.bounds();
        let tris = surf
            .triangles
            .iter()
            .filter(|t| skip.is_empty() || !t.iter().all(|v| skip.contains(v)))
            .map(|t| t.map(|v| positions[v as usize]))
            .filter(|q| {
                !(q.iter().all(|p| p.x < x0)
                    || q.iter().all(|p| p.x > x1)
                    || q.iter().all(|p| p.y < y0)
                    || q.iter().all(|p| p.y > y1))
            })
            .collect();
        EyeFront::new(self.left, tris)
    }

    /// `H(x, y)`: the largest z of the eye's triangles over `(x, y)`, if any lies there.
    pub(super) fn height(&self, x: f32, y: f32) -> Option<f32> {
        let (i, j) = ((x - self.lo.x) / self.cell.0, (y - self.lo.y) / self.cell.1);
        if !(0.0..=CELLS as f32).contains(&i) || !(0.0..=CELLS as f32).contains(&j) {
            return None;
        }
        let (i, j) = ((i as usize).min(CELLS - 1), (j as usize).min(CELLS - 1));
        let mut best: Option<f32> = None;
        for &k in &self.bins[j * CELLS + i] {
            let [a, b, c] = self.tris[k as usize];
            let d = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if d == 0.0 {
                continue;
            }
            let u = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / d;
            let w = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / d;
            if u < 0.0 || w < 0.0 || u + w > 1.0 {
                continue;
            }
            let z = a.z + u * (b.z - a.z) + w * (c.z - a.z);
            best = Some(best.map_or(z, |h: f32| h.max(z)));
        }
        best
    }
}

/// One lid vertex of an eye (step 2): the vertex, whether on the upper lid, and its rest
/// place.
#[derive(Clone, Copy, Debug)]
struct LidVertex {
    v: u32,
    upper: bool,
    rest: Vec3,
}

/// Step 2: the lid vertices of the eye with centre `c`, radius `r` and front `front` on
/// `surf`; `rows` the upper and lower margin rows, `corners` the eye's corners.
fn lid_vertices(
    surf: &CloneSurface,
    (c, r): (Vec3, f32),
    front: &EyeFront,
    rows: [&HashSet<u32>; 2],
    corners: (Vec3, Vec3),
) -> Vec<LidVertex> {
    let (o, i) = corners;
    let side = |p: Vec3| {
        let t = along(corners, p).clamp(0.0, 1.0);
        p.y - (o.y + t * (i.y - o.y))
    };
    surf.positions
        .iter()
        .enumerate()
        .filter_map(|(v, &p)| {
            let v32 = v as u32;
            let (on_up, on_low) = (rows[0].contains(&v32), rows[1].contains(&v32));
            if p.distance(c) > NEAR * r || (on_up && on_low) {
                return None;
            }
            let in_front = match front.height(p.x, p.y) {
                Some(h) => p.z >= h - BEHIND * r,
                None => p.z > c.z,
            };
            in_front.then_some(LidVertex {
                v: v32,
                upper: on_up || (!on_low && side(p) > 0.0),
                rest: p,
            })
        })
        .collect()
}

/// Steps 4–6 for one eye, pushing along `forward` (the target's own front, +z but for a
/// turned alignment): the lid vertices `lids` of the eye with eye-white radius `r` and
/// front `front`, the top and bottom FAPs' first-border fields `fields` (dense, changed in
/// place) with their borders `borders`, at the values `values` (closing, then full). Returns
/// how many vertices of each field changed.
fn cover(
    forward: Vec3,
    r: f32,
    front: &EyeFront,
    lids: &[LidVertex],
    fields: [&mut Vec<Vec3>; 2],
    borders: [f64; 2],
    values: &[f64],
) -> [usize; 2] {
    let [dt, db] = fields;
    let mut changed = [HashSet::new(), HashSet::new()];
    for &x in values {
        let (st, sb) = ((x / borders[0]) as f32, (x / borders[1]) as f32);
        let posed = |l: &LidVertex, dt: &[Vec3], db: &[Vec3]| {
            l.rest + st * dt[l.v as usize] + sb * db[l.v as usize]
        };
        // Step 4: what each lid vertex seen through needs.
        let needs: Vec<(usize, f32)> = lids
            .iter()
            .enumerate()
            .filter_map(|(k, l)| {
                let p = posed(l, dt, db);
                let h = front.height(p.x, p.y)?;
                (p.z < h).then_some((k, h + CLEAR * r - p.z))
            })
            .collect();
        if needs.is_empty() {
            continue;
        }
        // Step 5: spread over each lid, straight forward; step 6: through the lid's FAP at
        // its border.
        let reach = SPREAD * r;
        let pushes: Vec<(usize, Vec3)> = lids
            .iter()
            .enumerate()
            .filter_map(|(k, l)| {
                let amount = needs
                    .iter()
                    .filter(|&&(j, _)| lids[j].upper == l.upper)
                    .map(|&(j, need)| need * bump(lids[j].rest.distance(l.rest) / reach))
                    .fold(0.0f32, f32::max)
                    .min(MAX_PUSH * r);
                if amount <= 0.0 {
                    return None;
                }
                let scale = if l.upper { 1.0 / st } else { 1.0 / sb };
                Some((k, forward * (amount * scale)))
            })
            .collect();
        for (k, d) in pushes {
            let l = &lids[k];
            let (field, set) = if l.upper {
                (&mut *dt, &mut changed[0])
            } else {
                (&mut *db, &mut changed[1])
            };
            if d.is_finite() {
                field[l.v as usize] += d;
                set.insert(l.v);
            }
        }
    }
    changed.map(|s| s.len())
}

/// Per vertex of a posed margin `own` (place, height), the change of its height that closes
/// the slit where it is left open over the eye (`over`), to [`OVERLAP`] IRISD0 (`irisd`)
/// past the other margin `other`: its share of the closing (`top_share` for the upper lid,
/// the rest for the lower), nothing where the lids meet or cross.
fn closing(
    own: &[(f32, f32)],
    other: &[(f32, f32)],
    over: &[bool],
    is_upper: bool,
    top_share: f32,
    irisd: f32,
) -> Vec<f32> {
    let share = if is_upper { top_share } else { 1.0 - top_share };
    let need: Vec<(f32, f32)> = own
        .iter()
        .zip(over)
        .filter_map(|(&(t, y), &over)| {
            let o = height(other, t).filter(|_| over)?;
            let gap = if is_upper { y - o } else { o - y };
            (gap > 0.0).then_some((t, share * (gap + OVERLAP * irisd)))
        })
        .collect();
    // Each vertex at least its own closing, its neighbours along the slit a bump of it: a
    // single vertex closing alone creased the lid (alma → ICT's `close_t` at 512 turned
    // 139° against 101° without the step, 113° with the spread).
    own.iter()
        .map(|&(t, _)| {
            let close = need
                .iter()
                .map(|&(tj, c)| c * bump((t - tj).abs() / ALONG))
                .fold(0.0f32, f32::max);
            if is_upper {
                -close
            } else {
                close
            }
        })
        .collect()
}

/// One face's eyes as the rule measures them (module docs, "When"): their fronts, and the
/// surface vertices that are eyeballs (a one-mesh head's, which its skin surface holds),
/// which are no skin.
pub(super) struct Eyes {
    fronts: Vec<EyeFront>,
    balls: HashSet<u32>,
}

impl Eyes {
    /// The eyes of `face` with parts `parts` and skin surface `surf` (in its own frame): its
    /// eyeball parts, or, when it has none, the eyeballs its one skin mesh holds as pieces
    /// (found as [`super::split_embedded_parts`] finds them on the face without its FAT).
    pub(super) fn of(face: &FaceModel, parts: &FaceParts, surf: &SkinSurface) -> Eyes {
        let fronts = EyeFront::of(face, parts, &Similarity::IDENTITY);
        if !fronts.is_empty() {
            return Eyes {
                fronts,
                balls: HashSet::new(),
            };
        }
        let mut bare = face.clone();
        bare.fat = Fat::default();
        let Some(view) = super::split::split_view(&bare) else {
            return Eyes {
                fronts,
                balls: HashSet::new(),
            };
        };
        let mut balls = HashSet::new();
        let mut fronts = Vec::new();
        for (part, left) in [(Part::LeftEye, true), (Part::RightEye, false)] {
            let mut own = HashSet::new();
            for s in view.parts.iter().filter(|s| s.part == part) {
                let Some(k) = face
                    .mesh_index(&s.from)
                    .and_then(|mi| surf.meshes.iter().position(|&m| m == mi))
                else {
                    continue;
                };
                own.extend(
                    s.source_vertices
                        .iter()
                        .filter_map(|&v| surf.welded.get(surf.starts[k] + v as usize).copied()),
                );
            }
            let pos = &surf.surface.positions;
            let tris = surf
                .surface
                .triangles
                .iter()
                .filter(|t| t.iter().all(|v| own.contains(v)))
                .map(|t| t.map(|v| pos[v as usize]))
                .collect();
            fronts.extend(EyeFront::new(left, tris));
            balls.extend(own);
        }
        Eyes { fronts, balls }
    }

    /// The front of eye `left`, if known.
    fn front(&self, left: bool) -> Option<&EyeFront> {
        self.fronts.iter().find(|f| f.left == left)
    }
}

/// What of an eye shows through closed lids (module docs, "When").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Seen {
    /// The share (0–1) of what the open eye shows from the front.
    pub(super) share: f32,
    /// How far it stands out in front of the closed lids: the median over the places seen
    /// (with skin behind them) of the eye's front less the skin's, in half widths of the eye.
    pub(super) depth: f32,
}

/// What of the eye `front` shows from the front with the skin at rest (`rest`, its front
/// over the eye) and still shows with it posed (`posed`), sampled on a grid over the eye's
/// box: the eye is seen at `(x, y)` where no skin lies in front of `H`. Nothing when nothing
/// of it shows at rest.
fn seen_share(front: &EyeFront, rest: Option<&EyeFront>, posed: Option<&EyeFront>) -> Seen {
    let ((x0, y0), (x1, y1)) = front.bounds();
    let half = 0.5 * (x1 - x0);
    let (mut open, mut seen) = (0usize, 0usize);
    let mut depths = Vec::new();
    for i in 0..SAMPLES {
        for j in 0..SAMPLES {
            let x = x0 + (i as f32 + 0.5) / SAMPLES as f32 * (x1 - x0);
            let y = y0 + (j as f32 + 0.5) / SAMPLES as f32 * (y1 - y0);
            let Some(h) = front.height(x, y) else {
                continue;
            };
            let skin = |s: Option<&EyeFront>| s.and_then(|s| s.height(x, y));
            if skin(rest).is_some_and(|z| z > h) {
                continue;
            }
            open += 1;
            match skin(posed) {
                Some(z) if z > h => {}
                z => {
                    seen += 1;
                    depths.extend(z.map(|z| (h - z) / half));
                }
            }
        }
    }
    if open == 0 {
        return Seen::default();
    }
    depths.sort_by(f32::total_cmp);
    Seen {
        share: seen as f32 / open as f32,
        depth: depths.get(depths.len() / 2).copied().unwrap_or(0.0),
    }
}

/// What of eye `front` shows through `surf`'s closed lids (`seen_share`): the surface posed
/// by `fields` (dense offsets, each times its factor), `skip` its eyeball vertices.
fn seen_on(
    surf: &CloneSurface,
    front: &EyeFront,
    fields: [(&[Vec3], f32); 2],
    skip: &HashSet<u32>,
) -> Seen {
    let posed: Vec<Vec3> = surf
        .positions
        .iter()
        .enumerate()
        .map(|(v, &p)| p + fields.iter().map(|(d, s)| *s * d[v]).sum::<Vec3>())
        .collect();
    let rest = front.skin_over(surf, &surf.positions, skip);
    let closed = front.skin_over(surf, &posed, skip);
    seen_share(front, rest.as_ref(), closed.as_ref())
}

/// Whether the step covers an eye under `mode`, with what shows through the source's own
/// closed lids (`None`: the source has no eyeball there, nothing of one shows) and through
/// the clone's, and why (module docs, "When").
pub(super) fn decide(mode: LidCover, source: Option<Seen>, target: Seen) -> (bool, String) {
    let s = source.unwrap_or_default();
    match mode {
        LidCover::Off => (false, "lid_cover off".into()),
        LidCover::On => (true, "lid_cover on".into()),
        LidCover::Auto if target.share > s.share + MARGIN => (
            true,
            format!(
                "it shows over {:.0} % more than the source's",
                100.0 * MARGIN
            ),
        ),
        LidCover::Auto if target.share > 0.0 && target.depth < DEPTH * s.depth => (
            true,
            "it stands out less than half as far as the source's: a sliver".into(),
        ),
        LidCover::Auto => (false, "it shows as the source's does".into()),
    }
}

/// The step on every eye (module docs) under `mode` (not [`LidCover::Off`]): `motions` are
/// the source's (on `ssurf`, the skin of `face` with parts `parts`), `out` the cloned ones
/// (same order), `margins` the target's (with its eyeballs) and the source's, `fronts` the
/// target's eye fronts ([`EyeFront::of`]), `forward` the target's own front in the surface's
/// frame (the lids come forward along it: along the frame's +z a turned target's lid points
/// also moved along their FAPs, bruno → ict's 3.3 by 2.0 % at 3.15°). Returns what it
/// measured and did per eye.
#[allow(clippy::too_many_arguments)]
pub(super) fn cover_lids(
    mode: LidCover,
    forward: Vec3,
    (face, parts, ssurf): (&FaceModel, &FaceParts, &SkinSurface),
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    margins: [&LidMargins; 2],
    fronts: &[EyeFront],
    out: &mut [SurfaceMotion],
) -> Vec<LidCoverEye> {
    let source = &ssurf.surface;
    // The source's eyes, once an eye needs them (a one-mesh source's are cut out for it).
    let source_eyes = std::cell::OnceCell::new();
    let mut done = BTreeMap::new();
    let mut report = Vec::new();
    let [tm, sm] = margins;
    let n = target.positions.len();
    for (eye, c) in eye_closings(source, motions, sm, tm, out) {
        let (left, top, bottom, ..) = eye;
        let Some(front) = fronts.iter().find(|f| f.left == left) else {
            continue;
        };
        let Some(&(_, ball)) = tm.balls().iter().find(|b| b.0 == left) else {
            continue;
        };
        let (sc, (kt, vt), (kb, vb)) = (c.source, c.top, c.bottom);
        let (corners, upper, lower) = (c.corners, c.upper, c.lower);
        let rows: [HashSet<u32>; 2] = [upper.1, lower.1].map(|r| r.iter().copied().collect());
        let sphere = ball.sphere();
        let lids = lid_vertices(target, sphere, front, [&rows[0], &rows[1]], corners);
        if lids.is_empty() {
            continue;
        }
        let mut dt = dense_field(n, &out[kt].offsets);
        let mut db = dense_field(n, &out[kb].offsets);
        let (up, low) = (eye.3, eye.4);
        let (st, sb) = ((sc.value / vt) as f32, (sc.value / vb) as f32);
        // When: the share of each eye seen through the closed lids, the source's own and the
        // clone's as it stands.
        let source_eyes = source_eyes.get_or_init(|| Eyes::of(face, parts, ssurf));
        let source_seen = source_eyes.front(left).and_then(|sf| {
            let (kst, vst) = first_motion(motions, top)?;
            let (ksb, vsb) = first_motion(motions, bottom)?;
            let ns = source.positions.len();
            let (ft, fb) = (
                dense_field(ns, &motions[kst].offsets),
                dense_field(ns, &motions[ksb].offsets),
            );
            let shares = [(sc.value / vst) as f32, (sc.value / vsb) as f32];
            let fields = [(ft.as_slice(), shares[0]), (fb.as_slice(), shares[1])];
            Some(seen_on(source, sf, fields, &source_eyes.balls))
        });
        let fields = [(dt.as_slice(), st), (db.as_slice(), sb)];
        let target_seen = seen_on(target, front, fields, &HashSet::new());
        let (covered, reason) = decide(mode, source_seen, target_seen);
        report.push(LidCoverEye {
            eye: if left { "left" } else { "right" },
            source_seen: source_seen.map(|s| [s.share, s.depth].map(f64::from)),
            target_seen: [target_seen.share, target_seen.depth].map(f64::from),
            covered,
            reason,
        });
        if !covered {
            continue;
        }
        let slit = {
            let fields = [(dt.as_slice(), st), (db.as_slice(), sb)];
            let pu = posed(target, upper.1, corners, fields);
            let pl = posed(target, lower.1, corners, fields);
            let over = |verts: &[u32], row: &[(f32, f32)]| -> Vec<bool> {
                verts
                    .iter()
                    .zip(row)
                    .map(|(&v, &(_, y))| {
                        let p = target.positions[v as usize];
                        let x = p.x + st * dt[v as usize].x + sb * db[v as usize].x;
                        front.height(x, y).is_some()
                    })
                    .collect()
            };
            let irisd = target.fapu.distances.irisd0 as f32;
            [
                closing(&pu, &pl, &over(upper.1, &pu), true, sc.top_share, irisd),
                closing(&pl, &pu, &over(lower.1, &pl), false, sc.top_share, irisd),
            ]
        };
        let sets = RowSets::of(target, upper.1, lower.1, [up, low]);
        let reach = REACH * tm.es();
        let mut counts = [0usize; 2];
        for (k, (line, _)) in [upper, lower].into_iter().enumerate() {
            let (is_upper, share) = (k == 0, if k == 0 { st } else { sb });
            let ch: Vec<f32> = slit[k].iter().map(|c| c / share).collect();
            if share <= 0.0 || ch.iter().all(|c| *c == 0.0) || !ch.iter().all(|c| c.is_finite()) {
                continue;
            }
            let row = sets.row(line, corners, [up, low], is_upper);
            let field = if is_upper { &mut dt } else { &mut db };
            counts[k] = spread(target, row, &ch, reach, field);
        }
        let far = vt.min(vb);
        let values: Vec<f64> = if far > sc.value {
            vec![sc.value, far]
        } else {
            vec![sc.value]
        };
        let [ct, cb] = cover(
            forward,
            sphere.1,
            front,
            &lids,
            [&mut dt, &mut db],
            [vt, vb],
            &values,
        );
        store_changed(out, kt, &dt, ct.max(counts[0]), &mut done);
        store_changed(out, kb, &db, cb.max(counts[1]), &mut done);
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit eye at the origin whose front is a flat-topped bulge (a cornea) reaching
    /// z = 1.2 over |x|, |y| ≤ 0.5, and z = 1 elsewhere within |x|, |y| ≤ 1.
    fn front() -> EyeFront {
        let quad = |x0: f32, x1: f32, y0: f32, y1: f32, z: f32| {
            let (a, b, c, d) = (
                Vec3::new(x0, y0, z),
                Vec3::new(x1, y0, z),
                Vec3::new(x1, y1, z),
                Vec3::new(x0, y1, z),
            );
            [[a, b, c], [a, c, d]]
        };
        let mut tris = Vec::new();
        tris.extend(quad(-1.0, 1.0, -1.0, 1.0, 1.0));
        tris.extend(quad(-0.5, 0.5, -0.5, 0.5, 1.2));
        EyeFront::new(true, tris).unwrap()
    }

    /// An upper lid of five vertices resting above the cornea in front of the eye (z 1.1),
    /// and a lower lid of three below it.
    fn lids() -> Vec<LidVertex> {
        let mut out: Vec<LidVertex> = (0..5)
            .map(|k| LidVertex {
                v: k,
                upper: true,
                rest: Vec3::new(-0.4 + 0.2 * k as f32, 0.7, 1.1),
            })
            .collect();
        out.extend((0..3).map(|k| LidVertex {
            v: 5 + k,
            upper: false,
            rest: Vec3::new(-0.2 + 0.2 * k as f32, -0.7, 1.1),
        }));
        out
    }

    /// Two triangles: the square `x0..x1` × `y0..y1` at height `z`.
    fn square(x0: f32, x1: f32, y0: f32, y1: f32, z: f32) -> Vec<[Vec3; 3]> {
        let (a, b, c, d) = (
            Vec3::new(x0, y0, z),
            Vec3::new(x1, y0, z),
            Vec3::new(x1, y1, z),
            Vec3::new(x0, y1, z),
        );
        vec![[a, b, c], [a, c, d]]
    }

    #[test]
    fn auto_covers_only_an_eye_showing_otherwise_than_the_sources() {
        let seen = |share, depth| Seen { share, depth };
        let auto = |s: Option<Seen>, t: Seen| decide(LidCover::Auto, s, t).0;
        // Equal (a self-clone, whatever the source's blink leaves showing): kept.
        for (share, depth) in [(0.0, 0.0), (0.17, 0.05), (0.58, 0.137), (1.0, 0.3)] {
            assert!(
                !auto(Some(seen(share, depth)), seen(share, depth)),
                "{share}"
            );
        }
        // More of it: covered past the margin, kept within it; less of it standing out as
        // far: kept.
        assert!(auto(Some(seen(0.2, 0.1)), seen(0.2 + 1.1 * MARGIN, 0.1)));
        assert!(!auto(Some(seen(0.2, 0.1)), seen(0.2 + 0.9 * MARGIN, 0.1)));
        assert!(!auto(Some(seen(0.5, 0.1)), seen(0.3, 0.08)));
        // A sliver (alma → ICT: 20 % of the eye, standing out 0.03 where alma's 58 % stands
        // out 0.14): covered; as far out but for less than half: kept.
        assert!(auto(Some(seen(0.58, 0.137)), seen(0.2, 0.033)));
        assert!(!auto(Some(seen(0.58, 0.137)), seen(0.46, 0.084)));
        // Nothing showing: nothing to cover.
        assert!(!auto(Some(seen(0.58, 0.137)), seen(0.0, 0.0)));
        // A source without an eyeball shows none of it.
        assert!(auto(None, seen(0.18, 0.03)));
        assert!(!auto(None, seen(0.5 * MARGIN, 0.03)));
        // `on` and `off` whatever is seen.
        assert!(decide(LidCover::On, Some(seen(0.5, 0.1)), seen(0.0, 0.0)).0);
        assert!(!decide(LidCover::Off, None, seen(1.0, 1.0)).0);
    }

    #[test]
    fn the_share_seen_is_of_what_the_open_eye_shows() {
        let eye = EyeFront::new(true, square(-1.0, 1.0, -1.0, 1.0, 1.0)).unwrap();
        // At rest the skin hides the eye's top quarter (y > 0.5), closed everything above
        // y = 0, and behind the eye below it (0.4 half widths, the eye's half width 1): two
        // thirds of what showed still show, standing out 0.4.
        let rest = EyeFront::new(true, square(-1.0, 1.0, 0.5, 1.0, 2.0)).unwrap();
        let mut tris = square(-1.0, 1.0, 0.0, 1.0, 2.0);
        tris.extend(square(-1.0, 1.0, -1.0, 0.0, 0.6));
        let closed = EyeFront::new(true, tris).unwrap();
        let seen = seen_share(&eye, Some(&rest), Some(&closed));
        assert!((seen.share - 2.0 / 3.0).abs() < 1e-6, "{seen:?}");
        assert!((seen.depth - 0.4).abs() < 1e-5, "{seen:?}");
        // Skin behind the eye hides nothing; no skin at all neither (no depth then).
        let behind = EyeFront::new(true, square(-1.0, 1.0, -1.0, 1.0, 0.5)).unwrap();
        assert_eq!(seen_share(&eye, Some(&behind), Some(&behind)).share, 1.0);
        assert_eq!(
            seen_share(&eye, None, None),
            Seen {
                share: 1.0,
                depth: 0.0
            }
        );
        // Closed over the whole eye: nothing; an eye hidden at rest: nothing, not 0 / 0.
        let all = EyeFront::new(true, square(-1.5, 1.5, -1.5, 1.5, 2.0)).unwrap();
        assert_eq!(seen_share(&eye, Some(&rest), Some(&all)), Seen::default());
        assert_eq!(seen_share(&eye, Some(&all), Some(&all)), Seen::default());
    }

    #[test]
    fn the_front_is_the_eyes_largest_z() {
        let f = front();
        assert_eq!(f.height(0.0, 0.0), Some(1.2));
        assert_eq!(f.height(0.8, 0.0), Some(1.0));
        assert_eq!(f.height(2.0, 0.0), None);
    }

    #[test]
    fn lids_closing_behind_a_protruding_eye_come_in_front() {
        let f = front();
        let lids = lids();
        // At its border (1024) the upper lid comes down by 1.4, the lower up by 0.6, both
        // straight: at 512 the upper margin is at y 0 and the lower at −0.4, both over the
        // cornea (1.2) at z 1.1.
        let mut dt = vec![Vec3::ZERO; 8];
        let mut db = vec![Vec3::ZERO; 8];
        for l in &lids {
            if l.upper {
                dt[l.v as usize] = Vec3::new(0.0, -1.4, 0.0);
            } else {
                db[l.v as usize] = Vec3::new(0.0, 0.6, 0.0);
            }
        }
        let (t0, b0) = (dt.clone(), db.clone());
        let r = 1.0;
        let changed = cover(
            Vec3::Z,
            r,
            &f,
            &lids,
            [&mut dt, &mut db],
            [1024.0, 1024.0],
            &[512.0, 1024.0],
        );
        assert_eq!(changed, [5, 3]);
        for x in [512.0f32, 1024.0] {
            let s = x / 1024.0;
            for l in &lids {
                let p = l.rest + s * (dt[l.v as usize] + db[l.v as usize]);
                let h = f.height(p.x, p.y).unwrap();
                assert!(p.z >= h + CLEAR * r - 1e-5, "{x}: {l:?} at {p} behind {h}");
            }
        }
        // Nothing moves in height (the closed line is kept), nothing backwards.
        for (a, b) in dt.iter().zip(&t0).chain(db.iter().zip(&b0)) {
            assert_eq!(a.y, b.y);
            assert!(a.z >= b.z);
        }
        // Every push spreads from the needing vertices of its own lid only: the upper lid
        // pushed no lower vertex through the top FAP.
        assert!(dt[5..].iter().all(|d| *d == Vec3::ZERO));
    }

    #[test]
    fn a_slit_open_over_the_eye_closes_and_a_closed_one_is_kept() {
        // Upper margin at heights 0.1 (open by 0.1), 0 (meeting), −0.05 (crossing) over a
        // flat lower one; the top FAP does a quarter of the closing.
        let upper = [(0.2, 0.1), (0.5, 0.0), (0.8, -0.05)];
        let lower = [(0.0, 0.0), (1.0, 0.0)];
        let over = [true; 3];
        let cu = closing(&upper, &lower, &over, true, 0.25, 1.0);
        assert!((cu[0] + 0.25 * (0.1 + OVERLAP)).abs() < 1e-6, "{cu:?}");
        assert_eq!(&cu[1..], &[0.0, 0.0]);
        // The lower lid takes the rest, upwards.
        let low = [(0.2, -0.1)];
        let cl = closing(&low, &[(0.0, 0.0), (1.0, 0.0)], &[true], false, 0.25, 1.0);
        assert!((cl[0] - 0.75 * (0.1 + OVERLAP)).abs() < 1e-6, "{cl:?}");
        // Not over the eye: left open.
        let off = closing(&upper, &lower, &[false; 3], true, 0.25, 1.0);
        assert!(off.iter().all(|c| *c == 0.0));
    }

    #[test]
    fn lids_closing_in_front_of_the_eye_are_kept() {
        let f = front();
        // The same lids resting further forward (z 1.3): closed, they cover the cornea.
        let lids: Vec<LidVertex> = lids()
            .into_iter()
            .map(|l| LidVertex {
                rest: l.rest + Vec3::new(0.0, 0.0, 0.2),
                ..l
            })
            .collect();
        let mut dt = vec![Vec3::new(0.0, -1.4, 0.0); 8];
        let mut db = vec![Vec3::new(0.0, 0.6, 0.0); 8];
        let (t0, b0) = (dt.clone(), db.clone());
        let changed = cover(
            Vec3::Z,
            1.0,
            &f,
            &lids,
            [&mut dt, &mut db],
            [1024.0, 1024.0],
            &[512.0, 1024.0],
        );
        assert_eq!(changed, [0, 0]);
        assert_eq!((dt, db), (t0, b0));
    }
}
