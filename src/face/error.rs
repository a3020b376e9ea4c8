//! What can be wrong with a face model: its structure, its feature points, morph sets and
//! the scenes it is written into. Syntax errors in face files are located
//! [`crate::error::ParseError`]s; FAT binding errors are [`crate::fat::FatError`]s.

use std::path::PathBuf;

use crate::error::{Error, Location};
use crate::fat::TableKey;
use crate::spec::FeaturePointId;

/// A face-model problem. Every variant is bad input (exit code 2), as are the wrapped errors
/// of [`FaceError::InFile`] and [`FaceError::Morph`] whatever their own kind (a feature-point
/// file or morph that does not fit the face is the input's fault).
#[derive(Debug, thiserror::Error)]
pub enum FaceError {
    /// An error about another input, prefixed with that file (e.g. a feature-point file that
    /// does not fit the face).
    #[error("{}: {source}", file.display())]
    InFile {
        /// The file the problem is in.
        file: PathBuf,
        /// The problem.
        source: Box<Error>,
    },
    /// An error about one line of another input (a feature-point CSV row that does not fit
    /// the face), prefixed with the file and line.
    #[error("{}:{line}: {source}", file.display())]
    InFileAt {
        /// The file the problem is in.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// The problem.
        source: Box<Error>,
    },
    /// A folder given as a face is not an OBJ rig folder.
    #[error("{}: is a directory and not a rig folder ({reason}); expected a face file (.wrl, \
             .wrl.gz, .obj, .wfm, .glb, .gltf), a folder of rig shape OBJs or a bundled face \
             name ({bundled})", path.display())]
    NotAFaceFolder {
        /// The folder.
        path: PathBuf,
        /// Why it is not a rig folder.
        reason: String,
        /// The bundled face names, comma-separated.
        bundled: String,
    },
    /// A CANDIDE-3 model was read without its feature-point table.
    #[error("{}: a CANDIDE-3 model needs its feature-point table to become a face; give it \
             with --fp (e.g. feature-points.csv beside candide3.wfm)", path.display())]
    CandideNeedsFeaturePoints {
        /// The `.wfm` file.
        path: PathBuf,
    },
    /// A CANDIDE feature point has a position but no vertex binding.
    #[error("feature point {id} has a position but no CANDIDE vertex; the table must bind every point to vertices")]
    UnboundCandidePoint {
        /// The point.
        id: FeaturePointId,
    },
    /// A CANDIDE animation unit moves a vertex the model does not have.
    #[error("FAP unit {fap} moves vertex {vertex}, which does not exist")]
    AnimationUnitVertex {
        /// The FAP number.
        fap: u8,
        /// The 0-based vertex.
        vertex: u32,
    },
    /// A CANDIDE animation unit lists a vertex twice.
    #[error("FAP unit {fap} lists vertex {vertex} twice")]
    AnimationUnitRepeat {
        /// The FAP number.
        fap: u8,
        /// The 0-based vertex.
        vertex: u32,
    },
    /// Two meshes share a name.
    #[error("two meshes are named `{name}`")]
    DuplicateMesh {
        /// The name.
        name: String,
    },
    /// Two transforms share a name.
    #[error("two transforms are named `{name}`")]
    DuplicateTransform {
        /// The name.
        name: String,
    },
    /// A transform is listed before its parent.
    #[error("transform `{name}` comes before its parent")]
    TransformBeforeParent {
        /// The transform.
        name: String,
    },
    /// A mesh refers to a transform index the face does not have.
    #[error("mesh `{mesh}` refers to a missing transform")]
    MissingTransform {
        /// The mesh.
        mesh: String,
    },
    /// Feature points name meshes the face does not have.
    #[error("feature points bound to meshes the face does not have ({points}); the face's meshes: {meshes}")]
    UnknownFeaturePointMeshes {
        /// The first such point (its line is looked up for the message).
        first: crate::spec::FeaturePointId,
        /// Each point and the mesh it names, comma-separated.
        points: String,
        /// The face's mesh names, comma-separated.
        meshes: String,
    },
    /// A feature point is bound to a vertex its mesh does not have.
    #[error("feature point {id} is bound to vertex {vertex} of mesh `{mesh}`, which has {count} vertices (ids 0 to {last})", last = count.saturating_sub(1))]
    FeaturePointVertexOutOfRange {
        /// The point.
        id: crate::spec::FeaturePointId,
        /// The mesh, as the face names it.
        mesh: String,
        /// The vertex id given.
        vertex: u32,
        /// The mesh's vertex count.
        count: usize,
    },
    /// A feature point given by position is far from every vertex of the face.
    #[error("feature point {id} is {distance} from the nearest vertex, more than a tenth of the face size ({limit}); are the positions in the face file's frame and units (`fbakit face info`)?")]
    FeaturePointFarFromMesh {
        /// The point.
        id: crate::spec::FeaturePointId,
        /// Distance to the nearest vertex.
        distance: f32,
        /// The largest distance accepted.
        limit: f32,
    },
    /// A feature point's position holds NaN or infinity.
    #[error("feature point {id} has a non-finite position")]
    NonFiniteFeaturePoint {
        /// The point.
        id: FeaturePointId,
    },
    /// The face has more vertices than one OBJ can index.
    #[error("too many vertices for one OBJ")]
    TooManyVertices,
    /// The FAT names a mesh the written scene lacks.
    #[error("{key}: FAT refers to unknown mesh `{mesh}`")]
    FatMeshNotInScene {
        /// The table.
        key: TableKey,
        /// The mesh.
        mesh: String,
    },
    /// The FAT names a transform the written scene lacks.
    #[error("{key}: FAT refers to unknown transform `{transform}`")]
    FatTransformNotInScene {
        /// The table.
        key: TableKey,
        /// The transform.
        transform: String,
    },
    /// An interval border VRML cannot store (`intervalBorders` is `MFInt32`).
    #[error("{key}: interval border {border} is not an integer (intervalBorders is MFInt32)")]
    NonIntegerBorder {
        /// The table.
        key: TableKey,
        /// The border.
        border: f64,
    },
    /// A transform of the face is missing from the scene it is written into.
    #[error("transform `{name}` is not in the face's scene; clear `scene` to write a new one")]
    TransformNotInScene {
        /// The transform.
        name: String,
    },
    /// A mesh of the face is missing from the scene it is written into.
    #[error("mesh `{name}` is not in the face's scene; clear `scene` to write a new one")]
    MeshNotInScene {
        /// The mesh.
        name: String,
    },
    /// A morph manifest is not a JSON object of names to numbers.
    #[error("{location}: expected a JSON object mapping morph names to FAP values ({message})")]
    ManifestSyntax {
        /// Where the JSON breaks.
        location: Location,
        /// The JSON parser's message.
        message: String,
    },
    /// A morph manifest value is zero or not a finite number.
    #[error("{}: `{name}`: {value} is not a finite, non-zero FAP value", file.display())]
    ManifestValue {
        /// The manifest.
        file: PathBuf,
        /// The morph name.
        name: String,
        /// The value as written.
        value: String,
    },
    /// A manifest entry names no morph file.
    #[error("{manifest}: `{name}` names no morph file in {}", dir.display())]
    UnusedManifestEntry {
        /// The manifest path as given.
        manifest: String,
        /// The entry.
        name: String,
        /// The morph folder.
        dir: PathBuf,
    },
    /// A morph tolerance that is negative or not finite.
    #[error("tolerance {tolerance} must be a finite number ≥ 0")]
    BadTolerance {
        /// The tolerance.
        tolerance: f64,
    },
    /// A morph folder with too many entries.
    #[error("{}: more than {limit} entries; not a morph folder", dir.display())]
    TooManyMorphFiles {
        /// The folder.
        dir: PathBuf,
        /// The limit.
        limit: usize,
    },
    /// A morph file name that names no FAP, viseme or expression.
    #[error("{}: {message}", file.display())]
    BadMorphName {
        /// The morph file.
        file: PathBuf,
        /// What is wrong with its name.
        message: String,
    },
    /// Two morph files show the same key at the same value.
    #[error("{} and {} both show {key} at value {value}", first.display(), second.display())]
    DuplicateMorph {
        /// The first file.
        first: PathBuf,
        /// The second file.
        second: PathBuf,
        /// The key.
        key: TableKey,
        /// The value.
        value: f64,
    },
    /// A morph's vertex count differs from the neutral's.
    #[error("has {morph} vertices, the neutral has {neutral} (a morph must have the neutral's topology)")]
    MorphVertexCount {
        /// The morph's vertices.
        morph: usize,
        /// The neutral's vertices.
        neutral: usize,
    },
    /// A morph's polygons differ from the neutral's.
    #[error("its polygons differ from the neutral's (first at polygon {at}; {morph} vs {neutral} polygons)")]
    MorphPolygons {
        /// The first differing polygon, 1-based.
        at: usize,
        /// The morph's polygon count.
        morph: usize,
        /// The neutral's polygon count.
        neutral: usize,
    },
    /// A morph vertex holds NaN or infinity.
    #[error("vertex {vertex} has a non-finite coordinate")]
    MorphNonFinite {
        /// The vertex, 1-based as in OBJ.
        vertex: usize,
    },
    /// A morph value that is zero or not finite.
    #[error("--value {value}: must be a finite, non-zero FAP value")]
    BadMorphValue {
        /// The value.
        value: f64,
    },
    /// A problem with one in-memory morph.
    #[error("morph {key} @ {value}: {source}")]
    Morph {
        /// The morph's key.
        key: TableKey,
        /// The morph's value.
        value: f64,
        /// The problem.
        source: Box<Error>,
    },
    /// Subdividing a face would make more vertices than the limit.
    #[error("face `{face}`: {rounds} rounds of subdivision would make over {max} vertices from {vertices}; use fewer rounds")]
    TooManySubdivided {
        /// The face.
        face: String,
        /// Rounds asked for.
        rounds: usize,
        /// Vertices before subdividing.
        vertices: usize,
        /// The limit ([`crate::face::subdivide::MAX_SUBDIVIDED_VERTICES`]).
        max: usize,
    },
}

impl FaceError {
    /// Always true: every face problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }

    /// `source` about `file`, prefixed with the file's name.
    pub fn in_file(file: impl Into<PathBuf>, source: Error) -> Self {
        FaceError::InFile {
            file: file.into(),
            source: Box::new(source),
        }
    }
}
