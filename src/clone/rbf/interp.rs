//! Hardy multiquadric scattered-data interpolation with an affine part.
//!
//! `f(p) = p + Σ_j w_j · sqrt(‖q − c_j‖² + r_j²) + A q + b`, `q = (p − o) / s`, fitted so that
//! `f(p_i) = u_i` exactly at every centre. The interpolant is fitted to the *displacements*
//! `u_i − p_i` (the identity is added back), so an identity correspondence set gives
//! `w = 0, A = 0, b = 0` and `f` is the identity to rounding error. Coordinates are centred
//! and scaled (`o`, `s`) before building the system to keep it well conditioned.
//!
//! `r_j` is the distance from centre `j` to its nearest other centre (the usual choice
//! for Hardy multiquadrics in landmark volume morphing, Fang et al. 1996 and Eck 1991):
//! dense clusters get sharp basis functions and isolated centres smooth ones.
//!
//! The `(n+4)×(n+4)` system `[Φ P; Pᵀ 0]` is indefinite (and with per-centre `r_j` not even
//! symmetric), so it is solved with faer's dense LU with partial pivoting, once for the three
//! right-hand sides (faer's blocked LU is about 9× faster than nalgebra's at a few thousand
//! centres, which is where refinement takes a dense source).

use faer::linalg::solvers::Solve;
use faer::Mat;
use glam::{DVec3, Vec3};

use crate::clone::RbfFitError;

/// A fitted multiquadric volume morph.
#[derive(Clone, Debug)]
pub(crate) struct Multiquadric {
    origin: DVec3,
    scale: f64,
    centres: Vec<DVec3>,
    #[cfg_attr(not(test), allow(dead_code))] // read by tests
    weights: Vec<DVec3>,
    /// The centres and weights again, one array per component (`[cx, cy, cz, r², wx, wy,
    /// wz]`), so the evaluation loop vectorises.
    soa: [Vec<f64>; 7],
    /// Rows: the x, y, z and constant terms of the affine part.
    affine: [DVec3; 4],
    /// Ratio of the largest to the smallest LU pivot magnitude: a cheap conditioning figure.
    pub pivot_ratio: f64,
}

/// Largest pivot ratio accepted before the system is declared singular.
const MAX_PIVOT_RATIO: f64 = 1e13;

