//! OBJ shape sets: the neutral face and one OBJ per morph target, every file with the face's
//! own vertices in their order, so they drop into Blender, Maya or an engine as shape keys.
//! A face read from OBJ (that still has that file's layout) gets the user's file back in every
//! one of them — groups, `usemtl`/`mtllib`, `vt`, `vn`, comments kept — with only the `v` lines
//! rewritten ([`crate::face::write::source_obj_text`]); other faces get their meshes merged in
//! face coordinates, as OBJ output always does. The `.mtl` files a `mtllib` names are not
//! copied.
//!
//! **Where.** `DIR/`: `neutral.obj`, `feature-points.csv` and the shapes, a morph set that
//! `face from-morphs DIR/neutral.obj DIR --fp DIR/feature-points.csv` reads back. `OUT.obj`:
//! the neutral at `OUT.obj` and that whole set in the folder `OUT_shapes/` beside it.
//!
//! **Names.** [`ShapeNames::Fat`]: one file per table and non-zero interval border of the FAT
//! — `NAME.obj` when the border is the table's default value (512 for translation FAPs,
//! 20 000 AU for rotations, 63 for visemes and expressions), else `NAME@VALUE.obj`
//! (`open_jaw@1024.obj`), the FAP value the shape shows
//! ([`crate::face::morphs::morph_file_name`]); a multi-interval table gives one file per
//! border. [`ShapeNames::Arkit`]: one file per ARKit blend shape the FAT has a recipe for
//! (`jawOpen.obj`, `eyeBlinkLeft.obj`, ...), posed as [`crate::rig::arkit_export`] poses it.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Serialize;

use crate::error::Result;
use crate::face::morphs::{
    merged_feature_points, write_morph_set, FEATURE_POINTS_FILE, NEUTRAL_FILE,
};
use crate::face::write::{merged_mesh, source_obj_text};
use crate::face::FaceModel;
use crate::fdp::csv::{write_csv_file, FeaturePointTable};
use crate::format::OutputFormat;
use crate::mesh::obj::{write_obj_file, ObjScene};
use crate::rig::arkit_export::{face_to_arkit_rig, ArkitExportReport};

/// How the shapes of a set are named (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeNames {
    /// FAT keys and values: `open_jaw.obj`, `open_jaw@1024.obj`.
    #[default]
    Fat,
    /// The ARKit blend shapes.
    Arkit,
}

/// What [`write_obj_shapes`] wrote.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ObjShapesReport {
    /// The neutral OBJ.
    pub neutral: PathBuf,
    /// The folder holding the shapes.
    pub folder: PathBuf,
    /// One OBJ per shape, in writing order.
    pub shapes: Vec<PathBuf>,
    /// Whether the files are the user's OBJ with only its `v` lines rewritten.
    pub user_layout: bool,
    /// With [`ShapeNames::Arkit`]: the shapes made and those left out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arkit: Option<ArkitExportReport>,
}

/// The folder `OUT.obj`'s shapes go into: `OUT_shapes` beside it.
pub fn shapes_folder(obj: &Path) -> PathBuf {
    let stem = obj
        .file_stem()
        .map_or_else(|| "face".into(), |s| s.to_string_lossy().into_owned());
    obj.with_file_name(format!("{stem}_shapes"))
}

/// Writes `face` and its FAT as an OBJ shape set at `out` (a directory, or an `.obj` file and
/// its `_shapes` folder; module docs), each file atomically.
pub fn write_obj_shapes(
    out: impl AsRef<Path>,
    face: &FaceModel,
    names: ShapeNames,
) -> Result<ObjShapesReport> {
    let out = out.as_ref();
    let format = OutputFormat::resolve(
        out,
        &[OutputFormat::Obj, OutputFormat::Directory],
        "an OBJ shape set",
    )?;
    let folder = match format {
        OutputFormat::Directory => out.to_path_buf(),
        _ => shapes_folder(out),
    };
    let neutral_world: Vec<Vec3> = face.neutral_world_positions().concat();
    let user_layout = source_obj_text(face, &neutral_world).is_some();
    let mut report = ObjShapesReport {
        neutral: folder.join(NEUTRAL_FILE),
        folder: folder.clone(),
        user_layout,
        ..ObjShapesReport::default()
    };
    match names {
        ShapeNames::Fat => {
            report.shapes = write_morph_set(face, &folder, None)?
                .into_iter()
                .map(|m| m.file)
                .collect();
        }
        ShapeNames::Arkit => {
            let (shapes, arkit) = write_arkit_set(face, &folder, &neutral_world)?;
            report.shapes = shapes;
            report.arkit = Some(arkit);
        }
    }
    if format == OutputFormat::Obj {
        crate::face::write(out, face)?;
        report.neutral = out.to_path_buf();
    }
    Ok(report)
}

/// The ARKit-named set in `dir`: neutral, feature points and one OBJ per shape.
fn write_arkit_set(
    face: &FaceModel,
    dir: &Path,
    neutral_world: &[Vec3],
) -> Result<(Vec<PathBuf>, ArkitExportReport)> {
    if face.fat.tables.is_empty() {
        return Err(crate::rig::RigError::NoFat {
            face: face.name.clone(),
        }
        .into());
    }
    let amplitudes = crate::rig::arkit_amplitudes::arkit_amplitudes();
    let (rig, arkit) = face_to_arkit_rig(face, &amplitudes)?;
    let out_dir =
        crate::io::open_frame_dir(dir, |n| n.ends_with(".obj") || n == FEATURE_POINTS_FILE)?;
    let frames = face.frames();
    let merged = merged_mesh(face, &frames.meshes, None)?;
    let write = |name: &str, positions: &[Vec3]| match source_obj_text(face, positions) {
        Some(text) => out_dir.write_file(name, |p| crate::io::write_atomic(p, text.as_bytes())),
        None => {
            let mut mesh = merged.clone();
            mesh.positions = positions.to_vec();
            let scene = ObjScene {
                mesh,
                material_libraries: Vec::new(),
            };
            out_dir.write_file(name, |p| write_obj_file(&scene, p))
        }
    };
    write(NEUTRAL_FILE, neutral_world)?;
    let points = FeaturePointTable::from_set(&merged_feature_points(face));
    out_dir.write_file(FEATURE_POINTS_FILE, |p| write_csv_file(p, &points))?;
    // Where each of the rig's meshes (the face's, in order) starts in the merged numbering.
    let mut base = Vec::with_capacity(rig.meshes.len());
    let mut n = 0usize;
    for m in &rig.meshes {
        base.push(n);
        n += m.mesh.positions.len();
    }
    let mut files = Vec::new();
    for shape in &rig.shapes {
        let mut positions = neutral_world.to_vec();
        for d in &shape.deltas {
            let b = base.get(d.mesh).copied().unwrap_or(0);
            for (&v, &o) in d.vertices.iter().zip(&d.offsets) {
                if let Some(p) = positions.get_mut(b + v as usize) {
                    *p += o;
                }
            }
        }
        let name = format!("{}.obj", shape.name);
        write(&name, &positions)?;
        files.push(dir.join(name));
    }
    out_dir.commit()?;
    Ok((files, arkit))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_folder_is_beside_the_obj() {
        assert_eq!(
            shapes_folder(Path::new("out/head.obj")),
            Path::new("out/head_shapes")
        );
    }
}
