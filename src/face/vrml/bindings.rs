//! fbakit's feature-point record: `DEF fbakit_feature_points WorldInfo { title "fbakit feature
//! points" info [ "2.1 skin 123" ... ] }`, one `id mesh vertices` entry per present point
//! (module docs of [`super`]). Reading it back gives each point its exact binding.

use glam::Vec3;

use super::write::add;
use crate::error::{Diagnostic, Location, Severity};
use crate::face::FaceModel;
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::spec::FeaturePointId;
use crate::vrml::{FieldValue, Node, NodeId, NodeRef, Scene, Statement};

/// Title of fbakit's feature-point record (`WorldInfo`).
pub const FP_RECORD_TITLE: &str = "fbakit feature points";
const FP_RECORD_DEF: &str = "fbakit_feature_points";

/// Parses one entry of fbakit's feature-point record: `id mesh vertices`.
fn parse_record_entry(entry: &str) -> Option<(FeaturePointId, Option<VertexBinding>)> {
    let mut parts = entry.split_whitespace();
    let id: FeaturePointId = parts.next()?.parse().ok()?;
    let mesh = parts.next()?;
    let vertices = parts.next()?;
    if parts.next().is_some() {
        return None;
    }
    if mesh == "-" && vertices == "-" {
        return Some((id, None));
    }
    let vertices: Option<Vec<u32>> = vertices.split(';').map(|v| v.parse().ok()).collect();
    let vertices = vertices.filter(|v| !v.is_empty())?;
    Some((
        id,
        Some(VertexBinding {
            mesh: (mesh != "-").then(|| mesh.to_string()),
            vertices,
        }),
    ))
}

/// The record's entries and location, if the scene has one.
pub(super) fn find_record(scene: &Scene) -> Option<(Vec<String>, Location)> {
    scene
        .nodes
        .iter()
        .find(|n| {
            n.type_name == "WorldInfo"
                && matches!(n.field("title"), Some(FieldValue::SFString(t)) if t == FP_RECORD_TITLE)
        })
        .and_then(|n| match n.field("info") {
            Some(FieldValue::MFString(v)) => Some((v.clone(), n.location.clone())),
            _ => None,
        })
}

/// The points the record lists (at `rloc`), placed at their `featurePointsCoord` entry (at
/// `loc`); bad entries are reported and skipped.
pub(super) fn points_from_record(
    entries: &[String],
    rloc: &Location,
    points: &[[f32; 3]],
    loc: &Location,
    diagnostics: &mut Vec<Diagnostic>,
) -> FeaturePointSet {
    let mut set = FeaturePointSet::new();
    for entry in entries {
        let Some((id, binding)) = parse_record_entry(entry) else {
            diagnostics.push(Diagnostic {
                severity: Severity::Error,
                location: Some(rloc.clone()),
                message: format!("feature-point record entry `{entry}` is not `id mesh vertices`"),
            });
            continue;
        };
        let Some(&p) = points.get(id.ordinal()) else {
            diagnostics.push(Diagnostic {
                severity: Severity::Error,
                location: Some(loc.clone()),
                message: format!("featurePointsCoord has no entry for {id}"),
            });
            continue;
        };
        set.insert(FeaturePoint {
            id,
            position: Some(Vec3::from_array(p)),
            binding,
        });
    }
    set
}

/// One record entry per present feature point, in label order.
pub(super) fn record_entries(face: &FaceModel) -> Vec<String> {
    face.feature_points
        .iter()
        .map(|p| match &p.binding {
            Some(b) => format!(
                "{} {} {}",
                p.id,
                b.mesh.as_deref().unwrap_or("-"),
                b.vertices
                    .iter()
                    .map(|v| v.to_string())
                    .collect::<Vec<_>>()
                    .join(";")
            ),
            None => format!("{} - -", p.id),
        })
        .collect()
}

/// Replaces any record among the scene's root statements by a new one holding `entries`.
/// The new node is added but not yet placed; the caller puts it before the face.
pub(super) fn replace_record(scene: &mut Scene, entries: Vec<String>) -> NodeRef {
    let mut info = Node::new("WorldInfo");
    info.def_name = Some(FP_RECORD_DEF.to_string());
    info.fields
        .push(("title".into(), FieldValue::SFString(FP_RECORD_TITLE.into())));
    info.fields
        .push(("info".into(), FieldValue::MFString(entries)));
    let old_record: Vec<NodeId> = scene.nodes_of_type("WorldInfo").filter(|&id| {
        matches!(scene.node(id).field("title"), Some(FieldValue::SFString(t)) if t == FP_RECORD_TITLE)
    }).collect();
    scene
        .statements
        .retain(|s| !matches!(s, Statement::Node(r) if old_record.contains(&r.id)));
    add(scene, info)
}
