//! # fbakit — MPEG-4 Face and Body Animation toolkit
//!
//! Modules follow the data, from the standard's tables to the files built on them:
//!
//! - [`spec`]: the FAP table, feature points, FAP units, visemes and expressions as typed tables.
//! - [`fdp`]: feature points and the FAP units (FAPU) measured on them.
//! - [`mesh`]: polygon meshes, their geometry (triangulation, normals, nearest vertex) and
//!   Wavefront OBJ reading/writing.
//! - [`candide`]: the CANDIDE-3 parameterised face (`.wfm` reader, shape and animation units).
//! - [`error`]: located parse errors and diagnostics shared by every reader.
//! - [`io`]: bounded reads and atomic writes.

pub mod candide;
pub mod error;
pub mod fdp;
pub mod io;
pub mod mesh;
pub mod spec;
