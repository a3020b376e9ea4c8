//! What can be wrong with a blendshape rig, its files and the ARKit bridge. Syntax errors in
//! CSV and mapping files are located [`crate::error::ParseError`]s.

use std::path::PathBuf;

/// A rig problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RigError {
    /// Two meshes of a rig share a name.
    #[error("rig `{rig}`: two meshes are named `{mesh}`")]
    DuplicateMesh {
        /// The rig.
        rig: String,
        /// The mesh name.
        mesh: String,
    },
    /// A shape without a name.
    #[error("rig `{rig}`: a shape has no name")]
    UnnamedShape {
        /// The rig.
        rig: String,
    },
    /// Two shapes share a name.
    #[error("rig `{rig}`: two shapes are named `{shape}`")]
    DuplicateShape {
        /// The rig.
        rig: String,
        /// The shape name.
        shape: String,
    },
    /// A shape's default weight is NaN or infinite.
    #[error("rig `{rig}`: shape `{shape}` has a non-finite default weight")]
    NonFiniteWeight {
        /// The rig.
        rig: String,
        /// The shape.
        shape: String,
    },
    /// A shape's delta names a mesh index the rig does not have.
    #[error("rig `{rig}`: shape `{shape}`: unknown mesh {mesh}")]
    ShapeUnknownMesh {
        /// The rig.
        rig: String,
        /// The shape.
        shape: String,
        /// The mesh index.
        mesh: usize,
    },
    /// A shape's vertex list is unsorted, too long or out of range.
    #[error("rig `{rig}`: shape `{shape}`: bad vertex list on mesh `{mesh}`")]
    BadVertexList {
        /// The rig.
        rig: String,
        /// The shape.
        shape: String,
        /// The mesh.
        mesh: String,
    },
    /// A shape offset is NaN or infinite.
    #[error("rig `{rig}`: shape `{shape}`: non-finite offset on mesh `{mesh}`")]
    NonFiniteOffset {
        /// The rig.
        rig: String,
        /// The shape.
        shape: String,
        /// The mesh.
        mesh: String,
    },
    /// A file read as a rig has no blend shapes.
    #[error("{}: no morph targets (blend shapes): not a rig", file.display())]
    NoShapes {
        /// The file.
        file: PathBuf,
    },
    /// A mesh index beyond the rig's meshes.
    #[error("rig {rig}: no mesh {mesh} (it has {count})")]
    NoSuchMesh {
        /// The rig.
        rig: String,
        /// The index asked for.
        mesh: usize,
        /// The rig's mesh count.
        count: usize,
    },
    /// A keep mask whose length is not the mesh's vertex count.
    #[error("rig {rig}: mesh {mesh} has {vertices} vertices, the keep mask {mask}")]
    KeepMaskLength {
        /// The rig.
        rig: String,
        /// The mesh.
        mesh: String,
        /// The mesh's vertices.
        vertices: usize,
        /// The mask's length.
        mask: usize,
    },
    /// A GLB header shorter than itself.
    #[error("{}: not a readable glTF file: the GLB header gives a length of {length} bytes, less than the header itself", file.display())]
    GlbTooShort {
        /// The file.
        file: PathBuf,
        /// The declared length.
        length: u32,
    },
    /// A problem at a JSON path of a glTF file (`meshes[2].primitives[0]`).
    #[error("{}: {at}: {what}", file.display())]
    GltfContent {
        /// The file.
        file: PathBuf,
        /// The JSON path.
        at: String,
        /// What is wrong.
        what: String,
    },
    /// The glTF validator's findings (the first five, then a count).
    #[error("{}: invalid glTF: {findings}", file.display())]
    InvalidGltf {
        /// The file.
        file: PathBuf,
        /// The findings.
        findings: String,
    },
    /// The `gltf` crate could not read the file.
    #[error("{}: not a readable glTF file: {message}", file.display())]
    UnreadableGltf {
        /// The file.
        file: PathBuf,
        /// The reader's message.
        message: String,
    },
    /// A folder without a neutral OBJ.
    #[error("{}: no neutral OBJ (expected one of {expected} or a single *neutral*.obj)", dir.display())]
    NoNeutral {
        /// The folder.
        dir: PathBuf,
        /// The accepted names, comma-separated.
        expected: String,
    },
    /// A folder with several neutral candidates.
    #[error("{}: several candidate neutrals ({candidates}); name one neutral.obj", dir.display())]
    SeveralNeutrals {
        /// The folder.
        dir: PathBuf,
        /// The candidates' file names, comma-separated.
        candidates: String,
    },
    /// A folder with more OBJ files than a rig may have.
    #[error("{}: more than {limit} OBJ files; not a rig folder", dir.display())]
    TooManyShapes {
        /// The folder.
        dir: PathBuf,
        /// [`crate::rig::MAX_RIG_SHAPES`].
        limit: usize,
    },
    /// A shape OBJ whose vertex count differs from the neutral's.
    #[error("{}: has {vertices} vertices but the neutral {} has {expected}; a shape must be the full neutral mesh", file.display(), neutral.display())]
    ShapeVertexCount {
        /// The shape file.
        file: PathBuf,
        /// Its vertices.
        vertices: usize,
        /// The neutral file.
        neutral: PathBuf,
        /// The neutral's vertices.
        expected: usize,
    },
    /// A FAP mapping row names shapes the rig lacks (strict mapping).
    #[error("{}:{line}: unknown shape{} {shapes} (rig `{rig}` has no such blend shape)", file.display(), if *plural { "s" } else { "" })]
    UnknownShapes {
        /// The mapping file.
        file: PathBuf,
        /// The row's line.
        line: usize,
        /// More than one shape is missing.
        plural: bool,
        /// The missing shapes, quoted and comma-separated.
        shapes: String,
        /// The rig.
        rig: String,
    },
    /// A weight CSV frame rate out of range.
    #[error("{}: frame rate {fps} is not between 0 and 1000", file.display())]
    CsvFrameRate {
        /// The CSV file.
        file: PathBuf,
        /// The rate given.
        fps: f64,
    },
    /// A weight CSV whose frame rate cannot be detected from its seconds.
    #[error("{}: cannot detect the frame rate (fewer than two distinct times); give --fps", file.display())]
    UndetectableRate {
        /// The CSV file.
        file: PathBuf,
    },
    /// A weight CSV whose timecodes never cross a second.
    #[error("{}: the timecodes never cross a second, so their frame rate cannot be detected; give --fps", file.display())]
    UndetectableTimecodeRate {
        /// The CSV file.
        file: PathBuf,
    },
    /// A face without a FAT where ARKit shapes are to be made from it.
    #[error("face `{face}` has no FAT, so no ARKit shapes can be made from it")]
    NoFat {
        /// The face.
        face: String,
    },
    /// A face read without feature points for the ARKit bridge has no FAT.
    #[error("{}: the face has no FAT; give --fp FP for a blendshape rig, or a face with a FAT", file.display())]
    FaceWithoutFat {
        /// The face file (or bundled name).
        file: PathBuf,
    },
    /// A face that was not built from the rig it is paired with.
    #[error("face `{face}` is not the face of rig `{rig}` (meshes differ)")]
    FaceNotOfRig {
        /// The face.
        face: String,
        /// The rig.
        rig: String,
    },
    /// A face without vertex-bound feature points where the bridge needs them.
    #[error("face `{face}` has no feature points bound to vertices: nothing to compare (--fp)")]
    NoBoundFeaturePoints {
        /// The face.
        face: String,
    },
    /// A stream whose frame rate is not a finite positive number.
    #[error("stream `{stream}`: frame rate {rate} is not a finite positive number")]
    StreamFrameRate {
        /// The stream.
        stream: String,
        /// Its rate.
        rate: f64,
    },
    /// A stream without frames.
    #[error("stream `{stream}` has no frames")]
    EmptyStream {
        /// The stream.
        stream: String,
    },
    /// A stream longer than the bridge converts.
    #[error("stream `{stream}`: last frame number {last} is beyond {limit}")]
    StreamTooLong {
        /// The stream.
        stream: String,
        /// Its last frame number.
        last: u64,
        /// [`crate::rig::weights_csv::MAX_FRAME_NUMBER`].
        limit: u64,
    },
}

impl RigError {
    /// Always true: every rig problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
