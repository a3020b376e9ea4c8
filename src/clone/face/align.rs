//! The similarity that aligns the target face onto the source (Umeyama's least-squares fit,
//! with small rotations snapped away; module docs of [`super`], step 2).

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::CloneOptions;
use crate::clone::CloneError;
use crate::error::Result;
use crate::face::FaceModel;
use crate::mesh::rotation_fit::fit_rotation;

/// Largest turn (degrees) of a face's alignment under which it keeps its own axes
/// ([`Similarity::keeps_own_axes`]).
pub const OWN_AXES_MAX_DEGREES: f64 = 20.0;

/// A similarity `p ↦ s·R·p + t`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Similarity {
    /// Uniform scale.
    pub scale: f64,
    /// Rotation.
    pub rotation: glam::DQuat,
    /// Translation.
    pub translation: DVec3,
}

impl Default for Similarity {
    fn default() -> Self {
        Similarity::IDENTITY
    }
}

impl Similarity {
    /// The identity.
    pub const IDENTITY: Similarity = Similarity {
        scale: 1.0,
        rotation: glam::DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// Maps a point.
    pub fn point(&self, p: Vec3) -> Vec3 {
        (self.rotation * p.as_dvec3() * self.scale + self.translation).as_vec3()
    }

    /// The rotation's angle, degrees in [0, 180].
    pub fn turn_degrees(&self) -> f64 {
        // A quaternion's angle comes in [0, 360); q and −q turn alike.
        let a = self.rotation.to_axis_angle().1.to_degrees();
        a.min(360.0 - a)
    }

    /// Whether the face this maps is taken as modelled upright in its own axes: the turn is at
    /// most `OWN_AXES_MAX_DEGREES` (20°). FAP directions and FAPU are along a face's own axes, so
    /// two upright faces tilted a few degrees apart keep their own (CANDIDE onto the ICT head
    /// turns 6.65°); a face turned further is taken as placed turned (a scan lying on its
    /// side, a Z-up file), and clones like the same face upright.
    pub fn keeps_own_axes(&self) -> bool {
        self.turn_degrees() <= OWN_AXES_MAX_DEGREES
    }

    /// Maps a displacement.
    pub fn vector(&self, v: Vec3) -> Vec3 {
        (self.rotation * v.as_dvec3() * self.scale).as_vec3()
    }

    /// Maps a displacement back (`Rᵀ v / s`).
    pub fn inverse_vector(&self, v: DVec3) -> DVec3 {
        self.rotation.inverse() * v / self.scale
    }

    /// Maps a point back.
    pub fn inverse_point(&self, p: DVec3) -> DVec3 {
        self.inverse_vector(p - self.translation)
    }

    /// Least-squares similarity taking `from[i]` onto `to[i]` (Umeyama 1991). Needs three
    /// non-collinear pairs.
    pub fn fit(from: &[DVec3], to: &[DVec3]) -> Result<Similarity> {
        let n = from.len().min(to.len());
        if n < 3 {
            return Err(CloneError::TooFewSharedPoints { found: n }.into());
        }
        let mf = from[..n].iter().sum::<DVec3>() / n as f64;
        let mt = to[..n].iter().sum::<DVec3>() / n as f64;
        let var_f = from[..n]
            .iter()
            .map(|a| (*a - mf).length_squared())
            .sum::<f64>()
            / n as f64;
        let pairs = (0..n).map(|i| ((from[i] - mf) / n as f64, to[i] - mt));
        let fit = fit_rotation(pairs).ok_or(CloneError::SvdFailed)?;
        // Rank check: collinear points leave the rotation undetermined.
        if var_f <= 0.0 || fit.rank(1e-12) < 2 {
            return Err(CloneError::CollinearPoints.into());
        }
        let scale = fit.singular_values.iter().sum::<f64>() / var_f;
        let rm = fit.rotation;
        let rotation = glam::DQuat::from_mat3(&rm).normalize();
        let translation = mt - rotation * mf * scale;
        if !scale.is_finite() || scale <= 0.0 || !translation.is_finite() {
            return Err(CloneError::DegenerateSimilarity.into());
        }
        Ok(Similarity {
            scale,
            rotation,
            translation,
        })
    }

    /// [`Similarity::fit`], except that a rotation within `snap_degrees` of a quarter-turn
    /// rotation (one of the 24 that map the axes onto the axes: none at all for a face
    /// modelled upright, a half turn about y for one modelled facing −z, as VRM 0.x avatars
    /// are) is taken as exactly that turn: scale and translation are then refitted with it
    /// (least squares about the centroids, `s = Σ Qa·b / Σ |a|²`). Faces modelled upright in
    /// the MPEG-4 frame but with other proportions fit with a small spurious tilt (0.94° for
    /// the synthetic alma → bruno), which only turns FAP directions away from the target's
    /// axes — and, as the scale is fitted with the tilt, shrinks every FAPU-scaled motion
    /// (the ICT head turned round: 4 % smaller than the upright head's).
    pub fn fit_snapped(from: &[DVec3], to: &[DVec3], snap_degrees: f64) -> Result<Similarity> {
        let full = Similarity::fit(from, to)?;
        let Some(turn) = quarter_turns()
            .into_iter()
            .map(|q| (q, q.angle_between(full.rotation).to_degrees()))
            .filter(|&(_, a)| a <= snap_degrees)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(q, _)| q)
        else {
            return Ok(full);
        };
        let n = from.len().min(to.len());
        let mf = from[..n].iter().sum::<DVec3>() / n as f64;
        let mt = to[..n].iter().sum::<DVec3>() / n as f64;
        // No turn: the points as they are (bit for bit what an upright face always had).
        let upright = turn == glam::DQuat::IDENTITY;
        let turned = |v: DVec3| if upright { v } else { turn * v };
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            let a = from[i] - mf;
            num += turned(a).dot(to[i] - mt);
            den += a.length_squared();
        }
        let scale = num / den;
        if !scale.is_finite() || scale <= 0.0 {
            return Ok(full);
        }
        Ok(Similarity {
            scale,
            rotation: turn,
            translation: mt - turned(mf) * scale,
        })
    }

    /// Rotation angle in degrees.
    pub fn angle_degrees(&self) -> f64 {
        self.rotation.to_axis_angle().1.to_degrees()
    }
}

