//! Quality measures of a cloning result.
//!
//! - [`morph_target_error`]: formula (1) of Fratarcangeli & Schaerf 2005, the paper's
//!   self-cloning measure: per morph target, `Σ‖vS − vT‖ / Σ‖vS‖` over all vertices of the
//!   *displaced* meshes (absolute positions), averaged over targets, in percent.
//! - [`displacement_error`]: the stricter measure fbakit also reports: per morph target,
//!   `Σ‖dS − dT‖ / Σ‖dS‖` over the displacements only, averaged, in percent. Absolute
//!   positions dilute errors by the size of the head; displacements do not.

use glam::Vec3;

use super::SurfaceMotion;

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
