//! Why a mesh cannot be written as OBJ (reading errors are located
//! [`crate::error::ParseError`]s).

/// A mesh problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MeshError {
    /// The mesh fails [`crate::mesh::Mesh::validate`].
    #[error("cannot write an invalid mesh as OBJ: {details}")]
    InvalidMesh {
        /// The validation result, debug-printed.
        details: String,
    },
    /// A polygon has fewer than 3 corners.
    #[error("OBJ faces need at least 3 corners")]
    DegenerateFace,
    /// UVs, normals or colours hold NaN or infinity.
    #[error("cannot write non-finite uvs, normals or colours")]
    NonFiniteAttributes,
    /// An object, group, material or library name that would not read back.
    #[error(
        "name `{name}` cannot be written to OBJ (line break, `#`, outer spaces or trailing `\\`)"
    )]
    UnwritableName {
        /// The name, escaped for display.
        name: String,
    },
    /// A group name that is empty or holds spaces.
    #[error("OBJ group names cannot be empty or contain spaces")]
    BadGroupName,
}

impl MeshError {
    /// Always true: every mesh problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
