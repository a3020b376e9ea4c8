//! Played frames as a sequence of Wavefront OBJ files.
//!
//! Each frame is one OBJ with all meshes merged in face coordinates (one `o` object per mesh,
//! polygons as the face has them), named `frame_NNNNN.obj` after the output frame number and
//! written atomically. [`ObjSequence::finish`] writes `frames.json`, a small index of the
//! files with their times.

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
    dir: PathBuf,
    scene: ObjScene,
    index: ObjIndex,
}

impl ObjSequence {
    /// Prepares writing `face`'s frames into `dir` (created if missing).
    pub fn new(face: &FaceModel, dir: &Path, fps: f64) -> Result<ObjSequence> {
        std::fs::create_dir_all(dir).map_err(|e| Error::Io {
            path: dir.to_path_buf(),
            source: e,
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
            dir: dir.to_path_buf(),
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
        let path = self.dir.join(&file);
        write_obj_file(&self.scene, &path)?;
        self.index.frames.push(ObjFrameEntry {
            index: frame.index,
            time: frame.time,
            file,
        });
        Ok(path)
    }

    /// Writes `frames.json` and returns its path.
    pub fn finish(self) -> Result<PathBuf> {
        let path = self.dir.join("frames.json");
        let text = serde_json::to_string_pretty(&self.index)
            .map_err(|e| Error::Invalid(format!("cannot encode frames.json: {e}")))?;
        crate::io::write_atomic(&path, text.as_bytes())?;
        Ok(path)
    }
}
