//! The `lid_seam` step (module docs of [`super`], with `lid_close`): where the source's
//! blink closes its eye, the target's lids meet along one smooth line (issue 21 §1).
//!
//! `lid_close` brings the slit's gap towards the source's band by band, but fades its change
//! out over the margin's middle and caps it; `smooth` holds that middle with the lid point.
//! Across styles the margin then drops as a plateau with a step where the held middle ends
//! (alma → ICT's upper lid at alma's closing value 512: the margin vertex on the middle's
//! inner end down 0.0049, its neighbour 0.0013), so the closed line was jagged and the iris
//! showed through the slit beside the lid point.
//!
//! So, per eye, at the source's closing value `v` (as `lid_close` finds it), on a grid of
//! [`SAMPLES`] places along the corner line (0 outer corner, 1 inner):
//!
//! 1. The target's margins posed at `v` give the line where they meet, `C = (1 − s)·upper +
//!    s·lower` (`s` the top FAP's share of the source's closing: closing the gap by `e` moves
//!    the upper margin `s·e` down and the lower `(1 − s)·e` up, and leaves `C` where it is),
//!    and their gap `G = upper − lower`.
//! 2. `C` is smoothed along the slit ([`smoothed`]: least squares against a stiffness on its
//!    second differences, the corners and the lid points' place held) and the source's own
//!    detail put back: the source's `C` less its own smoothing, in IRISD0. A self-clone's
//!    lines are the source's, so nothing changes.
//! 3. The gap becomes the source's, `W` (in the target's IRISD0), but at the lid points,
//!    whose FAPs define them: there the target's own gap is kept, fading out half way to each
//!    corner.
//! 4. Each margin vertex's height at `v` changes by the difference (upper `ΔC + s·ΔW`,
//!    lower `ΔC − (1 − s)·ΔW`), through its lid's FAP (the top FAP moves the upper margin,
//!    the bottom one the lower), spread into its lid by `lid_close`'s bump, never closing a
//!    vertex past its lid point.

use std::collections::BTreeMap;

use glam::Vec3;

use super::lid_close::{eye_closings, height, posed, spread, store_changed, RowSets, REACH};
use super::lid_margin::LidMargins;
use super::smooth::dense_field;
use crate::clone::{CloneSurface, SurfaceMotion};
use crate::spec::FeaturePointId;

/// Places along the corner line the meeting line is sampled at.
pub(super) const SAMPLES: usize = 33;

/// Stiffness of the meeting line against its second differences (in grid steps): a wave
/// shorter than about a quarter of the slit is taken out, a lid's curve kept.
pub(super) const STIFFNESS: f64 = 4.0;

/// Weight of a held sample against a free one's.
const HOLD: f64 = 1e6;

/// Changes (in the target's IRISD0) below this are rounding: a self-clone is left alone.
const ROUNDING: f32 = 1e-5;

/// The least-squares smoothing of `c` (a uniform grid): `x` minimising
/// `Σ wᵢ (xᵢ − cᵢ)² + STIFFNESS · Σ (xᵢ₋₁ − 2xᵢ + xᵢ₊₁)²`, `wᵢ` = [`HOLD`] at `held`, else 1.
/// Linear in `c`: equal inputs give equal outputs to the bit.
pub(super) fn smoothed(c: &[f32], held: &[usize]) -> Vec<f32> {
    let n = c.len();
    if n < 3 {
        return c.to_vec();
    }
    // Normal equations, a symmetric band of half-width 2, solved densely (n is small).
    let mut a = vec![vec![0.0f64; n]; n];
    let mut b = vec![0.0f64; n];
    for i in 0..n {
        let w = if held.contains(&i) { HOLD } else { 1.0 };
        a[i][i] += w;
        b[i] += w * c[i] as f64;
    }
    for i in 1..n - 1 {
        let idx = [i - 1, i, i + 1];
        let coef = [1.0, -2.0, 1.0];
        for (p, cp) in idx.iter().zip(coef) {
            for (q, cq) in idx.iter().zip(coef) {
                a[*p][*q] += STIFFNESS * cp * cq;
            }
        }
    }
    // Gaussian elimination (the matrix is symmetric positive definite: no pivoting).
    for k in 0..n {
        let pivot = a[k].clone();
        for r in k + 1..n {
            let f = a[r][k] / pivot[k];
            if f == 0.0 {
                continue;
            }
            for (x, p) in a[r][k..].iter_mut().zip(&pivot[k..]) {
                *x -= f * p;
            }
            b[r] -= f * b[k];
        }
    }
    let mut x = vec![0.0f64; n];
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|col| a[k][col] * x[col]).sum();
        x[k] = (b[k] - s) / a[k][k];
    }
    x.into_iter().map(|v| v as f32).collect()
}

