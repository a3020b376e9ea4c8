//! Eyes and heads that turn on every face: the standard's eyeball (23–26) and head (48–50)
//! rotation tables where a face's FAT lacks them (`fbakit::clone::face::standard`). The
//! bundled real head `ict` builds its FAT from a rig without eye or head shapes; it, and every
//! clone of it, now turns its eyes about their centres and its head about the neck, the
//! neck's base still.

mod support;

use std::path::Path;

use fbakit::clone::face::{clone_face, CloneOptions};
use fbakit::face::FaceModel;
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::spec::{FapId, FeaturePointId};
use glam::{DQuat, DVec3, Vec3};
use support::cli::{command, fbakit, text};

/// ICT-FaceKit's vertex ranges (its README), the same in the bundled cut-down head.
const LEFT_EYEBALL: std::ops::Range<usize> = 21451..23021;
const RIGHT_EYEBALL: std::ops::Range<usize> = 23021..24591;

fn key(n: u8) -> TableKey {
    TableKey::LowLevel(FapId::new(n).expect("a FAP"))
}

fn ict() -> FaceModel {
    fbakit::face::read("ict").expect("read ict")
}

/// World positions of every vertex of `face` with FAP `n` at `value`.
fn posed(face: &FaceModel, n: u8, value: f64) -> Vec<Vec<Vec3>> {
    face.pose(&[Activation { key: key(n), value }])
        .expect("pose")
}

/// Bounding-box diagonal.
fn size(points: &[Vec3]) -> f32 {
    let lo = points.iter().fold(Vec3::splat(f32::MAX), |a, &p| a.min(p));
    let hi = points.iter().fold(Vec3::splat(f32::MIN), |a, &p| a.max(p));
    (hi - lo).length()
}

