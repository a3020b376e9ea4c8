//! FAP units (FAPU): the six unit sizes in which FAP values are measured on one face.
//!
//! Five are neutral-face distances divided by 1024 (IRISD0, ES0, ENS0, MNS0, MW0); AU is the
//! fixed angle 1e-5 rad. Multiplying a FAP value by its FAPU gives a model-space distance (or an
//! angle in radians), which is what makes one FAP stream animate any compliant face.

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::fdp::{FdpError, FeaturePointSet};
use crate::spec::{FapId, FapuKind, FeaturePointId, AU_RADIANS, FAPU_DIVISOR};

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
    pub fn from_distances(distances: FapuDistances) -> Result<Fapu, FdpError> {
        let named = [
            ("IRISD0", distances.irisd0),
            ("ES0", distances.es0),
            ("ENS0", distances.ens0),
            ("MNS0", distances.mns0),
            ("MW0", distances.mw0),
        ];
        for (name, d) in named {
            if !d.is_finite() || d <= 0.0 {
                return Err(FdpError::BadFapuDistance { name, value: d });
            }
        }
        Ok(Fapu { distances })
    }

    /// Units measured on neutral-face feature points with the standard's axis-aligned
    /// definitions (IRISD0 = 3.1.y − 3.3.y, ES0 = 3.5.x − 3.6.x, ENS0 = 3.5.y − 9.15.y,
    /// MNS0 = 9.15.y − 2.2.y, MW0 = 8.3.x − 8.4.x). See [`Fapu::measure`] for the notes.
    pub fn from_feature_points(points: &FeaturePointSet) -> Result<Fapu> {
        Fapu::measure(points).map(|m| m.fapu)
    }

    /// Like [`Fapu::from_feature_points`], also returning notes on how the units were
    /// obtained (e.g. IRISD0 taken from the right eye because a left-eye lid point is missing).
    ///
    /// Every missing point (or point without a position) is listed in one
    /// [`FdpError::FapuPointsMissing`]; a zero or negative distance is an error naming the FAPU and its
    /// points (usually a mirrored model or a wrong axis convention).
    pub fn measure(points: &FeaturePointSet) -> Result<FapuMeasurement> {
        let has = |id: FeaturePointId| points.position(id).is_some();
        let mut notes = Vec::new();
        let (l_top, l_bottom) = (FeaturePointId::FP_3_1, FeaturePointId::FP_3_3);
        let (r_top, r_bottom) = (FeaturePointId::FP_3_2, FeaturePointId::FP_3_4);
        let iris = if has(l_top) && has(l_bottom) {
            (l_top, l_bottom)
        } else if has(r_top) && has(r_bottom) {
            notes.push(crate::error::Diagnostic::warning(format!(
                "IRISD0 measured on the right eye (3.2.y - 3.4.y) because {} {} no position",
                missing_list(&[l_top, l_bottom], points),
                if has(l_top) || has(l_bottom) {
                    "has"
                } else {
                    "have"
                },
            )));
            (r_top, r_bottom)
        } else {
            (l_top, l_bottom)
        };
        // (name, upper/left point, lower/right point, axis 0 = x, 1 = y)
        let defs = [
            ("IRISD0", iris.0, iris.1, 1),
            ("ES0", FeaturePointId::FP_3_5, FeaturePointId::FP_3_6, 0),
            ("ENS0", FeaturePointId::FP_3_5, FeaturePointId::FP_9_15, 1),
            ("MNS0", FeaturePointId::FP_9_15, FeaturePointId::FP_2_2, 1),
            ("MW0", FeaturePointId::FP_8_3, FeaturePointId::FP_8_4, 0),
        ];
        let mut missing: Vec<(FeaturePointId, Vec<&str>)> = Vec::new();
        for (name, a, b, _) in defs {
            for id in [a, b] {
                if !has(id) {
                    match missing.iter_mut().find(|(m, _)| *m == id) {
                        Some((_, users)) => users.push(name),
                        None => missing.push((id, vec![name])),
                    }
                }
            }
        }
        if !missing.is_empty() {
            missing.sort_by_key(|(id, _)| *id);
            let list: Vec<String> = missing
                .iter()
                .map(|(id, users)| format!("{id} (for {})", users.join(", ")))
                .collect();
            let hint = if points.needs_mesh() {
                "; the points are bound to mesh vertices but have no positions: give the mesh"
            } else {
                ""
            };
            return Err(FdpError::FapuPointsMissing {
                points: list.join(", "),
                hint: hint.to_string(),
            }
            .into());
        }
        let mut values = [0.0f64; 5];
        let mut bad = Vec::new();
        // Along the face's own axes: a face modelled turned in its file (facing −z) is
        // measured stood up ([`FeaturePointSet::upright_turn`]).
        let turn = points.upright_turn();
        let at = |id| {
            let p = points.position(id).unwrap_or_default();
            turn.map_or(p, |t| t * p).as_dvec3()
        };
        for (k, (name, a, b, axis)) in defs.into_iter().enumerate() {
            let pa = at(a);
            let pb = at(b);
            let d = pa[axis] - pb[axis];
            let axis_name = if axis == 0 { "x" } else { "y" };
            if !d.is_finite() || d <= 0.0 {
                bad.push(format!(
                    "{name} = {a}.{axis_name} - {b}.{axis_name} = {} - {} = {d} is not positive",
                    pa[axis], pb[axis]
                ));
            }
            values[k] = d;
        }
        if !bad.is_empty() {
            return Err(FdpError::FapuNotPositive {
                details: bad.join("; "),
            }
            .into());
        }
        let distances = FapuDistances {
            irisd0: values[0],
            es0: values[1],
            ens0: values[2],
            mns0: values[3],
            mw0: values[4],
        };
        let fapu = Fapu::from_distances(distances)?;
        Ok(FapuMeasurement { fapu, notes })
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

/// The six units, one per line: `IRISD 0.000123 (IRISD0 0.126)`; AU has no distance.
impl std::fmt::Display for Fapu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, k) in crate::spec::FapuKind::ALL.into_iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{:<6} {:.6e}", k.abbreviation(), self.unit(k))?;
            if let Some(d) = self.distance(k) {
                write!(f, " ({}0 {d:.6})", k.abbreviation())?;
            }
        }
        Ok(())
    }
}

