//! Putting feature points from a separate file on a face's meshes: bound points on their
//! vertices, position-only points on the nearest vertex of the skin, or of the eye or teeth
//! part for the points the standard puts there ([`super::snap`]).
//!
//! A binding's mesh may be named as the face names it, or for a glTF face by
//! [`FaceModel::resolve_mesh_spec`]'s rule (`Name/1`, `#3/1`). A position farther than
//! [`MAX_SNAP_FRACTION`] of the face size (the diagonal of its neutral bounding box) from
//! every vertex is refused; [`snap_warnings`] names the snaps beyond [`WARN_SNAP_FRACTION`].

use super::snap::SnapIndex;
use super::vrml::FeaturePointMatch;
use super::FaceModel;
use crate::error::Diagnostic;
use crate::error::Result;
use crate::fdp::FeaturePointSet;

/// Largest snap distance, as a fraction of the face size, for a point given by position.
pub const MAX_SNAP_FRACTION: f32 = 0.1;

/// Snap distance (fraction of the face size) from which a snap is worth a warning.
pub const WARN_SNAP_FRACTION: f32 = 0.01;

/// The diagonal of the face's neutral bounding box (face frame; 0 for an empty face).
pub fn face_size(face: &FaceModel) -> f32 {
    let mut lo = glam::Vec3::splat(f32::INFINITY);
    let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
    for mesh in face.neutral_world_positions() {
        for p in mesh {
            if p.is_finite() {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        0.0
    }
}

/// One warning per snap of `matches` farther than [`WARN_SNAP_FRACTION`] of the face size,
/// naming the file the points came from (`source`), the point, the vertex and the distance.
pub fn snap_warnings(
    face: &FaceModel,
    matches: &[super::vrml::FeaturePointMatch],
    source: &std::path::Path,
) -> Vec<Diagnostic> {
    if matches.is_empty() {
        return Vec::new();
    }
    let size = face_size(face);
    matches
        .iter()
        .filter(|m| size > 0.0 && m.distance > WARN_SNAP_FRACTION * size)
        .map(|m| {
            Diagnostic::warning(format!(
                "{}: feature point {} snapped {:.4} to vertex {} of `{}` ({:.1} % of the face size)",
                source.display(),
                m.id,
                m.distance,
                m.vertex,
                m.mesh,
                100.0 * m.distance / size
            ))
        })
        .collect()
}

/// Puts `points` on `face`: bound points are placed on their vertices, position-only points
/// are bound to the nearest vertex (returned with the distance). On a single-mesh face a
/// binding naming no mesh, the mesh itself, or one of `aliases` (e.g. the OBJ file name an
/// Xface `.fdp` refers to) is bound to that mesh; any other mesh name is an error.
pub fn attach_feature_points(
    face: &mut FaceModel,
    mut points: FeaturePointSet,
    aliases: &[&str],
) -> Result<Vec<FeaturePointMatch>> {
    let single = (face.meshes.len() == 1).then(|| face.meshes[0].name.clone());
    let mut bad = Vec::new();
    let ids: Vec<_> = points.iter().map(|p| p.id).collect();
    for id in ids {
        let Some(p) = points.get_mut(id) else {
            continue;
        };
        let Some(b) = p.binding.as_mut() else {
            continue;
        };
        let resolved = b
            .mesh
            .as_deref()
            .and_then(|m| face.resolve_mesh_spec(m))
            .map(|i| face.meshes[i].name.clone());
        match (&single, b.mesh.as_deref()) {
            (Some(only), None) => b.mesh = Some(only.clone()),
            (Some(only), Some(m)) if m == only || aliases.contains(&m) => {
                b.mesh = Some(only.clone())
            }
            (_, Some(_)) if resolved.is_some() => b.mesh = resolved,
            (_, m) => bad.push((
                id,
                format!(
                    "{id} names mesh {}",
                    m.map_or("<none>".to_string(), |m| format!("`{m}`"))
                ),
            )),
        }
    }
    if let Some(&(first, _)) = bad.first() {
        let names: Vec<&str> = face.meshes.iter().map(|m| m.name.as_str()).collect();
        let points: Vec<&str> = bad.iter().map(|b| b.1.as_str()).collect();
        return Err(super::FaceError::UnknownFeaturePointMeshes {
            first,
            points: points.join(", "),
            meshes: names.join(", "),
        }
        .into());
    }
    // Vertex ids beyond their mesh, the first named with its mesh's range.
    for p in points.iter() {
        let Some(b) = &p.binding else {
            continue;
        };
        let mi = match b.mesh.as_deref() {
            Some(m) => face.mesh_index(m),
            None => single.as_ref().and(Some(0)),
        };
        let Some(mesh) = mi.and_then(|i| face.meshes.get(i)) else {
            continue;
        };
        let count = mesh.mesh.positions.len();
        if let Some(&vertex) = b.vertices.iter().find(|&&v| v as usize >= count) {
            return Err(super::FaceError::FeaturePointVertexOutOfRange {
                id: p.id,
                mesh: mesh.name.clone(),
                vertex,
                count,
            }
            .into());
        }
    }
    face.feature_points = points;
    face.resolve_feature_points()?;

    // Position-only points: bind to the nearest vertex of the skin, or of the part for
    // pupils, teeth and tongue (`super::snap`).
    let mut matches = Vec::new();
    let unbound: Vec<_> = face
        .feature_points
        .iter()
        .filter(|p| p.binding.is_none())
        .filter_map(|p| Some((p.id, p.position?)))
        .collect();
    if let Some((id, _)) = unbound.iter().find(|(_, p)| !p.is_finite()) {
        return Err(super::FaceError::NonFiniteFeaturePoint { id: *id }.into());
    }
    if unbound.is_empty() {
        return Ok(matches);
    }
    let bound: Vec<usize> = face
        .feature_points
        .iter()
        .filter_map(|p| p.binding.as_ref()?.mesh.as_deref())
        .filter_map(|m| face.mesh_index(m))
        .collect();
    let index = SnapIndex::new(face, &unbound, &bound);
    let limit = MAX_SNAP_FRACTION * face_size(face);
    for (id, pos) in unbound {
        let Some((binding, found)) = index.for_point(id, pos).bind(face, id, pos) else {
            continue;
        };
        if found.distance > limit {
            return Err(super::FaceError::FeaturePointFarFromMesh {
                id,
                distance: found.distance,
                limit,
            }
            .into());
        }
        if let Some(p) = face.feature_points.get_mut(id) {
            p.binding = Some(binding);
        }
        matches.push(found);
    }
    Ok(matches)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::face::FaceMesh;
    use crate::fdp::{FeaturePoint, VertexBinding};
    use crate::mesh::Mesh;
    use crate::spec::FeaturePointId;
    use glam::Vec3;

    fn fp(s: &str) -> FeaturePointId {
        s.parse().unwrap()
    }

    fn square() -> FaceModel {
        let mut face = FaceModel::new("sq");
        face.meshes.push(FaceMesh {
            name: "sq".into(),
            transform: None,
            mesh: Mesh::from_triangles(
                "sq",
                vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
                &[[0, 1, 2], [0, 2, 3]],
            ),
            color: None,
        });
        face
    }

    #[test]
    fn feature_points_bound_or_matched() {
        let mut face = square();
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(
            fp("2.1"),
            VertexBinding {
                mesh: Some("sq.obj".into()),
                vertices: vec![1, 2],
            },
        ));
        set.insert(FeaturePoint::at(fp("9.3"), Vec3::new(0.05, 0.95, 0.0)));
        let m = attach_feature_points(&mut face, set, &["sq.obj"]).unwrap();
        assert_eq!(
            face.feature_points.position(fp("2.1")),
            Some(Vec3::new(1.0, 0.5, 0.0))
        );
        assert_eq!(m.len(), 1);
        assert_eq!((m[0].id, m[0].vertex), (fp("9.3"), 3));
        assert!((m[0].distance - 0.070_711).abs() < 1e-4);
        // A snap of more than 1 % of the face size (√2) is a warning naming the file.
        let w = snap_warnings(&face, &m, std::path::Path::new("p.csv"));
        assert_eq!(w.len(), 1);
        assert!(w[0].message.starts_with("p.csv: feature point 9.3 snapped 0.0707 to vertex 3 of `sq` (5.0 % of the face size)"), "{}", w[0]);
        // Beyond a tenth of the face size: refused.
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::at(fp("9.3"), Vec3::new(0.0, 0.0, 0.3)));
        let e = attach_feature_points(&mut square(), set, &[]).unwrap_err();
        assert!(e.to_string().contains("feature point 9.3 is 0.3"), "{e}");
        // glTF primitive names: `Name/p` and `#m/p`.
        let mut two = square();
        two.meshes[0].name = "head.0".into();
        let mut eye = two.meshes[0].clone();
        eye.name = "mesh3.1".into();
        two.meshes.push(eye);
        assert_eq!(two.resolve_mesh_spec("head/0"), Some(0));
        assert_eq!(two.resolve_mesh_spec("head.0"), Some(0));
        assert_eq!(two.resolve_mesh_spec("#3/1"), Some(1));
        assert_eq!(two.resolve_mesh_spec("head/1"), None);
        assert_eq!(two.resolve_mesh_spec("#x/1"), None);
        assert_eq!(two.resolve_mesh_spec("head/"), None);
        assert_eq!(face.fp_vertex(fp("9.3")), Some((0, 3)));
        assert_eq!(face.fp_vertex(fp("2.1")), Some((0, 1)));

        // Out-of-range vertex and unknown mesh names are errors.
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(fp("2.1"), VertexBinding::vertex(9)));
        let e = attach_feature_points(&mut square(), set, &[]).unwrap_err();
        assert!(e.to_string().contains("vertex 9"), "{e}");
        let mut set = FeaturePointSet::new();
        set.insert(FeaturePoint::bound(
            fp("2.1"),
            VertexBinding {
                mesh: Some("other".into()),
                vertices: vec![0],
            },
        ));
        let e = attach_feature_points(&mut square(), set, &[]).unwrap_err();
        assert!(e.to_string().contains("`other`"), "{e}");
    }
}
