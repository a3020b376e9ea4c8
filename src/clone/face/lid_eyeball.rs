//! The `eyeball` step (module docs of [`super`], with `lid_close`): no lid through the
//! eyeball (issue 21 §1).
//!
//! A FAT moves each vertex along a straight chord between its table's borders. A source lid
//! turning about its eyeball (alma's) is carried onto a real head's lid as such chords, and
//! a chord from the open lid to the closed one cuts through the eyeball: alma → ICT's lid
//! points went 0.21–0.23 eyeball radii deep, ICT's own FAT 0.11.
//!
//! Each vertex within [`NEAR`] radii of an eyeball's centre has a clearance: the eye
//! white's sphere grown by [`CLEAR`], or its own rest distance if it rests closer (a lid's
//! inner face, the eye's corners), less [`SLACK`]. The source's own lids may dip below
//! theirs (ICT's real lids and the eye layers sliding on the ball do, by 0.1–0.2 radii), so
//! per motion the deepest dip of the source's chords under its own eyeball (in its radii) is
//! allowed on the target's too, up to [`REAL_DIP`]; a source dipping deeper turns its lids
//! about the eye (alma's lid shell: one interval to a 170° turn) and is not followed there. Then per eyeball of the target and per motion of every table,
//! in order of its borders outwards from 0, a vertex whose chord from the previous border
//! (or rest) to this one dips deeper has its displacement at this border pushed out along
//! the eyeball's normal at the chord's closest point, just as far as brings the chord clear
//! (bisection; at most [`MAX_PUSH`] times the dip and half a radius), and the push spreads
//! smoothly to the vertices around (a bump over [`SPREAD`] radii; pushing vertices one by
//! one folded the lower lid: 126° at a quarter of `close_b_l`, ICT's own 65°). Without
//! eyeball parts on both faces (a one-mesh head of the source's own mesh, whose eyes are
//! skin; a source without eyeballs) nothing is changed.

use std::collections::BTreeMap;

use glam::Vec3;

use super::lid_margin::LidMargins;
use super::rescale::bump;
use super::smooth::{dense_field, sparse_offsets};
use crate::clone::{CloneSurface, SurfaceMotion};

/// Skin vertices resting within this many eye-white radii of an eyeball's centre are kept
/// out of it.
pub(super) const NEAR: f32 = 1.6;

/// Clearance over the eye white's sphere, in its radii.
pub(super) const CLEAR: f32 = 0.02;

/// Depth (eye-white radii) below its clearance a chord may dip without a push: vertices
/// resting on the eyeball (a lid's inner face, the eye's corners) graze it as they slide.
pub(super) const SLACK: f32 = 0.02;

/// Longest push, in deficits (how far the chord dips below its clearance): the push that
/// clears a chord dipping in just after its start is long and its spread folded ICT's inner
/// eye corner (110° at a quarter of `close_b_l`).
pub(super) const MAX_PUSH: f32 = 4.0;

/// Deepest dip (eye-white radii) of a source's own chords under its eyeball that is copied:
/// a real lid sliding on the ball (ICT's own FAT: 0.1–0.2). A source dipping deeper turns
/// its lids about the eye (alma's shell: one interval to a 170° turn), and its clone is
/// kept out.
pub(super) const REAL_DIP: f32 = 0.25;

/// How far (eye-white radii) each vertex's push spreads to its neighbours.
pub(super) const SPREAD: f32 = 0.5;

/// Bisection steps on the push.
const STEPS: usize = 24;

