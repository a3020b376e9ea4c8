//! Quality measures of a cloning result.
//!
//! - [`morph_target_error`]: formula (1) of Fratarcangeli & Schaerf 2005, the paper's
//!   self-cloning measure: per morph target, `Σ‖vS − vT‖ / Σ‖vS‖` over all vertices of the
//!   *displaced* meshes (absolute positions), averaged over targets, in percent.
//! - [`displacement_error`]: the stricter measure fbakit also reports: per morph target,
//!   `Σ‖dS − dT‖ / Σ‖dS‖` over the displacements only, averaged, in percent. Absolute
//!   positions dilute errors by the size of the head; displacements do not.
//! - [`max_normal_turn`]: smoothness of one pose — the largest angle by which a triangle's
//!   normal turns between neutral and posed. A crease, fold or spike shows as a triangle
//!   whose normal turns much more than any of the motion it was cloned from; a smooth clone
//!   of a smooth motion turns its normals about as much as the source does (displacement and
//!   face scale by the same FAPU, so the turn is scale free). [`normal_turn_ratio`] compares
//!   the two.

use glam::Vec3;

use super::SurfaceMotion;

/// Below this turn (radians, 1°) a pose counts as flat: [`normal_turn_ratio`] divides by at
/// least this, so a FAP that barely bends its source (a rigid slide of a region) does not
/// make a sub-degree target turn look like a crease.
pub const NORMAL_TURN_FLOOR: f64 = std::f64::consts::PI / 180.0;

/// The largest normal turn of a pose and where it is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NormalTurn {
    /// The angle in radians, `0..=π`.
    pub angle: f64,
    /// The triangle (index into the triangles given) turning most, if any turned.
    pub triangle: Option<usize>,
}

/// Largest turn of a triangle's normal from `neutral` to `posed` (same vertex order).
///
/// For a triangle `(a, b, c)` with unit normal `n = (b−a)×(c−a) / ‖(b−a)×(c−a)‖` at neutral
/// and `n'` posed, the turn is `θ = atan2(‖n×n'‖, n·n') ∈ [0, π]` (the atan2 form stays exact
/// for tiny and near-π angles, where `acos` loses digits). The result is `max θ` over the
/// triangles. A triangle degenerate at neutral (twice its area under 1e-12 of the squared
/// longest edge, or a corner out of range) has no normal and is skipped; one that collapses
/// when posed (its area falls under 1e-6 of its neutral area) counts as a full turn `π`: a
/// collapse is a fold.
pub fn max_normal_turn(neutral: &[Vec3], posed: &[Vec3], triangles: &[[u32; 3]]) -> NormalTurn {
    let mut best = NormalTurn::default();
    let cross = |p: &[Vec3], t: &[u32; 3]| -> Option<(glam::DVec3, f64)> {
        let [a, b, c] = t.map(|v| p.get(v as usize).map(|q| q.as_dvec3()));
        let (a, b, c) = (a?, b?, c?);
        let (e1, e2) = (b - a, c - a);
        let longest = e1
            .length_squared()
            .max(e2.length_squared())
            .max((c - b).length_squared());
        Some((e1.cross(e2), longest))
    };
    for (i, t) in triangles.iter().enumerate() {
        let (Some((n0, l0)), Some((n1, _))) = (cross(neutral, t), cross(posed, t)) else {
            continue;
        };
        let a0 = n0.length();
        if a0.is_nan() || a0 <= 1e-12 * l0 {
            continue;
        }
        let a1 = n1.length();
        let angle = if a1 < 1e-6 * a0 || !a1.is_finite() {
            std::f64::consts::PI
        } else {
            n0.cross(n1).length().atan2(n0.dot(n1))
        };
        if angle > best.angle {
            best = NormalTurn {
                angle,
                triangle: Some(i),
            };
        }
    }
    best
}

/// How much more a cloned pose turns its normals than its source pose: `target / max(source,
/// NORMAL_TURN_FLOOR)` with both the [`max_normal_turn`] angles (radians). Up to about 1 the
/// clone is as smooth as the source; well above, the clone has a crease, fold or spike the
/// source does not.
pub fn normal_turn_ratio(source: f64, target: f64) -> f64 {
    target / source.max(NORMAL_TURN_FLOOR)
}

/// Dense displacement of every vertex for a motion.
pub fn dense(motion: &SurfaceMotion, vertex_count: usize) -> Vec<Vec3> {
    let mut d = vec![Vec3::ZERO; vertex_count];
    for &(v, o) in &motion.offsets {
        if let Some(slot) = d.get_mut(v as usize) {
            *slot = o;
        }
    }
    d
}

/// Whether two motions are the same morph target (key and value).
fn same_target(a: &SurfaceMotion, b: &SurfaceMotion) -> bool {
    a.key == b.key && a.value.to_bits() == b.value.to_bits()
}

/// Formula (1) of seed 002, in percent: `neutral` is the face both motion sets live on.
/// Motions are paired by key *and value* (a multi-interval table gives several motions of one
/// key); a motion missing from `actual` counts as a zero motion.
pub fn morph_target_error(
    neutral: &[Vec3],
    expected: &[SurfaceMotion],
    actual: &[SurfaceMotion],
) -> f64 {
    if expected.is_empty() {
        return 0.0;
    }
    let mut sum = 0.0;
    for e in expected {
        let de = dense(e, neutral.len());
        let da = actual
            .iter()
            .find(|a| same_target(a, e))
            .map(|a| dense(a, neutral.len()))
            .unwrap_or_else(|| vec![Vec3::ZERO; neutral.len()]);
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for ((p, a), b) in neutral.iter().zip(&de).zip(&da) {
            let vs = *p + *a;
            let vt = *p + *b;
            num += (vs - vt).length() as f64;
            den += vs.length() as f64;
        }
        if den > 0.0 {
            sum += num / den;
        }
    }
    sum / expected.len() as f64 * 100.0
}

