//! Reading and writing face models as VRML97 face files.
//!
//! A file may hold a whole `Face` node, a bare `FDP`, or a plain scene (meshes only).
//!
//! **Reading.** The face's geometry is `FDP.faceSceneGraph` when given, else
//! `Face.renderedFace`, else every root node other than the face nodes. Each `Transform` becomes
//! a [`FaceTransform`], each `Shape` with an `IndexedFaceSet` a [`FaceMesh`]. Nodes without a
//! `DEF` name get a generated one (`transform_N`, `mesh_N`) in the kept scene, so names are
//! stable across read → write → read. A node reached a second time through `USE` is not
//! instanced twice (a warning says so). `FDP.featurePointsCoord` holds the feature points in
//! the standard's label order, in the face frame; each is bound to the nearest mesh vertex and
//! the distance is reported, unless fbakit's own record says which points are present and
//! which vertices they are bound to (below). `FDP.faceDefTables` become the [`Fat`].
//!
//! **Writing.** A face read from a file is written by patching that scene: mesh coordinates
//! and polygons, transform fields, and the `FDP`'s feature points and tables are replaced;
//! every other node (lights, viewpoints, unknown nodes, PROTOs, ROUTEs) is written back as it
//! was. A transform the scene lacks (cloning may add a `head` root or a part transform) is
//! inserted where its shapes and child transforms sit, and they are moved into it. A face
//! without a scene is written as `Face { fdp FDP { featurePointsCoord, faceSceneGraph
//! [transforms and shapes], faceDefTables } }`, so every `USE` follows its `DEF`.
//!
//! **fbakit's feature-point record.** `featurePointsCoord` must list all 84 points, but real
//! faces rarely have them all, and the standard does not say which vertex a point is. fbakit
//! therefore also writes `DEF fbakit_feature_points WorldInfo { title "fbakit feature points"
//! info [ "2.1 skin 123" ... ] }`: one entry per present point, `id mesh vertices` (vertices
//! `;`-separated, `-` for a point with a position only). Missing points are written into
//! `featurePointsCoord` at the mean of the present ones. Other readers ignore the `WorldInfo`.
//!
//! **Files.** [`read`](read_face_file) and [`write`](face_to_scene) hold the entry points;
//! `read_geometry` / `write_geometry` the transforms and meshes, `read_fat` / `write_fat` the
//! `FaceDefTables`, `bindings` fbakit's record and `fp_match` the nearest-vertex binding of
//! files without it.
//!
//! [`FaceTransform`]: crate::face::FaceTransform
//! [`FaceMesh`]: crate::face::FaceMesh
//! [`Fat`]: crate::fat::Fat

mod bindings;
mod fp_match;
mod read;
mod read_fat;
mod read_geometry;
mod write;
mod write_fat;
mod write_geometry;
mod write_insert;

pub use bindings::FP_RECORD_TITLE;
pub use fp_match::FeaturePointMatch;
pub use read::{face_from_scene, read_face_file, FaceFileKind, FaceReadReport, TableNodes};
pub use write::{face_to_scene, write_face_file, write_face_string};
