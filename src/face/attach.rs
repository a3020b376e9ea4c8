//! Putting feature points from a separate file on a face's meshes: bound points on their
//! vertices, position-only points on the nearest vertex.

use super::vrml::FeaturePointMatch;
use super::FaceModel;
use crate::error::Result;
use crate::face::vertex_index::FaceVertexIndex;
use crate::fdp::FeaturePointSet;

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
        match (&single, b.mesh.as_deref()) {
            (Some(only), None) => b.mesh = Some(only.clone()),
            (Some(only), Some(m)) if m == only || aliases.contains(&m) => {
                b.mesh = Some(only.clone())
            }
            (_, Some(m)) if face.mesh_index(m).is_some() => {}
            (_, m) => bad.push(format!(
                "{id} names mesh {}",
                m.map_or("<none>".to_string(), |m| format!("`{m}`"))
            )),
        }
    }
    if !bad.is_empty() {
        let names: Vec<&str> = face.meshes.iter().map(|m| m.name.as_str()).collect();
        return Err(super::FaceError::UnknownFeaturePointMeshes {
            points: bad.join(", "),
            meshes: names.join(", "),
        }
        .into());
    }
    face.feature_points = points;
    face.resolve_feature_points()?;

    // Position-only points: bind to the nearest vertex of any mesh.
    let index = FaceVertexIndex::new(face);
    let mut matches = Vec::new();
    let unbound: Vec<_> = face
        .feature_points
        .iter()
        .filter(|p| p.binding.is_none())
        .filter_map(|p| Some((p.id, p.position?)))
        .collect();
    for (id, pos) in unbound {
        if !pos.is_finite() {
            return Err(super::FaceError::NonFiniteFeaturePoint { id }.into());
        }
        let Some((binding, found)) = index.bind(face, id, pos) else {
            continue;
        };
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
        set.insert(FeaturePoint::at(fp("9.3"), Vec3::new(0.1, 0.9, 0.0)));
        let m = attach_feature_points(&mut face, set, &["sq.obj"]).unwrap();
        assert_eq!(
            face.feature_points.position(fp("2.1")),
            Some(Vec3::new(1.0, 0.5, 0.0))
        );
        assert_eq!(m.len(), 1);
        assert_eq!((m[0].id, m[0].vertex), (fp("9.3"), 3));
        assert!((m[0].distance - 0.141_421).abs() < 1e-4);
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
