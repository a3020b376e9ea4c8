#![warn(missing_docs)]
//! # fbakit — MPEG-4 Face and Body Animation toolkit
//!
//! Modules follow the data, from the standard's tables to the files built on them:
//!
//! - [`spec`]: the FAP table, feature points, FAP units, visemes and expressions as typed tables.
//! - [`fap`]: ASCII FAP streams (`.fap`): reader, writer, hold semantics, resampling.
//! - [`fdp`]: feature points and the FAP units (FAPU) measured on them.
//! - [`fat`]: Facial Animation Tables: model, evaluation, morph-target view, validation.
//! - [`clone`]: facial motion cloning (Pandzic 2003 `fmc`, Fratarcangeli & Schaerf 2005 `rbf`).
//! - [`gltf`]: glTF 2.0 export (`.glb`/`.gltf`): meshes, morph targets, nodes, animations.
//! - [`synth`]: deterministic procedural faces (`alma`, `bruno`) with exact FATs, for demos,
//!   tests and as cloning ground truth.
//! - [`mesh`]: polygon meshes, their geometry (triangulation, normals, nearest vertex) and
//!   Wavefront OBJ reading/writing.
//! - [`candide`]: the CANDIDE-3 parameterised face (`.wfm` reader, shape and animation units).
//! - [`player`]: plays FAP streams on faces (FAT evaluation per frame, one frame at a time).
//! - [`face`]: complete face models (meshes, transforms, feature points, FAT) and VRML face files.
//! - [`rig`]: blendshape rigs (glTF morph targets, OBJ shape folders such as the ICT-FaceKit)
//!   read into neutral meshes plus named shapes.
//! - [`render`]: CPU software renderer: shaded PNG frames, turntables, contact sheets and the
//!   cloning grid.
//! - [`export`]: outputs — glTF with morph targets and animation, OBJ frame sequences,
//!   rendered pictures (contact sheets, turntables, the cloning grid), the one-file HTML
//!   viewer (`fbakit view`), videos (MP4 through `ffmpeg`, GIF, PNG frames).
//! - [`demo`]: the end-to-end demo application (`fbakit demo`).
//! - [`snapshot`]: FATs compared as animation (`diff`), FAP streams compared, and a stable
//!   text of a face to pin in snapshot tests.
//! - [`speech`]: text to a FAP stream: phoneme timing from espeak-ng, visemes, blending.
//! - [`error`]: located parse errors and diagnostics shared by every reader.
//! - [`io`]: bounded reads (plain and gzip) and atomic writes.
//! - [`mod@format`]: output formats resolved once from a path; refusing to overwrite inputs.
//! - [`vrml`]: VRML97 text syntax: parser, scene graph with DEF/USE, canonical writer.
//! - [`prelude`]: the names most programs need, in one `use fbakit::prelude::*`.
//!
//! `ARCHITECTURE.md` in the repository draws the layers and says where new things go.
//!
//! Reading a face and a stream and playing one on the other:
//!
//! ```
//! use fbakit::prelude::*;
//!
//! let face = face::read("alma")?;
//! let (stream, _warnings) = read_stream_file("samples/speech.fap", &ReadOptions::lenient())?;
//! let mut player = Player::new(&face, &stream, &PlayOptions::default())?;
//! let mut frame = player.new_frame();
//! let mut frames = 0;
//! while player.next_frame(&mut frame) {
//!     frames += 1; // frame.pose holds the posed meshes
//! }
//! assert_eq!(frames, player.frame_count());
//! # Ok::<(), fbakit::error::Error>(())
//! ```
//!
//! Errors are one [`error::Error`] wrapping a typed enum per layer, so `?` works everywhere
//! and callers can `match` on what went wrong (e.g. `Error::Face(face::FaceError::..)`).

/// The vector and matrix types of fbakit's public API (`Vec3`, `Quat`, `Affine3A`), so
/// users need no `glam` dependency of their own, nor a matching version.
pub use glam;

pub mod candide;
pub mod clone;
pub mod demo;
pub mod error;
pub mod export;
pub mod face;
pub mod fap;
pub mod fat;
pub mod fdp;
pub mod format;
pub mod gltf;
pub mod io;
pub mod mesh;
pub mod player;
pub mod prelude;
pub mod render;
pub mod rig;
pub mod snapshot;
pub mod spec;
pub mod speech;
pub mod synth;
pub mod vrml;
