//! The export front door: a face with its FAT written as the asset a pipeline needs.
//!
//! [`write()`] picks the output by the path's extension and the face's origin:
//!
//! | output | face read from glTF (fits its document) | any other face |
//! |---|---|---|
//! | `.glb` / `.gltf` | the user's document patched with morph targets, in its own units | a new document in metres |
//! | `.glb` / `.gltf`, [`ShapeNames::Arkit`] | the user's document patched with the 52 ARKit shapes | a new ARKit-named document in metres |
//! | `.obj` or a directory (`out/`) | an OBJ shape set: the neutral and one OBJ per morph target ([`super::obj_shapes`]) | the same |
//! | `.wrl` / `.wrl.gz` | the face and its FAT as VRML97 (patching the VRML scene it came from) | the same |
//!
//! Every file is written atomically; what a format could not hold exactly comes back in
//! [`ExportReport::warnings`], never on stderr.
//!
//! ```no_run
//! use fbakit::prelude::*;
//!
//! let face = face::read("avatar.glb")?;
//! let report = export::write("avatar_fat.glb", &face, &ExportOptions::default())?;
//! println!("{report}");
//! # Ok::<(), fbakit::error::Error>(())
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

use serde::Serialize;

pub use super::obj_shapes::ShapeNames;
use super::obj_shapes::{copy_obj_materials, write_obj_shapes, ObjShapesReport};
use crate::error::{Diagnostic, Error, Result};
use crate::face::units::LengthUnit;
use crate::face::FaceModel;
use crate::format::OutputFormat;
use crate::rig::arkit_export::ArkitExportReport;

/// The outputs [`write()`] makes.
pub const EXPORTS: &[OutputFormat] = &[
    OutputFormat::Glb,
    OutputFormat::Gltf,
    OutputFormat::Obj,
    OutputFormat::Directory,
    OutputFormat::Vrml,
    OutputFormat::VrmlGz,
];

/// How [`write()`] writes a face.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ExportOptions {
    /// Morph target names: the FAT's keys, or the 52 ARKit shapes (glTF and OBJ outputs).
    pub names: ShapeNames,
    /// The face's length unit when a new glTF document is made (scaled to metres); `None`:
    /// guessed from its size. A user's own document is never rescaled.
    pub units: Option<LengthUnit>,
    /// Write a new document even when the face came from glTF (default: patch the user's).
    pub new_document: bool,
    /// The user's nodes that turn for head, eye and jaw FAPs in a patched glTF (default:
    /// found by their usual names); an eye node holding its eyeball alone shows the eye's
    /// motion instead of morph targets.
    pub nodes: super::gltf_rotations::RotationNodes,
}

/// What kind of asset [`write()`] made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExportKind {
    /// The glTF document the face came from, with morph targets added.
    PatchedGltf,
    /// A new glTF document (metres).
    Gltf,
    /// An OBJ neutral and one OBJ per shape.
    ObjShapes,
    /// VRML97 with the FAT.
    Vrml,
}

impl ExportKind {
    fn describe(self) -> &'static str {
        match self {
            ExportKind::PatchedGltf => "the face's own glTF, patched",
            ExportKind::Gltf => "a new glTF in metres",
            ExportKind::ObjShapes => "an OBJ shape set",
            ExportKind::Vrml => "VRML97 with its FAT",
        }
    }
}

/// What [`write()`] wrote.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExportReport {
    /// The path written (for a shape set: the neutral OBJ or the folder).
    pub output: PathBuf,
    /// The kind of asset.
    pub kind: ExportKind,
    /// Meshes of the written asset.
    pub meshes: usize,
    /// Morph targets added (glTF), shapes written (OBJ), or FAT tables (VRML).
    pub morph_targets: usize,
    /// The length unit of the output: `"m"` for new glTF, else the face's own (`None` when it
    /// is the user's and cannot be guessed).
    pub units: Option<String>,
    /// With [`ShapeNames::Arkit`]: the shapes made and those left out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arkit: Option<ArkitExportReport>,
    /// For an OBJ shape set: its files.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shapes: Option<ObjShapesReport>,
    /// What could not be written exactly.
    pub warnings: Vec<Diagnostic>,
}

