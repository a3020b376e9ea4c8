//! The `lid_close` step (module docs of [`super`]): at the value where the source's blink
//! closes its eye, the target's slit closes band by band as the source's does.
//!
//! The surface method carries a lid's motion vertex by vertex; across styles the margin's
//! drop comes out a plateau with a steep fall at the corners (alma's lid shell onto ICT's
//! lid: 0.10 IRISD0 left open near the outer corner, the lids crossing by 0.18 further in).
//! So, per eye with both lid FAPs (19 and 21, or 20 and 22):
//!
//! 1. The source's closing value `v` is where its lid points (3.1 / 3.3, 3.2 / 3.4) meet
//!    under both FAPs at `v`, within both tables' first interval (else nothing is done), and
//!    the source's gap between its margins at `v` is read along the corner line (in IRISD0).
//! 2. The target's margins posed at `v` give its gap along the same line; the difference from
//!    the source's (in the target's IRISD0) is taken up by the upper margin through the top
//!    FAP and by the lower one through the bottom FAP, in the shares each FAP closes the
//!    source's lid points by, as a vertical change of each margin vertex's motion (the FAPs'
//!    own feature points and the corners keep theirs).
//! 3. The change fades out over the margin's middle ([`LidMargins::middle_weights`]: none at
//!    the lid point, all of it from half way to each corner on). The lid point moves as its
//!    FAP defines, and the lashes over the lid's middle ride the margin beside it: a change
//!    there left alone took them off their lid (alma → ICT's lower lashes 0.14 of the lid
//!    opening past the lid point at 1024).
//! 4. The change grows with the FAP value over the table's first interval, so it is capped
//!    where that would close (or open) the slit at the interval's end further than the
//!    source's own slit is closed there (the source over-closes past `v`; the target by no
//!    more): a change of `v`'s full size doubled at 1024 for alma's `v` = 512.
//! 5. Each change spreads over its lid's side of the corner line, fading out by a Wendland
//!    bump within [`REACH`] ES0 of the margin. `smooth`'s second pass follows (holding the
//!    margins there instead creased ICT's lids cloned onto alma's and bruno's: turn ratios
//!    1.37 → 1.56, 2.03 → 2.75).
//! 6. No vertex is moved by the change further along the closing than its lid point moves
//!    (the point's FAP defines how far the lid closes): ICT's eye blend, lying on the
//!    eyeball under the upper margin half way to the inner corner, went 15 % past the lid
//!    point at alma's closing value (0.567 against 0.492), and the lashes riding the margin
//!    followed that peak 63 %.
//!
//! Measured, alma → ICT at alma's closing value 512 (left eye, per band outer → inner,
//! IRISD0): before 0.01 0.10 −0.18 −0.14 −0.02 0.01 0.00 0.01 −0.08 −0.09 −0.10 0.03, after
//! 0.05 −0.01 −0.05 −0.07 −0.01 0.07 0.00 0.02 −0.01 −0.00 −0.00 0.04 (ICT's own FAT at its
//! closing value 493: −0.11 … 0.02, its lids crossing where alma's just meet).

use std::collections::{BTreeMap, HashSet};

use glam::Vec3;

use super::lid_margin::{nearest_on, LidMargins};
use super::rescale::bump;
use super::smooth::{dense_field, sparse_offsets};
use crate::clone::{CloneSurface, SurfaceMotion};
use crate::fat::TableKey;
use crate::spec::{FapId, FeaturePointId};

/// How far (ES0) a margin's change spreads into its lid.
pub(super) const REACH: f32 = 0.2;

/// One eye: left or not, top and bottom lid FAPs, upper and lower lid points.
pub(super) type Eye = (bool, u8, u8, &'static str, &'static str);

/// The two eyes.
pub(super) const EYES: [Eye; 2] = [(true, 19, 21, "3.1", "3.3"), (false, 20, 22, "3.2", "3.4")];

