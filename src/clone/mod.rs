//! Facial motion cloning: copying a source face's animation (its FAT, seen as morph targets)
//! onto a target face that is only a mesh with feature points.
//!
//! Three methods share one interface:
//! - [`fmc`]: Pandzic 2003, "Facial Motion Cloning" — FAPU regional normalisation, cylindrical
//!   projection into a 2D alignment space, feature-point-driven alignment, barycentric motion
//!   mapping with an anti-aliasing filter and upper/lower lip separation.
//! - [`rbf`]: Fratarcangeli & Schaerf 2005, "Fast Facial Motion Cloning in MPEG-4" — eye and
//!   inner-lip contour extraction, a Hardy multiquadric RBF volume morph refined iteratively by
//!   ray casting, and barycentric mapping of target vertices into the deformed source.
//! - [`fit`]: fbakit's own — a landmark-guided non-rigid registration of the source's neutral
//!   onto the target's (non-rigid ICP with a bending-regularised displacement field, sparse
//!   Cholesky by faer), lips and eyelids kept apart, every target vertex located on the
//!   registered source and each motion carried over by barycentric interpolation and scaled
//!   by the target / source FAPU of the FAP's unit.
//!
//! Both work on a [`CloneSurface`]: the deformable skin of a face in the MPEG-4 face frame
//! (meshes already placed by their transforms, concatenated into one vertex array), its feature
//! points and its FAPU. Motions are sparse morph targets on that surface ([`SurfaceMotion`]).
//! Rigid parts (eyes, teeth, tongue, head) move through transforms and are handled separately.

mod error;
pub mod eval;
pub mod face;
pub mod fit;
pub mod fmc;
mod mouth_interior;
pub mod quality;
pub mod rbf;
mod tri_filter;

pub use error::{CloneError, FitSystemError, RbfFitError};

use std::collections::BTreeMap;

use glam::Vec3;
use serde::Serialize;

use crate::fat::TableKey;
use crate::fdp::Fapu;
use crate::spec::FeaturePointId;

/// The deformable surface of one face, as the cloning methods see it.
#[derive(Clone, Debug, PartialEq)]
pub struct CloneSurface {
    /// Neutral vertex positions in the MPEG-4 face frame (+x face's left, +y up, +z forward).
    pub positions: Vec<Vec3>,
    /// Triangles (indices into `positions`), consistently oriented (counter-clockwise seen
    /// from outside the face).
    pub triangles: Vec<[u32; 3]>,
    /// Feature points that are vertices of this surface.
    pub fp_vertices: BTreeMap<FeaturePointId, u32>,
    /// Positions of all known feature points, on the surface or not (pupils, teeth, 7.1, ...).
    pub fp_positions: BTreeMap<FeaturePointId, Vec3>,
    /// The face's FAP units.
    pub fapu: Fapu,
}

impl CloneSurface {
    /// Position of a feature point, if known.
    pub fn fp(&self, id: FeaturePointId) -> Option<Vec3> {
        self.fp_positions.get(&id).copied()
    }

