//! FAP units (FAPU): the six unit sizes in which FAP values are measured on one face.
//!
//! Five are neutral-face distances divided by 1024 (IRISD0, ES0, ENS0, MNS0, MW0); AU is the
//! fixed angle 1e-5 rad. Multiplying a FAP value by its FAPU gives a model-space distance (or an
//! angle in radians), which is what makes one FAP stream animate any compliant face.

use serde::{Deserialize, Serialize};

use crate::spec::{FapId, FapuKind, AU_RADIANS, FAPU_DIVISOR};

/// The five neutral-face distances of one face, in model units (not yet divided by 1024).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FapuDistances {
    /// IRISD0: iris diameter (upper to lower eyelid distance on the neutral face).
    pub irisd0: f64,
    /// ES0: eye separation (distance between the pupil centres).
    pub es0: f64,
    /// ENS0: eye to nose separation.
    pub ens0: f64,
    /// MNS0: mouth to nose separation.
    pub mns0: f64,
    /// MW0: mouth width.
    pub mw0: f64,
}

/// The six FAP units of one face: model-space length per FAP unit (angle for AU).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fapu {
    /// The neutral distances the units were derived from.
    pub distances: FapuDistances,
}

impl Fapu {
    /// Units from neutral-face distances. Every distance must be finite and positive.
    pub fn from_distances(distances: FapuDistances) -> Result<Fapu, String> {
        let named = [
            ("IRISD0", distances.irisd0),
            ("ES0", distances.es0),
            ("ENS0", distances.ens0),
            ("MNS0", distances.mns0),
            ("MW0", distances.mw0),
        ];
        for (name, d) in named {
            if !d.is_finite() || d <= 0.0 {
                return Err(format!(
                    "FAPU distance {name} is {d}; it must be a positive finite length"
                ));
            }
        }
        Ok(Fapu { distances })
    }

    /// Size of one unit of `kind`: a model-space length, or radians for AU.
    pub fn unit(&self, kind: FapuKind) -> f64 {
        let d = &self.distances;
        match kind {
            FapuKind::Irisd => d.irisd0 / FAPU_DIVISOR,
            FapuKind::Es => d.es0 / FAPU_DIVISOR,
            FapuKind::Ens => d.ens0 / FAPU_DIVISOR,
            FapuKind::Mns => d.mns0 / FAPU_DIVISOR,
            FapuKind::Mw => d.mw0 / FAPU_DIVISOR,
            FapuKind::Au => AU_RADIANS,
        }
    }

    /// The neutral distance behind `kind` (AU has none and returns `None`).
    pub fn distance(&self, kind: FapuKind) -> Option<f64> {
        let d = &self.distances;
        match kind {
            FapuKind::Irisd => Some(d.irisd0),
            FapuKind::Es => Some(d.es0),
            FapuKind::Ens => Some(d.ens0),
            FapuKind::Mns => Some(d.mns0),
            FapuKind::Mw => Some(d.mw0),
            FapuKind::Au => None,
        }
    }

    /// The unit size of a FAP (`None` for the high-level FAPs 1 and 2, which have no unit).
    pub fn unit_of(&self, fap: FapId) -> Option<f64> {
        fap.info().fapu.map(|k| self.unit(k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Fapu {
        Fapu::from_distances(FapuDistances {
            irisd0: 16.0,
            es0: 69.0,
            ens0: 51.0,
            mns0: 30.0,
            mw0: 50.0,
        })
        .unwrap()
    }

    #[test]
    fn units_divide_by_1024_and_au_is_fixed() {
        let f = sample();
        assert_eq!(f.unit(FapuKind::Mns), 30.0 / 1024.0);
        assert_eq!(f.unit(FapuKind::Au), 1e-5);
        assert_eq!(f.unit_of(FapId::OPEN_JAW), Some(30.0 / 1024.0));
        assert_eq!(f.unit_of(FapId::VISEME), None);
        assert_eq!(f.distance(FapuKind::Au), None);
    }

    #[test]
    fn rejects_non_positive_or_non_finite() {
        let mut d = sample().distances;
        d.mw0 = 0.0;
        assert!(Fapu::from_distances(d).unwrap_err().contains("MW0"));
        d.mw0 = f64::NAN;
        assert!(Fapu::from_distances(d).is_err());
        d.mw0 = -1.0;
        assert!(Fapu::from_distances(d).is_err());
    }
}
