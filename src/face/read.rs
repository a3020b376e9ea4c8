//! The one front door for faces: [`read`] a face from a file of any supported format, from
//! bytes with a name ([`read_bytes`]), or by the name of a bundled face (`alma`, `bruno`).
//!
//! The format comes from the extension ([`FaceFormat::of_extension`]) and, where the
//! extension says nothing, from the content ([`FaceFormat::sniff`]): gzip is recognised by
//! its magic bytes whatever the name, so `head.wrl` that is really compressed still reads.
//! Every input is size-bounded ([`crate::io::DEFAULT_MAX_INPUT_BYTES`], compressed and
//! decompressed alike).
//!
//! **Feature points.** [`FaceReadOptions::feature_points`] names a feature-point file (any
//! format [`crate::fdp::read_feature_points`] reads) whose points replace the face's own: an
//! OBJ face has no other source of points; a CANDIDE-3 model needs its table (vertex
//! bindings) to become a face with a FAT. Points given by position only are bound to the
//! nearest vertex and reported in [`FaceReadReport::fp_matches`].
//!
//! **Rigs.** A glTF file with morph targets (`.glb`, `.gltf`) or a folder of shape OBJs (the
//! ICT-FaceKit layout) reads as a face too: with feature points its shapes become a
//! FAP-compliant FAT through the ARKit-52 map, without them only its neutral meshes.
//!
//! ```
//! let alma = fbakit::face::read("alma")?; // a bundled face, by name
//! assert!(alma.fat.tables.len() > 60);
//! # Ok::<(), fbakit::error::Error>(())
//! ```

use std::path::{Path, PathBuf};

use super::attach::attach_feature_points;
use super::bundled::BundledFace;
use super::format::{face_name, FaceFormat};
use super::vrml::{face_from_scene, FaceReadReport};
use super::FaceModel;
use crate::error::{Error, Result};
use crate::io::{gunzip_bounded, DEFAULT_MAX_INPUT_BYTES};

/// How [`read_with`] and [`read_bytes`] read a face.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceReadOptions {
    /// A feature-point file whose points replace the face's own (required for CANDIDE-3).
    pub feature_points: Option<PathBuf>,
    /// The format, when neither the name nor the content should decide.
    pub format: Option<FaceFormat>,
}

impl FaceReadOptions {
    /// Options with a feature-point file.
    pub fn with_feature_points(path: Option<&Path>) -> FaceReadOptions {
        FaceReadOptions {
            feature_points: path.map(Path::to_path_buf),
            ..FaceReadOptions::default()
        }
    }
}

/// Reads a face from a file, or a bundled face by name (`alma`, `bruno`) when no file of
/// that name exists. See the module docs.
///
/// ```
/// let alma = fbakit::face::read("alma")?;
/// assert!(!alma.fat.tables.is_empty());
/// // Errors are typed: a missing file is an I/O error on that path, exit code 2 in the CLI.
/// let err = fbakit::face::read("no-such-face.wrl").unwrap_err();
/// assert!(err.is_input_error());
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read(path: impl AsRef<Path>) -> Result<FaceModel> {
    read_with(path.as_ref(), &FaceReadOptions::default()).map(|(face, _)| face)
}

/// [`read`] with options, returning what the reader noticed (diagnostics, feature-point
/// matches, scene paths).
pub fn read_with(
    path: impl AsRef<Path>,
    opts: &FaceReadOptions,
) -> Result<(FaceModel, FaceReadReport)> {
    let path = path.as_ref();
    if !path.exists() {
        if let Some(bundled) = path.to_str().and_then(BundledFace::from_name) {
            let (mut face, mut report) = bundled.read()?;
            if let Some(fp) = &opts.feature_points {
                report.fp_matches = attach_file(&mut face, fp, path)?;
            }
            return Ok((face, report));
        }
    }
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        // A folder is a face only as an OBJ blendshape rig (a neutral plus shape OBJs); a
        // folder with a neutral is a rig, and its own errors (a shape of the wrong size) stand.
        if let Err(e) = crate::rig::obj_folder::find_neutral(path) {
            return Err(super::FaceError::NotAFaceFolder {
                path: path.to_path_buf(),
                reason: e.to_string(),
                bundled: BundledFace::NAMES.join(", "),
            }
            .into());
        }
        let rig = crate::rig::obj_folder::read_obj_rig(path)?;
        return super::from_rig::rig_face(path, &rig, opts.feature_points.as_deref());
    }
    // Text formats stop at the first NUL byte instead of reading a file of zeros whole.
    let text = matches!(
        opts.format.or_else(|| FaceFormat::of_extension(path)),
        Some(FaceFormat::Vrml | FaceFormat::Obj | FaceFormat::Wfm)
    );
    let bytes = if text {
        crate::io::read_bounded_text(path, DEFAULT_MAX_INPUT_BYTES)?
    } else {
        crate::io::read_bounded(path, DEFAULT_MAX_INPUT_BYTES)?
    };
    read_bytes_at(path, &bytes, opts)
}