    /// Checks what every cloning method relies on: at least one vertex and one triangle, at
    /// most `u32::MAX` vertices, finite positions (vertices and feature points), and
    /// triangles and feature points naming existing vertices. `side` (`source` or `target`)
    /// names the surface in the error.
    ///
    /// ```
    /// use fbakit::clone::{CloneError, CloneSurface};
    /// use fbakit::fdp::{Fapu, FapuDistances};
    /// use glam::Vec3;
    ///
    /// let d = FapuDistances { irisd0: 0.01, es0: 0.06, ens0: 0.04, mns0: 0.02, mw0: 0.05 };
    /// let s = CloneSurface {
    ///     positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
    ///     triangles: vec![[0, 1, 3]],
    ///     fp_vertices: Default::default(),
    ///     fp_positions: Default::default(),
    ///     fapu: Fapu::from_distances(d).unwrap(),
    /// };
    /// let e = s.check("target").unwrap_err();
    /// assert!(matches!(e, CloneError::TriangleOutOfRange { .. }));
    /// assert!(e.to_string().starts_with("the target surface: triangle [0, 1, 3]"));
    /// ```
    pub fn check(&self, side: &str) -> Result<(), CloneError> {
        let n = self.positions.len();
        if n == 0 || self.triangles.is_empty() {
            return Err(CloneError::EmptySurface { side: side.into() });
        }
        if u32::try_from(n).is_err() {
            return Err(CloneError::TooManyVertices {
                side: side.into(),
                vertices: n,
            });
        }
        if let Some(vertex) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(CloneError::NonFinitePosition {
                side: side.into(),
                vertex,
            });
        }
        if let Some(&triangle) = self
            .triangles
            .iter()
            .find(|t| t.iter().any(|&v| v as usize >= n))
        {
            return Err(CloneError::TriangleOutOfRange {
                side: side.into(),
                triangle,
                vertices: n,
            });
        }
        if let Some((&id, _)) = self.fp_positions.iter().find(|(_, p)| !p.is_finite()) {
            return Err(CloneError::NonFiniteFeaturePoint {
                side: side.into(),
                id,
            });
        }
        if let Some((&id, &vertex)) = self.fp_vertices.iter().find(|(_, &v)| v as usize >= n) {
            return Err(CloneError::FeaturePointOutOfRange {
                side: side.into(),
                id,
                vertex,
                vertices: n,
            });
        }
        Ok(())
    }

    /// Checks that every motion moves vertices of this (source) surface by finite offsets.
    pub(crate) fn check_motions(&self, motions: &[SurfaceMotion]) -> Result<(), CloneError> {
        let vertices = self.positions.len();
        for m in motions {
            if let Some(&(vertex, d)) = m
                .offsets
                .iter()
                .find(|(v, d)| *v as usize >= vertices || !d.is_finite())
            {
                return Err(CloneError::BadMotion {
                    key: m.key,
                    vertex,
                    offset: d.to_string(),
                    vertices,
                });
            }
        }
        Ok(())
    }
}

/// One morph target on a [`CloneSurface`]: the moved vertices and their displacement from
/// neutral when the table `key` is at `value`.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceMotion {
    /// Which FAP / viseme / expression.
    pub key: TableKey,
    /// The value the displacements represent.
    pub value: f64,
    /// `(vertex, displacement)` for every moved vertex, sorted by vertex.
    pub offsets: Vec<(u32, Vec3)>,
}

impl SurfaceMotion {
    /// Vertex `v`'s displacement (zero where it does not move).
    pub fn offset_at(&self, v: u32) -> Vec3 {
        self.offsets
            .binary_search_by_key(&v, |o| o.0)
            .map_or(Vec3::ZERO, |i| self.offsets[i].1)
    }
}

/// Time spent in each step of a cloning run, in seconds.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StepTimings {
    /// Named steps in execution order (e.g. `fit`, `refine`, `map`, `deform`).
    pub steps: Vec<(String, f64)>,
}

impl StepTimings {
    /// Records a step's duration.
    pub fn push(&mut self, name: &str, seconds: f64) {
        self.steps.push((name.to_string(), seconds));
    }

    /// Total seconds.
    pub fn total(&self) -> f64 {
        self.steps.iter().map(|(_, s)| s).sum()
    }
}

/// What a cloning method produced for the surface.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceCloneResult {
    /// One motion per source motion, on the target surface's vertices.
    pub motions: Vec<SurfaceMotion>,
    /// Per-step timings.
    pub timings: StepTimings,
    /// Method-specific figures (iterations, correspondence count, fallbacks, ...).
    pub stats: BTreeMap<String, f64>,
    /// Warnings for the user (missing optional feature points, ...).
    pub warnings: Vec<crate::error::Diagnostic>,
}

/// CANDIDE-3 test faces with exact motions (tests and the `bench-fixtures` benchmarks only:
/// they read `../shared` beside the checkout).
#[cfg(any(test, feature = "bench-fixtures"))]
#[doc(hidden)]
pub mod fixtures;