impl fmt::Display for ExportReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match (self.kind, &self.arkit) {
            (ExportKind::Vrml, _) => "FAT tables",
            (ExportKind::ObjShapes, _) => "shape OBJs",
            (_, Some(_)) => "ARKit morph targets",
            _ => "morph targets",
        };
        write!(
            f,
            "wrote {} ({}): {} meshes, {} {what}",
            self.output.display(),
            self.kind.describe(),
            self.meshes,
            self.morph_targets
        )?;
        if let Some(u) = &self.units {
            write!(f, ", in {u}")?;
        }
        if let Some(a) = &self.arkit {
            if !a.unmapped.is_empty() {
                write!(f, "; {} ARKit shapes without a target", a.unmapped.len())?;
            }
        }
        if !self.warnings.is_empty() {
            write!(f, "; {} warning(s)", self.warnings.len())?;
        }
        Ok(())
    }
}

/// Writes `face` and its FAT to `path` as the asset its extension names (module docs).
///
/// Errors: an output format that cannot hold what `options` ask for (ARKit names in VRML),
/// a face without a FAT where shapes are asked for, I/O. Nothing is written on error.
pub fn write(
    path: impl AsRef<Path>,
    face: &FaceModel,
    options: &ExportOptions,
) -> Result<ExportReport> {
    let path = path.as_ref();
    let format = OutputFormat::resolve(path, EXPORTS, "an exported face")?;
    match format {
        OutputFormat::Glb | OutputFormat::Gltf => write_gltf(path, face, options),
        OutputFormat::Obj | OutputFormat::Directory => {
            let mut shapes = write_obj_shapes(path, face, options.names)?;
            if let Some(obj) = &face.obj_path {
                copy_obj_materials(face, obj, &mut shapes)?;
            }
            let warnings = std::mem::take(&mut shapes.warnings);
            Ok(ExportReport {
                output: path.to_path_buf(),
                kind: ExportKind::ObjShapes,
                meshes: if shapes.user_layout {
                    1
                } else {
                    face.meshes.len()
                },
                morph_targets: shapes.shapes.len(),
                units: own_units(face),
                arkit: shapes.arkit.take(),
                shapes: Some(shapes),
                warnings,
            })
        }
        _ => {
            if options.names == ShapeNames::Arkit {
                return Err(Error::Usage(format!(
                    "{}: ARKit names need a .glb, .gltf or .obj output or a directory (VRML \
                     holds the FAT itself)",
                    path.display()
                )));
            }
            crate::face::write(path, face)?;
            Ok(ExportReport {
                output: path.to_path_buf(),
                kind: ExportKind::Vrml,
                meshes: face.meshes.len(),
                morph_targets: face.fat.tables.len(),
                units: own_units(face),
                arkit: None,
                shapes: None,
                warnings: Vec::new(),
            })
        }
    }
}

/// The glTF outputs: the user's document patched when the face came from one, else new.
fn write_gltf(path: &Path, face: &FaceModel, options: &ExportOptions) -> Result<ExportReport> {
    let mut warnings = Vec::new();
    let source = face
        .gltf_source
        .as_deref()
        .filter(|_| !options.new_document);
    let fits = source.filter(|s| match super::gltf_patch::mismatch(face, s) {
        None => true,
        Some(why) => {
            warnings.push(Diagnostic::warning(format!(
                "{} cannot be patched ({why}): written as a new document",
                s.path.display()
            )));
            false
        }
    });
    if let Some(source) = fits {
        let meshes = source.json["meshes"].as_array().map_or(0, Vec::len);
        let (document, morph_targets, arkit, more) = match options.names {
            ShapeNames::Fat => {
                let e = super::gltf_patch::patch_face(face, source, None, &options.nodes)?;
                (e.document, e.morph_targets, None, e.warnings)
            }
            ShapeNames::Arkit => {
                let e = super::arkit_patch::patch_arkit(face, source)?;
                (e.document, e.morph_targets, Some(e.arkit), e.warnings)
            }
        };
        document.write(path)?;
        warnings.extend(more);
        return Ok(ExportReport {
            output: path.to_path_buf(),
            kind: ExportKind::PatchedGltf,
            meshes,
            morph_targets,
            units: own_units(face),
            arkit,
            shapes: None,
            warnings,
        });
    }
    match options.names {
        ShapeNames::Fat => {
            let export = super::gltf::export_face_with_units(face, None, options.units)?;
            export.document.write(path)?;
            warnings.extend(export.warnings);
            let root = &export.document.root;
            Ok(ExportReport {
                output: path.to_path_buf(),
                kind: ExportKind::Gltf,
                meshes: root.meshes.len(),
                morph_targets: root
                    .meshes
                    .iter()
                    .flat_map(|m| m.primitives.first())
                    .map(|p| p.targets.len())
                    .sum(),
                units: Some(LengthUnit::M.to_string()),
                arkit: None,
                shapes: None,
                warnings,
            })
        }
        ShapeNames::Arkit => {
            let (arkit, more) =
                crate::rig::arkit_export::write_arkit_gltf(path, face, options.units)?;
            warnings.extend(more);
            Ok(ExportReport {
                output: path.to_path_buf(),
                kind: ExportKind::Gltf,
                meshes: face.meshes.len(),
                morph_targets: arkit.targets.len(),
                units: Some(LengthUnit::M.to_string()),
                arkit: Some(arkit),
                shapes: None,
                warnings,
            })
        }
    }
}