/// What every lid step starts from for one eye whose source blink closes it: the source's
/// closing, the target's top and bottom lid motions at their first borders (index, border),
/// and the target's corners and margins (upper, lower).
pub(super) struct EyeClosing<'a> {
    pub(super) source: SourceClose,
    pub(super) top: (usize, f64),
    pub(super) bottom: (usize, f64),
    pub(super) corners: (Vec3, Vec3),
    pub(super) upper: (&'a [Vec3], &'a [u32]),
    pub(super) lower: (&'a [Vec3], &'a [u32]),
}

/// [`EyeClosing`] for each of [`EYES`] a step has something to do for: the source's blink
/// closes that eye, both lid FAPs move the target and its margins were found. (Only indices
/// and borders of `out` are kept, which the steps' changes to offsets leave as they are.)
pub(super) fn eye_closings<'a>(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    source_margins: &LidMargins,
    target_margins: &'a LidMargins,
    out: &[SurfaceMotion],
) -> Vec<(Eye, EyeClosing<'a>)> {
    EYES.into_iter()
        .filter_map(|eye| {
            let (left, top, bottom, ..) = eye;
            let c = EyeClosing {
                source: source_close(source, motions, source_margins, eye)?,
                top: first_motion(out, top)?,
                bottom: first_motion(out, bottom)?,
                corners: target_margins.corners(left)?,
                upper: target_margins.lid(left, true)?,
                lower: target_margins.lid(left, false)?,
            };
            Some((eye, c))
        })
        .collect()
}

/// Index of the motion of FAP `fap` at its smallest positive border, with that border.
pub(super) fn first_motion(motions: &[SurfaceMotion], fap: u8) -> Option<(usize, f64)> {
    let key = TableKey::LowLevel(FapId::new(fap)?);
    motions
        .iter()
        .enumerate()
        .filter(|(_, m)| m.key == key && m.value > 0.0)
        .min_by(|a, b| a.1.value.total_cmp(&b.1.value))
        .map(|(k, m)| (k, m.value))
}

/// A motion's offset at vertex `v` (zero if it has none).
fn offset(m: &SurfaceMotion, v: u32) -> Vec3 {
    m.offsets
        .iter()
        .find(|o| o.0 == v)
        .map_or(Vec3::ZERO, |o| o.1)
}

/// A margin posed at the closing value: per vertex, its place along the corner line (0 at
/// the outer corner, 1 at the inner) and its height.
pub(super) fn posed(
    surf: &CloneSurface,
    vertices: &[u32],
    corners: (Vec3, Vec3),
    fields: [(&[Vec3], f32); 2],
) -> Vec<(f32, f32)> {
    vertices
        .iter()
        .map(|&v| {
            let p = surf.positions[v as usize];
            let y = p.y + fields.iter().map(|(d, s)| s * d[v as usize].y).sum::<f32>();
            (along(corners, p), y)
        })
        .collect()
}

/// Place of `p` along the corner line (0 outer, 1 inner), by x.
pub(super) fn along((o, i): (Vec3, Vec3), p: Vec3) -> f32 {
    if (i.x - o.x).abs() > 0.0 {
        (p.x - o.x) / (i.x - o.x)
    } else {
        0.5
    }
}

/// Height of a posed margin at place `t` (linear between its vertices, the nearest end
/// outside them).
pub(super) fn height(line: &[(f32, f32)], t: f32) -> Option<f32> {
    for w in line.windows(2) {
        let ((t0, y0), (t1, y1)) = (w[0], w[1]);
        if (t0 <= t && t <= t1) || (t1 <= t && t <= t0) {
            let s = if t1 != t0 { (t - t0) / (t1 - t0) } else { 0.0 };
            return Some(y0 + s * (y1 - y0));
        }
    }
    line.iter()
        .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
        .map(|p| p.1)
}

