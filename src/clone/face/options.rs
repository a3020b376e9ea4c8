//! Settings of a whole-face clone: the surface method and its options.

use serde::Serialize;

use crate::clone::fit::FitOptions;
use crate::clone::fmc::{FmcCorrespondence, FmcOptions, NormalisationMode, OverlapRule};
use crate::clone::rbf::{RbfCorrespondence, RbfOptions, RbfTransport};

/// Which surface method clones the skin. The default, `Fit`, is the one every command uses
/// unless told otherwise: on the real-head ground truth (ICT-FaceKit heads with known FATs)
/// it has the lowest error of the three (median 2.6 % against the papers' projections and
/// rays, 7.4 % and 5.5 %), and on alma → bruno too (25.5 % against 30.6 / 31.5 %). The
/// default modes of `Fmc` and `Rbf` now take `fit`'s dense correspondence too (their module
/// docs): on ICT identity heads fit 4.4–5.0 %, fmc 5.7–6.9 %, rbf 4.4–5.0 %.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Pandžić 2003 ([`crate::clone::fmc`]).
    Fmc,
    /// Fratarcangeli & Schaerf 2005 ([`crate::clone::rbf`]).
    Rbf,
    /// Dense correspondence by non-rigid registration ([`crate::clone::fit`]).
    #[default]
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

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// When the `lid_cover` step runs ([`CloneOptions::lid_cover`]; its module docs in
/// `lid_cover.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LidCover {
    /// Per eye the source's blink closes: cover it only where what the clone's closed lids
    /// leave of it differs from what the source's own closed lids leave of the source's
    /// (`lid_cover.rs` module docs, "When"): the clone shows a share of its eye more than
    /// 0.1 over the source's (a source whose closed lids hide its eye, or that has none), or
    /// a sliver standing out in front of its closed lids less than half as far as the
    /// source's eye stands out in front of the source's (alma's blink on ICT's head: 20 % of
    /// the eye standing out 0.03 half widths, alma's own 58 % standing out 0.14). A
    /// self-clone sees the same on both sides and is kept exactly; so is a cartoon onto a
    /// cartoon whose blinks both leave the eye showing (alma ↔ bruno).
    #[default]
    Auto,
    /// Cover every eye the source's blink closes (self-clones change: alma → alma's lid FAPs
    /// 4.6 % upper / 3.7 % lower off the truth, bruno → bruno's 4.6 % / 3.4 %).
    On,
    /// Never run the step.
    Off,
}

impl LidCover {
    /// `auto`, `on` or `off`.
    pub fn name(self) -> &'static str {
        match self {
            LidCover::Auto => "auto",
            LidCover::On => "on",
            LidCover::Off => "off",
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
    /// `smooth` checks the turns at a quarter and a half of each lid FAP's motion too (module docs,
    /// `smooth`): alma's lids onto ICT no longer fold at the eye corners. The middle of a lid
    /// FAP's margin is held with its lid point then, so the lashes riding it follow the lid.
    /// Default on.
    pub smooth_shares: bool,
    /// Run `lid_close` (module docs): the slit closes band by band where the source's does,
    /// the change faded out over the margins' middles and capped past the closing value;
    /// `lid_seam`: there the lids meet along one smooth line; and `eyeball`: no lid vertex
    /// passes into an eyeball part on its way to any border. Default on.
    pub lid_close: bool,
    /// When to run `lid_cover` (module docs, after `eyeball` and `smooth`'s second pass):
    /// where the source's blink closes its eye, the target's slit closes over its eyeball and
    /// the closed lids come forward until they cover it from the front. Default
    /// [`LidCover::Auto`]: only on an eye whose closed lids leave it seen differently from
    /// how the source's own closed lids leave the source's (alma's blink on ICT's head: 69 / 70
    /// eye vertices per eye seen through the closed lids, none with the step), so a
    /// self-clone is kept exactly. The report says per eye what it measured and did
    /// ([`CloneReport::lid_cover`](super::CloneReport::lid_cover)).
    pub lid_cover: LidCover,
}

impl Default for CloneOptions {
    fn default() -> Self {
        CloneOptions {
            method: Method::default(),
            fmc: face_fmc_options(),
            rbf: face_rbf_options(),
            fit: FitOptions::default(),
            rbf_fapu_rescale: true,
            align: true,
            align_snap_degrees: 3.0,
            smooth_shares: true,
            lid_close: true,
            lid_cover: LidCover::default(),
        }
    }
}

/// The RBF settings whole faces clone with: target vertices bound by `fit`'s dense
/// correspondence instead of normal rays, motions carried as displacements (scaled to the
/// target's FAP units by the pipeline's rescale) instead of through the volume morph
/// ([`crate::clone::rbf`] module docs, "Default mode").
pub fn face_rbf_options() -> RbfOptions {
    RbfOptions {
        correspondence: RbfCorrespondence::Dense,
        transport: RbfTransport::Displacement,
        ..RbfOptions::default()
    }
}

/// The FMC settings whole faces clone with (module docs, "FMC settings"): `Global` position
/// normalisation, nearest-depth overlap resolution and no anti-aliasing filter.
pub fn face_fmc_options() -> FmcOptions {
    FmcOptions {
        normalisation: NormalisationMode::Global,
        overlap: OverlapRule::NearestDepth,
        filter_support: 0.0,
        correspondence: FmcCorrespondence::Dense,
        ..FmcOptions::default()
    }
}