/// Per-motion relative displacement error `Σ‖dE − dA‖ / Σ‖dE‖` in percent, paired by key and
/// value like [`morph_target_error`] (motions of `expected` whose displacements are all zero
/// are skipped).
pub fn displacement_errors(
    vertex_count: usize,
    expected: &[SurfaceMotion],
    actual: &[SurfaceMotion],
) -> Vec<(crate::fat::TableKey, f64)> {
    let mut out = Vec::new();
    for e in expected {
        let de = dense(e, vertex_count);
        let da = actual
            .iter()
            .find(|a| same_target(a, e))
            .map(|a| dense(a, vertex_count))
            .unwrap_or_else(|| vec![Vec3::ZERO; vertex_count]);
        let den: f64 = de.iter().map(|d| d.length() as f64).sum();
        if den == 0.0 {
            continue;
        }
        let num: f64 = de
            .iter()
            .zip(&da)
            .map(|(a, b)| (*a - *b).length() as f64)
            .sum();
        out.push((e.key, num / den * 100.0));
    }
    out
}

/// Mean of [`displacement_errors`], in percent.
pub fn displacement_error(
    vertex_count: usize,
    expected: &[SurfaceMotion],
    actual: &[SurfaceMotion],
) -> f64 {
    let e = displacement_errors(vertex_count, expected, actual);
    if e.is_empty() {
        0.0
    } else {
        e.iter().map(|x| x.1).sum::<f64>() / e.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fat::TableKey;
    use crate::spec::FapId;

    #[test]
    fn normal_turn_of_a_hinged_pair_is_the_hinge_angle() {
        // Two triangles sharing the edge (0,0,0)-(1,0,0); the second folds up by 30° about
        // that edge, the first stays.
        let neutral = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(0.5, -1.0, 0.0),
        ];
        let tris = [[0, 1, 2], [1, 0, 3]];
        let a = 30f32.to_radians();
        let mut posed = neutral.clone();
        posed[3] = Vec3::new(0.5, -a.cos(), a.sin());
        let t = max_normal_turn(&neutral, &posed, &tris);
        assert!((t.angle - 30f64.to_radians()).abs() < 1e-5, "{t:?}");
        assert_eq!(t.triangle, Some(1));
        // A rigid motion of the whole pair turns both by its rotation, a translation by 0.
        let moved: Vec<Vec3> = neutral
            .iter()
            .map(|&p| p + Vec3::new(3.0, 1.0, 2.0))
            .collect();
        assert!(max_normal_turn(&neutral, &moved, &tris).angle < 1e-9);
        // A collapsed triangle is a full fold; a degenerate neutral triangle is skipped.
        posed[3] = Vec3::new(0.5, 0.0, 0.0);
        assert_eq!(
            max_normal_turn(&neutral, &posed, &tris).angle,
            std::f64::consts::PI
        );
        let flat = [[0, 1, 1]];
        assert_eq!(
            max_normal_turn(&neutral, &posed, &flat),
            NormalTurn::default()
        );
        // The ratio floors a nearly still source at 1°.
        assert!((normal_turn_ratio(0.0, 2f64.to_radians()) - 2.0).abs() < 1e-12);
        assert!((normal_turn_ratio(0.2, 0.3) - 1.5).abs() < 1e-12);
    }

    #[test]
    fn errors_are_zero_for_identical_and_positive_otherwise() {
        let neutral = vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let m = SurfaceMotion {
            key: TableKey::LowLevel(FapId::OPEN_JAW),
            value: 100.0,
            offsets: vec![(1, Vec3::new(0.0, -0.5, 0.0))],
        };
        assert_eq!(
            morph_target_error(&neutral, std::slice::from_ref(&m), std::slice::from_ref(&m)),
            0.0
        );
        assert_eq!(
            displacement_error(2, std::slice::from_ref(&m), std::slice::from_ref(&m)),
            0.0
        );
        let mut half = m.clone();
        half.offsets[0].1 *= 0.5;
        // Displacement error: |0.25| / |0.5| = 50 %.
        assert!(
            (displacement_error(2, std::slice::from_ref(&m), &[half.clone()]) - 50.0).abs() < 1e-9
        );
        // Formula (1): 0.25 / (1 + 0.5) = 16.67 %.
        let e = morph_target_error(&neutral, std::slice::from_ref(&m), &[half]);
        assert!((e - 100.0 / 6.0).abs() < 1e-4, "{e}");
        // Two motions of one key (a multi-interval table) pair by value, not by key alone.
        let mut neg = m.clone();
        neg.value = -100.0;
        neg.offsets[0].1 = -neg.offsets[0].1;
        let both = [m.clone(), neg];
        assert_eq!(morph_target_error(&neutral, &both, &both), 0.0);
        assert_eq!(displacement_error(2, &both, &both), 0.0);
        // A missing key counts as no motion at all.
        assert!((displacement_error(2, &[m], &[]) - 100.0).abs() < 1e-9);
    }
}