/// The source side of one eye: closing value, share of the closing done by the top FAP,
/// and the gap between its margins along the corner line (IRISD0).
pub(super) struct SourceClose {
    pub(super) value: f64,
    pub(super) top_share: f32,
    pub(super) upper: Vec<(f32, f32)>,
    pub(super) lower: Vec<(f32, f32)>,
    pub(super) irisd: f32,
}

impl SourceClose {
    pub(super) fn gap(&self, t: f32) -> Option<f32> {
        Some((height(&self.upper, t)? - height(&self.lower, t)?) / self.irisd)
    }
}

/// Step 1 for one eye of the source.
pub(super) fn source_close(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    margins: &LidMargins,
    eye: (bool, u8, u8, &str, &str),
) -> Option<SourceClose> {
    let (_, top, bottom, up, low) = eye;
    let (kt, vt) = first_motion(motions, top)?;
    let (kb, vb) = first_motion(motions, bottom)?;
    let fp = |s: &str| {
        s.parse::<FeaturePointId>()
            .ok()
            .and_then(|id| source.fp_vertices.get(&id).copied())
    };
    let (u, l) = (fp(up)?, fp(low)?);
    let gap0 = source.positions[u as usize].y - source.positions[l as usize].y;
    // Closing per unit of FAP value, by each FAP.
    let rate_t = (offset(&motions[kt], u) - offset(&motions[kt], l)).y / vt as f32;
    let rate_b = (offset(&motions[kb], u) - offset(&motions[kb], l)).y / vb as f32;
    let rate = rate_t + rate_b;
    if !(gap0 > 0.0 && rate < 0.0) {
        return None;
    }
    let value = (-gap0 / rate) as f64;
    if !(value.is_finite() && value <= vt.min(vb)) {
        return None;
    }
    let mut sc = source_at(source, motions, margins, eye, value)?;
    sc.top_share = (rate_t / rate).clamp(0.0, 1.0);
    Some(sc)
}

/// The source's margins of one eye posed with both lid FAPs at `value` (within both tables'
/// first interval); `top_share` is left at ½.
fn source_at(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    margins: &LidMargins,
    eye: (bool, u8, u8, &str, &str),
    value: f64,
) -> Option<SourceClose> {
    let (left, top, bottom, ..) = eye;
    let (kt, vt) = first_motion(motions, top)?;
    let (kb, vb) = first_motion(motions, bottom)?;
    let corners = margins.corners(left)?;
    let n = source.positions.len();
    let (dt, db) = (
        dense_field(n, &motions[kt].offsets),
        dense_field(n, &motions[kb].offsets),
    );
    let fields = [
        (dt.as_slice(), (value / vt) as f32),
        (db.as_slice(), (value / vb) as f32),
    ];
    let upper = posed(source, margins.lid(left, true)?.1, corners, fields);
    let lower = posed(source, margins.lid(left, false)?.1, corners, fields);
    let irisd = source.fapu.distances.irisd0 as f32;
    (irisd > 0.0).then_some(SourceClose {
        value,
        top_share: 0.5,
        upper,
        lower,
        irisd,
    })
}

