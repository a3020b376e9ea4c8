//! Step 2 — cylindrical projection about a vertical axis into the 2D alignment space.

use glam::{DVec2, DVec3};

/// A vertical cylinder axis through `(x0, ·, z0)` in the normalised space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cylinder {
    /// x of the axis (the nose tip's, so the nose tip is at angle 0).
    pub x0: f64,
    /// z of the axis (solved so that the mouth has the fixed angular width).
    pub z0: f64,
    /// Angle of the nose tip (0 unless the nose is behind the axis), subtracted from all.
    pub zero: f64,
}

impl Cylinder {
    fn raw_angle(&self, p: DVec3) -> f64 {
        (p.x - self.x0).atan2(p.z - self.z0)
    }

    /// Solves the axis: through the nose tip's x, at the depth where the angle between the
    /// left (`left`, +x) and right mouth corners is `mouth_angle` (radians, in (0, π/2]).
    ///
    /// With a = left − axis and b = right − axis, the width w(z0) = atan2(aₓ, a_z − z0) −
    /// atan2(bₓ, b_z − z0) grows monotonically from 0 (axis infinitely far behind) to at least
    /// π/2 (axis level with the rearmost corner), so bisection finds the unique z0. For a
    /// symmetric mouth (corners ±h at depth z_m) this is the closed form
    /// z0 = z_m − h / tan(mouth_angle / 2).
    pub fn solve(
        nose: DVec3,
        left: DVec3,
        right: DVec3,
        mouth_angle: f64,
    ) -> Result<Cylinder, String> {
        let x0 = nose.x;
        if !(left.x > x0 && right.x < x0) {
            return Err(format!(
                "the mouth corners (x {:.4} and {:.4}, normalised) are not on either side of the \
                 nose tip (x {x0:.4}); is the face in the MPEG-4 frame (+x = face's left)?",
                left.x, right.x
            ));
        }
        if !(mouth_angle > 0.0 && mouth_angle <= std::f64::consts::FRAC_PI_2) {
            return Err(format!("mouth angle {mouth_angle} is not in (0, π/2]"));
        }
        let width = |z0: f64| (left.x - x0).atan2(left.z - z0) - (right.x - x0).atan2(right.z - z0);
        let hi0 = left.z.min(right.z);
        let mut span = (left.x - right.x).max(1e-9);
        let mut lo = hi0 - span;
        let mut guard = 0;
        while width(lo) > mouth_angle {
            span *= 2.0;
            lo = hi0 - span;
            guard += 1;
            if guard > 200 {
                return Err("cannot place the projection axis".into());
            }
        }
        let mut hi = hi0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if width(mid) > mouth_angle {
                hi = mid;
            } else {
                lo = mid;
            }
            if hi - lo <= 1e-15 * (1.0 + hi.abs()) {
                break;
            }
        }
        let mut c = Cylinder {
            x0,
            z0: 0.5 * (lo + hi),
            zero: 0.0,
        };
        c.zero = c.raw_angle(nose);
        Ok(c)
    }

    /// The alignment-space point (angle, y) of `p` and its depth, the negated distance from
    /// the axis (so the smallest depth is the outermost, front-most surface).
    pub fn project(&self, p: DVec3) -> (DVec2, f64) {
        let mut a = self.raw_angle(p) - self.zero;
        if a > std::f64::consts::PI {
            a -= std::f64::consts::TAU;
        } else if a <= -std::f64::consts::PI {
            a += std::f64::consts::TAU;
        }
        let r = DVec2::new(p.x - self.x0, p.z - self.z0).length();
        (DVec2::new(a, p.y), -r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symmetric_mouth_matches_closed_form() {
        let nose = DVec3::new(0.0, -0.5, 0.6);
        let (h, zm) = (0.4, 0.1);
        let c =
            Cylinder::solve(nose, DVec3::new(h, -1.0, zm), DVec3::new(-h, -1.0, zm), 0.8).unwrap();
        let expected = zm - h / (0.4f64).tan();
        assert!((c.z0 - expected).abs() < 1e-12, "{} vs {expected}", c.z0);
        assert_eq!(c.project(nose).0.x, 0.0);
    }

    #[test]
    fn asymmetric_mouth_gets_the_constant_angle() {
        let nose = DVec3::new(0.05, -0.5, 0.6);
        let (l, r) = (DVec3::new(0.5, -1.0, 0.0), DVec3::new(-0.3, -1.0, 0.2));
        for angle in [0.3, 0.8, 1.5] {
            let c = Cylinder::solve(nose, l, r, angle).unwrap();
            let w = c.project(l).0.x - c.project(r).0.x;
            assert!((w - angle).abs() < 1e-9, "{w} vs {angle}");
            assert!(c.project(nose).0.x.abs() < 1e-12);
            // The nose tip is further from the axis, so in front of the mouth corners.
            assert!(c.project(nose).1 < c.project(l).1);
        }
        assert!(Cylinder::solve(nose, r, l, 0.8).is_err());
    }
}
