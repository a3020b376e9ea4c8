//! OBJ shape sets: the neutral face and one OBJ per morph target, every file with the face's
//! own vertices in their order, so they drop into Blender, Maya or an engine as shape keys.
//! A face read from OBJ (that still has that file's layout) gets the user's file back in every
//! one of them — groups, `usemtl`/`mtllib`, `vt`, `vn`, comments kept — with only the `v` lines
//! rewritten ([`crate::face::write::source_obj_text`]); other faces get their meshes merged in
//! face coordinates, as OBJ output always does. [`copy_obj_materials`] copies the `.mtl` files
//! the user's `mtllib` lines name, and the textures those name by relative path, beside every
//! written OBJ, so `mtllib` still points at its materials.
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

use crate::error::{Diagnostic, Result};
use crate::face::morphs::{
    merged_feature_points, write_morph_set, FEATURE_POINTS_FILE, NEUTRAL_FILE,
};
use crate::face::write::{source_obj_lines, ObjPose, ObjPoses};
use crate::face::FaceModel;
use crate::fdp::csv::{write_csv_file, FeaturePointTable};
use crate::format::OutputFormat;
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
    /// Material libraries and textures copied from beside the user's OBJ
    /// ([`copy_obj_materials`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<PathBuf>,
    /// Material files that could not be carried over (missing, outside the OBJ's folder).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<Diagnostic>,
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
    let user_layout = source_obj_lines(face).is_some();
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

/// Copies the material libraries the face's own OBJ text names (`mtllib`, relative to the
/// folder of `source_obj`, the file the face was read from) beside the OBJs `report` lists
/// (the neutral's folder and the shapes' folder), and the texture maps each library names by
/// a relative path, keeping their relative places so every `mtllib` and `map_*` still
/// resolves. Absolute paths are left as they are (they resolve anywhere); names reaching out
/// of the folder (`..`) and missing files are warnings in the report. Each file is written
/// atomically. A face not read from OBJ has nothing to copy.
pub fn copy_obj_materials(
    face: &FaceModel,
    source_obj: &Path,
    report: &mut ObjShapesReport,
) -> Result<()> {
    let Some(text) = face.obj_source.as_deref() else {
        return Ok(());
    };
    let from = source_obj.parent().unwrap_or(Path::new("."));
    let mut files: Vec<PathBuf> = Vec::new();
    for lib in statement_args(text, &["mtllib"]) {
        let Some(rel) = relative_inside(&lib, source_obj, &mut report.warnings) else {
            continue;
        };
        let Ok(mtl) = std::fs::read(from.join(&rel)) else {
            report.warnings.push(Diagnostic::warning(format!(
                "{}: material library `{lib}` not found beside it; not copied",
                source_obj.display()
            )));
            continue;
        };
        files.push(rel.clone());
        let mtl_dir = rel.parent().map(Path::to_path_buf).unwrap_or_default();
        let maps = statement_args(
            &String::from_utf8_lossy(&mtl),
            &[
                "map_Ka", "map_Kd", "map_Ks", "map_Ke", "map_Ns", "map_d", "map_bump", "bump",
                "disp", "decal", "norm", "map_Pr", "map_Pm",
            ],
        );
        for map in maps {
            // Options (`-s 1 1 1`) come first: the file is the last word.
            let Some(name) = map.split_whitespace().last() else {
                continue;
            };
            let Some(tex) = relative_inside(name, &from.join(&rel), &mut report.warnings) else {
                continue;
            };
            let tex = mtl_dir.join(tex);
            if from.join(&tex).is_file() {
                if !files.contains(&tex) {
                    files.push(tex);
                }
            } else {
                report.warnings.push(Diagnostic::warning(format!(
                    "{}: texture `{name}` not found; not copied",
                    from.join(&rel).display()
                )));
            }
        }
    }
    let mut dests: Vec<PathBuf> = vec![report.folder.clone()];
    if let Some(d) = report.neutral.parent() {
        if !dests.iter().any(|x| x == d) {
            dests.push(d.to_path_buf());
        }
    }
    for rel in &files {
        let bytes = std::fs::read(from.join(rel))
            .map_err(|e| crate::error::Error::io(from.join(rel), e))?;
        for d in &dests {
            let to = d.join(rel);
            if to == from.join(rel) {
                continue;
            }
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent)
                    .map_err(|e| crate::error::Error::output(parent, e))?;
            }
            crate::io::write_atomic(&to, &bytes)?;
            report.materials.push(to);
        }
    }
    Ok(())
}

/// The arguments of every statement of `text` whose keyword is one of `keywords` (trimmed).
fn statement_args(text: &str, keywords: &[&str]) -> Vec<String> {
    text.lines()
        .filter_map(|l| {
            let l = l.trim();
            let (kw, rest) = l.split_once(char::is_whitespace)?;
            keywords
                .iter()
                .any(|k| k.eq_ignore_ascii_case(kw))
                .then(|| rest.trim().to_string())
                .filter(|r| !r.is_empty())
        })
        .collect()
}

/// `name` (a file a `mtllib` or `map_*` in `file` names) as a path relative to that file's
/// folder; `None`, with a warning for names outside it, for absolute and escaping names.
fn relative_inside(name: &str, file: &Path, warnings: &mut Vec<Diagnostic>) -> Option<PathBuf> {
    let p = Path::new(name);
    if p.is_absolute() {
        return None;
    }
    if p.components().any(|c| {
        !matches!(
            c,
            std::path::Component::Normal(_) | std::path::Component::CurDir
        )
    }) {
        warnings.push(Diagnostic::warning(format!(
            "{}: `{name}` lies outside the file's folder; not copied",
            file.display()
        )));
        return None;
    }
    Some(p.to_path_buf())
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
    let poses = ObjPoses::new(face)?;
    let pose = |name: String, positions: Vec<Vec3>| ObjPose {
        file: name,
        mesh_name: None,
        positions,
    };
    poses.write(
        &out_dir,
        &[pose(NEUTRAL_FILE.to_string(), neutral_world.to_vec())],
    )?;
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
    // A batch at a time on rayon's threads, as the FAT-named set.
    for shapes in rig.shapes.chunks(ObjPoses::batch_len()) {
        let mut batch = Vec::with_capacity(shapes.len());
        for shape in shapes {
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
            files.push(dir.join(&name));
            batch.push(pose(name, positions));
        }
        poses.write(&out_dir, &batch)?;
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
