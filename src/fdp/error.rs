//! What can be wrong with feature points, FAP units and landmark ids beyond file syntax
//! (syntax errors are located [`crate::error::ParseError`]s).

use std::path::PathBuf;

use super::landmarks::ICT_LANDMARK_KEY;

/// A feature-point, FAPU or landmark problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FdpError {
    /// A FAPU distance is zero, negative or not finite.
    #[error("FAPU distance {name} is {value}; it must be a positive finite length")]
    BadFapuDistance {
        /// `IRISD0`, `ES0`, `ENS0`, `MNS0` or `MW0`.
        name: &'static str,
        /// The distance.
        value: f64,
    },
    /// Feature points the FAPUs are measured on have no position.
    #[error("cannot compute the FAPUs: feature points without a position: {points}{hint}")]
    FapuPointsMissing {
        /// The points and the units needing them, e.g. `3.5 (for ES0, ENS0)`.
        points: String,
        /// Advice, starting with `; ` (or empty).
        hint: String,
    },
    /// A measured FAPU distance is not positive (mirrored model or wrong axes).
    #[error("cannot compute the FAPUs: {details} (MPEG-4 frame: +x = the face's left, +y = up)")]
    FapuNotPositive {
        /// Each failing unit with its points and values.
        details: String,
    },
    /// Feature points bound to mesh vertices could not be placed.
    #[error("cannot place feature points on the mesh: {problems}")]
    Unplaceable {
        /// The first problems, `; `-separated.
        problems: String,
    },
    /// A landmark id list has the wrong length.
    #[error("{what}: expected {expected} landmark vertex ids, found {found}")]
    LandmarkCount {
        /// The list's source or scheme.
        what: String,
        /// Landmarks the scheme has.
        expected: usize,
        /// Ids in the list.
        found: usize,
    },
    /// A landmark names a vertex the mesh does not have.
    #[error("{place}: landmark {landmark} is vertex {vertex}, beyond the mesh's {vertex_count} vertices")]
    LandmarkBeyondMesh {
        /// Where the id is written.
        place: String,
        /// 0-based landmark.
        landmark: usize,
        /// The vertex id.
        vertex: u32,
        /// The mesh's vertex count.
        vertex_count: usize,
    },
    /// Two landmarks name the same vertex.
    #[error(
        "{place}: landmark {landmark} repeats vertex {vertex} of landmark {first} ({first_place})"
    )]
    LandmarkRepeated {
        /// Where the repeat is written.
        place: String,
        /// 0-based landmark.
        landmark: usize,
        /// The vertex id.
        vertex: u32,
        /// The landmark that named it first.
        first: usize,
        /// Where that one is written.
        first_place: String,
    },
    /// A landmark JSON file has the ICT key, but not with an array.
    #[error("{}: {ICT_LANDMARK_KEY}: expected an array of vertex indices", file.display())]
    LandmarkKeyNotArray {
        /// The file.
        file: PathBuf,
    },
    /// A landmark JSON file is neither an array nor an object with the ICT key.
    #[error("{}: expected a JSON array of vertex indices or an object with the key `{ICT_LANDMARK_KEY}`", file.display())]
    NotLandmarkJson {
        /// The file.
        file: PathBuf,
    },
    /// A landmark id is not a vertex index.
    #[error(
        "{place}: expected a vertex index (an integer from 0 to {}), found {found}",
        u32::MAX
    )]
    BadVertexIndex {
        /// Where it is written.
        place: String,
        /// What is there.
        found: String,
    },
    /// A mesh vertex has a non-finite position.
    #[error("mesh `{mesh}`: vertex {vertex} has a non-finite position {position}")]
    NonFiniteVertex {
        /// The mesh.
        mesh: String,
        /// 0-based vertex.
        vertex: usize,
        /// The position as written.
        position: String,
    },
    /// `--mesh` names no mesh of the face.
    #[error("{}: no mesh `{mesh}` (its meshes: {meshes})", file.display())]
    UnknownLandmarkMesh {
        /// The face file.
        file: PathBuf,
        /// The name given.
        mesh: String,
        /// The face's mesh names, comma-separated.
        meshes: String,
    },
    /// Landmark ids index one mesh, but the face has several.
    #[error("{}: landmark ids index one mesh, but this face has {meshes} meshes; name it with --mesh NAME", file.display())]
    LandmarksNeedOneMesh {
        /// The face file.
        file: PathBuf,
        /// Its mesh count.
        meshes: usize,
    },
    /// A mesh whose vertex order is taken as the landmark order has too few vertices.
    #[error("{} has {vertices} vertices; without landmark ids its vertex order is the landmark order, so it needs at least {needed}", file.display())]
    TooFewLandmarkVertices {
        /// The mesh file.
        file: PathBuf,
        /// Its vertices.
        vertices: usize,
        /// Landmarks the scheme has.
        needed: usize,
    },
    /// Feature points bound to vertices without positions or FAPU distances: the mesh is needed.
    #[error("{}: the feature points are mesh-vertex indices without positions and the file has no FAPU distances; pass --mesh MESH with the neutral mesh they index", file.display())]
    NeedsMesh {
        /// The feature-point file.
        file: PathBuf,
    },
    /// The landmarks do not make a face frame (coincident or mirrored points).
    #[error("{0}")]
    LandmarkFrame(String),
}

impl FdpError {
    /// Always true: every feature-point problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
