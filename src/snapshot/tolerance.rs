//! The tolerance of a comparison or snapshot: absolute in the face's units, or relative to
//! the face's size (the neutral's bounding-box diagonal in the face frame).

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use super::SnapshotError;

/// The default: 1e-4 of the face size (for a 25 cm head, 25 µm), far above float noise
/// and far below anything an eye can see.
pub const DEFAULT_RELATIVE: f64 = 1e-4;

/// A tolerance as given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tolerance {
    /// A distance in the face's units.
    Absolute(f64),
    /// A fraction of the face size (written `1e-4x`).
    Relative(f64),
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance::Relative(DEFAULT_RELATIVE)
    }
}

impl Tolerance {
    /// Checks the number is positive and finite.
    pub fn checked(self) -> Result<Tolerance, SnapshotError> {
        let v = match self {
            Tolerance::Absolute(v) | Tolerance::Relative(v) => v,
        };
        if v.is_finite() && v > 0.0 {
            Ok(self)
        } else {
            Err(SnapshotError::BadTolerance {
                given: self.to_string(),
            })
        }
    }

    /// The distance this tolerance stands for on a face of size `face_size`.
    pub fn absolute(self, face_size: f64) -> f64 {
        match self {
            Tolerance::Absolute(v) => v,
            Tolerance::Relative(r) => r * face_size,
        }
    }
}

impl fmt::Display for Tolerance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tolerance::Absolute(v) => write!(f, "{v}"),
            Tolerance::Relative(r) => write!(f, "{r}x"),
        }
    }
}

impl FromStr for Tolerance {
    type Err = SnapshotError;

    /// `0.001` (absolute) or `1e-4x` (relative to the face size).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || SnapshotError::BadTolerance {
            given: s.to_string(),
        };
        let t = s.trim();
        let tol = match t.strip_suffix(['x', 'X']) {
            Some(r) => Tolerance::Relative(r.trim().parse().map_err(|_| bad())?),
            None => Tolerance::Absolute(t.parse().map_err(|_| bad())?),
        };
        tol.checked().map_err(|_| bad())
    }
}

/// A tolerance resolved on a face: what was given and the distance it means.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResolvedTolerance {
    /// As given (`0.001` or `1e-4x`).
    pub given: String,
    /// The distance in the face's units.
    pub absolute: f64,
    /// The face size it was resolved on (bounding-box diagonal of face A's neutral).
    pub face_size: f64,
}

impl ResolvedTolerance {
    /// `tolerance` on a face of size `face_size`.
    pub fn new(tolerance: Tolerance, face_size: f64) -> Self {
        ResolvedTolerance {
            given: tolerance.to_string(),
            absolute: tolerance.absolute(face_size),
            face_size,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_absolute_and_relative() {
        assert_eq!(
            "0.5".parse::<Tolerance>().unwrap(),
            Tolerance::Absolute(0.5)
        );
        assert_eq!(
            "1e-4x".parse::<Tolerance>().unwrap(),
            Tolerance::Relative(1e-4)
        );
        assert_eq!(
            " 2X ".parse::<Tolerance>().unwrap(),
            Tolerance::Relative(2.0)
        );
        assert_eq!(Tolerance::Relative(1e-4).absolute(30.0), 30.0 * 1e-4);
    }

    #[test]
    fn refuses_what_is_not_positive_and_finite() {
        for bad in ["0", "-1", "nan", "inf", "x", "", "1e-4y", "-1e-3x", "0x"] {
            let e = bad.parse::<Tolerance>().unwrap_err();
            assert!(e.to_string().contains("--tolerance"), "{bad}: {e}");
        }
    }
}