impl Multiquadric {
    /// Fits `f(p_i) = u_i`. The centres must be distinct (merge coincident ones first) and
    /// span 3D space (at least four not coplanar), else the system is singular and this
    /// returns the [`RbfFitError`] saying why.
    pub fn fit(pairs: &[(Vec3, Vec3)]) -> Result<Multiquadric, RbfFitError> {
        let n = pairs.len();
        if n < 4 {
            return Err(RbfFitError::TooFew { found: n });
        }
        if pairs.iter().any(|(p, u)| !p.is_finite() || !u.is_finite()) {
            return Err(RbfFitError::NonFinite);
        }
        let origin = pairs.iter().map(|(p, _)| p.as_dvec3()).sum::<DVec3>() / n as f64;
        let scale = pairs
            .iter()
            .map(|(p, _)| (p.as_dvec3() - origin).length())
            .fold(0.0, f64::max);
        if scale <= 0.0 || !scale.is_finite() {
            return Err(RbfFitError::AllCoincide);
        }
        let centres: Vec<DVec3> = pairs
            .iter()
            .map(|(p, _)| (p.as_dvec3() - origin) / scale)
            .collect();
        check_not_coplanar(&centres)?;
        let radii2: Vec<f64> = (0..n)
            .map(|i| {
                let mut best = f64::INFINITY;
                for (j, c) in centres.iter().enumerate() {
                    if j != i {
                        best = best.min(c.distance_squared(centres[i]));
                    }
                }
                best
            })
            .collect();
        if radii2.iter().any(|&r| r.is_nan() || r <= 1e-20) {
            return Err(RbfFitError::Coincide);
        }
        let m = n + 4;
        let mut a = Mat::<f64>::zeros(m, m);
        let mut b = Mat::<f64>::zeros(m, 3);
        for i in 0..n {
            for j in 0..n {
                a[(i, j)] = (centres[i].distance_squared(centres[j]) + radii2[j]).sqrt();
            }
            let c = centres[i];
            for (k, x) in [c.x, c.y, c.z, 1.0].into_iter().enumerate() {
                a[(i, n + k)] = x;
                a[(n + k, i)] = x;
            }
            let d = (pairs[i].1.as_dvec3() - pairs[i].0.as_dvec3()).to_array();
            for (k, x) in d.into_iter().enumerate() {
                b[(i, k)] = x;
            }
        }
        let lu = a.partial_piv_lu();
        let u = lu.U();
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for i in 0..m {
            let x = u[(i, i)].abs();
            lo = lo.min(x);
            hi = hi.max(x);
        }
        let pivot_ratio = if lo > 0.0 { hi / lo } else { f64::INFINITY };
        if pivot_ratio.is_nan() || pivot_ratio >= MAX_PIVOT_RATIO {
            return Err(RbfFitError::Singular { pivot_ratio });
        }
        lu.solve_in_place(&mut b);
        let x = b;
        if (0..m).any(|i| (0..3).any(|k| !x[(i, k)].is_finite())) {
            return Err(RbfFitError::NonFiniteSolution);
        }
        let row = |i: usize| DVec3::new(x[(i, 0)], x[(i, 1)], x[(i, 2)]);
        let weights: Vec<DVec3> = (0..n).map(row).collect();
        let soa = [
            centres.iter().map(|c| c.x).collect(),
            centres.iter().map(|c| c.y).collect(),
            centres.iter().map(|c| c.z).collect(),
            radii2,
            weights.iter().map(|w| w.x).collect(),
            weights.iter().map(|w| w.y).collect(),
            weights.iter().map(|w| w.z).collect(),
        ];
        Ok(Multiquadric {
            origin,
            scale,
            soa,
            weights,
            affine: [row(n), row(n + 1), row(n + 2), row(n + 3)],
            centres,
            pivot_ratio,
        })
    }

    /// The displacement part `f(p) − p`, in f64.
    pub fn displacement(&self, p: DVec3) -> DVec3 {
        let q = (p - self.origin) / self.scale;
        let s = self.affine[0] * q.x + self.affine[1] * q.y + self.affine[2] * q.z + self.affine[3];
        let [cx, cy, cz, r2, wx, wy, wz] = &self.soa;
        let n = cx.len();
        let (cy, cz, r2, wx, wy, wz) = (&cy[..n], &cz[..n], &r2[..n], &wx[..n], &wy[..n], &wz[..n]);
        let (mut sx, mut sy, mut sz) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let (dx, dy, dz) = (q.x - cx[i], q.y - cy[i], q.z - cz[i]);
            let phi = (dx * dx + dy * dy + dz * dz + r2[i]).sqrt();
            sx += wx[i] * phi;
            sy += wy[i] * phi;
            sz += wz[i] * phi;
        }
        s + DVec3::new(sx, sy, sz)
    }

    /// `f(p + d) − f(p)` given `disp_p = self.displacement(p)` (one evaluation instead of
    /// two when many offsets of one point are carried over).
    pub fn moved_from(&self, p: DVec3, disp_p: DVec3, d: Vec3) -> Vec3 {
        let dd = d.as_dvec3();
        (dd + self.displacement(p + dd) - disp_p).as_vec3()
    }

    /// `f(p)`.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        let pd = p.as_dvec3();
        (pd + self.displacement(pd)).as_vec3()
    }

    /// `f(p + d) − f(p)`, computed without cancelling the large `p` terms.
    #[cfg(test)]
    pub fn moved(&self, p: Vec3, d: Vec3) -> Vec3 {
        let pd = p.as_dvec3();
        self.moved_from(pd, self.displacement(pd), d)
    }

    /// Number of centres.
    pub fn len(&self) -> usize {
        self.centres.len()
    }
}

