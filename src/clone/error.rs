//! What can go wrong cloning whole faces (alignment, skin surfaces, the surface methods
//! `fmc`, `rbf` and `fit`, assembling the FAT, measuring a clone).

use crate::fat::TableKey;
use crate::spec::FeaturePointId;

/// A cloning problem. Every variant is bad input (exit code 2): it comes from the faces or
/// options given (too few shared feature points, degenerate geometry, an option out of range).
#[derive(Debug, thiserror::Error)]
pub enum CloneError {
    /// Too few feature points shared by the two faces to align them.
    #[error("aligning the faces needs at least 3 shared feature points, found {found}")]
    TooFewSharedPoints {
        /// Shared points found.
        found: usize,
    },
    /// The alignment's singular value decomposition failed.
    #[error("feature point alignment: SVD failed")]
    SvdFailed,
    /// The shared feature points lie on a line.
    #[error("feature point alignment: the shared feature points are collinear")]
    CollinearPoints,
    /// The alignment is not a usable similarity (zero or non-finite scale).
    #[error("feature point alignment gave a degenerate similarity")]
    DegenerateSimilarity,
    /// A cloned displacement is NaN or infinite.
    #[error("cloning produced a non-finite displacement for {key} on mesh `{mesh}`")]
    NonFiniteDisplacement {
        /// The table.
        key: TableKey,
        /// The mesh.
        mesh: String,
    },
    /// A cloned transform entry is NaN or infinite.
    #[error("cloning produced a non-finite transform entry for {key} on `{transform}`")]
    NonFiniteTransform {
        /// The table.
        key: TableKey,
        /// The transform.
        transform: String,
    },
    /// A skin vertex is NaN or infinite.
    #[error("face `{face}`: skin vertex {vertex} has a non-finite position")]
    NonFiniteSkin {
        /// The face.
        face: String,
        /// The vertex in the concatenated skin.
        vertex: usize,
    },
    /// A face's FAP units cannot be measured.
    #[error("face `{face}`: {source}")]
    Fapu {
        /// The face.
        face: String,
        /// Why.
        source: Box<crate::error::Error>,
    },
    /// A face to clone from has no Facial Animation Table.
    #[error("source face `{face}` has no FAT to clone")]
    NoSourceFat {
        /// The face.
        face: String,
    },
    /// The ground-truth face of a measurement has no FAT to compare with.
    #[error(
        "face `{face}` has no FAT to compare with: the truth must be a face with its true tables"
    )]
    NoTruthFat {
        /// The face.
        face: String,
    },
    /// No mesh of a face holds a skin feature point.
    #[error("{face} has no skin mesh: no mesh holds a skin feature point")]
    NoSkin {
        /// The face as the user knows it (`source face`, ``face `alma` ``).
        face: String,
    },
    /// A ground-truth comparison got a clone whose neutral differs from the truth's.
    #[error("ground truth comparison needs the same neutral geometry on both faces")]
    TruthGeometryDiffers,
    /// A ground-truth comparison got a clone without vertices.
    #[error("cloned face has no vertices")]
    EmptyClone,
    /// A surface has no vertices or no triangles ([`crate::clone::CloneSurface::check`]).
    #[error("the {side} surface has no vertices or no triangles")]
    EmptySurface {
        /// `source` or `target`.
        side: String,
    },
    /// A surface has more vertices than 32-bit indices can name.
    #[error("the {side} surface has {vertices} vertices, more than 32-bit indices can name")]
    TooManyVertices {
        /// `source` or `target`.
        side: String,
        /// Its vertex count.
        vertices: usize,
    },
    /// A surface vertex is NaN or infinite.
    #[error("the {side} surface: vertex {vertex} has a non-finite position")]
    NonFinitePosition {
        /// `source` or `target`.
        side: String,
        /// The vertex.
        vertex: usize,
    },
    /// A surface triangle names a vertex the surface lacks.
    #[error("the {side} surface: triangle {triangle:?} refers to a vertex beyond the {vertices} vertices")]
    TriangleOutOfRange {
        /// `source` or `target`.
        side: String,
        /// The triangle's vertex indices.
        triangle: [u32; 3],
        /// The surface's vertex count.
        vertices: usize,
    },
    /// A feature point's position is NaN or infinite.
    #[error("the {side} surface: feature point {id} has a non-finite position")]
    NonFiniteFeaturePoint {
        /// `source` or `target`.
        side: String,
        /// The feature point.
        id: FeaturePointId,
    },
    /// A feature point is bound to a vertex the surface lacks.
    #[error("the {side} surface: feature point {id} names vertex {vertex} beyond the {vertices} vertices")]
    FeaturePointOutOfRange {
        /// `source` or `target`.
        side: String,
        /// The feature point.
        id: FeaturePointId,
        /// The vertex it names.
        vertex: u32,
        /// The surface's vertex count.
        vertices: usize,
    },
    /// A source motion moves a vertex the source lacks, or by a non-finite offset.
    #[error("motion {key}: offset {offset} of vertex {vertex} is not a finite displacement of one of the source's {vertices} vertices")]
    BadMotion {
        /// The motion's table.
        key: TableKey,
        /// The vertex.
        vertex: u32,
        /// The offset, as written.
        offset: String,
        /// The source's vertex count.
        vertices: usize,
    },
    /// A method's numeric option is out of range.
    #[error("{method} option {option} must be a finite non-negative number, got {value}")]
    BadOption {
        /// `fmc`, `rbf` or `fit`.
        method: &'static str,
        /// The option, as named in the options struct.
        option: &'static str,
        /// Its value.
        value: f64,
    },
    /// Facial motion cloning lacks some of its required feature points.
    #[error("facial motion cloning needs these feature points: {}", missing_lists(.source_lacks, .target_lacks))]
    MissingFeaturePoints {
        /// Labels the source lacks.
        source_lacks: Vec<String>,
        /// Labels the target lacks.
        target_lacks: Vec<String>,
    },
    /// A feature point a step needs is missing.
    #[error("{side} face lacks feature point {id}")]
    MissingFeaturePoint {
        /// `source` or `target`.
        side: String,
        /// The feature point.
        id: FeaturePointId,
    },
    /// fmc's cylindrical projection does not fit a face.
    #[error("{side} face: {reason}")]
    Projection {
        /// `source` or `target`.
        side: String,
        /// Why (names the feature points involved).
        reason: String,
    },
    /// Every source triangle is degenerate in fmc's alignment space.
    #[error("source face has no usable (non-degenerate) triangles")]
    NoUsableTriangles,
    /// A surface method produced a NaN or infinite offset.
    #[error(
        "{method} cloning produced a non-finite displacement for {key} at target vertex {vertex}"
    )]
    NonFiniteOutput {
        /// `fmc`, `rbf` or `fit`.
        method: &'static str,
        /// The motion's table.
        key: TableKey,
        /// The target vertex.
        vertex: u32,
    },
    /// rbf's first fit, from the feature points alone, failed.
    #[error(
        "RBF fit from {correspondences} distinct feature-point correspondences failed: {source}"
    )]
    RbfFeaturePointFit {
        /// Distinct correspondences.
        correspondences: usize,
        /// Why.
        source: RbfFitError,
    },
    /// An RBF fit failed.
    #[error(transparent)]
    RbfFit(#[from] RbfFitError),
    /// fit's sparse system cannot be built or solved.
    #[error("fit: {0}")]
    FitSystem(FitSystemError),
}

