//! Length units of face models. Face files carry no unit: the bundled procedural faces are in
//! millimetres, ICT-FaceKit and MediaPipe in centimetres, glTF requires metres. The unit is
//! guessed from the face's size (an adult's pupils are about 63 mm apart, a head with its
//! neck 0.15–0.35 m tall) and can always be overridden.

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::face::FaceModel;
use crate::fdp::Fapu;

/// A length unit of model coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
}

impl LengthUnit {
    /// Every unit, smallest first.
    pub const ALL: [LengthUnit; 3] = [LengthUnit::Mm, LengthUnit::Cm, LengthUnit::M];

    /// Metres per unit.
    pub fn metres(self) -> f32 {
        match self {
            LengthUnit::Mm => 0.001,
            LengthUnit::Cm => 0.01,
            LengthUnit::M => 1.0,
        }
    }

    /// The symbol (`mm`, `cm`, `m`).
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::Mm => "mm",
            LengthUnit::Cm => "cm",
            LengthUnit::M => "m",
        }
    }
}

impl fmt::Display for LengthUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

impl FromStr for LengthUnit {
    type Err = String;

    fn from_str(s: &str) -> Result<LengthUnit, String> {
        LengthUnit::ALL
            .into_iter()
            .find(|u| u.symbol() == s)
            .ok_or_else(|| format!("unknown length unit `{s}` (expected mm, cm or m)"))
    }
}

/// What a face's size was measured on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum UnitBasis {
    /// The eye separation ES0 of the face's FAP units.
    EyeSeparation,
    /// The height of the bounding box of all meshes.
    HeadHeight,
    /// Given by the user.
    Override,
}

/// The unit assumed for a face and why.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct UnitGuess {
    /// The unit.
    pub unit: LengthUnit,
    /// What was measured.
    pub basis: UnitBasis,
    /// The measured length in model units (0 for an override).
    pub measured: f32,
    /// False when no unit makes the face head-sized (more than 3× off the typical size,
    /// e.g. CANDIDE-3's normalised coordinates): the coordinates are then taken as metres,
    /// unchanged.
    pub plausible: bool,
}

impl fmt::Display for UnitGuess {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = self.measured * self.unit.metres();
        let odd = if self.plausible {
            ""
        } else {
            "; no unit makes it head-sized, taken as metres unchanged"
        };
        match self.basis {
            UnitBasis::EyeSeparation => write!(
                f,
                "{} (eye separation ES0 {} = {m:.3} m{odd})",
                self.unit, self.measured
            ),
            UnitBasis::HeadHeight => write!(
                f,
                "{} (height {} = {m:.3} m{odd})",
                self.unit, self.measured
            ),
            UnitBasis::Override => write!(f, "{} (given)", self.unit),
        }
    }
}

/// Typical adult eye separation (pupil to pupil), metres.
const TYPICAL_ES0_M: f32 = 0.063;
/// Typical height of a head model (a face mask to a head with neck), metres.
const TYPICAL_HEIGHT_M: f32 = 0.23;

/// The unit whose metres make `length` closest to `typical` on a log scale (the candidates
/// are a factor 10-100 apart, so a head is never ambiguous), and whether it lands within 3×
/// of it; when it does not, metres (coordinates unchanged).
fn closest(length: f32, typical: f32) -> (LengthUnit, bool) {
    let d = |u: LengthUnit| (length * u.metres() / typical).ln().abs();
    let best = LengthUnit::ALL
        .into_iter()
        .min_by(|a, b| d(*a).total_cmp(&d(*b)))
        .expect("three units");
    if d(best) <= 3f32.ln() {
        (best, true)
    } else {
        (LengthUnit::M, false)
    }
}

