//! Validation of a face read from a file: every problem with its scene-graph path and line.
//!
//! Checks: what the reader found (bad table nodes, unknown `faceSceneGraphNode` targets,
//! negative indices), each mesh's structure (indices in range, polygons of three or more
//! corners, finite coordinates, uv/normal index lists), the FAT against the meshes and
//! transforms (interval borders increasing and holding 0 exactly once, displacement counts =
//! intervals × coordIndex, coordIndex in range, fapID/highLevelSelect in range — see
//! [`crate::fat::validate`]), and that the FAPUs can be measured on the feature points.

use crate::error::{Diagnostic, Severity};
use crate::fat::validate::{validate_fat, FatEntry};

use super::vrml::FaceReadReport;
use super::FaceModel;

/// All problems of a face read from a file (reader diagnostics included), located.
pub fn validate_face(face: &FaceModel, report: &FaceReadReport) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = report.diagnostics.clone();
    let scene = face.scene.as_ref();
    let node_location = |id| scene.map(|s| s.node(id).location.clone());

    for (i, m) in face.meshes.iter().enumerate() {
        let v = m.mesh.validate();
        let path = report
            .mesh_paths
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("mesh `{}`", m.name));
        let location = scene
            .and_then(|s| s.find_def(&m.name))
            .and_then(node_location);
        let mut err = |message: String| {
            out.push(Diagnostic {
                severity: Severity::Error,
                location: location.clone(),
                message: format!("{path}: {message}"),
            })
        };
        if v.out_of_range_indices > 0 {
            err(format!(
                "{} coordIndex value(s) beyond its {} points",
                v.out_of_range_indices,
                m.mesh.vertex_count()
            ));
        }
        if v.short_faces > 0 {
            err(format!(
                "{} polygon(s) with fewer than 3 corners",
                v.short_faces
            ));
        }
        if v.non_finite_positions > 0 {
            err(format!(
                "{} point(s) with NaN or infinite coordinates",
                v.non_finite_positions
            ));
        }
        if v.bad_uv_polygons > 0 {
            err(format!(
                "{} texCoordIndex polygon(s) not matching coordIndex or out of range",
                v.bad_uv_polygons
            ));
        }
        if v.bad_normal_polygons > 0 {
            err(format!(
                "{} normalIndex polygon(s) not matching coordIndex or out of range",
                v.bad_normal_polygons
            ));
        }
    }

    for p in validate_fat(&face.fat, &face.mesh_sizes(), &face.transform_names()) {
        let nodes = report.table_nodes.get(p.table);
        let id = nodes.and_then(|n| match p.entry {
            FatEntry::Table => n.table,
            FatEntry::Mesh(i) => n.meshes.get(i).copied(),
            FatEntry::Transform(i) => n.transforms.get(i).copied(),
        });
        let what = match p.entry {
            FatEntry::Table => "FaceDefTables".to_string(),
            FatEntry::Mesh(i) => format!("FaceDefMesh #{}", i + 1),
            FatEntry::Transform(i) => format!("FaceDefTransform #{}", i + 1),
        };
        out.push(Diagnostic {
            severity: Severity::Error,
            location: id.and_then(node_location),
            message: format!(
                "FDP > faceDefTables #{} ({}) > {what}: {}",
                p.table + 1,
                p.key,
                p.message
            ),
        });
    }

    if !face.fat.tables.is_empty() || !face.feature_points.is_empty() {
        if let Err(e) = face.fapu() {
            out.push(Diagnostic {
                // FATs are in raw FAP values, so a face without FAPUs still plays; cloning
                // and compliance checks need them.
                severity: Severity::Warning,
                location: None,
                message: format!("FAPU cannot be measured: {e}"),
            });
        }
    }
    out
}