/// Grid place `j` of [`SAMPLES`].
fn place(j: usize) -> f32 {
    j as f32 / (SAMPLES - 1) as f32
}

/// The grid sample nearest place `t`.
fn sample_at(t: f32) -> usize {
    ((t.clamp(0.0, 1.0) * (SAMPLES - 1) as f32).round() as usize).min(SAMPLES - 1)
}

/// Value of grid samples `g` at place `t` (linear, clamped to the ends).
fn on_grid(g: &[f32], t: f32) -> f32 {
    let x = t.clamp(0.0, 1.0) * (g.len() - 1) as f32;
    let a = (x.floor() as usize).min(g.len() - 1);
    let b = (a + 1).min(g.len() - 1);
    let s = x - a as f32;
    (1.0 - s) * g[a] + s * g[b]
}

/// A posed margin pair sampled on the grid: meeting line `C` and gap `G` (step 1).
fn meeting(upper: &[(f32, f32)], lower: &[(f32, f32)], s: f32) -> Option<(Vec<f32>, Vec<f32>)> {
    let mut c = Vec::with_capacity(SAMPLES);
    let mut g = Vec::with_capacity(SAMPLES);
    for j in 0..SAMPLES {
        let (u, l) = (height(upper, place(j))?, height(lower, place(j))?);
        c.push((1.0 - s) * u + s * l);
        g.push(u - l);
    }
    Some((c, g))
}

/// Place along the corner line of the lid points `up`, `low` on `surf` (their mean).
fn lid_points_place(
    surf: &CloneSurface,
    corners: (Vec3, Vec3),
    up: &str,
    low: &str,
) -> Option<f32> {
    let at = |s: &str| {
        let id = s.parse::<FeaturePointId>().ok()?;
        let v = *surf.fp_vertices.get(&id)?;
        Some(super::lid_close::along(corners, surf.positions[v as usize]))
    };
    Some(0.5 * (at(up)? + at(low)?))
}

/// Weight of the target's own gap near the lid points' place `tp` (step 3): 1 there,
/// falling smoothly to 0 half way to each corner.
fn own_gap_weight(tp: f32, t: f32) -> f32 {
    let span = 0.5 * if t <= tp { tp } else { 1.0 - tp };
    if span <= 0.0 {
        return 0.0;
    }
    let x = ((t - tp).abs() / span).min(1.0);
    1.0 - x * x * (3.0 - 2.0 * x)
}