/// The step on every eye (module docs): `motions` are the source's, `out` the cloned ones
/// (same order), `margins` the target's and the source's. Returns, per changed motion
/// (`name@value`), how many target vertices changed.
pub(super) fn close_lids(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    margins: [&LidMargins; 2],
    out: &mut [SurfaceMotion],
) -> BTreeMap<String, usize> {
    let mut done = BTreeMap::new();
    let [tm, sm] = margins;
    let n = target.positions.len();
    let irisd = target.fapu.distances.irisd0 as f32;
    for (eye, c) in eye_closings(source, motions, sm, tm, out) {
        let (left, _, _, up, low) = eye;
        let (sc, (kt, vt), (kb, vb)) = (c.source, c.top, c.bottom);
        let (corners, upper, lower) = (c.corners, c.upper, c.lower);
        // Where both tables are still in their first interval the change grows linearly with
        // the FAP value; at `far` it is capped (step 4).
        let far = vt.min(vb);
        let Some(sfar) = source_at(source, motions, sm, eye, far) else {
            continue;
        };
        let (st, sb) = ((sc.value / vt) as f32, (sc.value / vb) as f32);
        let mut dt = dense_field(n, &out[kt].offsets);
        let mut db = dense_field(n, &out[kb].offsets);
        let fields = [(dt.as_slice(), st), (db.as_slice(), sb)];
        let pu = posed(target, upper.1, corners, fields);
        let pl = posed(target, lower.1, corners, fields);
        let fields_far = [
            (dt.as_slice(), (far / vt) as f32),
            (db.as_slice(), (far / vb) as f32),
        ];
        let (fu, fl) = (
            posed(target, upper.1, corners, fields_far),
            posed(target, lower.1, corners, fields_far),
        );
        // Kept: the corners (on both margins) and the FAPs' own feature points; the change
        // fades out over the margins' middles (step 3).
        let sets = RowSets::of(target, upper.1, lower.1, [up, low]);
        // Per margin vertex, the change of its height at the closing value.
        let change = |own: &[(f32, f32)],
                      other: &[(f32, f32)],
                      own_far: &[(f32, f32)],
                      other_far: &[(f32, f32)],
                      is_upper: bool|
         -> Vec<f32> {
            let fade = tm.middle_weights(left, is_upper);
            own.iter()
                .zip(own_far)
                .zip(fade)
                .map(|((&(t, y), &(_, y_far)), fade)| {
                    let (Some(o), Some(want), Some(o_far), Some(want_far)) = (
                        height(other, t),
                        sc.gap(t),
                        height(other_far, t),
                        sfar.gap(t),
                    ) else {
                        return 0.0;
                    };
                    let gap = if is_upper { y - o } else { o - y };
                    let gap_far = if is_upper {
                        y_far - o_far
                    } else {
                        o_far - y_far
                    };
                    let excess = capped(
                        gap - want * irisd,
                        (gap_far - want_far * irisd) * (sc.value / far) as f32,
                    );
                    let faded = excess * fade;
                    if is_upper {
                        -sc.top_share * faded
                    } else {
                        (1.0 - sc.top_share) * faded
                    }
                })
                .collect()
        };
        let cu = change(&pu, &pl, &fu, &fl, true);
        let cl = change(&pl, &pu, &fl, &fu, false);
        let reach = REACH * tm.es();
        for ((line, verts), ch, share, field, is_upper) in [
            (upper, cu, st, &mut dt, true),
            (lower, cl, sb, &mut db, false),
        ] {
            let ch: Vec<f32> = verts
                .iter()
                .zip(ch)
                .map(|(v, c)| {
                    if sets.fixed.contains(v) {
                        0.0
                    } else {
                        c / share
                    }
                })
                .collect();
            if !ch.iter().all(|c| c.is_finite()) || share <= 0.0 {
                continue;
            }
            let row = sets.row(line, corners, [up, low], is_upper);
            let count = spread(target, row, &ch, reach, field);
            store_changed(out, if is_upper { kt } else { kb }, field, count, &mut done);
        }
    }
    done
}

/// The vertices of an eye's two margin rows, and those a change keeps: the lid FAPs' own
/// feature points and the corners both rows share (step 3).
pub(super) struct RowSets {
    pub(super) upper: HashSet<u32>,
    pub(super) lower: HashSet<u32>,
    pub(super) fixed: HashSet<u32>,
}

impl RowSets {
    /// The sets of the rows `upper` and `lower` on `target`, whose lid points are `points`
    /// (the upper and lower lid FAPs' feature point ids).
    pub(super) fn of(
        target: &CloneSurface,
        upper: &[u32],
        lower: &[u32],
        points: [&str; 2],
    ) -> Self {
        let upper: HashSet<u32> = upper.iter().copied().collect();
        let lower: HashSet<u32> = lower.iter().copied().collect();
        let fixed = points
            .iter()
            .filter_map(|s| s.parse::<FeaturePointId>().ok())
            .filter_map(|id| target.fp_vertices.get(&id).copied())
            .chain(upper.intersection(&lower).copied())
            .collect();
        RowSets {
            upper,
            lower,
            fixed,
        }
    }

