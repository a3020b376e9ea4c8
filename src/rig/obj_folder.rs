//! OBJ rigs: a neutral OBJ plus one full-mesh OBJ per blend shape, each the neutral with that
//! one shape applied at weight 1 (same vertex order), named after the shape (`jawOpen.obj`).
//!
//! Two layouts: the neutral among its shapes in one folder (the ICT-FaceKit layout, neutral
//! `generic_neutral_mesh.obj`), or a neutral file and a separate folder of shapes. Shapes are
//! read in parallel; a shape whose vertex count differs from the neutral's is an error naming
//! both files. Only positions are taken from shape files (their faces are the neutral's by
//! definition of the layout).

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::{sparse_delta, BlendShape, Rig, RigError, RigMesh, MAX_RIG_SHAPES};
use crate::error::{Error, Result};
use crate::mesh::obj::{read_obj_file, read_obj_positions_file};

/// File names taken as the neutral of a rig folder, in order of preference.
pub const NEUTRAL_NAMES: [&str; 3] = ["generic_neutral_mesh.obj", "neutral.obj", "base.obj"];

/// Reads an OBJ rig from a folder (neutral found by name, see [`find_neutral`]) or from a
/// neutral `.obj` whose folder holds the shapes.
pub fn read_obj_rig(path: &Path) -> Result<Rig> {
    if path.is_dir() {
        let neutral = find_neutral(path)?;
        read_obj_rig_with(&neutral, path)
    } else {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        read_obj_rig_with(path, dir)
    }
}

/// The neutral OBJ of a rig folder: the first of [`NEUTRAL_NAMES`] present, else the only
/// `.obj` whose name contains `neutral`.
pub fn find_neutral(dir: &Path) -> Result<PathBuf> {
    for n in NEUTRAL_NAMES {
        let p = dir.join(n);
        if p.is_file() {
            return Ok(p);
        }
    }
    let candidates: Vec<PathBuf> = obj_files(dir)?
        .into_iter()
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().to_ascii_lowercase().contains("neutral"))
        })
        .collect();
    match candidates.as_slice() {
        [one] => Ok(one.clone()),
        [] => Err(RigError::NoNeutral {
            dir: dir.to_path_buf(),
            expected: NEUTRAL_NAMES.join(", "),
        }
        .into()),
        many => Err(RigError::SeveralNeutrals {
            dir: dir.to_path_buf(),
            candidates: many
                .iter()
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect::<Vec<_>>()
                .join(", "),
        }
        .into()),
    }
}

/// The `.obj` files of `dir`, sorted (at most [`MAX_RIG_SHAPES`] + 1).
fn obj_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let path = entry.map_err(|e| Error::io(dir, e))?.path();
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        if is_obj && path.is_file() {
            if out.len() > MAX_RIG_SHAPES {
                return Err(RigError::TooManyShapes {
                    dir: dir.to_path_buf(),
                    limit: MAX_RIG_SHAPES,
                }
                .into());
            }
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

/// Reads the neutral `neutral` and every other `.obj` of `shapes_dir` as a shape.
pub fn read_obj_rig_with(neutral: &Path, shapes_dir: &Path) -> Result<Rig> {
    let (scene, _) = read_obj_file(neutral)?;
    let neutral_mesh = scene.mesh;
    let neutral_canon = std::fs::canonicalize(neutral).map_err(|e| Error::io(neutral, e))?;
    let files: Vec<PathBuf> = obj_files(shapes_dir)?
        .into_iter()
        .filter(|p| std::fs::canonicalize(p).ok().as_ref() != Some(&neutral_canon))
        .collect();
    let n = neutral_mesh.vertex_count();
    let shapes: Vec<BlendShape> = files
        .par_iter()
        .map(|path| {
            let positions = read_obj_positions_file(path)?;
            if positions.len() != n {
                return Err(RigError::ShapeVertexCount {
                    file: path.clone(),
                    vertices: positions.len(),
                    neutral: neutral.to_path_buf(),
                    expected: n,
                }
                .into());
            }
            let name = path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let delta = sparse_delta(0, &neutral_mesh.positions, &positions);
            Ok(BlendShape {
                name,
                default_weight: 0.0,
                deltas: if delta.vertices.is_empty() {
                    Vec::new()
                } else {
                    vec![delta]
                },
            })
        })
        .collect::<Result<_>>()?;
    let name = neutral_mesh.name.clone();
    let rig_name = if neutral
        .file_name()
        .is_some_and(|f| NEUTRAL_NAMES.contains(&f.to_string_lossy().as_ref()))
    {
        super::rig_name(shapes_dir)
    } else {
        super::rig_name(neutral)
    };
    let rig = Rig {
        name: rig_name,
        meshes: vec![RigMesh {
            name,
            mesh: neutral_mesh,
        }],
        shapes,
        warnings: Vec::new(),
        source: None,
    };
    rig.check()?;
    Ok(rig)
}