/// The step on every eye (module docs): `motions` are the source's, `out` the cloned ones
/// (same order), `margins` the target's and the source's. Returns, per changed motion
/// (`name@value`), how many target vertices changed.
pub(super) fn seam_lids(
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
        let Some(scorners) = sm.corners(left) else {
            continue;
        };
        let (Some(tp), Some(stp)) = (
            lid_points_place(target, corners, up, low),
            lid_points_place(source, scorners, up, low),
        ) else {
            continue;
        };
        let s = sc.top_share;
        let (st, sb) = ((sc.value / vt) as f32, (sc.value / vb) as f32);
        let mut dt = dense_field(n, &out[kt].offsets);
        let mut db = dense_field(n, &out[kb].offsets);
        let fields = [(dt.as_slice(), st), (db.as_slice(), sb)];
        let pu = posed(target, upper.1, corners, fields);
        let pl = posed(target, lower.1, corners, fields);
        let (Some((c, g)), Some((sc_line, _))) =
            (meeting(&pu, &pl, s), meeting(&sc.upper, &sc.lower, s))
        else {
            continue;
        };
        // Step 2: the target's line smoothed, the source's own detail kept.
        let held = [0, SAMPLES - 1, sample_at(tp)];
        let sheld = [0, SAMPLES - 1, sample_at(stp)];
        let (cs, scs) = (smoothed(&c, &held), smoothed(&sc_line, &sheld));
        let to_target = irisd / sc.irisd;
        let dc: Vec<f32> = (0..SAMPLES)
            .map(|j| cs[j] - c[j] + (sc_line[j] - scs[j]) * to_target)
            .collect();
        // Step 3: the source's gap, but the lid points' own.
        let raw: Vec<f32> = (0..SAMPLES)
            .map(|j| sc.gap(place(j)).map_or(0.0, |w| w * irisd) - g[j])
            .collect();
        let at_points = on_grid(&raw, tp);
        let dw: Vec<f32> = (0..SAMPLES)
            .map(|j| raw[j] - at_points * own_gap_weight(tp, place(j)))
            .collect();
        if dc.iter().chain(&dw).all(|x| x.abs() <= ROUNDING * irisd) {
            continue;
        }
        let sets = RowSets::of(target, upper.1, lower.1, [up, low]);
        let reach = REACH * tm.es();
        for ((line, verts), posed_row, share, field, is_upper) in [
            (upper, &pu, st, &mut dt, true),
            (lower, &pl, sb, &mut db, false),
        ] {
            if share <= 0.0 {
                continue;
            }
            // Step 4, per margin vertex, at the table's border.
            let ch: Vec<f32> = verts
                .iter()
                .zip(posed_row)
                .map(|(v, &(t, _))| {
                    if sets.fixed.contains(v) {
                        return 0.0;
                    }
                    let w = on_grid(&dw, t);
                    let gap = if is_upper { s * w } else { -(1.0 - s) * w };
                    let c = on_grid(&dc, t) + gap;
                    if c.abs() <= ROUNDING * irisd {
                        0.0
                    } else {
                        c / share
                    }
                })
                .collect();
            if !ch.iter().all(|c| c.is_finite()) || ch.iter().all(|c| *c == 0.0) {
                continue;
            }
            let row = sets.row(line, corners, [up, low], is_upper);
            let count = spread(target, row, &ch, reach, field);
            store_changed(out, if is_upper { kt } else { kb }, field, count, &mut done);
        }
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_is_smoothed_and_a_held_sample_kept() {
        // A plateau with a step (the held middle's end) becomes a slope; a straight line is
        // kept; held samples stay.
        let step: Vec<f32> = (0..SAMPLES)
            .map(|j| if j < 16 { 1.0 } else { 0.0 })
            .collect();
        let s = smoothed(&step, &[0, SAMPLES - 1]);
        let second = |x: &[f32]| {
            x.windows(3)
                .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
                .fold(0.0f32, f32::max)
        };
        assert!(second(&s) < 0.25 * second(&step), "{s:?}");
        assert!((s[0] - 1.0).abs() < 1e-4 && s[SAMPLES - 1].abs() < 1e-4);
        let line: Vec<f32> = (0..SAMPLES).map(|j| 0.5 + 0.1 * j as f32).collect();
        let l = smoothed(&line, &[0, 16, SAMPLES - 1]);
        assert!(line.iter().zip(&l).all(|(a, b)| (a - b).abs() < 1e-4));
        // Linear and bit-repeatable: a self-clone's residual is zero.
        assert_eq!(smoothed(&step, &[0, 5]), smoothed(&step, &[0, 5]));
    }

    #[test]
    fn the_lid_points_keep_their_own_gap() {
        assert_eq!(own_gap_weight(0.5, 0.5), 1.0);
        assert_eq!(own_gap_weight(0.5, 0.25), 0.0);
        assert_eq!(own_gap_weight(0.5, 0.0), 0.0);
        let w = own_gap_weight(0.4, 0.5);
        assert!(w > 0.0 && w < 1.0);
    }
}
