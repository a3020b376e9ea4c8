//! Faces from blendshape rigs, for the front door ([`super::read`]): a glTF file with morph
//! targets or a folder of shape OBJs reads as a face wherever a face is accepted.
//!
//! With feature points (`--fp`), the rig's shapes become a FAP-compliant FAT through the
//! ARKit-52 map ([`crate::rig::fat_build::face_from_rig`]); what the map could not realise is
//! listed as notes. Without them only the neutral meshes are read (a FAT needs the FAP units
//! the feature points give), and a note says how to get the FAT.

use std::path::Path;

use super::vrml::FaceReadReport;
use super::FaceModel;
use crate::error::{Diagnostic, Result, Severity};
use crate::rig::fap_map::FapMap;
use crate::rig::fat_build::face_from_rig;
use crate::rig::Rig;

/// The face of `rig` (read from `path`), with a FAT when `feature_points` names a file.
pub(crate) fn rig_face(
    path: &Path,
    rig: &Rig,
    feature_points: Option<&Path>,
) -> Result<(FaceModel, FaceReadReport)> {
    let mut report = FaceReadReport::default();
    let note = |message: String| Diagnostic {
        severity: Severity::Warning,
        location: None,
        message,
    };
    // The rig readers' warnings name their file already; others get it in front (the
    // diagnostic's own `warning:` prefix is not repeated).
    let shown = path.display().to_string();
    report.diagnostics.extend(rig.warnings.iter().map(|w| {
        if w.message.contains(&shown) {
            w.clone()
        } else {
            note(format!("{shown}: {}", w.message))
        }
    }));
    let Some(fp) = feature_points else {
        let mut face = rig.to_face();
        face.name = super::format::face_name(path);
        // A glTF fbakit wrote carries its FAT and feature points (specs/gltf-fat.md).
        if let Some(records) = super::gltf_fat::read_records(rig)? {
            records.apply(&mut face);
            return Ok((face, report));
        }
        if !rig.shapes.is_empty() {
            report.diagnostics.push(note(format!(
                "{}: a rig with {} shapes read as its neutral meshes only; give its feature \
                 points (--fp FILE, e.g. from `fbakit fp from-landmarks`) to turn the shapes \
                 into a FAP-compliant FAT",
                path.display(),
                rig.shapes.len()
            )));
        }
        return Ok((face, report));
    };
    let points = crate::fdp::read_feature_points(fp)?.points;
    // Problems of the points (unknown meshes, far positions, degenerate FAP units) name
    // the feature-point file; the rig's own keep theirs.
    let (mut face, mut fat) =
        face_from_rig(rig, Some(points), &FapMap::arkit()).map_err(|e| match e {
            crate::error::Error::Rig(_) => e,
            e => super::read::in_fp_file(fp, e).into(),
        })?;
    face.name = super::format::face_name(path);
    report.fp_matches = std::mem::take(&mut fat.fp_matches);
    // A file without shapes (a plain glTF target) realises no FAP: nothing worth saying.
    if !fat.unmapped.is_empty() && !rig.shapes.is_empty() {
        let keys: Vec<&str> = fat.unmapped.iter().map(|u| u.key.as_str()).collect();
        report.diagnostics.push(note(format!(
            "{}: {} FAP sides not realised by the rig's shapes (`fbakit face from-rig --json` \
             says why): {}",
            path.display(),
            keys.len(),
            keys.join(", ")
        )));
    }
    Ok((face, report))
}