/// FAP units measured on feature points, with notes on how they were measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapuMeasurement {
    /// The units.
    pub fapu: Fapu,
    /// Deviations from the standard's primary definition (e.g. the right eye used for IRISD0),
    /// as warnings.
    pub notes: Vec<crate::error::Diagnostic>,
}

fn missing_list(ids: &[FeaturePointId], points: &FeaturePointSet) -> String {
    let v: Vec<String> = ids
        .iter()
        .filter(|id| points.position(**id).is_none())
        .map(|id| id.to_string())
        .collect();
    v.join(" and ")
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
        assert!(Fapu::from_distances(d)
            .unwrap_err()
            .to_string()
            .contains("MW0"));
        d.mw0 = f64::NAN;
        assert!(Fapu::from_distances(d).is_err());
        d.mw0 = -1.0;
        assert!(Fapu::from_distances(d).is_err());
    }
}

#[cfg(test)]
mod feature_point_tests {
    use super::*;
    use crate::fdp::FeaturePoint;
    use glam::Vec3;

    fn fp(s: &str) -> FeaturePointId {
        s.parse().unwrap()
    }

    /// A hand-made neutral face: every number below is chosen so the FAPUs are easy to check.
    fn face() -> FeaturePointSet {
        [
            ("3.1", [1.5, 10.25, 0.0]),
            ("3.3", [1.5, 9.75, 0.0]),
            ("3.2", [-1.5, 10.3, 0.0]),
            ("3.4", [-1.5, 9.7, 0.0]),
            ("3.5", [1.5, 10.0, 1.0]),
            ("3.6", [-1.5, 10.0, 1.0]),
            ("9.15", [0.0, 7.0, 2.0]),
            ("2.2", [0.0, 5.0, 1.5]),
            ("8.3", [1.25, 5.0, 1.0]),
            ("8.4", [-1.25, 5.0, 1.0]),
        ]
        .into_iter()
        .map(|(id, p)| FeaturePoint::at(fp(id), Vec3::from_array(p)))
        .collect()
    }

    #[test]
    fn hand_computed_distances() {
        let m = Fapu::measure(&face()).unwrap();
        let d = m.fapu.distances;
        assert_eq!(d.irisd0, 0.5);
        assert_eq!(d.es0, 3.0);
        assert_eq!(d.ens0, 3.0);
        assert_eq!(d.mns0, 2.0);
        assert_eq!(d.mw0, 2.5);
        assert!(m.notes.is_empty());
        assert_eq!(m.fapu.unit(FapuKind::Mw), 2.5 / 1024.0);
    }

    #[test]
    fn right_eye_fallback_is_noted() {
        let mut set = face();
        set.remove(fp("3.3"));
        let m = Fapu::measure(&set).unwrap();
        assert!((m.fapu.distances.irisd0 - 0.6).abs() < 1e-6);
        assert_eq!(m.notes.len(), 1);
        assert!(
            m.notes[0].message.contains("right eye") && m.notes[0].message.contains("3.3"),
            "{:?}",
            m.notes
        );
    }

    #[test]
    fn all_missing_points_listed_at_once() {
        let mut set = face();
        for id in ["3.1", "3.2", "9.15", "8.4"] {
            set.remove(fp(id));
        }
        let e = Fapu::from_feature_points(&set).unwrap_err().to_string();
        assert!(
            e.contains("3.1 (for IRISD0), 8.4 (for MW0), 9.15 (for ENS0, MNS0)"),
            "{e}"
        );
        let e = Fapu::from_feature_points(&FeaturePointSet::new())
            .unwrap_err()
            .to_string();
        for id in ["2.2", "3.1", "3.3", "3.5", "3.6", "8.3", "8.4", "9.15"] {
            assert!(e.contains(&format!("{id} (for")), "{id} in {e}");
        }
    }

    #[test]
    fn mirrored_face_is_rejected_naming_fapu_and_points() {
        let set: FeaturePointSet = face()
            .iter()
            .map(|p| {
                let q = p.position.unwrap();
                FeaturePoint::at(p.id, Vec3::new(-q.x, q.y, q.z))
            })
            .collect();
        let e = Fapu::from_feature_points(&set).unwrap_err().to_string();
        assert!(
            e.contains("ES0 = 3.5.x - 3.6.x = -1.5 - 1.5 = -3 is not positive"),
            "{e}"
        );
        assert!(e.contains("MW0 = 8.3.x - 8.4.x"), "{e}");
        assert!(!e.contains("MNS0"), "{e}");
    }

    #[test]
    fn bound_points_without_positions_ask_for_a_mesh() {
        let set: FeaturePointSet = face()
            .iter()
            .map(|p| FeaturePoint::bound(p.id, crate::fdp::VertexBinding::vertex(0)))
            .collect();
        let e = Fapu::from_feature_points(&set).unwrap_err().to_string();
        assert!(e.contains("give the mesh"), "{e}");
    }
}
