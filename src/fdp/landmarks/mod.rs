//! Landmarks → MPEG-4 feature points.
//!
//! Real face meshes come with a landmark scheme, not with MPEG-4 feature points: the 68 iBUG
//! (Multi-PIE) points of most face trackers and fitting pipelines (ICT-FaceKit ships them as
//! vertex ids), or the 468 points of MediaPipe Face Mesh (whose canonical mesh is in landmark
//! order). A [`LandmarkScheme`] preset maps landmarks to feature points by a table in
//! `specs/landmarks-*.csv` (one row per point with its reasoning) and **derives** the points the
//! landmarks do not give from the mesh itself (module `derive`): eyelid centres on the visible
//! lid margin, pupils from the eyeball, chin boss, cheeks, nose wings and bump, top and back of
//! the skull. Every point is bound to one mesh vertex (the pupil of an eyeless mesh to the mean
//! of its lid contour's vertices) and carries its [`Provenance`].
//!
//! The result has enough points for the six FAP units and for both cloning methods.

mod derive;
pub mod ids;
mod surface;
mod table;

use std::fmt;
use std::sync::OnceLock;

use glam::Vec3;
use serde::Serialize;

use crate::error::Result;
use crate::fdp::csv::{Combine, FeaturePointRow, FeaturePointTable};
use crate::fdp::{FdpError, FeaturePoint, FeaturePointSet, VertexBinding};
use crate::mesh::Mesh;
use crate::spec::FeaturePointId;

pub use ids::{
    parse_landmark_ids, read_landmark_ids, read_landmark_ids_from, LandmarkIds, ICT_LANDMARK_KEY,
};
pub use table::{PresetRow, Rule};

/// A landmark scheme with a built-in preset table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LandmarkScheme {
    /// The 68 iBUG / Multi-PIE points (jaw 1–17, brows 18–27, nose 28–36, eyes 37–48,
    /// mouth 49–68; 0-based positions in the id list).
    Ibug68,
    /// The 468 MediaPipe Face Mesh points (vertex i of the canonical mesh is landmark i).
    MediaPipe468,
}

static IBUG68: OnceLock<Vec<PresetRow>> = OnceLock::new();
static MEDIAPIPE468: OnceLock<Vec<PresetRow>> = OnceLock::new();

impl LandmarkScheme {
    /// Number of landmarks.
    pub fn landmark_count(self) -> usize {
        match self {
            LandmarkScheme::Ibug68 => 68,
            LandmarkScheme::MediaPipe468 => 468,
        }
    }

    /// Display name.
    pub fn name(self) -> &'static str {
        match self {
            LandmarkScheme::Ibug68 => "iBUG-68",
            LandmarkScheme::MediaPipe468 => "MediaPipe-468",
        }
    }

    /// The conventional name of the landmark at 0-based position `index` (`iBUG 9` is
    /// index 8; MediaPipe numbers are 0-based already).
    pub fn landmark_name(self, index: usize) -> String {
        match self {
            LandmarkScheme::Ibug68 => format!("iBUG {}", index + 1),
            LandmarkScheme::MediaPipe468 => format!("MediaPipe {index}"),
        }
    }

    /// The preset table (`specs/landmarks-ibug68.csv`, `specs/landmarks-mediapipe468.csv`).
    pub fn preset(self) -> &'static [PresetRow] {
        match self {
            LandmarkScheme::Ibug68 => table::preset(&IBUG68, table::IBUG68_CSV, 68),
            LandmarkScheme::MediaPipe468 => {
                table::preset(&MEDIAPIPE468, table::MEDIAPIPE468_CSV, 468)
            }
        }
    }
}

impl fmt::Display for LandmarkScheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Where a feature point came from.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Provenance {
    /// A landmark's vertex.
    Landmark {
        /// 0-based landmark index.
        landmark: usize,
        /// Its conventional name (`iBUG 9`).
        name: String,
    },
    /// Derived from the mesh by a rule.
    Derived {
        /// The rule.
        rule: Rule,
        /// How, with the measured figures.
        how: String,
    },
}

impl fmt::Display for Provenance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Provenance::Landmark { name, .. } => write!(f, "landmark {name}"),
            Provenance::Derived { rule, how } => write!(f, "derived ({rule}): {how}"),
        }
    }
}

/// One feature point placed on the mesh.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlacedPoint {
    /// The point.
    pub id: FeaturePointId,
    /// Mesh vertices: one, or several whose mean is the point.
    pub vertices: Vec<u32>,
    /// Position in the mesh's coordinates (the vertex, or the mean).
    pub position: Vec3,
    /// Where it came from.
    pub provenance: Provenance,
    /// The preset row's reasoning.
    pub reasoning: String,
}

/// A preset point the mesh does not give.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AbsentPoint {
    /// The point.
    pub id: FeaturePointId,
    /// The rule that could not place it.
    pub rule: Rule,
    /// Why.
    pub reason: String,
}

/// The feature points found from a mesh's landmarks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LandmarkFeaturePoints {
    /// The scheme.
    pub scheme: LandmarkScheme,
    /// Placed points in label order.
    pub points: Vec<PlacedPoint>,
    /// Preset points that could not be placed.
    pub absent: Vec<AbsentPoint>,
    /// Remarks on the derivation (e.g. which eye had no eyeball).
    pub notes: Vec<String>,
}

impl LandmarkFeaturePoints {
    /// The points as a set, each bound to its vertices (no mesh name) with its position.
    pub fn feature_point_set(&self) -> FeaturePointSet {
        self.points
            .iter()
            .map(|p| FeaturePoint {
                id: p.id,
                position: Some(p.position),
                binding: Some(VertexBinding {
                    mesh: None,
                    vertices: p.vertices.clone(),
                }),
            })
            .collect()
    }

    /// The points as a CSV table whose description column is the provenance.
    pub fn table(&self) -> FeaturePointTable {
        FeaturePointTable {
            rows: self
                .points
                .iter()
                .map(|p| FeaturePointRow {
                    fp: p.id,
                    vertices: p.vertices.clone(),
                    mesh: None,
                    position: None,
                    combine: if p.vertices.len() == 1 {
                        Combine::Single
                    } else {
                        Combine::Mean
                    },
                    description: Some(p.provenance.to_string()),
                })
                .collect(),
        }
    }

    /// The placed point with this label.
    pub fn get(&self, id: FeaturePointId) -> Option<&PlacedPoint> {
        self.points.iter().find(|p| p.id == id)
    }
}

/// Places the scheme's feature points on `mesh` given the mesh vertex of every landmark
/// (`landmarks[i]` is landmark `i`).
///
/// Errors (all [`FdpError`], i.e. bad input): wrong landmark count, ids out of range or
/// repeated (use [`LandmarkIds::check`] first for messages naming the file and place), a
/// non-finite vertex position, or landmarks that do not make a face frame (coincident or
/// mirrored).
pub fn feature_points_from_landmarks(
    mesh: &Mesh,
    scheme: LandmarkScheme,
    landmarks: &[u32],
) -> Result<LandmarkFeaturePoints> {
    LandmarkIds::from_ids(landmarks.to_vec()).check(
        scheme.landmark_count(),
        mesh.positions.len(),
        scheme.name(),
    )?;
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(FdpError::NonFiniteVertex {
            mesh: mesh.name.clone(),
            vertex: i,
            position: mesh.positions[i].to_string(),
        }
        .into());
    }
    derive::place(mesh, scheme, landmarks).map_err(|e| FdpError::LandmarkFrame(e).into())
}

#[cfg(test)]
mod tests;
