//! Outputs: what a face or a played animation becomes for people and other tools.
//!
//! - [`gltf`]: a face with its FAT as glTF 2.0 morph targets and transform nodes, optionally
//!   with a played clip as an animation.
//! - [`obj_sequence`]: one OBJ file per played frame plus a `frames.json` index.
//! - [`picture`]: rendered PNG pictures — played frames, contact sheets, turntables, the
//!   cloning grid.
//!
//! The player ([`crate::player`]) only computes frames; everything that turns frames into
//! files lives here.

pub mod gltf;
pub mod obj_sequence;
pub mod picture;
