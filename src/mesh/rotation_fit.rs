//! The rotation that best takes one set of centred points onto another (Kabsch 1976; with
//! the scale of Umeyama 1991), as one plain function for every caller: the clone's
//! similarity alignment, the rig's rigid eyeball turns, the glTF eye-joint fit.
//!
//! Math: given pairs `(pᵢ, qᵢ)` already centred (each caller chooses its centres: both means,
//! or a fixed pivot for `p`), the rotation minimising `Σ |R pᵢ − qᵢ|²` is the polar factor of
//! the covariance `H = Σ qᵢ pᵢᵀ = U Σ Vᵀ`: `R = U D Vᵀ`, where `D = diag(1, 1, det(U Vᵀ))`
//! turns a reflection into the nearest rotation. `trace(D Σ)` is what Umeyama's scale needs
//! (`s = trace(D Σ) / Σ |pᵢ|²`).

use glam::{DMat3, DVec3};
use nalgebra::{Matrix3, Vector3};

/// A fitted rotation and what the covariance said about it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotationFit {
    /// `R`, a proper rotation (det +1).
    pub rotation: DMat3,
    /// Singular values of the covariance, largest first, the last one negated where a
    /// reflection was turned into a rotation (so their sum is `trace(D Σ)`).
    pub singular_values: [f64; 3],
}

impl RotationFit {
    /// How many singular values exceed `relative` × the largest: 3 for points spanning space,
    /// 2 for coplanar points (still a unique rotation), 1 or 0 for collinear or coincident
    /// points (the rotation about their line is undetermined).
    pub fn rank(&self, relative: f64) -> usize {
        let largest = self.singular_values[0].abs();
        self.singular_values
            .iter()
            .filter(|s| s.abs() > relative * largest)
            .count()
    }
}

/// The least-squares rotation taking the centred `pᵢ` onto the centred `qᵢ`; `None` when the
/// decomposition did not converge or the input is not finite.
pub fn fit_rotation(pairs: impl IntoIterator<Item = (DVec3, DVec3)>) -> Option<RotationFit> {
    let column = |d: DVec3| Vector3::new(d.x, d.y, d.z);
    let mut h = Matrix3::<f64>::zeros();
    for (p, q) in pairs {
        h += column(q) * column(p).transpose();
    }
    if !h.iter().all(|x| x.is_finite()) {
        return None;
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    // nalgebra sorts singular values in decreasing order, so the flip falls on the smallest.
    let mut sv = svd.singular_values;
    let mut d = Matrix3::<f64>::identity();
    if (u * vt).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
        sv[2] = -sv[2];
    }
    let r = u * d * vt;
    // nalgebra is column-major, as glam's column arrays are.
    let rotation = DMat3::from_cols_slice(r.as_slice());
    Some(RotationFit {
        rotation,
        singular_values: [sv[0], sv[1], sv[2]],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    fn cloud() -> Vec<DVec3> {
        (0..12)
            .map(|i| {
                let t = f64::from(i);
                DVec3::new(
                    (t * 0.618).fract() - 0.5,
                    (t * 0.414 + 0.1).fract() - 0.5,
                    (t * 0.732 + 0.3).fract() - 0.5,
                )
            })
            .collect()
    }

    #[test]
    fn a_known_rotation_is_found_with_its_scale() {
        let turn = DQuat::from_euler(glam::EulerRot::YXZ, 0.4, -0.2, 0.1);
        let p = cloud();
        let mean = p.iter().sum::<DVec3>() / p.len() as f64;
        let pairs: Vec<_> = p
            .iter()
            .map(|&x| (x - mean, turn * (x - mean) * 2.5))
            .collect();
        let fit = fit_rotation(pairs.iter().copied()).unwrap();
        let want = DMat3::from_quat(turn);
        assert!(fit.rotation.abs_diff_eq(want, 1e-12), "{:?}", fit.rotation);
        let var: f64 = pairs.iter().map(|(a, _)| a.length_squared()).sum();
        let scale = fit.singular_values.iter().sum::<f64>() / var;
        assert!((scale - 2.5).abs() < 1e-12, "scale {scale}");
        assert_eq!(fit.rank(1e-9), 3);
    }

    #[test]
    fn a_mirror_image_gives_the_nearest_proper_rotation() {
        let p = cloud();
        let pairs: Vec<_> = p.iter().map(|&x| (x, DVec3::new(-x.x, x.y, x.z))).collect();
        let fit = fit_rotation(pairs).unwrap();
        assert!((fit.rotation.determinant() - 1.0).abs() < 1e-12);
        assert!(fit.singular_values[2] <= 0.0);
    }

    #[test]
    fn collinear_points_have_rank_one_and_nan_gives_none() {
        let line: Vec<_> = (0..5)
            .map(|i| {
                let x = DVec3::X * f64::from(i - 2);
                (x, x)
            })
            .collect();
        assert_eq!(fit_rotation(line).unwrap().rank(1e-12), 1);
        assert!(fit_rotation([(DVec3::NAN, DVec3::X)]).is_none());
    }
}