    /// The upper (`is_upper`) or lower row with neutral points `line`, for [`spread`].
    pub(super) fn row<'a>(
        &'a self,
        line: &'a [Vec3],
        corners: (Vec3, Vec3),
        points: [&'a str; 2],
        is_upper: bool,
    ) -> Row<'a> {
        let (own, across, lid_point) = if is_upper {
            (&self.upper, &self.lower, points[0])
        } else {
            (&self.lower, &self.upper, points[1])
        };
        Row {
            line,
            own,
            across,
            fixed: &self.fixed,
            corners,
            lid_point,
            is_upper,
        }
    }
}

/// One lid's margin row as a change spreads from it: its neutral points, its vertices, the
/// other lid's (never changed), the vertices kept, the eye's corners, its lid point (a
/// feature point id) and which lid.
pub(super) struct Row<'a> {
    pub(super) line: &'a [Vec3],
    pub(super) own: &'a HashSet<u32>,
    pub(super) across: &'a HashSet<u32>,
    pub(super) fixed: &'a HashSet<u32>,
    pub(super) corners: (Vec3, Vec3),
    pub(super) lid_point: &'a str,
    pub(super) is_upper: bool,
}

/// Stores `field` as the offsets of motion `k` of `out` when `count` vertices of it changed,
/// noting the count in `done` under `name@value`.
pub(super) fn store_changed(
    out: &mut [SurfaceMotion],
    k: usize,
    field: &[Vec3],
    count: usize,
    done: &mut BTreeMap<String, usize>,
) {
    if count > 0 {
        out[k].offsets = sparse_offsets(field);
        done.insert(format!("{}@{}", out[k].key.name(), out[k].value), count);
    }
}

/// The vertical motion in `field` of the lid point `fp` (a feature point id) on `target`.
pub(super) fn lid_point_motion(target: &CloneSurface, fp: &str, field: &[Vec3]) -> Option<f32> {
    fp.parse::<FeaturePointId>()
        .ok()
        .and_then(|id| target.fp_vertices.get(&id))
        .map(|&v| field[v as usize].y)
}

/// Adds the vertical change `ch` (per vertex of `row`, at the table's border) to `field`:
/// in full on the row, fading out by a Wendland bump within `reach` of it over the row's
/// side of the corner line, never closing a vertex past the motion its lid point has in
/// `field` before the change (step 6). Returns how many vertices changed.
pub(super) fn spread(
    target: &CloneSurface,
    row: Row,
    ch: &[f32],
    reach: f32,
    field: &mut [Vec3],
) -> usize {
    let point = lid_point_motion(target, row.lid_point, field);
    let (o, i) = row.corners;
    let side = |p: Vec3| {
        let t = along(row.corners, p).clamp(0.0, 1.0);
        p.y - (o.y + t * (i.y - o.y))
    };
    let near = reach_box(target, &row, reach);
    let mut count = 0;
    for (v, p) in target.positions.iter().enumerate() {
        if near.is_some_and(|(lo, hi)| p.cmplt(lo).any() || p.cmpgt(hi).any()) {
            continue;
        }
        let v32 = v as u32;
        let on = row.own.contains(&v32);
        if (!on && (side(*p) > 0.0) != row.is_upper)
            || row.fixed.contains(&v32)
            || row.across.contains(&v32)
        {
            continue;
        }
        let (a, t, dist) = nearest_on(row.line, *p);
        let w = if on { 1.0 } else { bump(dist / reach) };
        if w <= 0.0 {
            continue;
        }
        let b = (a + 1).min(ch.len() - 1);
        let c = (1.0 - t) * ch[a] + t * ch[b];
        let y = field[v].y;
        let to = no_further(y, y + w * c, point, row.is_upper);
        if to != y {
            field[v].y = to;
            count += 1;
        }
    }
    count
}