/// The 24 rotations that map the coordinate axes onto the axes (signed permutations of
/// determinant +1), the identity first.
fn quarter_turns() -> Vec<glam::DQuat> {
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut out = vec![glam::DQuat::IDENTITY];
    for x in axes {
        for y in axes {
            if x == y {
                continue;
            }
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let (x, y) = (x * sx, y * sy);
                let m = glam::DMat3::from_cols(x, y, x.cross(y));
                let q = glam::DQuat::from_mat3(&m).normalize();
                if !out.iter().any(|o| o.angle_between(q) < 1e-9) {
                    out.push(q);
                }
            }
        }
    }
    out
}

/// Feature points both faces place: `(target positions, source positions)`, in target order.
fn shared_fps(source: &FaceModel, target: &FaceModel) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut from = Vec::new();
    let mut to = Vec::new();
    for fp in target.feature_points.iter() {
        if let (Some(pt), Some(ps)) = (fp.position, source.feature_points.position(fp.id)) {
            if pt.is_finite() && ps.is_finite() {
                from.push(pt.as_dvec3());
                to.push(ps.as_dvec3());
            }
        }
    }
    (from, to)
}

/// The target → source alignment [`super::clone_face`] uses: the snapped fit over the shared
/// feature points, or the identity when [`CloneOptions::align`] is off.
pub(super) fn face_alignment(
    source: &FaceModel,
    target: &FaceModel,
    opts: &CloneOptions,
) -> Result<Similarity> {
    if opts.align {
        let (from, to) = shared_fps(source, target);
        Similarity::fit_snapped(&from, &to, opts.align_snap_degrees)
    } else {
        Ok(Similarity::IDENTITY)
    }
}

/// RMS distance of the target's feature points mapped by `alignment` to the source's, in
/// source units.
pub(super) fn alignment_rms(source: &FaceModel, target: &FaceModel, alignment: &Similarity) -> f64 {
    let (from, to) = shared_fps(source, target);
    let ss: f64 = from
        .iter()
        .zip(&to)
        .map(|(f, t)| (alignment.point(f.as_vec3()).as_dvec3() - *t).length_squared())
        .sum();
    (ss / from.len().max(1) as f64).sqrt()
}