/// Reads a face held in memory (data first, then its source name, as every reader); `source`
/// stands for the file in messages and gives the face its name (`head.obj` → `head`), and its
/// extension picks the format unless the content or [`FaceReadOptions::format`] does.
pub fn read_bytes(
    bytes: &[u8],
    source: impl AsRef<Path>,
    opts: &FaceReadOptions,
) -> Result<(FaceModel, FaceReadReport)> {
    read_bytes_at(source.as_ref(), bytes, opts)
}

fn read_bytes_at(
    path: &Path,
    bytes: &[u8],
    opts: &FaceReadOptions,
) -> Result<(FaceModel, FaceReadReport)> {
    let format = detect(path, bytes, opts.format)?;
    let name = face_name(path);
    let (mut face, mut report) = match format {
        FaceFormat::Vrml => vrml_face(path, &text_of(path, bytes, "UTF-8 VRML text")?, &name)?,
        FaceFormat::VrmlGz => {
            let inner = gunzip_bounded(bytes, DEFAULT_MAX_INPUT_BYTES).map_err(|e| {
                Error::io(path, std::io::Error::new(e.kind(), format!("gzip: {e}")))
            })?;
            match FaceFormat::sniff(&inner) {
                Some(FaceFormat::Obj) => obj_face(path, &inner, &name)?,
                _ => vrml_face(
                    path,
                    &text_of(path, &inner, "UTF-8 VRML text (after gzip decompression)")?,
                    &name,
                )?,
            }
        }
        FaceFormat::Obj => obj_face(path, bytes, &name)?,
        FaceFormat::Wfm => return candide(path, bytes, opts),
        FaceFormat::Gltf => {
            let rig = crate::rig::gltf_read::read_gltf_bytes(bytes, path)?;
            return super::from_rig::rig_face(path, &rig, opts.feature_points.as_deref());
        }
    };
    if let Some(fp) = &opts.feature_points {
        report.fp_matches = attach_file(&mut face, fp, path)?;
    }
    Ok((face, report))
}

/// The format: forced, else the extension (unless the bytes are gzip, which no text format
/// can be), else the content.
fn detect(path: &Path, bytes: &[u8], forced: Option<FaceFormat>) -> Result<FaceFormat> {
    if let Some(f) = forced {
        return Ok(f);
    }
    let sniffed = FaceFormat::sniff(bytes);
    if sniffed == Some(FaceFormat::VrmlGz) {
        return Ok(FaceFormat::VrmlGz);
    }
    if let Some(f) = FaceFormat::of_extension(path) {
        return Ok(f);
    }
    sniffed.ok_or_else(|| {
        Error::Unsupported(format!(
            "{}: not a face file fbakit recognises (expected VRML97 (#VRML header), gzip, \
             OBJ or CANDIDE-3 .wfm; or name it .wrl, .wrl.gz, .obj or .wfm)",
            path.display()
        ))
    })
}

fn text_of(path: &Path, bytes: &[u8], expected: &str) -> Result<String> {
    String::from_utf8(bytes.to_vec()).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let valid = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
        Error::Parse(crate::error::ParseError {
            location: crate::error::Location::from_offset(path, valid, at),
            expected: expected.to_string(),
            found: Some(format!("byte 0x{:02X}", bytes[at])),
        })
    })
}

fn vrml_face(path: &Path, text: &str, name: &str) -> Result<(FaceModel, FaceReadReport)> {
    let scene = crate::vrml::parse_vrml(text, path)?;
    face_from_scene(scene, name)
}

fn obj_face(path: &Path, bytes: &[u8], name: &str) -> Result<(FaceModel, FaceReadReport)> {
    let text = text_of(path, bytes, "UTF-8 OBJ text")?;
    let (obj, diagnostics) = crate::mesh::obj::parse_obj(&text, path)?;
    let mut face = FaceModel::single_mesh(name, obj.mesh);
    face.obj_source = Some(text.into());
    face.obj_path = Some(path.to_path_buf());
    let report = FaceReadReport {
        diagnostics,
        mesh_paths: vec![format!("OBJ {}", path.display())],
        ..FaceReadReport::default()
    };
    Ok((face, report))
}