/// The box [`spread`] reaches: around the row's neutral points and its own vertices, grown
/// by `reach` and a margin for rounding (1 % of it, and 1e-5 of the box's largest
/// coordinate). A vertex outside it is none of the row's and lies further than `reach` from
/// the row, where the bump is zero: skipping it changes nothing. `None` (no box: visit
/// every vertex) when `reach` is not positive or the box not finite.
fn reach_box(target: &CloneSurface, row: &Row, reach: f32) -> Option<(Vec3, Vec3)> {
    if !(reach > 0.0 && reach.is_finite()) {
        return None;
    }
    let own = row
        .own
        .iter()
        .filter_map(|&v| target.positions.get(v as usize));
    let (lo, hi) = row
        .line
        .iter()
        .chain(own)
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let scale = lo.abs().max(hi.abs()).max_element();
    let grow = Vec3::splat(1.01 * reach + 1e-5 * scale);
    let (lo, hi) = (lo - grow, hi + grow);
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

/// A vertex's vertical motion `y` changed to `to`, held back where the change closes the
/// slit (down for the upper lid, up for the lower) past its lid point's motion `point`
/// (step 6): nothing is taken back of a motion already past it, and a change that opens is
/// kept.
pub(super) fn no_further(y: f32, to: f32, point: Option<f32>, is_upper: bool) -> f32 {
    let Some(point) = point else {
        return to;
    };
    if is_upper && to < y {
        to.max(point.min(y))
    } else if !is_upper && to > y {
        to.min(point.max(y))
    } else {
        to
    }
}

/// A margin point's change of the gap at the closing value, `excess`, capped by `at_far`,
/// the change that would bring the gap at the end of the first interval to the source's
/// there (scaled back to the closing value): the change grows linearly with the FAP value,
/// so past the closing value it must not close (or open) the slit more than the source's
/// own over-closure at that end. Opposite signs: no change.
fn capped(excess: f32, at_far: f32) -> f32 {
    if excess * at_far <= 0.0 {
        0.0
    } else {
        excess.signum() * excess.abs().min(at_far.abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_change_is_capped_by_what_the_end_of_the_interval_allows() {
        // Closing by 0.2 at the closing value, but only 0.1 (scaled back) keeps the end of
        // the interval no more closed than the source's there.
        assert_eq!(capped(0.2, 0.1), 0.1);
        assert_eq!(capped(0.05, 0.1), 0.05);
        assert_eq!(capped(-0.2, -0.05), -0.05);
        // The end is already past the source's: no change at all.
        assert_eq!(capped(0.2, -0.1), 0.0);
        assert_eq!(capped(-0.2, 0.1), 0.0);
    }

    #[test]
    fn no_vertex_closes_past_its_lid_point() {
        // Upper lid: the point goes down 1.0; a change to −1.2 stops at −1.0.
        assert_eq!(no_further(-0.8, -1.2, Some(-1.0), true), -1.0);
        // Within the point's motion, or opening: kept.
        assert_eq!(no_further(-0.8, -0.9, Some(-1.0), true), -0.9);
        assert_eq!(no_further(-0.8, -0.7, Some(-1.0), true), -0.7);
        // Already past the point: not taken back, not pushed further.
        assert_eq!(no_further(-1.1, -1.3, Some(-1.0), true), -1.1);
        // Lower lid: up is closing.
        assert_eq!(no_further(0.2, 0.6, Some(0.5), false), 0.5);
        assert_eq!(no_further(0.2, 0.1, Some(0.5), false), 0.1);
        // No lid point: the change as it is.
        assert_eq!(no_further(0.2, 0.6, None, false), 0.6);
    }
}
