//! A face's own axes from its feature points, for faces modelled turned in their file: the
//! standard measures FAPU and FAP directions in the face frame (x towards the face's left,
//! y up, z out of the face), and a model facing −z (VRM 0.x avatars, a scan turned round) or
//! lying with z up has that frame turned by quarter turns from its file's.
//!
//! `x` runs from the right pupil (3.6) to the left (3.5); `y` from the mouth (between 2.2
//! and 2.3, else 8.1 and 8.2, else the chin 2.1) to the pupils, made orthogonal to `x`. Each
//! is snapped to the nearest axis of the file (±x, ±y, ±z) and `z = x × y`. A turn is given
//! only where the points agree on it: the chin's up (2.1, when placed) snaps as the mouth's,
//! and the front they show — from the pupils to the nose tip (9.3), else to the mouth —
//! snaps to that `z` (the other way round, the points are a mirror image: a model with its x
//! reversed, not a turned face). Every face modelled upright snaps to its file's own axes
//! whatever its small tilts, and one misplaced point does not turn it.

use glam::{Mat3, Vec3};

use super::FeaturePointSet;
use crate::spec::FeaturePointId;

impl FeaturePointSet {
    /// The quarter turns that stand the face up in its file's axes (module docs), as the
    /// matrix taking file coordinates into upright ones; `None` when it stands upright
    /// already, or its pupils and mouth are not all placed, or they are a mirror image.
    pub fn upright_turn(&self) -> Option<Mat3> {
        let p = |id: FeaturePointId| self.position(id);
        let (left, right) = (p(FeaturePointId::FP_3_5)?, p(FeaturePointId::FP_3_6)?);
        let mouth = match (p(FeaturePointId::FP_2_2), p(FeaturePointId::FP_2_3)) {
            (Some(a), Some(b)) => (a + b) / 2.0,
            _ => match (p(FeaturePointId::FP_8_1), p(FeaturePointId::FP_8_2)) {
                (Some(a), Some(b)) => (a + b) / 2.0,
                _ => p(FeaturePointId::FP_2_1)?,
            },
        };
        let eyes = (left + right) / 2.0;
        let x = (left - right).try_normalize()?;
        // Up from a point below the eyes, made orthogonal to x.
        let up_from = |below: Vec3| {
            let u = eyes - below;
            (u - u.dot(x) * x).try_normalize()
        };
        let y = up_from(mouth)?;
        let sx = snap(x, None);
        let sy = snap(y, Some(sx));
        if sx == Vec3::X && sy == Vec3::Y {
            return None;
        }
        // A turn is taken only where every point agrees on it: the chin's up, and the
        // front (the nose tip, else the mouth, lies in front of the eyes). One misplaced
        // point (a lip bound to the back of the head) does not turn an upright face.
        if let Some(chin) = p(FeaturePointId::FP_2_1) {
            if snap(up_from(chin)?, Some(sx)) != sy {
                return None;
            }
        }
        let sz = sx.cross(sy);
        // The front, out of the plane of x and up: its side of that plane is all it says.
        let front = p(FeaturePointId::FP_9_3).unwrap_or(mouth) - eyes;
        if front.dot(x.cross(y)) * x.cross(y).dot(sz) <= 0.0 {
            return None;
        }
        // Rows: the face's axes in the file; applied to a point, its upright coordinates.
        Some(Mat3::from_cols(sx, sy, sz).transpose())
    }
}

/// The signed file axis nearest `v`, other than `not`'s axis.
fn snap(v: Vec3, not: Option<Vec3>) -> Vec3 {
    [Vec3::X, Vec3::Y, Vec3::Z]
        .into_iter()
        .filter(|a| not.is_none_or(|n| n.dot(*a) == 0.0))
        .map(|a| if v.dot(a) < 0.0 { -a } else { a })
        .max_by(|a, b| v.dot(*a).total_cmp(&v.dot(*b)))
        .unwrap_or(Vec3::X)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fdp::FeaturePoint;

    fn set(points: &[(&str, Vec3)]) -> FeaturePointSet {
        let mut s = FeaturePointSet::new();
        for (id, p) in points {
            s.insert(FeaturePoint::at(id.parse().unwrap(), *p));
        }
        s
    }

    /// An upright face: pupils, lips, nose tip (slightly tilted).
    fn upright() -> Vec<(&'static str, Vec3)> {
        vec![
            ("3.5", Vec3::new(3.2, 0.1, 0.0)),
            ("3.6", Vec3::new(-3.2, -0.1, 0.0)),
            ("2.2", Vec3::new(0.0, -6.0, 1.2)),
            ("2.3", Vec3::new(0.0, -6.4, 1.1)),
            ("9.3", Vec3::new(0.0, -3.5, 2.5)),
        ]
    }

    #[test]
    fn quarter_turns_are_found_and_mirror_images_are_not() {
        assert_eq!(set(&upright()).upright_turn(), None);
        let half_y = Mat3::from_rotation_y(std::f32::consts::PI);
        let z_up = Mat3::from_rotation_x(std::f32::consts::FRAC_PI_2);
        for turned_by in [half_y, z_up, z_up * half_y, Mat3::from_rotation_z(1.6)] {
            let pts: Vec<_> = upright()
                .into_iter()
                .map(|(i, p)| (i, turned_by * p))
                .collect();
            let turn = set(&pts).upright_turn().expect("a turned face");
            let undo = turn * turned_by;
            // Up to the face's own small tilt (and the 1.6 rad roll's remainder).
            assert!(
                undo.x_axis.x > 0.99 && undo.y_axis.y > 0.99 && undo.z_axis.z > 0.99,
                "{undo:?}"
            );
        }
        // The same face mirrored (x reversed, still facing +z): no turn.
        let mirrored: Vec<_> = upright()
            .into_iter()
            .map(|(i, p)| (i, Vec3::new(-p.x, p.y, p.z)))
            .collect();
        assert_eq!(set(&mirrored).upright_turn(), None);
        // An upright face with its lower lip bound to the back of the head: not turned.
        let mut broken = upright();
        broken[3].1 = Vec3::new(0.0, -4.0, -12.0);
        broken.push(("2.1", Vec3::new(0.0, -9.0, 0.8)));
        assert_eq!(set(&broken).upright_turn(), None);
        // Without pupils: nothing to go by.
        assert_eq!(set(&upright()[2..]).upright_turn(), None);
    }
}
