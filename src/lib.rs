//! # fbakit — MPEG-4 Face and Body Animation toolkit
//!
//! Modules follow the data, from the standard's tables to the files built on them:
//!
//! - [`spec`]: the FAP table, feature points, FAP units, visemes and expressions as typed tables.
//! - [`fdp`]: feature points and the FAP units (FAPU) measured on them.
//! - [`fat`]: Facial Animation Tables: model, evaluation, morph-target view, validation.
//! - [`synth`]: deterministic procedural faces (`alma`, `bruno`) with exact FATs, for demos,
//!   tests and as cloning ground truth.
//! - [`error`]: located parse errors and diagnostics shared by every reader.
//! - [`io`]: bounded reads and atomic writes.

pub mod error;
pub mod fat;
pub mod fdp;
pub mod io;
pub mod spec;
pub mod synth;
