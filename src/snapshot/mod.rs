//! Snapshot testing of FAT outputs: comparing two faces' animation ([`diff`]), two FAP
//! streams ([`fap_diff()`]), and a stable text of one face ([`snapshot()`]) to pin with
//! `insta` or any text snapshot tool.
//!
//! Faces are compared as animation, not as bytes: each table is evaluated alone at every
//! non-zero interval border and at its reference value (the value a morph target of it shows,
//! [`crate::fat::morph::default_value`]), which pins a piecewise-linear table down
//! completely, and every vertex's displacement from neutral in the face frame is compared
//! (motion a table gives through transforms, such as eyeballs, included). So a sparse VRML
//! table, a dense morph target and a re-borders table of the same motion compare equal.
//!
//! ```
//! use fbakit::snapshot::{diff, snapshot, DiffOptions};
//!
//! let face = fbakit::face::read("alma")?;
//! let text = snapshot(&face, &Default::default());
//! // in a test: insta::assert_snapshot!(fbakit::snapshot::snapshot(&face, &Default::default()));
//! assert!(text.contains("table: \"open_jaw\""));
//!
//! let copy = face.clone();
//! let report = diff(&face, &copy, &DiffOptions::default());
//! assert!(report.is_equal(), "{report}");
//! // the same, with the problems that stop a comparison as errors:
//! assert!(fbakit::snapshot::try_diff(&face, &copy, &DiffOptions::default())?.is_equal());
//! # Ok::<(), fbakit::error::Error>(())
//! ```
//!
//! # What a snapshot promises
//!
//! Every number in a snapshot is put on a grid whose step `g` is the largest 1, 2 or 5 ×
//! 10ⁿ not above the tolerance (so `tol/2.5 < g ≤ tol`), and every displacement enters its
//! table's digest as the index of its nearest grid point. From that:
//!
//! - **Determinism.** The same face gives the same bytes, on any run and thread count
//!   (nothing here is parallel or order-dependent; sums run in vertex order).
//! - **A change above the tolerance always shows.** If any displacement component of any
//!   table at any compared value, any neutral vertex coordinate, feature-point coordinate or
//!   FAP-unit distance changes by more than the tolerance, its grid index changes (two
//!   values more than `g` apart cannot round to one point), so the text changes (up to a
//!   64-bit digest collision, about 1 in 1.8 × 10¹⁹).
//! - **Noise far below it usually does not.** A value moved by noise `ε` changes its grid
//!   point only when it lies within `ε` of a midpoint between two points; vertices that do
//!   not move at all (most of them) sit exactly on a point and never flip while `ε < g/2`.
//!   Values spread evenly over the grid flip with probability about `2ε/g`, so for noise of
//!   `tol/100` about 2–5 % of the *moving* values are at risk.
//! - **In between** (noise between `tol/100` and `tol`) the text may or may not change.
//!
//! No text can promise both "never changes under noise ≤ tol/100" and "always changes under
//! a change > tol": a chain of small steps of noise leads from any value to any other, so
//! some value must flip under arbitrarily small noise. fbakit keeps the second promise
//! exactly. For a table that moves thousands of vertices, noise of `tol/100` on *every*
//! value will therefore change some digest; when inputs come from another tool or machine
//! and carry such noise, compare them with [`diff`] (or `fbakit face diff`) against a
//! reference face, which has no grid and no boundary: it reports equal exactly when every
//! difference is within the tolerance. fbakit's own writers are exact (shortest round-trip
//! floats), so a face written and read back snapshots identically.

mod diff;
mod error;
mod face_snapshot;
mod fap_diff;
mod motion;
pub mod quantise;
mod report;
mod tolerance;

pub use diff::{
    diff, try_diff, DiffOptions, FaceDiff, FapuDiff, FapuUnitDiff, FeaturePointDiff,
    FeaturePointsDiff, NeutralDiff, TableDiff, TransformDiff, VertexMatch,
};
pub use error::{Side, SnapshotError};
pub use face_snapshot::{
    face_snapshot, FaceSnapshot, FapuSnapshot, FeaturePointSnapshot, MeshSnapshot, SnapshotOptions,
    TableSnapshot, TransformSnapshot,
};
pub use fap_diff::{fap_diff, FapDiff, FapDiffOptions, FapValueDiff, DEFAULT_FAP_TOLERANCE};
pub use tolerance::{ResolvedTolerance, Tolerance, DEFAULT_RELATIVE};

use crate::error::Result;
use crate::face::FaceModel;

/// The snapshot text (YAML) of `face`: meshes, transforms, feature points, FAP units and per
/// table its borders, values, moving vertices, largest and mean displacement and a digest of
/// its displacements on the tolerance's grid (see the module docs for what it promises).
///
/// Made for snapshot tests, it never fails: a face that cannot be snapshot (no FAT, no
/// vertices, a tolerance that is not a positive finite number) gives a one-line text naming
/// the problem (`error: "…"`), which no reviewed snapshot matches. [`try_snapshot`] returns
/// the problem as an error instead.
///
/// ```
/// let face = fbakit::face::read("alma")?;
/// let text = fbakit::snapshot::snapshot(&face, &Default::default());
/// // in a test: insta::assert_snapshot!(fbakit::snapshot::snapshot(&face, &Default::default()));
/// assert!(text.contains("table: \"open_jaw\""));
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn snapshot(face: &FaceModel, options: &SnapshotOptions) -> String {
    try_snapshot(face, options).unwrap_or_else(|e| {
        let message = serde_json::to_string(&e.to_string()).unwrap_or_default();
        format!("error: {message}\n")
    })
}

/// [`snapshot`], with the problems that stop it (a face without a FAT or vertices, a bad
/// tolerance) as errors.
pub fn try_snapshot(face: &FaceModel, options: &SnapshotOptions) -> Result<String> {
    Ok(face_snapshot(face, options)?.to_yaml())
}
