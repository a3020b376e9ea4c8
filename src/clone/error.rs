//! What can go wrong cloning whole faces (alignment, skin surfaces, assembling the FAT).
//! The surface-cloning methods (`fmc`, `rbf`) still report [`crate::error::Error::Invalid`].

/// A cloning problem. Every variant is bad input (exit code 2): it comes from the faces
/// given (too few shared feature points, degenerate geometry).
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
        key: crate::fat::TableKey,
        /// The mesh.
        mesh: String,
    },
    /// A cloned transform entry is NaN or infinite.
    #[error("cloning produced a non-finite transform entry for {key} on `{transform}`")]
    NonFiniteTransform {
        /// The table.
        key: crate::fat::TableKey,
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
}

impl CloneError {
    /// Always true (see the type's docs).
    pub fn is_input_error(&self) -> bool {
        true
    }
}