/// The point of the chord `a → b` closest to `c`.
fn closest(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((c - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + t * ab
}

/// Closest distance of the chord `a → b` to `c`.
fn chord_distance(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    closest(a, b, c).distance(c)
}

/// One eyeball of a surface: left or not, centre, eye-white radius, and the vertices near it
/// with their clearance (the smaller of the sphere's and their rest distance, less
/// [`SLACK`]).
struct NearEye {
    left: bool,
    centre: Vec3,
    radius: f32,
    near: Vec<(u32, f32)>,
}

fn near_eyes(surf: &CloneSurface, margins: &LidMargins) -> Vec<NearEye> {
    margins
        .balls()
        .iter()
        .map(|&(left, b)| {
            let (c, r) = b.sphere();
            let near = surf
                .positions
                .iter()
                .enumerate()
                .filter_map(|(v, p)| {
                    let d = p.distance(c);
                    (d < NEAR * r).then_some((v as u32, d.min((1.0 + CLEAR) * r) - SLACK * r))
                })
                .collect();
            NearEye {
                left,
                centre: c,
                radius: r,
                near,
            }
        })
        .collect()
}

/// The motions' order by table, outwards from 0 on each side, each with the border before it
/// on its side (none: rest).
fn chords(motions: &[SurfaceMotion]) -> Vec<(usize, Option<usize>)> {
    let mut order: Vec<usize> = (0..motions.len()).collect();
    order.sort_by(|&a, &b| {
        let (ma, mb) = (&motions[a], &motions[b]);
        (ma.key.name(), ma.value < 0.0, ma.value.abs())
            .partial_cmp(&(mb.key.name(), mb.value < 0.0, mb.value.abs()))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut out = Vec::with_capacity(order.len());
    let mut previous: Option<usize> = None;
    for k in order {
        let before = previous.filter(|&p| {
            motions[p].key == motions[k].key && (motions[p].value < 0.0) == (motions[k].value < 0.0)
        });
        previous = Some(k);
        out.push((k, before));
    }
    out
}

/// Per motion and eye (left, right): how far (eye-white radii) its chords dip below their
/// clearance at most — what the source's own lids do to its own eyeballs.
fn dips(surf: &CloneSurface, margins: &LidMargins, motions: &[SurfaceMotion]) -> Vec<[f32; 2]> {
    let eyes = near_eyes(surf, margins);
    let mut out = vec![[0.0f32; 2]; motions.len()];
    for (k, before) in chords(motions) {
        for e in &eyes {
            let mut dip = 0.0f32;
            for &(v, clear) in &e.near {
                let d = motions[k].offset_at(v);
                if d == Vec3::ZERO {
                    continue;
                }
                let rest = surf.positions[v as usize];
                let a = rest + before.map_or(Vec3::ZERO, |p| motions[p].offset_at(v));
                dip = dip.max((clear - chord_distance(a, rest + d, e.centre)) / e.radius);
            }
            let slot = &mut out[k][usize::from(!e.left)];
            *slot = slot.max(dip);
        }
    }
    out
}

/// The step on every motion of the target's skin surface `surf` (module docs); `margins`
/// hold the target's eyeballs, `source` the source's surface, margins with its eyeballs and
/// motions (in the order of `motions`). Without eyeballs on both faces nothing is done: what
/// the source's own lids do to its eyes is the measure. Returns, per changed motion
/// (`name@value`), how many vertices were pushed out.
pub(super) fn keep_lids_out(
    surf: &CloneSurface,
    margins: &LidMargins,
    source: (&CloneSurface, &LidMargins, &[SurfaceMotion]),
    motions: &mut [SurfaceMotion],
) -> BTreeMap<String, usize> {
    let mut done = BTreeMap::new();
    let eyes = near_eyes(surf, margins);
    let (ssurf, smargins, smotions) = source;
    if eyes.iter().all(|e| e.near.is_empty())
        || smargins.balls().is_empty()
        || smotions.len() != motions.len()
    {
        return done;
    }
    let allowed = dips(ssurf, smargins, smotions);
    for (k, before) in chords(motions) {
        let mut field = dense_field(surf.positions.len(), &motions[k].offsets);
        let mut count = 0usize;
        for e in &eyes {
            let (c, r) = (&e.centre, e.radius);
            // The source's own dip is allowed, up to a real lid's.
            let dip = allowed[k][usize::from(!e.left)];
            let allow = if dip <= REAL_DIP { dip * r } else { 0.0 };
            // Per vertex whose chord cuts in: how far its end must go out, along the
            // eyeball's normal at the chord's closest point (the way out of the ball there:
            // the end's own normal pushed a rising lower lid up at a quarter of the motion).
            let mut pushes: Vec<(Vec3, f32, Vec3)> = Vec::new();
            for &(v, clear) in &e.near {
                let clear = clear - allow;
                let d = field[v as usize];
                if d == Vec3::ZERO {
                    continue;
                }
                let rest = surf.positions[v as usize];
                let a = rest + before.map_or(Vec3::ZERO, |p| motions[p].offset_at(v));
                let b = rest + d;
                let deficit = clear - chord_distance(a, b, *c);
                if deficit <= 0.0 {
                    continue;
                }
                let n = (closest(a, b, *c) - *c).normalize_or_zero();
                if n == Vec3::ZERO {
                    continue;
                }
                // The end moves out by at most [`MAX_PUSH`] deficits (a chord dipping in
                // just after its start would need a long lever) and half a radius.
                let cap = (MAX_PUSH * deficit).min(0.5 * r);
                let (mut lo, mut hi) = (0.0f32, cap);
                if chord_distance(a, b + hi * n, *c) < clear {
                    lo = hi;
                }
                for _ in 0..STEPS {
                    let mid = 0.5 * (lo + hi);
                    if chord_distance(a, b + mid * n, *c) < clear {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                if hi.is_finite() && hi > 0.0 {
                    pushes.push((rest, hi, n));
                }
            }
            if pushes.is_empty() {
                continue;
            }
            // The pushes spread as bumps over [`SPREAD`] radii around their vertices: each
            // vertex they reach goes as far as the largest reaching it, in their weighted
            // mean direction (pushing single vertices folded the lids).
            let reach = SPREAD * r;
            for (v, rest) in surf.positions.iter().enumerate() {
                if rest.distance(*c) > NEAR * r + reach {
                    continue;
                }
                let (mut amount, mut dir) = (0.0f32, Vec3::ZERO);
                for &(p, push, n) in &pushes {
                    let w = bump(p.distance(*rest) / reach);
                    amount = amount.max(w * push);
                    dir += w * push * n;
                }
                let dir = dir.normalize_or_zero();
                if amount > 0.0 && dir != Vec3::ZERO {
                    field[v] += amount * dir;
                    count += 1;
                }
            }
        }
        if count > 0 {
            let m = &mut motions[k];
            m.offsets = sparse_offsets(&field);
            done.insert(format!("{}@{}", m.key.name(), m.value), count);
        }
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chord_through_the_ball_is_pushed_clear_and_a_clear_one_kept() {
        let c = Vec3::ZERO;
        // From above the ball straight down past it: the chord passes through the centre.
        let (a, b) = (Vec3::new(0.0, 1.2, 0.0), Vec3::new(0.0, -1.2, 0.1));
        assert!(chord_distance(a, b, c) < 0.1);
        // Along its side: clear.
        let (a2, b2) = (Vec3::new(0.0, 1.2, 1.2), Vec3::new(0.0, -1.2, 1.2));
        assert!((chord_distance(a2, b2, c) - 1.2).abs() < 1e-6);
    }
}
