//! Centres of rotation for rigid parts: moving a transform's centre without moving the face,
//! and the eyeball centre a turning eye pivots about.

use std::collections::{BTreeMap, HashSet};

use glam::{Affine3A, DVec3, Mat3, Vec3};

use crate::clone::face::{FaceParts, Part, Similarity};
use crate::error::Diagnostic;
use crate::face::FaceModel;

/// Moves `center` of transform `t` to the face-frame point `world`, compensating `translation`
/// so the transform's matrix (and the neutral pose) does not change.
pub fn install_center(face: &mut FaceModel, t: usize, world: Vec3) {
    let frames = face.frames();
    let c_new = frames.transforms[t].inverse().transform_point3(world);
    let tf = &mut face.transforms[t];
    let lin = crate::face::local_matrix(
        Vec3::ZERO,
        tf.rotation,
        tf.scale,
        tf.scale_orientation,
        Vec3::ZERO,
    )
    .matrix3;
    let dc = tf.center - c_new;
    tf.translation += dc - Mat3::from(lin) * dc;
    tf.center = c_new;
}

/// Least-squares sphere centre of points, or their bounding-box centre when they are no sphere.
pub(super) fn eyeball_centre(points: &[Vec3]) -> Option<Vec3> {
    if points.is_empty() {
        return None;
    }
    let lo = points
        .iter()
        .fold(Vec3::splat(f32::INFINITY), |a, &p| a.min(p));
    let hi = points
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, &p| a.max(p));
    let bbox = (lo + hi) / 2.0;
    if points.len() < 4 {
        return Some(bbox);
    }
    // |p|² = 2c·p + k, linear in (c, k); solved about the box centre for conditioning.
    let mut a = nalgebra::Matrix4::<f64>::zeros();
    let mut b = nalgebra::Vector4::<f64>::zeros();
    for &p in points {
        let q = (p - bbox).as_dvec3();
        let row = nalgebra::Vector4::new(2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0);
        a += row * row.transpose();
        b += row * q.length_squared();
    }
    let Some(x) = a.lu().solve(&b) else {
        return Some(bbox);
    };
    let c = DVec3::new(x[0], x[1], x[2]);
    let r2 = x[3] + c.length_squared();
    if r2.is_nan() || r2 <= 0.0 || !c.is_finite() {
        return Some(bbox);
    }
    let r = r2.sqrt();
    let rms = (points
        .iter()
        .map(|&p| ((p - bbox).as_dvec3().distance(c) - r).powi(2))
        .sum::<f64>()
        / points.len() as f64)
        .sqrt();
    if rms > 0.1 * r {
        Some(bbox)
    } else {
        Some((c + bbox.as_dvec3()).as_vec3())
    }
}

/// Installs `world` as the centre of transform `t` and records it for the report.
fn install_recorded(
    face: &mut FaceModel,
    t: usize,
    world: Vec3,
    installed: &mut Vec<(String, [f32; 3])>,
) {
    install_center(face, t, world);
    installed.push((face.transforms[t].name.clone(), world.to_array()));
}

/// Centres each eye's transform at its eyeball centre: the eye white's (the largest piece of
/// the eye's meshes), whatever caps lie in front of it.
pub(super) fn install_eye_centres(
    face: &mut FaceModel,
    tparts: &FaceParts,
    part_tf: &BTreeMap<Part, usize>,
    installed: &mut Vec<(String, [f32; 3])>,
) {
    // Installing a centre keeps every matrix, so these frames stay valid across the loop.
    let frames = face.frames();
    for eye in [Part::LeftEye, Part::RightEye] {
        if let (Some(&t), Some(meshes)) = (part_tf.get(&eye), tparts.parts.get(&eye)) {
            let pts = super::super::eyeball::eye_white_points(face, &frames, meshes);
            if let Some(c) = eyeball_centre(&pts) {
                install_recorded(face, t, c, installed);
            }
        }
    }
}

/// Centres the head transform at 7.1 (neck base), or warns that the target lacks it.
pub(super) fn install_head_centre(
    face: &mut FaceModel,
    head: usize,
    installed: &mut Vec<(String, [f32; 3])>,
    warnings: &mut Vec<Diagnostic>,
) {
    match face
        .feature_points
        .position(crate::spec::FeaturePointId::FP_7_1)
    {
        Some(c) => install_recorded(face, head, c, installed),
        None => warnings.push(Diagnostic::warning(
            "target lacks 7.1 (neck base): the head keeps its centre of rotation",
        )),
    }
}

/// Teeth and tongue transforms the source rotates but that have no centre (zero) get the
/// source transform's centre mapped back through the alignment `frame`.
pub(super) fn install_rotated_part_centres(
    source: &FaceModel,
    sroles: &BTreeMap<Part, usize>,
    rotated: &HashSet<&str>,
    face: &mut FaceModel,
    part_tf: &BTreeMap<Part, usize>,
    frame: &Similarity,
    installed: &mut Vec<(String, [f32; 3])>,
) {
    let sframes = source.frames();
    for p in [Part::UpperTeeth, Part::LowerTeeth, Part::Tongue] {
        let (Some(&tt), Some(&st)) = (part_tf.get(&p), sroles.get(&p)) else {
            continue;
        };
        let sname = source.transforms[st].name.as_str();
        if rotated.contains(sname) && face.transforms[tt].center == Vec3::ZERO {
            let s = &source.transforms[st];
            let parent = s
                .parent
                .map_or(Affine3A::IDENTITY, |q| sframes.transforms[q]);
            let sc = parent.transform_point3(s.translation + s.center);
            let c = frame.inverse_point(sc.as_dvec3()).as_vec3();
            install_recorded(face, tt, c, installed);
        }
    }
}
