//! Recognising a turned face's parts (module docs of [`super`], step 1) in its own upright
//! frame. The recognition works by place in the face frame of the MPEG-4 standard — x towards
//! the face's left, y up, z out of the face — where pieces lie "behind the lips", "below the
//! lip line" or "in front of the eyeball"; the cloning steps after it run in the aligned frame
//! (step 2), whatever way the target faces. A target modelled facing −z (VRM 0.x avatars, a
//! scan turned round) had its parts recognised in its file's frame, where its eyes lie
//! behind its head: no eyeball or tooth was cut out of the one-mesh ICT head turned 180°, and
//! its eyes were cloned as skin.
//!
//! The face's axes come from its feature points, snapped to its file's axes
//! ([`crate::fdp::FeaturePointSet::upright_turn`]): a face modelled facing −z, or lying with
//! z up, gets the quarter or half turn that stands it up exactly, and the recognition reads a
//! copy of the face with every mesh at its world place turned so ([`upright_copy`]); a copy
//! keeps every mesh, vertex and polygon in order, so what it finds by index holds for the
//! face. A face whose axes snap to the file's own (every upright face, whatever its small
//! tilt) is read as it is, as before.

use std::borrow::Cow;

use glam::Mat3;

use crate::face::FaceModel;
use crate::spec::FeaturePointId;

/// `face` itself when it stands upright in its file (or its axes are unknown), else its
/// [`upright_copy`]: what part recognition reads.
pub(super) fn for_recognition(face: &FaceModel) -> Cow<'_, FaceModel> {
    match face.feature_points.upright_turn() {
        Some(turn) => Cow::Owned(upright_copy(face, turn)),
        None => Cow::Borrowed(face),
    }
}

/// A copy of `face` for recognition by place: every mesh's vertices at their world places
/// turned by `turn`, no mesh under a transform (the transforms stay, holding nothing), every
/// feature point's position turned by `turn`. Meshes, vertices, polygons and feature-point
/// bindings are the face's, in order.
pub(crate) fn upright_copy(face: &FaceModel, turn: Mat3) -> FaceModel {
    let frames = face.frames();
    let mut out = face.clone();
    for (mi, m) in out.meshes.iter_mut().enumerate() {
        let world = frames.meshes[mi];
        for p in &mut m.mesh.positions {
            *p = turn * world.transform_point3(*p);
        }
        for n in &mut m.mesh.normals {
            *n = turn * world.transform_vector3(*n).normalize_or_zero();
        }
        m.transform = None;
    }
    let ids: Vec<FeaturePointId> = out.feature_points.iter().map(|p| p.id).collect();
    for id in ids {
        if let Some(mut point) = out.feature_points.remove(id) {
            point.position = point.position.map(|q| turn * q);
            out.feature_points.insert(point);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_face_turned_by_quarter_turns_is_read_upright() {
        let face = crate::face::read("alma").unwrap();
        // Upright (its small tilts included): read as it is.
        assert!(face.feature_points.upright_turn().is_none());
        assert!(matches!(for_recognition(&face), Cow::Borrowed(_)));
        let half_y = Mat3::from_rotation_y(std::f32::consts::PI);
        let z_up = Mat3::from_rotation_x(std::f32::consts::FRAC_PI_2);
        // A slight tilt on top of the turn is not taken out: the copy is the upright face.
        let tilt = Mat3::from_rotation_z(0.2);
        for turned_by in [half_y, z_up, z_up * half_y, half_y * tilt] {
            let turned = upright_copy(&face, turned_by);
            let turn = turned
                .feature_points
                .upright_turn()
                .expect("a turned face is stood up");
            let back = for_recognition(&turned);
            let Cow::Owned(back) = back else {
                panic!("a turned face must be read upright")
            };
            let undo = turn * turned_by;
            let tilt_left = if turned_by == half_y * tilt {
                tilt
            } else {
                Mat3::IDENTITY
            };
            assert!(undo.abs_diff_eq(tilt_left, 1e-5), "{undo:?}");
            for p in face.feature_points.iter() {
                let (Some(a), Some(b)) = (p.position, back.feature_points.position(p.id)) else {
                    continue;
                };
                assert!(
                    (tilt_left * a).distance(b) < 1e-4 * (1.0 + a.length()),
                    "{}",
                    p.id
                );
            }
            let f = face.frames();
            for (mi, m) in face.meshes.iter().enumerate() {
                assert_eq!(m.mesh.positions.len(), back.meshes[mi].mesh.positions.len());
                assert!(back.meshes[mi].transform.is_none());
                let w = f.meshes[mi].transform_point3(m.mesh.positions[0]);
                assert!((tilt_left * w).distance(back.meshes[mi].mesh.positions[0]) < 1e-3);
            }
        }
    }
}
