use glam::{DVec3, Vec3};

use super::*;
use crate::face::FaceTransform;
use crate::fat::eval::Activation;
use crate::spec::FapId;
use crate::synth::{generate, HeadParams};

/// The presets, built once per test binary.
fn small(params: HeadParams) -> FaceModel {
    static FACES: std::sync::OnceLock<(FaceModel, FaceModel)> = std::sync::OnceLock::new();
    let (a, b) = FACES.get_or_init(|| {
        (
            generate(&HeadParams::alma()).to_face_model(),
            generate(&HeadParams::bruno()).to_face_model(),
        )
    });
    if params.name == "alma" {
        a.clone()
    } else {
        b.clone()
    }
}

#[test]
fn moving_the_centre_alone_keeps_the_matrix() {
    let mut face = FaceModel::new("t");
    let mut t = FaceTransform::new("a", None, Vec3::new(1.0, 2.0, 3.0));
    t.translation = Vec3::new(0.5, -1.0, 2.0);
    t.rotation = glam::Quat::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.7);
    t.scale = Vec3::new(1.5, 0.8, 1.2);
    face.transforms.push(t);
    let before = face.transforms[0].local_matrix();
    install_center(&mut face, 0, Vec3::new(-4.0, 7.0, 0.5));
    let after = face.transforms[0].local_matrix();
    for p in [Vec3::ZERO, Vec3::X, Vec3::new(3.0, -2.0, 5.0)] {
        assert!(
            before
                .transform_point3(p)
                .distance(after.transform_point3(p))
                < 1e-4
        );
    }
    // The centre is where asked, in world terms: rotating about it keeps that point fixed.
    let w = face.frames().transforms[0].transform_point3(face.transforms[0].center);
    assert!(w.distance(Vec3::new(-4.0, 7.0, 0.5)) < 1e-4, "{w}");
    // With R = I and S = 1, T·C·C⁻¹ = T: the translation does not change at all.
    let mut plain = FaceModel::new("p");
    plain
        .transforms
        .push(FaceTransform::new("b", None, Vec3::ONE));
    install_center(&mut plain, 0, Vec3::new(5.0, 5.0, 5.0));
    assert_eq!(plain.transforms[0].translation, Vec3::ZERO);
}

#[test]
fn similarity_fit_recovers_a_known_transform() {
    let truth = Similarity {
        scale: 2.5,
        rotation: glam::DQuat::from_axis_angle(DVec3::new(0.3, 1.0, -0.2).normalize(), 1.1),
        translation: DVec3::new(10.0, -3.0, 4.0),
    };
    let from: Vec<DVec3> = (0..10)
        .map(|i| DVec3::new(i as f64, (i * i % 7) as f64, (i * 3 % 5) as f64))
        .collect();
    let to: Vec<DVec3> = from
        .iter()
        .map(|&p| truth.point(p.as_vec3()).as_dvec3())
        .collect();
    let fit = Similarity::fit(&from, &to).unwrap();
    assert!((fit.scale - 2.5).abs() < 1e-5);
    assert!(fit.rotation.angle_between(truth.rotation) < 1e-5);
    assert!(Similarity::fit(&from[..2], &to[..2]).is_err());
    let line: Vec<DVec3> = (0..5).map(|i| DVec3::X * i as f64).collect();
    assert!(Similarity::fit(&line, &line).is_err());
}

#[test]
fn synth_parts_are_identified() {
    let face = small(HeadParams::alma());
    let parts = identify_parts(&face);
    let names =
        |v: &[usize]| -> Vec<&str> { v.iter().map(|&m| face.meshes[m].name.as_str()).collect() };
    assert_eq!(names(&parts.skin), ["skin"]);
    assert_eq!(names(&parts.parts[&Part::LeftEye]), ["eye_l"]);
    assert_eq!(names(&parts.parts[&Part::RightEye]), ["eye_r"]);
    assert_eq!(names(&parts.parts[&Part::UpperTeeth]), ["teeth_upper"]);
    assert_eq!(names(&parts.parts[&Part::LowerTeeth]), ["teeth_lower"]);
    assert_eq!(names(&parts.parts[&Part::Tongue]), ["tongue"]);
    assert!(parts.other.is_empty());
}

fn world_of(face: &FaceModel, posed: &[Vec<Vec3>], mesh: &str, v: usize) -> Vec3 {
    posed[face.mesh_index(mesh).unwrap()][v]
}

