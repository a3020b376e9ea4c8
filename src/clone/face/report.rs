//! What a whole-face clone reports besides the face: timings, statistics, warnings, parts,
//! alignment and the rigid-part handling.

use std::collections::BTreeMap;

use serde::Serialize;

use super::{FaceParts, FapFailure, Method, Part, Similarity, SplitPart};
use crate::clone::StepTimings;
use crate::face::FaceModel;

/// What the rigid-part step found and did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RigidReport {
    /// Target transform used for each part (by name).
    pub part_transforms: BTreeMap<Part, String>,
    /// Target head transform (the lowest one enclosing every face mesh; none is created).
    pub head_transform: Option<String>,
    /// Transforms fbakit created.
    pub created_transforms: Vec<String>,
    /// Centres installed: `(transform, centre in the face frame)`.
    pub installed_centres: Vec<(String, [f32; 3])>,
    /// Transform entries written to the target FAT.
    pub transform_entries: usize,
    /// Tables whose tongue deformation became a rigid tongue translation.
    pub rigid_tongue_tables: usize,
    /// Transforms the clone needed only for parts cut out of a one-mesh target: their motion
    /// is baked into that mesh's tables and they are not in the output face.
    pub baked_transforms: Vec<String>,
}

/// What `lid_cover` ([`CloneOptions::lid_cover`](super::CloneOptions::lid_cover)) found for
/// one eye the source's blink closes (its module docs, "When"): what of the eye shows from
/// the front through the closed lids, on the source at its closing value and on the clone
/// before the step, and whether the step covered the eye.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LidCoverEye {
    /// `left` or `right` (the face's own).
    pub eye: &'static str,
    /// The source's eye through its own closed lids: the share (0–1) of what its open eye
    /// shows, and how far that stands out in front of the lids (median, in half widths of
    /// the eye). `None`: the source has no eyeball there (taken as nothing seen).
    pub source_seen: Option<[f64; 2]>,
    /// The same for the target's eye through the clone's closed lids, before the step.
    pub target_seen: [f64; 2],
    /// Whether the step covered the eye.
    pub covered: bool,
    /// Why, in words.
    pub reason: String,
}

impl std::fmt::Display for LidCoverEye {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let seen = |s: [f64; 2]| format!("{:.0} % standing out {:.3}", 100.0 * s[0], s[1]);
        write!(
            f,
            "{} eye {}: seen through the closed lids {} (the source's: {}); {}",
            self.eye,
            if self.covered { "covered" } else { "kept" },
            seen(self.target_seen),
            self.source_seen.map_or("no eyeball".to_string(), seen),
            self.reason
        )
    }
}

/// Everything [`clone_face`](super::clone_face) reports besides the face.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CloneReport {
    /// Method used.
    pub method: Method,
    /// Per-step timings (surface steps prefixed `fmc:` / `rbf:`).
    pub timings: StepTimings,
    /// Figures from the surface method and the face layer.
    pub stats: BTreeMap<String, f64>,
    /// Warnings for the user.
    pub warnings: Vec<crate::error::Diagnostic>,
    /// Source parts.
    pub source_parts: FaceParts,
    /// Target parts, as mesh indices of the internal view the clone worked on: for a one-mesh
    /// target whose parts were cut out (`split_parts`), that view's meshes, not the output's.
    pub target_parts: FaceParts,
    /// Target → source alignment used.
    pub alignment: Similarity,
    /// RMS distance of the aligned target feature points to the source's, in source units.
    pub alignment_rms: f64,
    /// Skin vertices (welded) of source and target surfaces.
    pub surface_vertices: [usize; 2],
    /// Source morph targets cloned.
    pub motions: usize,
    /// Tables in the output FAT.
    pub tables: usize,
    /// RBF FAPU rescaling factors applied, per FAP name.
    pub fapu_rescale: BTreeMap<String, f64>,
    /// Compliance gains at the feature points (`gain` step), per FAP name and value.
    pub fapu_gain: BTreeMap<String, f64>,
    /// Motions the `smooth` and `bound` steps re-solved, per FAP name and value: how many
    /// target surface vertices.
    pub smoothed: BTreeMap<String, usize>,
    /// Target surface vertices of the hidden mouth interior the `mouth` step fills (0: none).
    pub mouth_interior: usize,
    /// Rigid-part handling.
    pub rigid: RigidReport,
    /// Part meshes cut out of a one-mesh target (step 1).
    pub split_parts: Vec<SplitPart>,
    /// The standard's eyeball and head rotation tables the target got where the source had
    /// none (or had them as vertex motion, which is re-made about the target's own centres).
    pub standard_rotations: super::standard::StandardRotations,
    /// Cloned FAPs that failed the guard (step 6), repaired or dropped.
    pub failed_faps: Vec<FapFailure>,
    /// Meshes of neither skin nor a part that ride on the skin (lashes; step 8).
    pub attached_meshes: Vec<String>,
    /// Per eye the source's blink closes, what `lid_cover` measured and did (empty when it
    /// is off or the target has no eyeball parts).
    pub lid_cover: Vec<LidCoverEye>,
}

/// The report as the CLI prints it: a summary line, the alignment, the warnings.
impl std::fmt::Display for CloneReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "cloned {} morph targets ({} tables) with {} onto {} skin vertices in {:.3} s",
            self.motions,
            self.tables,
            self.method,
            self.surface_vertices[1],
            self.timings.total()
        )?;
        write!(
            f,
            "alignment: scale {:.4}, rotation {:.2} deg, rms {:.4}",
            self.alignment.scale,
            self.alignment.angle_degrees(),
            self.alignment_rms
        )?;
        for w in &self.warnings {
            write!(f, "\n{w}")?;
        }
        Ok(())
    }
}

/// The target with its new FAT, and the report.
#[derive(Clone, Debug)]
pub struct CloneOutcome {
    /// The target face with the cloned FAT (and any transforms fbakit had to add).
    pub face: FaceModel,
    /// Timings, statistics, warnings.
    pub report: CloneReport,
}
