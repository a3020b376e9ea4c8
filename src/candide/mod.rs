//! CANDIDE-3, the parameterised wireframe face of J. Ahlberg (Linköping University, 2001):
//! its model and its `.wfm` text format ([`wfm`]).
//!
//! The model is a neutral triangle mesh plus two families of sparse displacement fields:
//! *shape units* (static, person-specific: head height, eye separation, ...) and *animation
//! units* (dynamic: FACS action unit vectors and, since 3.1.3, MPEG-4 FAP units). A deformed
//! face is `g = ḡ + S·σ + A·α`: each unit adds `value × displacement` to its vertices.
//! Units are in the model's arbitrary length scale (head height ≈ 2).

mod error;
pub mod wfm;

use glam::Vec3;
use serde::Serialize;

use crate::error::Result;
use crate::mesh::Mesh;
use crate::spec::{FapId, FapuKind};

pub use error::CandideError;
pub use wfm::{parse_wfm, read_wfm_file, read_wfm_from};

/// One animation unit: an action unit vector (`AUV..`) or an MPEG-4 FAP unit (`FAP..`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AnimationUnit {
    /// Short name: the FAP name for FAP units (`open_jaw`), otherwise the whole first comment
    /// with blanks collapsed (`AUV0 Upper lip raiser (AU10)`).
    pub name: String,
    /// The unit's first comment line as written (trimmed).
    pub label: String,
    /// The FAP this unit implements, for `FAPnn` units.
    pub fap: Option<FapId>,
    /// The FAP unit named in a following comment line (`# MNS`), if any.
    pub fapu: Option<FapuKind>,
    /// Further comment lines of the unit, verbatim (trimmed).
    pub comments: Vec<String>,
    /// `(vertex, displacement per unit value)`, in file order.
    pub displacements: Vec<(u32, Vec3)>,
}

/// One shape unit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShapeUnit {
    /// The unit's name, from its comment line (`Mouth width`).
    pub name: String,
    /// Further comment lines, verbatim (trimmed).
    pub comments: Vec<String>,
    /// `(vertex, displacement per unit value)`, in file order.
    pub displacements: Vec<(u32, Vec3)>,
}

/// Global head pose stored at the end of a `.wfm` file.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GlobalMotion {
    /// Rotation (first line; the reference file gives zeros).
    pub rotation: Vec3,
    /// Scale per axis (second line; ones in the reference file).
    pub scale: Vec3,
    /// Translation (third line).
    pub translation: Vec3,
}

/// A CANDIDE model as read from a `.wfm` file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CandideModel {
    /// Comment lines before the vertex list (version history, credits), without `#`.
    pub header: Vec<String>,
    /// Neutral vertex positions (+x the face's left, +y up, +z towards the viewer).
    pub vertices: Vec<Vec3>,
    /// Triangles, vertex indices as in the file.
    pub triangles: Vec<[u32; 3]>,
    /// Animation units, in file order (their position is the animation parameter index).
    pub animation_units: Vec<AnimationUnit>,
    /// Shape units, in file order (their position is the shape parameter index).
    pub shape_units: Vec<ShapeUnit>,
    /// Animation parameters stored in the file: `(unit index, value)`.
    pub animation_params: Vec<(u32, f32)>,
    /// Shape parameters stored in the file: `(unit index, value)`.
    pub shape_params: Vec<(u32, f32)>,
    /// Lines of the texture section after its count, verbatim and not interpreted (the
    /// reference file has none).
    pub texture: Vec<String>,
    /// Global motion, if the file has that section.
    pub global_motion: Option<GlobalMotion>,
}

impl CandideModel {
    /// The neutral mesh (name `candide3`).
    pub fn to_mesh(&self) -> Mesh {
        Mesh::from_triangles("candide3", self.vertices.clone(), &self.triangles)
    }

    /// The animation unit implementing `fap`, if the model has one.
    pub fn fap_unit(&self, fap: FapId) -> Option<&AnimationUnit> {
        self.animation_units.iter().find(|u| u.fap == Some(fap))
    }

    /// The shape unit called `name` (ASCII case-insensitive, outer blanks ignored).
    pub fn shape_unit(&self, name: &str) -> Option<&ShapeUnit> {
        let name = name.trim();
        self.shape_units
            .iter()
            .find(|u| u.name.eq_ignore_ascii_case(name))
    }

    /// A copy with shape units applied: for each `(name, value)`, every displaced vertex moves
    /// by `value × displacement`. Names as in [`CandideModel::shape_unit`]; an unknown name is
    /// an error listing the valid ones; values must be finite.
    pub fn with_shape(&self, values: &[(impl AsRef<str>, f32)]) -> Result<CandideModel> {
        let mut out = self.clone();
        for (name, value) in values {
            let name = name.as_ref();
            if !value.is_finite() {
                return Err(CandideError::NonFiniteShapeValue {
                    unit: name.to_string(),
                    value: *value,
                }
                .into());
            }
            let unit = self.shape_unit(name).ok_or_else(|| {
                let valid: Vec<&str> = self.shape_units.iter().map(|u| u.name.as_str()).collect();
                CandideError::UnknownShapeUnit {
                    name: name.to_string(),
                    valid: valid.join(", "),
                }
            })?;
            for &(v, d) in &unit.displacements {
                let p = out.vertices.get_mut(v as usize).ok_or_else(|| {
                    CandideError::MissingVertex {
                        unit: unit.name.clone(),
                        vertex: v,
                    }
                })?;
                *p += *value * d;
            }
        }
        Ok(out)
    }
}

/// Parses a shape specification `name=value,name=value` (e.g.
/// `Mouth width=0.3,Eyes height=-0.1`). Names may themselves contain commas (`Eyes, width`):
/// a comma-separated piece without `=` is joined to the next piece. Values must be finite.
pub fn parse_shape_spec(spec: &str) -> Result<Vec<(String, f32)>> {
    let mut out = Vec::new();
    let mut pending = String::new();
    for piece in spec.split(',') {
        if !piece.contains('=') {
            pending.push_str(piece);
            pending.push(',');
            continue;
        }
        let item = std::mem::take(&mut pending) + piece;
        let (name, value) = item.rsplit_once('=').unwrap_or((&item, ""));
        let name = name.trim();
        if name.is_empty() {
            return Err(CandideError::ShapeSpecItem {
                item: item.trim().to_string(),
            }
            .into());
        }
        let value: f32 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f32| v.is_finite())
            .ok_or_else(|| CandideError::ShapeSpecValue {
                item: item.trim().to_string(),
            })?;
        out.push((name.to_string(), value));
    }
    if !pending.trim_matches([',', ' ']).is_empty() {
        return Err(CandideError::ShapeSpecItem {
            item: pending.trim_end_matches(',').trim().to_string(),
        }
        .into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_spec_items_and_commas_in_names() {
        assert_eq!(
            parse_shape_spec("Mouth width=0.3,Eyes height=-0.1").unwrap(),
            vec![("Mouth width".into(), 0.3), ("Eyes height".into(), -0.1)]
        );
        assert_eq!(
            parse_shape_spec("Eyes, width=0.5, Nose, pointing up = 1").unwrap(),
            vec![
                ("Eyes, width".into(), 0.5),
                ("Nose, pointing up".into(), 1.0)
            ]
        );
        assert!(parse_shape_spec("").unwrap().is_empty());
        assert!(parse_shape_spec("Mouth width").is_err());
        assert!(parse_shape_spec("=1").is_err());
        assert!(parse_shape_spec("a=x").is_err());
        assert!(parse_shape_spec("a=inf").is_err());
        assert!(parse_shape_spec("a=NaN").is_err());
    }
}
