//! # fbakit — MPEG-4 Face and Body Animation toolkit
//!
//! Modules follow the data, from the standard's tables to the files built on them:
//!
//! - [`spec`]: the FAP table, feature points, FAP units, visemes and expressions as typed tables.
//! - [`fdp`]: feature points and the FAP units (FAPU) measured on them.
//! - [`error`]: located parse errors and diagnostics shared by every reader.
//! - [`io`]: bounded reads and atomic writes.
//! - [`vrml`]: VRML97 text syntax: parser, scene graph with DEF/USE, canonical writer.

pub mod error;
pub mod fdp;
pub mod io;
pub mod spec;
pub mod vrml;
