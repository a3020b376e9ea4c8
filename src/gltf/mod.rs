//! glTF 2.0 export: meshes with morph targets, a node hierarchy and animations, as `.glb` or
//! `.gltf`.
//!
//! Faces become glTF meshes whose morph targets are the FAT's tables
//! ([`crate::fat::morph`]); FAP playback becomes animations of morph weights plus node
//! rotations (eyes, head). The output is meant to load in three.js and Blender and to pass the
//! Khronos glTF validator with no errors and no warnings.
//!
//! The module has three layers, kept apart as in the `gltf` crate's design:
//! - [`json`]: a plain serde model of the glTF JSON schema (the subset fbakit writes). fbakit
//!   uses its own small model rather than `gltf-json`, whose index/`Checked` wrappers buy little
//!   for a writer that only ever produces valid indices, and whose output we want to control to
//!   the field (no defaults written, no empty arrays).
//! - The scene builder: plain data in ([`MeshData`], [`NodeData`], [`AnimationData`];
//!   `scene_data.rs`), checked as it is added to a [`SceneBuilder`] (`builder.rs`), laid out
//!   by [`SceneBuilder::build`] into one binary buffer of views and accessors (`layout.rs`)
//!   and the JSON objects that use them (`document.rs`). [`area_weighted_normals`]
//!   (`normals.rs`) supplies normals a mesh is given without.
//! - [`container`]: the [`GltfDocument`] written as `.glb` (JSON and `BIN` chunks, 4-byte
//!   aligned) or as `.gltf` with the buffer embedded as a base64 data URI (one self-contained
//!   file; prefer `.glb` for large faces, it is a quarter smaller and faster to load).
//!
//! Reading is the `gltf` crate's (in [`crate::rig::gltf_read`]); [`decode`] first turns a read
//! document's compressed data (`EXT_meshopt_compression`) into plain glTF and refuses required
//! extensions fbakit cannot decode.
//!
//! ## Layout choices
//! - One buffer; every buffer view starts at a multiple of 4 bytes and none has a `byteStride`
//!   (all data is tightly packed). Vertex data views carry `target` `ARRAY_BUFFER`, index views
//!   `ELEMENT_ARRAY_BUFFER`; animation and sparse views carry no target.
//! - Indices are `u16` when every index is below 65535, `u32` otherwise.
//! - Morph targets are written as sparse accessors (no base view: zeros plus the moved
//!   vertices) when that is smaller than dense data, which it is for the typical FAT table
//!   that moves a few hundred vertices of a face. Target names go to
//!   `mesh.extras.targetNames`, read by three.js (`morphTargetDictionary`) and Blender (shape
//!   key names).
//! - `POSITION` accessors (base and targets) and keyframe-time accessors carry exact `min` /
//!   `max`; equal keyframe-time arrays share one accessor.
//! - Non-finite numbers are rejected when data is added; nothing NaN is ever written.
//!
//! ## Validating with the Khronos validator
//! `tests/gltf_validator.rs` runs the official validator (npm package `gltf-validator`) on
//! generated files through `tests/support/validate-gltf.mjs` and requires 0 errors and 0
//! warnings. CI installs it with `npm install --prefix <dir> gltf-validator` and sets
//! `GLTF_VALIDATOR_DIR=<dir>`; without `node` or the package the test prints a note and passes.
//!
//! ## Example
//! ```
//! use fbakit::gltf::{AnimationData, ChannelData, ChannelValues, Interpolation};
//! use fbakit::gltf::{MeshData, NodeData, SceneBuilder};
//! use glam::Vec3;
//!
//! let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
//! let mut scene = SceneBuilder::new("face");
//! let mesh = scene.add_mesh(
//!     MeshData::new("skin", &positions[..], &[[0, 1, 2]][..])
//!         // Borrowed slices or owned `Vec`s both work (`Cow`).
//!         .with_sparse_target("open_jaw", vec![2], vec![Vec3::new(0.0, -0.1, 0.0)]),
//! )?;
//! let node = scene.add_node(NodeData::new("skin").with_mesh(mesh))?;
//! scene.add_animation(AnimationData {
//!     name: "talk".into(),
//!     channels: vec![ChannelData {
//!         node,
//!         times: vec![0.0, 0.04],
//!         values: ChannelValues::Weights(vec![0.0, 1.0]),
//!         interpolation: Interpolation::Linear,
//!     }],
//! })?;
//! let glb: Vec<u8> = scene.build()?.to_glb()?;
//! assert_eq!(&glb[..4], b"glTF");
//! # Ok::<(), fbakit::error::Error>(())
//! ```

mod builder;
pub mod container;
pub mod decode;
mod document;
mod error;
mod images;
pub mod json;
mod layout;
mod normals;
pub mod patch;
mod reclaim;
mod scene_data;
pub mod source;
pub mod vrm;

pub use builder::SceneBuilder;
pub use container::{parse_glb, GlbChunks, GltfDocument};
pub use error::GltfError;
pub use normals::area_weighted_normals;
pub use scene_data::{
    AnimationData, ChannelData, ChannelValues, Interpolation, MaterialData, MeshData, MeshId,
    MorphOffsets, MorphTargetData, NodeData, NodeId,
};
pub use vrm::check_vrm_output;

#[cfg(test)]
mod tests;
