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
//! - [`player`]: plays FAP streams on faces (FAT evaluation per frame), glTF and OBJ output.
//! - [`face`]: complete face models (meshes, transforms, feature points, FAT) and VRML face files.
//! - [`rig`]: blendshape rigs (glTF morph targets, OBJ shape folders such as the ICT-FaceKit)
//!   read into neutral meshes plus named shapes.
//! - [`render`]: CPU software renderer: shaded PNG frames, turntables, contact sheets and the
//!   cloning grid.
//! - [`showcase`]: rendered playback frames, contact sheets, the cloning grid and the
//!   end-to-end demo (`fbakit demo`).
//! - [`error`]: located parse errors and diagnostics shared by every reader.
//! - [`io`]: bounded reads and atomic writes.
//! - [`vrml`]: VRML97 text syntax: parser, scene graph with DEF/USE, canonical writer.

pub mod candide;
pub mod clone;
pub mod error;
pub mod face;
pub mod fap;
pub mod fat;
pub mod fdp;
pub mod gltf;
pub mod io;
pub mod mesh;
pub mod player;
pub mod render;
pub mod rig;
pub mod showcase;
pub mod spec;
pub mod synth;
pub mod vrml;
