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
//! inner face, the eye's corners), less [`SLACK`]. The source's own chords may dip below
//! theirs (ICT's real lids and the eye layers sliding on the ball do, by 0.1–0.2 radii;
//! alma's: 0.15 under `close_t`, more under her brow FAPs, whose lid shell sinks into the
//! ball), so per motion and eye the deepest dip of the source's chords under its own
//! eyeball (in its radii) is allowed on the target's too — however deep: a clone that does
//! what its source does is not changed (a self-clone is exact). An earlier cap on the
//! copied dip (a quarter radius) pushed alma's own brow motions out of her eyes on
//! alma → alma (7.4 % off). Then per eyeball of the target and per motion of every table,
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

/// How far (eye-white radii) each vertex's push spreads to its neighbours.
pub(super) const SPREAD: f32 = 0.5;

/// Dips (eye-white radii) within this of the allowed are rounding, not pushed.
const ROUNDING: f32 = 1e-5;

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

/// The eye-white spheres of `margins`' eyeballs: left eye or not, centre, radius.
fn spheres(margins: &LidMargins) -> Vec<(bool, Vec3, f32)> {
    margins
        .balls()
        .iter()
        .map(|&(left, b)| {
            let (c, r) = b.sphere();
            (left, c, r)
        })
        .collect()
}

fn near_eyes(surf: &CloneSurface, spheres: &[(bool, Vec3, f32)]) -> Vec<NearEye> {
    spheres
        .iter()
        .map(|&(left, c, r)| {
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
fn dips(surf: &CloneSurface, eyes: &[NearEye], motions: &[SurfaceMotion]) -> Vec<[f32; 2]> {
    let mut out = vec![[0.0f32; 2]; motions.len()];
    for (k, before) in chords(motions) {
        for e in eyes {
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
    let (ssurf, smargins, smotions) = source;
    let source_spheres = spheres(smargins);
    if source_spheres.is_empty() || smotions.len() != motions.len() {
        return BTreeMap::new();
    }
    let eyes = near_eyes(surf, &spheres(margins));
    let allowed = dips(ssurf, &near_eyes(ssurf, &source_spheres), smotions);
    keep_out(surf, &eyes, &allowed, motions)
}

/// [`keep_lids_out`] on the target's `eyes`, with the dips each motion's source `allowed`
/// per eye (left, right; eye-white radii).
fn keep_out(
    surf: &CloneSurface,
    eyes: &[NearEye],
    allowed: &[[f32; 2]],
    motions: &mut [SurfaceMotion],
) -> BTreeMap<String, usize> {
    let mut done = BTreeMap::new();
    if eyes.iter().all(|e| e.near.is_empty()) {
        return done;
    }
    for (k, before) in chords(motions) {
        let mut field = dense_field(surf.positions.len(), &motions[k].offsets);
        let mut count = 0usize;
        for e in eyes {
            let (c, r) = (&e.centre, e.radius);
            // The source's own dip is allowed: a clone doing what its source does is kept.
            let allow = allowed[k][usize::from(!e.left)] * r;
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
                // Rounding: the source's own deepest chord measured again on its clone.
                if deficit <= ROUNDING * r {
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

    /// A lid of three vertices resting just outside a unit eyeball at the origin (left eye),
    /// and a far vertex.
    fn lid() -> CloneSurface {
        CloneSurface {
            positions: vec![
                Vec3::new(0.0, 1.05, 0.2),
                Vec3::new(0.3, 1.0, 0.3),
                Vec3::new(-0.3, 1.0, 0.3),
                Vec3::new(5.0, 5.0, 5.0),
            ],
            triangles: vec![[0, 1, 2]],
            fp_vertices: Default::default(),
            fp_positions: Default::default(),
            fapu: crate::clone::fixtures::unit_fapu(),
        }
    }

    /// A lid closing straight down through the ball (a chord 0.9 radii deep, as a lid
    /// turning about its eye leaves between two borders).
    fn through() -> Vec<SurfaceMotion> {
        let down = Vec3::new(0.0, -2.0, 0.0);
        vec![SurfaceMotion {
            key: crate::fat::TableKey::LowLevel(crate::spec::FapId::new(19).unwrap()),
            value: 1024.0,
            offsets: vec![(0, down), (1, down), (2, down)],
        }]
    }

    #[test]
    fn a_self_clone_dipping_as_deep_as_its_source_is_kept() {
        let surf = lid();
        let eyes = near_eyes(&surf, &[(true, Vec3::ZERO, 1.0)]);
        let source = through();
        let allowed = dips(&surf, &eyes, &source);
        // Deeper than a real lid slides (the cap the step had: a quarter radius).
        assert!(allowed[0][0] > 0.5, "{:?}", allowed);
        let mut clone = source.clone();
        let done = keep_out(&surf, &eyes, &allowed, &mut clone);
        assert!(done.is_empty(), "{done:?}");
        assert_eq!(clone[0].offsets, source[0].offsets);
    }

    #[test]
    fn a_clone_dipping_deeper_than_its_source_is_pushed_clear() {
        let surf = lid();
        let eyes = near_eyes(&surf, &[(true, Vec3::ZERO, 1.0)]);
        // The source's lid does not enter its eyeball.
        let mut clone = through();
        let done = keep_out(&surf, &eyes, &[[0.0, 0.0]], &mut clone);
        assert_eq!(done.values().sum::<usize>(), 3, "{done:?}");
        let before = through();
        for (&(v, d), &(_, d0)) in clone[0].offsets.iter().zip(&before[0].offsets) {
            let rest = surf.positions[v as usize];
            let (dist, dist0) = (
                chord_distance(rest, rest + d, Vec3::ZERO),
                chord_distance(rest, rest + d0, Vec3::ZERO),
            );
            // Out by the longest push (half a radius at the chord's end), not through.
            assert!(dist > dist0 + 0.2, "vertex {v}: {dist0} → {dist}");
            assert!(
                (d - d0).length() <= 0.5 + 1e-4,
                "vertex {v}: pushed {}",
                (d - d0).length()
            );
        }
    }
}
