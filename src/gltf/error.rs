//! glTF container and scene problems, and problems decoding a read document's compressed or
//! extended data (`gltf::decode`).

use std::path::PathBuf;

/// A glTF problem. Every variant is bad input (exit code 2): a scene the builder rejects
/// comes from the caller's data, a bad GLB from the file read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GltfError {
    /// The binary buffer is larger than glTF's 32-bit lengths allow.
    #[error("glTF buffer exceeds 4 GiB")]
    BufferTooLarge,
    /// The whole `.glb` would be larger than its 32-bit length field allows.
    #[error("glTF asset exceeds the 4 GiB GLB limit")]
    AssetTooLarge,
    /// The JSON chunk could not be serialised.
    #[error("cannot serialise glTF JSON: {0}")]
    Serialize(String),
    /// A `.glb` file's header or chunks are malformed.
    #[error("not a valid GLB file: {what}")]
    BadGlb {
        /// What is wrong.
        what: String,
    },
    /// The [`crate::gltf::SceneBuilder`] rejected an object; the message names it
    /// (`mesh `face`: non-finite UV`).
    #[error("{0}")]
    Scene(String),
    /// A read document requires an extension fbakit cannot decode (`KHR_draco_mesh_compression`,
    /// an unknown one); `how` says how to get a file without it.
    #[error("{}: requires the glTF extension `{extension}`, which fbakit cannot decode; {how}", file.display())]
    UnsupportedExtension {
        /// The file.
        file: PathBuf,
        /// The extension's name.
        extension: String,
        /// What to do instead (a command that rewrites the file without it).
        how: String,
    },
    /// Compressed or extended data of a read document is malformed, at JSON path `at`
    /// (`bufferViews[3].extensions.EXT_meshopt_compression`).
    #[error("{}: {at}: {what}", file.display())]
    Decode {
        /// The file.
        file: PathBuf,
        /// The JSON path.
        at: String,
        /// What is wrong.
        what: String,
    },
    /// A `.vrm` output for a document that is no VRM avatar (no `VRM` / `VRMC_vrm`
    /// extension): written, it would not load as one.
    #[error("{}: a .vrm is a VRM avatar, and {what} has no VRM extension (`VRM` or `VRMC_vrm`); write .glb instead", path.display())]
    NotVrm {
        /// The output asked for.
        path: PathBuf,
        /// What would be written (`the face's own glTF`, `a new glTF document`).
        what: String,
    },
}

impl GltfError {
    /// Always true: every glTF problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