#[test]
fn rigid_parts_pivot_about_installed_centres() {
    let (a, b) = (small(HeadParams::alma()), small(HeadParams::bruno()));
    let out = clone_face(&a, &b, &CloneOptions::default()).unwrap();
    let face = &out.face;
    let mut ev = face.evaluator().unwrap();
    let mut o = ev.output();
    let neutral = face.pose_with(&mut ev, &mut o, &[]);
    // Eyeball yaw: every left-eye vertex keeps its distance to the eyeball centre.
    let eye = face.mesh_index("eye_l").unwrap();
    let frames = face.frames();
    let t = face.transform_index("eye_l_tf").unwrap();
    let centre = frames.transforms[t].transform_point3(face.transforms[t].center);
    let yaw = face.pose_with(
        &mut ev,
        &mut o,
        &[Activation {
            key: TableKey::LowLevel(FapId::new(23).unwrap()),
            value: 30_000.0,
        }],
    );
    let mut moved = 0.0f32;
    for v in 0..neutral[eye].len() {
        let (p0, p1) = (neutral[eye][v], yaw[eye][v]);
        assert!((p0.distance(centre) - p1.distance(centre)).abs() < 1e-3);
        moved = moved.max(p0.distance(p1));
    }
    assert!(moved > 1.0, "the eye must turn, moved {moved}");
    // The installed centre is the eyeball's own (bruno's generator puts it there).
    let truth = b.frames().transforms[b.transform_index("eye_l_tf").unwrap()]
        .transform_point3(b.transforms[b.transform_index("eye_l_tf").unwrap()].center);
    assert!(centre.distance(truth) < 0.05, "{centre} vs {truth}");
    // Head pitch pivots about 7.1.
    let fp71 = face
        .feature_points
        .position("7.1".parse().unwrap())
        .unwrap();
    let pitch = face.pose_with(
        &mut ev,
        &mut o,
        &[Activation {
            key: TableKey::LowLevel(FapId::new(48).unwrap()),
            value: 20_000.0,
        }],
    );
    let (mi, vi) = face.fp_vertex("7.1".parse().unwrap()).unwrap();
    assert!(pitch[mi][vi as usize].distance(fp71) < 1e-3);
    let tip = face.fp_vertex("9.3".parse().unwrap()).unwrap();
    let d0 = world_of(face, &neutral, "skin", tip.1 as usize).distance(fp71);
    let d1 = world_of(face, &pitch, "skin", tip.1 as usize).distance(fp71);
    assert!((d0 - d1).abs() < 1e-3);
    assert!(
        world_of(face, &neutral, "skin", tip.1 as usize).distance(world_of(
            face,
            &pitch,
            "skin",
            tip.1 as usize
        )) > 1.0
    );
}

fn transformed(face: &FaceModel, s: &Similarity) -> FaceModel {
    let mut f = face.clone();
    f.transforms.clear();
    for m in &mut f.meshes {
        m.transform = None;
    }
    let frames = face.frames();
    for (mi, m) in f.meshes.iter_mut().enumerate() {
        for p in &mut m.mesh.positions {
            *p = s.point(frames.meshes[mi].transform_point3(*p));
        }
    }
    f.fat = Fat::default();
    f.scene = None;
    f.resolve_feature_points().unwrap();
    f
}