/// Guesses the face's unit from ES0 when its FAP units can be measured, else from the height
/// of all its meshes in the face frame. `None` for an empty or degenerate face.
pub fn detect_unit(face: &FaceModel) -> Option<UnitGuess> {
    if let Ok(fapu) = Fapu::from_feature_points(&face.feature_points) {
        let es0 = fapu.distances.es0 as f32;
        if es0.is_finite() && es0 > 0.0 {
            let (unit, plausible) = closest(es0, TYPICAL_ES0_M);
            return Some(UnitGuess {
                unit,
                basis: UnitBasis::EyeSeparation,
                measured: es0,
                plausible,
            });
        }
    }
    let frames = face.frames();
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    for (mi, m) in face.meshes.iter().enumerate() {
        for p in &m.mesh.positions {
            let y = frames.meshes[mi].transform_point3(*p).y;
            if y.is_finite() {
                lo = lo.min(y);
                hi = hi.max(y);
            }
        }
    }
    let height = hi - lo;
    (height.is_finite() && height > 0.0).then(|| {
        let (unit, plausible) = closest(height, TYPICAL_HEIGHT_M);
        UnitGuess {
            unit,
            basis: UnitBasis::HeadHeight,
            measured: height,
            plausible,
        }
    })
}

/// The override when given, else [`detect_unit`]; `None` when neither gives a unit.
pub fn unit_of(face: &FaceModel, unit: Option<LengthUnit>) -> Option<UnitGuess> {
    match unit {
        Some(unit) => Some(UnitGuess {
            unit,
            basis: UnitBasis::Override,
            measured: 0.0,
            plausible: true,
        }),
        None => detect_unit(face),
    }
}

/// The factor from the face's units to metres ([`unit_of`]), and a warning when no unit can be
/// guessed (the coordinates are then taken as metres, factor 1).
pub fn metres_factor(face: &FaceModel, unit: Option<LengthUnit>) -> (f32, Option<String>) {
    match unit_of(face, unit) {
        Some(g) => (g.unit.metres(), None),
        None => (
            1.0,
            Some("the face's length unit cannot be guessed (no size); written as metres".into()),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::face::FaceMesh;
    use crate::mesh::Mesh;
    use glam::Vec3;

    fn box_face(height: f32) -> FaceModel {
        let mut face = FaceModel::new("box");
        face.meshes.push(FaceMesh {
            name: "m".into(),
            transform: None,
            mesh: Mesh::from_triangles(
                "m",
                vec![Vec3::ZERO, Vec3::new(1.0, height, 0.0), Vec3::X],
                &[[0, 1, 2]],
            ),
            color: None,
        });
        face
    }

    #[test]
    fn heads_are_recognised_in_every_unit() {
        for (h, unit) in [
            (230.0, LengthUnit::Mm),
            (33.8, LengthUnit::Cm),
            (0.25, LengthUnit::M),
        ] {
            let g = detect_unit(&box_face(h)).unwrap();
            assert_eq!((g.unit, g.basis), (unit, UnitBasis::HeadHeight), "{h}");
        }
        assert!(detect_unit(&box_face(0.0)).is_none());
        // 2 units tall (CANDIDE-3's normalised frame): no unit fits, kept as metres.
        let g = detect_unit(&box_face(2.0)).unwrap();
        assert_eq!((g.unit, g.plausible), (LengthUnit::M, false));
        assert!(g.to_string().contains("no unit makes it head-sized"), "{g}");
        // The bundled faces are in millimetres, measured on their eye separation.
        let alma = crate::synth::alma().to_face_model();
        let g = detect_unit(&alma).unwrap();
        assert_eq!(
            (g.unit, g.basis),
            (LengthUnit::Mm, UnitBasis::EyeSeparation)
        );
        assert!(g.to_string().starts_with("mm (eye separation ES0 "), "{g}");
        let o = unit_of(&alma, Some(LengthUnit::Cm)).unwrap();
        assert_eq!(
            (o.unit, o.to_string()),
            (LengthUnit::Cm, "cm (given)".to_string())
        );
    }

    #[test]
    fn units_parse_and_convert() {
        assert_eq!("cm".parse::<LengthUnit>(), Ok(LengthUnit::Cm));
        assert!("km"
            .parse::<LengthUnit>()
            .unwrap_err()
            .contains("mm, cm or m"));
        assert_eq!(LengthUnit::Mm.metres() * 1000.0, 1.0);
    }
}
