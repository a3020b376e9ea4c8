//! Outputs: what a face or a played animation becomes for people and other tools.
//!
//! - [`write()`]: the front door — a face with its FAT as the asset a pipeline needs (the
//!   user's own glTF patched, a new glTF in metres, ARKit names, OBJ shape sets, VRML), with
//!   [`ExportOptions`] and an [`ExportReport`] that carries the warnings.
//! - [`arkit_patch`]: the user's glTF with ARKit-named morph targets.
//! - [`budget`]: the size estimate every played output passes before its first frame.
//! - [`gltf`]: a face with its FAT as glTF 2.0 morph targets and transform nodes, optionally
//!   with a played clip as an animation.
//! - [`obj_sequence`]: one OBJ file per played frame plus a `frames.json` index.
//! - [`picture`]: rendered PNG pictures — played frames, contact sheets, turntables, the
//!   cloning grid.
//! - [`viewer`]: one self-contained HTML page that shows a face in the browser, plays a FAP
//!   stream on it and poses it live with FAP sliders (`fbakit view`).
//! - [`video`], [`movie`]: videos of a played stream — MP4 through `ffmpeg`, GIF, PNG frames
//!   (`fbakit render`).
//!
//! The player ([`crate::player`]) only computes frames; everything that turns frames into
//! files lives here.

pub mod arkit_patch;
pub mod budget;
mod error;
pub mod gltf;
pub mod gltf_carried;
pub mod gltf_eye_parts;
pub mod gltf_patch;
pub mod gltf_rotations;
pub mod gltf_user_nodes;
pub mod movie;
pub mod obj_sequence;
pub mod obj_shapes;
pub mod picture;
pub mod video;
pub mod viewer;
mod write;

pub use error::ExportError;
pub use write::{write, ExportKind, ExportOptions, ExportReport, ShapeNames, EXPORTS};

use std::path::Path;

use crate::error::Result;
use crate::face::FaceModel;
use crate::format::OutputFormat;

/// Writes `face` in the face format `path` names ([`OutputFormat::FACES`]): VRML, gzip VRML
/// or OBJ (the neutral only) through [`crate::face::write()`], glTF (`.glb`, `.gltf`) as
/// [`write()`] makes it. Returns what the format could not hold exactly. [`write()`] is the
/// front door with options and a report.
pub fn write_face(
    path: impl AsRef<Path>,
    face: &FaceModel,
) -> Result<Vec<crate::error::Diagnostic>> {
    let path = path.as_ref();
    match OutputFormat::resolve(path, OutputFormat::FACES, "a face file")? {
        OutputFormat::Glb | OutputFormat::Gltf => {
            write(path, face, &ExportOptions::default()).map(|r| r.warnings)
        }
        _ => crate::face::write(path, face).map(|()| Vec::new()),
    }
}