#[test]
fn rotated_scaled_target_clones_like_the_plain_one() {
    let (a, b) = (small(HeadParams::alma()), small(HeadParams::bruno()));
    let turn = Similarity {
        scale: 3.0,
        rotation: glam::DQuat::from_axis_angle(DVec3::new(0.2, 1.0, 0.1).normalize(), 0.9),
        translation: DVec3::new(100.0, -20.0, 7.0),
    };
    for method in [Method::Fmc, Method::Rbf, Method::Fit] {
        // No rotation snap: the plain target's small spurious tilt would be dropped while the
        // turned one keeps it, and this test is about the fit's equivariance.
        let opts = CloneOptions {
            method,
            align_snap_degrees: 0.0,
            ..CloneOptions::default()
        };
        let plain = clone_face(&a, &transformed(&b, &Similarity::IDENTITY), &opts).unwrap();
        let turned = clone_face(&a, &transformed(&b, &turn), &opts).unwrap();
        let key = TableKey::LowLevel(FapId::new(5).unwrap());
        let get = |f: &FaceModel| {
            let t = f.fat.table(key).unwrap();
            let m = &t.meshes[0];
            (m.coord_index.clone(), m.displacements.clone())
        };
        let (vp, dp) = get(&plain.face);
        let (vt, dt) = get(&turned.face);
        assert_eq!(vp, vt, "{method:?}: same vertices move");
        let scale = dp.iter().map(|d| d.length()).fold(0.0, f32::max);
        let worst = dp
            .iter()
            .zip(&dt)
            .map(|(p, t)| (turn.vector(*p) - *t).length())
            .fold(0.0, f32::max);
        let sum: f32 = dp.iter().map(|d| d.length()).sum();
        let diff: f32 = dp
            .iter()
            .zip(&dt)
            .map(|(p, t)| (turn.vector(*p) - *t).length())
            .sum();
        // FMC was equivariant to float precision (1.5e-6 of the summed displacement) until
        // FAPU and FAP directions followed a face's own axes while it is upright (alignment
        // turn ≤ 20°, `Similarity::keeps_own_axes`): the plain target's alignment keeps a
        // small spurious tilt, so it keeps its own axes, while the turned one is measured in
        // the aligned frame; they differ by that tilt's share (measured 5.0 % of the largest
        // displacement). RBF: float noise from the alignment changes which 125 worst vertices
        // each refinement round picks, so the fit differs (measured 6.8 % for FAP 5).
        match method {
            Method::Fmc => assert!(worst < 0.06 * scale, "{worst} vs {scale}"),
            Method::Rbf => assert!(diff < 0.1 * sum, "{diff} vs {sum}"),
            // Fit: closest points move with float noise, nothing chooses discretely; the tilt's
            // share as for FMC (3.6 % of the summed displacement, was under 1 %).
            Method::Fit => assert!(diff < 0.05 * sum, "{diff} vs {sum}"),
        }
        eprintln!("{method:?}: worst {worst} of {scale}, sum {diff} of {sum}");
    }
}

#[test]
fn missing_feature_points_are_listed() {
    let a = small(HeadParams::alma());
    let mut b = small(HeadParams::bruno());
    for l in ["8.3", "2.1", "9.3"] {
        b.feature_points.remove(l.parse().unwrap());
    }
    let e = clone_face(&a, &b, &CloneOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("8.3"), "{e}");
}

#[test]
fn small_alignment_rotations_snap_to_none() {
    let from: Vec<DVec3> = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        [0.0, 0.0, 3.0],
        [1.0, 1.0, 1.0],
    ]
    .iter()
    .map(|&a| DVec3::from_array(a))
    .collect();
    let moved = |deg: f64| -> Vec<DVec3> {
        let q = glam::DQuat::from_axis_angle(DVec3::X, deg.to_radians());
        from.iter()
            .map(|&p| q * p * 2.0 + DVec3::new(5.0, 0.0, 0.0))
            .collect()
    };
    let small = Similarity::fit_snapped(&from, &moved(1.0), 3.0).unwrap();
    assert_eq!(small.rotation, glam::DQuat::IDENTITY);
    assert!((small.scale - 2.0).abs() < 1e-3, "{}", small.scale);
    let large = Similarity::fit_snapped(&from, &moved(10.0), 3.0).unwrap();
    assert!(
        (large.angle_degrees() - 10.0).abs() < 1e-6,
        "{}",
        large.angle_degrees()
    );
    assert!((large.scale - 2.0).abs() < 1e-9);
    // Without snapping the small rotation is kept.
    let kept = Similarity::fit_snapped(&from, &moved(1.0), 0.0).unwrap();
    assert!((kept.angle_degrees() - 1.0).abs() < 1e-6);
    // A face turned round (half a turn about y) and tilted 1°: exactly the half turn, and
    // the scale refitted with it.
    let half = glam::DQuat::from_rotation_y(std::f64::consts::PI);
    let round: Vec<DVec3> = moved(1.0).iter().map(|&p| half * p).collect();
    let snapped = Similarity::fit_snapped(&from, &round, 3.0).unwrap();
    assert!(
        snapped.rotation.angle_between(half) < 1e-12,
        "{:?}",
        snapped.rotation
    );
    assert!((snapped.scale - 2.0).abs() < 1e-3, "{}", snapped.scale);
    for (a, b) in from.iter().zip(&round) {
        assert!(
            (snapped.rotation * *a * snapped.scale + snapped.translation).distance(*b) < 0.1,
            "{a} {b}"
        );
    }
}
