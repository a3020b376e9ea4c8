//! Helpers shared by integration tests (each test binary uses some of them).
#![allow(dead_code)]
pub mod avatar;
pub mod blender;
pub mod cli;
pub mod glb;
pub mod gltf_scenes;
pub mod gltf_transform;
pub mod ict_full_head;
pub mod loader_outputs;
pub mod node_check;
pub mod rpm_avatar;
pub mod validator;