/// The centre of a turn by `angle` about +y taking `from` to `to` (least squares over the
/// points, in x and z; y is the points' mean).
fn yaw_centre(from: &[Vec3], to: &[Vec3], angle: f64) -> DVec3 {
    let q = DQuat::from_rotation_y(angle);
    // p' − R p = (I − R) c; (I − R) restricted to the xz plane is invertible for angle ≠ 0.
    let (c, s) = (angle.cos(), angle.sin());
    let m = [[1.0 - c, -s], [s, 1.0 - c]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let mut sum = DVec3::ZERO;
    for (p, p2) in from.iter().zip(to) {
        let r = p2.as_dvec3() - q * p.as_dvec3();
        let x = (m[1][1] * r.x - m[0][1] * r.z) / det;
        let z = (-m[1][0] * r.x + m[0][0] * r.z) / det;
        sum += DVec3::new(x, p.y as f64, z);
    }
    sum / from.len() as f64
}

#[test]
fn ict_has_eye_and_head_tables() {
    let face = ict();
    for n in [23, 24, 25, 26, 48, 49, 50] {
        assert!(face.fat.table(key(n)).is_some(), "FAP {n} has no table");
    }
    let out = fbakit(&["face", "info", "ict"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let info = text(&out.stdout);
    let line = info
        .lines()
        .find(|l| l.contains("low-level FAPs without a table"))
        .expect("a line of FAPs without tables");
    assert!(
        !line.contains("23-") && !line.contains("48") && !line.contains("-50"),
        "{line}"
    );
}

/// `yaw_l_eyeball` turns the left eyeball (and only it) about one centre, within 1 % of its
/// size at every interval border, mid-interval value and +0.3 rad; the right eye, lids and
/// skin stay still.
#[test]
fn ict_left_eyeball_turns_alone() {
    let face = ict();
    let neutral = face.neutral_world_positions();
    let mesh = face
        .fp_vertex(FeaturePointId::FP_3_5)
        .map(|x| x.0)
        .expect("pupil 3.5 on a mesh");
    let pupil = face.fp_vertex(FeaturePointId::FP_3_5).expect("3.5").1 as usize;
    assert!(LEFT_EYEBALL.contains(&pupil), "3.5 is vertex {pupil}");
    let eye: Vec<Vec3> = neutral[mesh][LEFT_EYEBALL].to_vec();
    let eye_size = size(&eye);
    let table = face.fat.table(key(23)).expect("table 23");
    let borders = table.meshes[0].interval_borders.clone();
    assert!(borders.len() >= 3, "{borders:?}");
    // The centre from the largest border (the table is exact at borders).
    let top = *borders.last().expect("a border");
    let at_top = posed(&face, 23, top);
    let centre = yaw_centre(&eye, &at_top[mesh][LEFT_EYEBALL], top * 1e-5);
    let bbox_mid = eye.iter().fold(DVec3::ZERO, |a, p| a + p.as_dvec3()) / eye.len() as f64;
    assert!(
        centre.distance(bbox_mid) < 0.25 * eye_size as f64,
        "centre {centre} far from the eyeball's middle {bbox_mid}"
    );
    let mut values: Vec<f64> = borders.clone();
    values.extend(borders.windows(2).map(|w| (w[0] + w[1]) / 2.0));
    values.push(30_000.0);
    let mut worst: f64 = 0.0;
    for &v in &values {
        let pose = posed(&face, 23, v);
        let q = DQuat::from_rotation_y(v * 1e-5);
        for (i, p) in LEFT_EYEBALL.enumerate() {
            let want = centre + q * (eye[i].as_dvec3() - centre);
            let err = want.distance(pose[mesh][p].as_dvec3()) / eye_size as f64;
            worst = worst.max(err);
        }
        for (i, (a, b)) in neutral[mesh].iter().zip(&pose[mesh]).enumerate() {
            if !LEFT_EYEBALL.contains(&i) {
                assert_eq!(a, b, "vertex {i} moved under yaw_l_eyeball {v}");
            }
        }
    }
    eprintln!("yaw_l_eyeball worst error {worst:.5} of the eyeball size over {values:?}");
    assert!(
        worst <= 0.01,
        "worst error {:.4} of the eyeball's size",
        worst
    );
    // Positive yaw looks to the face's left (+x): the pupil moves +x.
    let pose = posed(&face, 23, 30_000.0);
    assert!(pose[mesh][pupil].x > neutral[mesh][pupil].x + 0.05 * eye_size);
    let _ = RIGHT_EYEBALL;
}

/// `head_yaw` turns the face rigidly about a point behind it; the neck's base stays.
#[test]
fn ict_head_yaw_turns_the_face_not_the_neck_base() {
    assert_head_yaw_keeps_the_neck_base(&ict());
}

/// `head_yaw` at 0.3 rad turns `face`'s pupils' line by that angle about +y, keeps the
/// distances between its face points within 0.5 % (the skull turns rigidly), turns the nose
/// to the face's left and leaves the neck's base (the lowest 2 % of its height) still.
fn assert_head_yaw_keeps_the_neck_base(face: &FaceModel) {
    let neutral = face.neutral_world_positions();
    let pose = posed(face, 49, 30_000.0);
    let fps = [
        FeaturePointId::FP_3_5,
        FeaturePointId::FP_3_6,
        FeaturePointId::FP_2_1,
        FeaturePointId::FP_8_3,
        FeaturePointId::FP_8_4,
        FeaturePointId::FP_9_3,
    ];
    let at = |w: &Vec<Vec<Vec3>>, id| {
        let (m, v) = face.fp_vertex(id).expect("feature point on the face");
        w[m][v as usize].as_dvec3()
    };
    let (a0, a1) = (
        at(&neutral, fps[0]) - at(&neutral, fps[1]),
        at(&pose, fps[0]) - at(&pose, fps[1]),
    );
    let turn = (a0.z.atan2(a0.x)) - (a1.z.atan2(a1.x));
    assert!((turn - 0.3).abs() < 0.01, "pupils turned {turn} rad");
    for i in 0..fps.len() {
        for j in i + 1..fps.len() {
            let d0 = at(&neutral, fps[i]).distance(at(&neutral, fps[j]));
            let d1 = at(&pose, fps[i]).distance(at(&pose, fps[j]));
            assert!(
                (d1 - d0).abs() <= 0.005 * d0,
                "{} {}: {d0} → {d1}",
                fps[i],
                fps[j]
            );
        }
    }
    assert!(at(&pose, fps[5]).x > at(&neutral, fps[5]).x);
    let all: Vec<Vec3> = neutral.iter().flatten().copied().collect();
    let lo = all.iter().map(|p| p.y).fold(f32::MAX, f32::min);
    let hi = all.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    let mut base = 0;
    for (m, mesh) in neutral.iter().enumerate() {
        for (v, p) in mesh.iter().enumerate() {
            if p.y < lo + 0.02 * (hi - lo) {
                base += 1;
                assert_eq!(*p, pose[m][v], "neck-base vertex {v} moved");
            }
        }
    }
    assert!(base > 0);
}

/// alma turns her head with a `head` transform; a one-mesh head has none, and the clone
/// creates none (a root around the user's face would change their asset and turn the neck's
/// base with the skull): the head turns are re-made per vertex, faded down the neck, with no
/// warning that they were dropped.
#[test]
fn clone_alma_onto_a_one_mesh_head_turns_it_per_vertex() {
    let work = tempfile::tempdir().expect("temp dir");
    let Some((_, target)) = support::ict_full_head::ict_full_head(work.path()) else {
        return;
    };
    let alma = fbakit::face::read("alma").expect("alma");
    assert!(
        alma.fat
            .table(key(49))
            .is_some_and(|t| !t.transforms.is_empty()),
        "alma turns her head by a transform"
    );
    let out = clone_face(&alma, &target, &CloneOptions::default()).expect("clone");
    let face = out.face;
    assert!(
        face.transforms.is_empty(),
        "no transform added: {:?}",
        face.transforms
    );
    assert_eq!(out.report.rigid.head_transform, None);
    for w in &out.report.warnings {
        for bad in ["created transforms", "no counterpart", "are not cloned"] {
            assert!(!w.message.contains(bad), "{}", w.message);
        }
    }
    for n in [48, 49, 50] {
        let t = face.fat.table(key(n)).unwrap_or_else(|| panic!("FAP {n}"));
        assert!(t.transforms.is_empty() && !t.meshes.is_empty(), "FAP {n}");
    }
    assert_head_yaw_keeps_the_neck_base(&face);
}

/// A clone from `ict` turns its target's eyes: per-vertex on a one-mesh OBJ head.
#[test]
fn clone_ict_onto_a_one_mesh_head_turns_its_eyes() {
    let work = tempfile::tempdir().expect("temp dir");
    let Some((_, target)) = support::ict_full_head::ict_full_head(work.path()) else {
        return;
    };
    let out = clone_face(&ict(), &target, &CloneOptions::default()).expect("clone");
    let face = out.face;
    assert_eq!(face.meshes.len(), target.meshes.len());
    assert!(
        face.transforms.is_empty(),
        "no transform added: {:?}",
        face.transforms
    );
    assert!(
        !out.report
            .warnings
            .iter()
            .any(|w| w.message.contains("created transforms")),
        "{:?}",
        out.report.warnings
    );
    for n in [23, 24, 25, 26, 48, 49, 50] {
        let t = face.fat.table(key(n)).unwrap_or_else(|| panic!("FAP {n}"));
        assert!(t.transforms.is_empty() && !t.meshes.is_empty(), "FAP {n}");
    }
    let neutral = face.neutral_world_positions();
    let pose = posed(&face, 23, 30_000.0);
    let (m, pupil) = face.fp_vertex(FeaturePointId::FP_3_5).expect("3.5");
    let moved = pose[m][pupil as usize] - neutral[m][pupil as usize];
    assert!(
        moved.x > 0.0 && moved.length() > 1e-3 * size(&neutral[m]),
        "{moved}"
    );
    for id in [
        FeaturePointId::FP_3_1,
        FeaturePointId::FP_3_3,
        FeaturePointId::FP_3_6,
    ] {
        let (m, v) = face.fp_vertex(id).expect("lid points");
        assert_eq!(pose[m][v as usize], neutral[m][v as usize], "{id} moved");
    }
}

/// A clone from `ict` onto alma turns alma's eye transforms.
#[test]
fn clone_ict_onto_alma_turns_its_eye_transforms() {
    let alma = fbakit::face::read("alma").expect("alma");
    let mut target = alma.clone();
    target.fat = Default::default();
    let out = clone_face(&ict(), &target, &CloneOptions::default()).expect("clone");
    let face = out.face;
    for n in [23, 24, 25, 26] {
        let t = face.fat.table(key(n)).unwrap_or_else(|| panic!("FAP {n}"));
        assert!(
            t.meshes.is_empty() && t.transforms.len() == 1,
            "FAP {n}: {t:?}"
        );
    }
    let neutral = face.neutral_world_positions();
    let pose = posed(&face, 23, 30_000.0);
    let (m, v) = face.fp_vertex(FeaturePointId::FP_3_5).expect("3.5");
    assert!(pose[m][v as usize].x > neutral[m][v as usize].x);
    let (m, v) = face.fp_vertex(FeaturePointId::FP_3_6).expect("3.6");
    assert_eq!(pose[m][v as usize], neutral[m][v as usize]);
}

/// A Live Link Face capture turning the head: `fap from-arkit` on `ict`, then `play` turns
/// the head in the frames written.
#[test]
fn live_link_head_yaw_turns_ict_in_play() {
    let work = tempfile::tempdir().expect("temp dir");
    let names: Vec<String> = fbakit::rig::arkit_names::ARKIT_SHAPES
        .iter()
        .map(|n| fbakit::rig::arkit_names::capture_name(n))
        .collect();
    let rot = "HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll";
    let mut csv = format!("Timecode,BlendShapeCount,{},{rot}\n", names.join(","));
    for (f, yaw) in [(0, 0.0), (1, 0.3)] {
        let zeros = vec!["0"; 52].join(",");
        csv.push_str(&format!(
            "00:00:00:{f:02}.000,61,{zeros},{yaw},0,0,0,0,0,0,0,0\n"
        ));
    }
    let capture = work.path().join("capture.csv");
    std::fs::write(&capture, csv).expect("write");
    let stream = work.path().join("capture.fap");
    let out = command()
        .args(["fap", "from-arkit"])
        .arg(&capture)
        .args(["--face", "ict", "--fps", "30", "-o"])
        .arg(&stream)
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let frames = work.path().join("frames");
    let out = command()
        .args(["play", "ict"])
        .arg(&stream)
        .args(["--format", "obj", "-o"])
        .arg(&frames)
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        !text(&out.stderr).contains("head_yaw"),
        "play still misses head_yaw: {}",
        text(&out.stderr)
    );
    let read = |p: &Path| -> Vec<Vec3> {
        std::fs::read_to_string(p)
            .expect("frame")
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f32> = l
                    .split_whitespace()
                    .map(|x| x.parse().expect("num"))
                    .collect();
                Vec3::new(c[0], c[1], c[2])
            })
            .collect()
    };
    let f0 = read(&frames.join("frame_00000.obj"));
    let f1 = read(&frames.join("frame_00001.obj"));
    let face = ict();
    let (_, nose) = face.fp_vertex(FeaturePointId::FP_9_3).expect("9.3");
    let d = f1[nose as usize] - f0[nose as usize];
    let scale = size(&f0);
    assert!(d.x > 0.02 * scale, "nose moved {d} (head size {scale})");
}
