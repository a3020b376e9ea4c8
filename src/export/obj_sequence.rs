//! Played frames as a sequence of Wavefront OBJ files.
//!
//! Each frame is one OBJ with all meshes merged in face coordinates (one `o` object per mesh,
//! polygons as the face has them), named `frame_NNNNN.obj` after the output frame number and
//! written into a temporary sibling directory. [`ObjSequence::finish`] writes `frames.json`,
//! a small index of the files with their times, and renames the directory into place; a
//! sequence dropped before that (an error mid-way) leaves nothing behind.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{Error, Result};
use crate::face::FaceModel;
use crate::mesh::obj::{write_obj_file, ObjScene};
use crate::mesh::{FaceGroup, Mesh, Polygons};
use crate::player::PlayerFrame;

/// One entry of `frames.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObjFrameEntry {
    /// Output frame number.
    pub index: usize,
    /// Time in seconds.
    pub time: f64,
    /// File name inside the directory.
    pub file: String,
}

/// The `frames.json` index.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObjIndex {
    /// Face name.
    pub face: String,
    /// Frame rate of the sequence.
    pub fps: f64,
    /// The files in frame order.
    pub frames: Vec<ObjFrameEntry>,
}

/// Writes played frames as OBJ files into a directory.
#[derive(Debug)]
pub struct ObjSequence {
    dir: crate::io::AtomicDir,
    scene: ObjScene,
    index: ObjIndex,
}

impl ObjSequence {
    /// Prepares writing `face`'s frames into `dir`: new, or a directory holding only the
    /// frames of an earlier sequence, which [`ObjSequence::finish`] replaces.
    pub fn new(face: &FaceModel, dir: &Path, fps: f64) -> Result<ObjSequence> {
        let dir = crate::io::open_frame_dir(dir, |name| {
            name == "frames.json" || crate::io::is_numbered_file(name, "frame_", ".obj")
        })?;
        let mut mesh = Mesh {
            name: face.name.clone(),
            ..Mesh::default()
        };
        let mut polygons = Polygons::new();
        let mut offset = 0u32;
        for m in &face.meshes {
            if m.mesh.polygons.is_empty() {
                offset += m.mesh.vertex_count() as u32;
                continue;
            }
            mesh.groups.push(FaceGroup {
                first_face: polygons.len() as u32,
                object: Some(m.name.clone()),
                ..FaceGroup::default()
            });
            let mut poly = Vec::new();
            for p in m.mesh.polygons.iter() {
                poly.clear();
                poly.extend(p.iter().map(|&i| i + offset));
                polygons.push(&poly);
            }
            offset += m.mesh.vertex_count() as u32;
        }
        mesh.polygons = polygons;
        mesh.positions.reserve(offset as usize);
        Ok(ObjSequence {
            dir,
            scene: ObjScene {
                mesh,
                material_libraries: Vec::new(),
            },
            index: ObjIndex {
                face: face.name.clone(),
                fps,
                frames: Vec::new(),
            },
        })
    }

    /// Writes one frame; returns the file written.
    pub fn write_frame(&mut self, frame: &PlayerFrame) -> Result<PathBuf> {
        let positions = &mut self.scene.mesh.positions;
        positions.clear();
        for m in 0..frame.pose.positions.len() {
            positions.extend(frame.pose.world_positions(m));
        }
        let file = format!("frame_{:05}.obj", frame.index);
        let path = self.dir.path().join(&file);
        write_obj_file(&self.scene, &self.dir.temp_path().join(&file))
            .map_err(|e| named_output(e, &path))?;
        self.index.frames.push(ObjFrameEntry {
            index: frame.index,
            time: frame.time,
            file,
        });
        Ok(path)
    }

    /// Writes `frames.json`, moves the directory into place and returns the index's path.
    pub fn finish(self) -> Result<PathBuf> {
        let path = self.dir.path().join("frames.json");
        let text = serde_json::to_string_pretty(&self.index)
            .map_err(|e| crate::error::EncodeError::new("frames.json", e))?;
        crate::io::write_atomic(&self.dir.temp_path().join("frames.json"), text.as_bytes())
            .map_err(|e| named_output(e, &path))?;
        self.dir.commit()?;
        Ok(path)
    }
}

/// A write error named after the file the user will see, not its temporary directory.
fn named_output(e: Error, path: &Path) -> Error {
    match e {
        Error::Output { source, .. } | Error::Io { source, .. } => Error::output(path, source),
        other => other,
    }
}
