//! Settings of a whole-face clone: the surface method and its options.

use serde::Serialize;

use crate::clone::fit::FitOptions;
use crate::clone::fmc::{FmcOptions, NormalisationMode, OverlapRule};
use crate::clone::rbf::RbfOptions;

/// Which surface method clones the skin. The default, `Fmc`, is the one every command uses
/// unless told otherwise: on the bundled procedural faces both reach the same figures (`Fmc`
/// leaves faint seams at bruno's chin), but on the real ICT-FaceKit head `Rbf` tears the
/// mouth open (its inner-lip contours are not found on that mesh) where `Fmc` keeps it whole.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Pandžić 2003 ([`crate::clone::fmc`]).
    #[default]
    Fmc,
    /// Fratarcangeli & Schaerf 2005 ([`crate::clone::rbf`]).
    Rbf,
    /// Dense correspondence by non-rigid registration ([`crate::clone::fit`]).
    Fit,
}

impl Method {
    /// `fmc`, `rbf` or `fit`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Fmc => "fmc",
            Method::Rbf => "rbf",
            Method::Fit => "fit",
        }
    }
}

/// Settings of [`clone_face`](super::clone_face).
#[derive(Clone, Debug, PartialEq)]
pub struct CloneOptions {
    /// Surface method.
    pub method: Method,
    /// FMC settings (default: [`face_fmc_options`]).
    pub fmc: FmcOptions,
    /// RBF settings.
    pub rbf: RbfOptions,
    /// Fit settings.
    pub fit: FitOptions,
    /// RBF only: rescale each low-level translation FAP's motion so its feature point moves
    /// FAPU-compliantly (module docs, step 6). Default on; off is the paper's behaviour.
    pub rbf_fapu_rescale: bool,
    /// Align the target onto the source by a similarity before cloning (step 2). Default on.
    pub align: bool,
    /// Alignment rotations up to this many degrees are dropped (upright faces of other
    /// proportions; [`Similarity::fit_snapped`](super::Similarity::fit_snapped)). Default 3°.
    pub align_snap_degrees: f64,
}

impl Default for CloneOptions {
    fn default() -> Self {
        CloneOptions {
            method: Method::default(),
            fmc: face_fmc_options(),
            rbf: RbfOptions::default(),
            fit: FitOptions::default(),
            rbf_fapu_rescale: true,
            align: true,
            align_snap_degrees: 3.0,
        }
    }
}

/// The FMC settings whole faces clone with (module docs, "FMC settings"): `Global` position
/// normalisation, nearest-depth overlap resolution and no anti-aliasing filter.
pub fn face_fmc_options() -> FmcOptions {
    FmcOptions {
        normalisation: NormalisationMode::Global,
        overlap: OverlapRule::NearestDepth,
        filter_support: 0.0,
        ..FmcOptions::default()
    }
}