/// A CANDIDE-3 model becomes a face with a FAT once its feature-point table binds the
/// standard's points to its vertices.
fn candide(
    path: &Path,
    bytes: &[u8],
    opts: &FaceReadOptions,
) -> Result<(FaceModel, FaceReadReport)> {
    let Some(fp) = &opts.feature_points else {
        return Err(super::FaceError::CandideNeedsFeaturePoints {
            path: path.to_path_buf(),
        }
        .into());
    };
    // CANDIDE files carry Latin-1 author names in comments; only ASCII matters to the model.
    let text = String::from_utf8_lossy(bytes);
    let model = crate::candide::parse_wfm(&text, path)?;
    let points = crate::fdp::read_feature_points(fp)?.points;
    let face = super::candide::candide_face(&model, &points, &[])?;
    Ok((face, FaceReadReport::default()))
}

fn attach_file(
    face: &mut FaceModel,
    fp: &Path,
    face_path: &Path,
) -> Result<Vec<super::vrml::FeaturePointMatch>> {
    let file = crate::fdp::read_feature_points(fp)?;
    let alias = face_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    attach_feature_points(face, file.points, &[&alias]).map_err(|e| in_fp_file(fp, e).into())
}

/// A problem of the feature points of file `fp` (that do not fit the face), prefixed with the
/// file and, for a CSV row naming an unknown mesh or a vertex out of range, its line.
pub(crate) fn in_fp_file(fp: &Path, e: crate::error::Error) -> super::FaceError {
    let id = match &e {
        crate::error::Error::Face(super::FaceError::UnknownFeaturePointMeshes {
            first, ..
        }) => Some(*first),
        crate::error::Error::Face(super::FaceError::FeaturePointVertexOutOfRange {
            id, ..
        }) => Some(*id),
        _ => None,
    };
    match id.and_then(|id| csv_line_of(fp, id)) {
        Some(line) => super::FaceError::InFileAt {
            file: fp.to_path_buf(),
            line,
            source: Box::new(e),
        },
        None => super::FaceError::in_file(fp, e),
    }
}

/// The 1-based line of the CSV feature-point file `fp` whose first field is point `id`
/// (`None` for other formats or an unreadable file: the message then names the file alone).
fn csv_line_of(fp: &Path, id: crate::spec::FeaturePointId) -> Option<usize> {
    let is_csv = fp
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if !is_csv {
        return None;
    }
    let bytes = crate::io::read_bounded_text(fp, crate::io::DEFAULT_MAX_INPUT_BYTES).ok()?;
    let text = String::from_utf8_lossy(&bytes);
    let want = id.to_string();
    text.lines()
        .position(|l| l.split(',').next().map(|f| f.trim().trim_matches('"')) == Some(&want))
        .map(|i| i + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_faces_by_name() {
        let alma = read("alma").unwrap();
        assert_eq!(alma.name, "alma");
        assert!(alma.fat.tables.len() > 60);
        let e = read("no-such-face").unwrap_err();
        assert!(e.is_input_error());
    }

    #[test]
    fn gzip_and_formats_by_content() {
        let dir = tempfile::tempdir().unwrap();
        let alma = read("alma").unwrap();
        // A compressed face under a plain name, and a VRML face with no extension.
        let gz = dir.path().join("compressed.wrl");
        std::fs::write(&gz, BundledFace::Alma.bytes()).unwrap();
        assert!(
            read(&gz).unwrap()
                == FaceModel {
                    name: "compressed".into(),
                    ..alma.clone()
                }
        );
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let (face, _) = read_bytes(obj.as_bytes(), "tri", &FaceReadOptions::default()).unwrap();
        assert_eq!(face.vertex_count(), 3);
        let e = read_bytes(b"hello", "x", &FaceReadOptions::default()).unwrap_err();
        assert!(e.to_string().contains("not a face file"), "{e}");
        let e = read(dir.path()).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
        assert!(e.is_input_error());
    }

    #[test]
    fn candide_needs_its_table() {
        let e = read_bytes(
            b"# VERTEX LIST:\n0\n# FACE LIST:\n0\n",
            "c.wfm",
            &FaceReadOptions::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("feature-point table"), "{e}");
    }
}