/// The face's own length unit as guessed from its size (outputs that keep its coordinates).
fn own_units(face: &FaceModel) -> Option<String> {
    crate::face::units::detect_unit(face).map(|g| g.unit.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn alma() -> FaceModel {
        crate::face::read("alma").unwrap()
    }

    #[test]
    fn vrml_refuses_arkit_names_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a.wrl");
        let opts = ExportOptions {
            names: ShapeNames::Arkit,
            ..ExportOptions::default()
        };
        let e = write(&out, &alma(), &opts).unwrap_err();
        assert!(e.to_string().contains("ARKit names"), "{e}");
        assert!(!out.exists());
    }

    #[test]
    fn generated_gltf_is_in_metres_and_says_so() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a.glb");
        let r = write(&out, &alma(), &ExportOptions::default()).unwrap();
        assert_eq!(r.kind, ExportKind::Gltf);
        assert_eq!(r.units.as_deref(), Some("m"));
        assert!(r.morph_targets > 60, "{r}");
        assert!(r.to_string().starts_with("wrote "), "{r}");
        assert!(out.exists());
    }

    #[test]
    fn patched_gltf_keeps_the_users_units_and_arkit_replaces_its_own_on_rewrite() {
        let dir = tempfile::tempdir().unwrap();
        let first = dir.path().join("a.glb");
        let r = write(&first, &alma(), &ExportOptions::default()).unwrap();
        assert_eq!(r.kind, ExportKind::Gltf);
        // Read back: a glTF face, patched from here on.
        let face = crate::face::read(&first).unwrap();
        let arkit = ExportOptions {
            names: ShapeNames::Arkit,
            ..ExportOptions::default()
        };
        let second = dir.path().join("b.glb");
        let r2 = write(&second, &face, &arkit).unwrap();
        assert_eq!(r2.kind, ExportKind::PatchedGltf);
        let made = r2.arkit.as_ref().unwrap().targets.len();
        // alma has recipes for 34 of the 52 shapes (tests/arkit_bridge.rs lists the rest).
        assert!(made >= 30, "{r2}");
        assert!(r2.morph_targets >= made, "{r2}");
        let count = |p: &Path| {
            let f = crate::face::read(p).unwrap();
            f.gltf_source.as_ref().unwrap().json["meshes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|m| m["extras"]["targetNames"].as_array().map_or(0, Vec::len))
                .max()
                .unwrap()
        };
        let n2 = count(&second);
        // Exporting the patched file again with ARKit names replaces fbakit's own targets.
        let again = crate::face::read(&second).unwrap();
        let third = dir.path().join("c.glb");
        write(&third, &again, &arkit).unwrap();
        assert_eq!(count(&third), n2, "ARKit targets were appended twice");
        let back = crate::face::read(&third).unwrap();
        let names = back.gltf_source.as_ref().unwrap().json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|m| {
                m["extras"]["targetNames"]
                    .as_array()
                    .cloned()
                    .unwrap_or_default()
            })
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect::<Vec<_>>();
        assert!(names.iter().any(|n| n == "jawOpen"), "{names:?}");
        assert!(!names.iter().any(|n| n.ends_with("_fbakit")), "{names:?}");
    }

    #[test]
    fn obj_shape_set_through_the_front_door() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("set/");
        let r = write(&out, &alma(), &ExportOptions::default()).unwrap();
        assert_eq!(r.kind, ExportKind::ObjShapes);
        let set = r.shapes.as_ref().unwrap();
        assert_eq!(set.shapes.len(), r.morph_targets);
        assert!(set.shapes.iter().all(|p| p.exists()));
    }
}