fn missing_lists(source: &[String], target: &[String]) -> String {
    let mut parts = Vec::new();
    if !source.is_empty() {
        parts.push(format!("source face lacks {}", source.join(", ")));
    }
    if !target.is_empty() {
        parts.push(format!("target face lacks {}", target.join(", ")));
    }
    parts.join("; ")
}

/// Why a multiquadric RBF could not be fitted to a set of correspondences.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RbfFitError {
    /// Fewer than four distinct correspondences.
    #[error("RBF fit needs at least 4 distinct correspondences, got {found}")]
    TooFew {
        /// Correspondences given.
        found: usize,
    },
    /// A correspondence is NaN or infinite.
    #[error("RBF fit: a correspondence is not finite")]
    NonFinite,
    /// Every correspondence point is the same point.
    #[error("RBF fit: all correspondence points coincide")]
    AllCoincide,
    /// Two correspondence points coincide.
    #[error("RBF fit: two correspondence points coincide (merge them first)")]
    Coincide,
    /// The points do not span 3D space.
    #[error("RBF fit: the correspondence points are coplanar or collinear; at least 4 non-coplanar feature points are needed")]
    Coplanar,
    /// The linear system is numerically singular.
    #[error("RBF fit: the linear system is singular (pivot ratio {pivot_ratio:.3e})")]
    Singular {
        /// Largest over smallest LU pivot magnitude.
        pivot_ratio: f64,
    },
    /// The solution has NaN or infinite entries.
    #[error("RBF fit: the solution is not finite (singular system)")]
    NonFiniteSolution,
}

/// Why fit's sparse smoothness system failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitSystemError {
    /// The vertex count is zero or too large for the solver's indices.
    #[error("cannot solve for {vertices} vertices")]
    Size {
        /// Vertices.
        vertices: usize,
    },
    /// The right-hand side or diagonal does not match the system.
    #[error("system size mismatch")]
    SizeMismatch,
    /// The sparse solver refused.
    #[error("{step} failed ({details})")]
    Solver {
        /// The solver step.
        step: &'static str,
        /// The solver's message.
        details: String,
    },
    /// The solution has NaN or infinite entries.
    #[error("non-finite solution")]
    NonFinite,
}

impl CloneError {
    /// Always true (see the type's docs).
    pub fn is_input_error(&self) -> bool {
        true
    }
}
