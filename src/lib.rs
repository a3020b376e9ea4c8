//! # fbakit — MPEG-4 Face and Body Animation toolkit
//!
//! Modules follow the data, from the standard's tables to the files built on them:
//!
//! - [`spec`]: the FAP table, feature points, FAP units, visemes and expressions as typed tables.
//! - [`fap`]: ASCII FAP streams (`.fap`): reader, writer, hold semantics, resampling.
//! - [`fdp`]: feature points and the FAP units (FAPU) measured on them.
//! - [`error`]: located parse errors and diagnostics shared by every reader.
//! - [`io`]: bounded reads and atomic writes.

pub mod error;
pub mod fap;
pub mod fdp;
pub mod io;
pub mod spec;