/// The affine part needs four centres that are not coplanar (else `P` loses rank).
fn check_not_coplanar(centres: &[DVec3]) -> Result<(), RbfFitError> {
    let mean = centres.iter().sum::<DVec3>() / centres.len() as f64;
    let mut cov = nalgebra::Matrix3::<f64>::zeros();
    for c in centres {
        let d = *c - mean;
        let v = nalgebra::Vector3::new(d.x, d.y, d.z);
        cov += v * v.transpose();
    }
    cov /= centres.len() as f64;
    let eig = cov.symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if lo.is_nan() || hi.is_nan() || lo <= 1e-12 * hi || hi <= 0.0 {
        return Err(RbfFitError::Coplanar);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud() -> Vec<Vec3> {
        // Deterministic scattered points in a 2×2×1 box.
        (0..30)
            .map(|i| {
                let t = i as f32;
                Vec3::new(
                    (t * 0.618).fract() * 2.0 - 1.0,
                    (t * 0.414 + 0.1).fract() * 2.0 - 1.0,
                    (t * 0.732 + 0.3).fract(),
                )
            })
            .collect()
    }

    #[test]
    fn interpolates_exactly_at_centres() {
        let pairs: Vec<(Vec3, Vec3)> = cloud()
            .into_iter()
            .map(|p| {
                (
                    p,
                    p + Vec3::new(p.y * p.y, (3.0 * p.x).sin() * 0.1, p.z * p.x),
                )
            })
            .collect();
        let f = Multiquadric::fit(&pairs).unwrap();
        assert!(f.pivot_ratio.is_finite() && f.len() == 30);
        for (p, u) in &pairs {
            assert!(
                f.apply(*p).distance(*u) < 1e-5,
                "{p} → {} vs {u}",
                f.apply(*p)
            );
        }
    }

    #[test]
    fn reproduces_affine_maps_exactly() {
        let m = glam::Mat3::from_cols(
            Vec3::new(1.2, 0.1, 0.0),
            Vec3::new(-0.2, 0.9, 0.05),
            Vec3::new(0.0, 0.3, 1.1),
        );
        let t = Vec3::new(0.5, -2.0, 0.25);
        let pairs: Vec<(Vec3, Vec3)> = cloud().into_iter().map(|p| (p, m * p + t)).collect();
        let f = Multiquadric::fit(&pairs).unwrap();
        for probe in [Vec3::new(0.3, -0.7, 0.2), Vec3::new(3.0, 2.0, -1.0)] {
            assert!(f.apply(probe).distance(m * probe + t) < 1e-4);
        }
        assert!(f.weights.iter().all(|w| w.length() < 1e-3));
        // Identity: displacements exactly zero.
        let id: Vec<(Vec3, Vec3)> = cloud().into_iter().map(|p| (p, p)).collect();
        let f = Multiquadric::fit(&id).unwrap();
        assert_eq!(f.moved(Vec3::ONE, Vec3::X), Vec3::X);
    }

    #[test]
    fn degenerate_sets_are_errors() {
        let flat: Vec<(Vec3, Vec3)> = cloud()
            .into_iter()
            .map(|p| (Vec3::new(p.x, p.y, 0.0), p))
            .collect();
        assert!(Multiquadric::fit(&flat).is_err());
        let same = vec![(Vec3::ONE, Vec3::ZERO); 10];
        assert!(Multiquadric::fit(&same).is_err());
        let mut dup: Vec<(Vec3, Vec3)> = cloud().into_iter().map(|p| (p, p)).collect();
        dup.push(dup[3]);
        assert!(Multiquadric::fit(&dup).is_err());
        assert!(Multiquadric::fit(&dup[..3]).is_err());
        let mut nan: Vec<(Vec3, Vec3)> = cloud().into_iter().map(|p| (p, p)).collect();
        nan[0].1.x = f32::NAN;
        assert!(Multiquadric::fit(&nan).is_err());
    }
}
