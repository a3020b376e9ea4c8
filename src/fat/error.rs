//! What can be wrong with a Facial Animation Table when it is bound to a face or built from
//! morph targets.

use super::TableKey;

/// A FAT problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FatError {
    /// A table for viseme 0 or the neutral expression, which cannot move anything.
    #[error("{key}: viseme 0 and the neutral expression cannot have tables")]
    NeutralTable {
        /// The table.
        key: TableKey,
    },
    /// A `FaceDefMesh` names a mesh the face does not have.
    #[error("{key}: FaceDefMesh refers to unknown mesh `{mesh}`")]
    UnknownMesh {
        /// The table.
        key: TableKey,
        /// The mesh name.
        mesh: String,
    },
    /// A `coordIndex` entry beyond the mesh's vertices.
    #[error(
        "{key}: coordIndex {index} is out of range for mesh `{mesh}` with {vertex_count} vertices"
    )]
    CoordIndexOutOfRange {
        /// The table.
        key: TableKey,
        /// The mesh name.
        mesh: String,
        /// The index.
        index: u32,
        /// The mesh's vertex count.
        vertex_count: usize,
    },
    /// The displacement count is not `coordIndex × intervals`.
    #[error("{key}: mesh `{mesh}` has {found} displacements, expected {} (coordIndex {coord_index} × intervals {intervals})", coord_index * intervals)]
    DisplacementCount {
        /// The table.
        key: TableKey,
        /// The mesh name.
        mesh: String,
        /// Displacements in the table.
        found: usize,
        /// Length of `coordIndex`.
        coord_index: usize,
        /// Number of intervals.
        intervals: usize,
    },
    /// A `FaceDefTransform` names a transform the face does not have.
    #[error("{key}: FaceDefTransform refers to unknown transform `{transform}`")]
    UnknownTransform {
        /// The table.
        key: TableKey,
        /// The transform name.
        transform: String,
    },
    /// A morph target's FAP value is zero or not finite.
    #[error("morph target {key} has value {value}; it must be finite and non-zero")]
    BadMorphValue {
        /// The target's key.
        key: TableKey,
        /// Its value.
        value: f64,
    },
    /// A morph target's vertex and offset lists differ in length.
    #[error("morph target {key} mesh `{mesh}`: {vertices} vertices but {offsets} offsets")]
    MorphLengths {
        /// The target's key.
        key: TableKey,
        /// The mesh name.
        mesh: String,
        /// Vertices listed.
        vertices: usize,
        /// Offsets listed.
        offsets: usize,
    },
    /// Two morph targets of one key at the same value.
    #[error("two morph targets of {key} have the same value {value}")]
    DuplicateMorphValue {
        /// The key.
        key: TableKey,
        /// The shared value.
        value: f64,
    },
}

impl FatError {
    /// Always true: every FAT problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
