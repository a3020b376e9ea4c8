//! The `eyeball` step (module docs of [`super`], with `lid_close`): no lid through the
//! eyeball (issue 21 §1).
//!
//! A FAT moves each vertex along a straight chord between its table's borders. A source lid
//! turning about its eyeball (alma's) is carried onto a real head's lid as such chords, and
//! a chord from the open lid to the closed one cuts through the eyeball: alma → ICT's lid
//! points went 0.21–0.23 eyeball radii deep, ICT's own FAT 0.11. So, per eyeball of the
//! target and per motion of every table, in order of its borders outwards from 0: each skin
//! vertex within [`NEAR`] radii of the eyeball's centre whose chord from the previous border
//! (or rest) to this one passes closer to the centre than its clearance — the eye white's
//! sphere grown by [`CLEAR`], or the vertex's own rest distance if it rests closer — has its
//! displacement at this border pushed out along the eyeball's normal there, just as far as
//! brings the whole chord clear (bisection), and the push spreads smoothly to the vertices
//! around (a bump over [`SPREAD`] radii; pushing vertices one by one folded the lower lid:
//! 126° at a quarter of `close_b_l`, ICT's own 65°). A vertex resting inside the sphere (a lid's
//! inner face, the eye's corners) goes no deeper than it rests; one whose chord already
//! stays clear, and every table of a target without eyeball parts (a one-mesh head of the
//! source's own mesh: its eyes are skin), is not changed.

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

/// How far (eye-white radii) each vertex's push spreads to its neighbours.
pub(super) const SPREAD: f32 = 0.5;

/// Bisection steps on the push.
const STEPS: usize = 24;

/// Closest distance of the chord `a → b` to `c`.
fn chord_distance(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((c - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + t * ab).distance(c)
}

/// The step on every motion of the target's skin surface `surf` (module docs); `margins`
/// hold the target's eyeballs. Returns, per changed motion (`name@value`), how many
/// vertices were pushed out.
pub(super) fn keep_lids_out(
    surf: &CloneSurface,
    margins: &LidMargins,
    motions: &mut [SurfaceMotion],
) -> BTreeMap<String, usize> {
    let mut done = BTreeMap::new();
    // Per eyeball: centre, the clearance radius, and the vertices near it with their
    // clearance (the smaller of the sphere's and their rest distance).
    let eyes: Vec<(Vec3, Vec<(u32, f32)>, f32)> = margins
        .balls()
        .iter()
        .map(|(_, b)| {
            let (c, r) = b.sphere();
            let near = surf
                .positions
                .iter()
                .enumerate()
                .filter_map(|(v, p)| {
                    let d = p.distance(c);
                    (d < NEAR * r).then_some((v as u32, d.min((1.0 + CLEAR) * r)))
                })
                .collect();
            (c, near, r)
        })
        .collect();
    if eyes.iter().all(|e| e.1.is_empty()) {
        return done;
    }
    // Each table's motions, outwards from 0 on each side.
    let mut order: Vec<usize> = (0..motions.len()).collect();
    order.sort_by(|&a, &b| {
        let (ma, mb) = (&motions[a], &motions[b]);
        (ma.key.name(), ma.value < 0.0, ma.value.abs())
            .partial_cmp(&(mb.key.name(), mb.value < 0.0, mb.value.abs()))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut previous: Option<usize> = None;
    for &k in &order {
        // The border before this one on its side of 0 (none: rest).
        let before = previous.filter(|&p| {
            motions[p].key == motions[k].key && (motions[p].value < 0.0) == (motions[k].value < 0.0)
        });
        previous = Some(k);
        let mut field = dense_field(surf.positions.len(), &motions[k].offsets);
        let mut count = 0usize;
        for (c, near, r) in &eyes {
            // Per vertex whose chord cuts in: how far out (along the eyeball's normal at its
            // posed place) its end must go.
            let mut pushes: Vec<(Vec3, f32)> = Vec::new();
            for &(v, clear) in near {
                let d = field[v as usize];
                if d == Vec3::ZERO {
                    continue;
                }
                let rest = surf.positions[v as usize];
                let a = rest + before.map_or(Vec3::ZERO, |p| motions[p].offset_at(v));
                let b = rest + d;
                // Below the clearance by a hair is float noise, not a lid in the eye.
                if chord_distance(a, b, *c) >= clear * (1.0 - 1e-4) {
                    continue;
                }
                let out = |s: f32| *c + (b - *c) * s;
                let (mut lo, mut hi) = (1.0f32, 1.0f32);
                // Grow the push until the chord is clear (at most 3× the distance).
                while chord_distance(a, out(hi), *c) < clear && hi < 3.0 {
                    lo = hi;
                    hi = (hi * 1.25).min(3.0);
                }
                for _ in 0..STEPS {
                    let mid = 0.5 * (lo + hi);
                    if chord_distance(a, out(mid), *c) < clear {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let push = (hi - 1.0) * b.distance(*c);
                if push.is_finite() && push > 0.0 {
                    pushes.push((rest, push));
                }
            }
            if pushes.is_empty() {
                continue;
            }
            // The pushes spread as bumps over [`SPREAD`] radii around their vertices (each
            // vertex the largest that reaches it): pushing single vertices folded the lids.
            let reach = SPREAD * r;
            for &(v, _) in near {
                let rest = surf.positions[v as usize];
                let push = pushes
                    .iter()
                    .map(|&(p, amount)| amount * bump(p.distance(rest) / reach))
                    .fold(0.0, f32::max);
                let posed = rest + field[v as usize];
                let n = (posed - *c).normalize_or_zero();
                if push > 0.0 && n != Vec3::ZERO {
                    field[v as usize] += push * n;
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
