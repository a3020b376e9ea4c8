use std::sync::OnceLock;

use glam::{Quat, Vec3};

use super::*;
use crate::fap::{ExpressionParams, FapFrame, VisemeParams};
use crate::spec::{Expression, FapId, FeaturePointId, Viseme};

fn alma() -> &'static FaceModel {
    static FACE: OnceLock<FaceModel> = OnceLock::new();
    FACE.get_or_init(|| crate::synth::alma().to_face_model())
}

fn fp(id: &str) -> FeaturePointId {
    id.parse().unwrap()
}

fn stream_of(frames: Vec<FapFrame>) -> FapStream {
    FapStream {
        frames,
        ..FapStream::new("t", 25.0)
    }
}

fn world_fp(face: &FaceModel, frame: &PlayerFrame, id: &str) -> Vec3 {
    let (m, v) = face.fp_vertex(fp(id)).unwrap();
    frame.pose.world.meshes[m].transform_point3(frame.pose.positions[m][v as usize])
}

#[test]
fn head_yaw_rotates_nose_tip_about_7_1() {
    let face = alma();
    let mut f = FapFrame::new(0);
    f.set(FapId::new(49).unwrap(), 20_000.0);
    let stream = stream_of(vec![f]);
    let mut player = Player::new(face, &stream, &PlayOptions::default()).unwrap();
    let mut frame = player.new_frame();
    assert!(player.next_frame(&mut frame));
    assert!(!player.next_frame(&mut frame));
    let pivot = face
        .feature_points
        .get(fp("7.1"))
        .unwrap()
        .position
        .unwrap();
    let nose0 = face
        .feature_points
        .get(fp("9.3"))
        .unwrap()
        .position
        .unwrap();
    let nose = world_fp(face, &frame, "9.3");
    let expected = pivot + Quat::from_rotation_y(0.2) * (nose0 - pivot);
    assert!(
        (nose - expected).length() < 1e-3,
        "{nose} vs {expected} (neutral {nose0})"
    );
    // The nose really moved (towards the face's left, +x).
    assert!(nose.x - nose0.x > 1.0, "{nose} {nose0}");
    assert!(player.missing_tables().is_empty());
}

#[test]
fn eyeball_yaw_turns_about_eye_centre() {
    let face = alma();
    let mut f = FapFrame::new(0);
    f.set(FapId::new(23).unwrap(), 30_000.0);
    let mut player = Player::new(face, &stream_of(vec![f]), &PlayOptions::default()).unwrap();
    let mut frame = player.new_frame();
    player.next_frame(&mut frame);
    let ti = face.transform_index("eye_l_tf").unwrap();
    let c = face.transforms[ti].center;
    let w = frame.pose.world.transforms[ti];
    // The centre stays, a point in front of it turns by 0.3 rad about +y.
    assert!((w.transform_point3(c) - c).length() < 1e-4);
    let p = c + Vec3::Z * 10.0;
    let expected = c + Quat::from_rotation_y(0.3) * (p - c);
    assert!((w.transform_point3(p) - expected).length() < 1e-4);
}

#[test]
fn hold_rule_and_missing_tables() {
    let mut face = alma().clone();
    face.fat
        .tables
        .retain(|t| t.key != TableKey::LowLevel(FapId::OPEN_JAW));
    let mut a = FapFrame::new(0);
    a.set(FapId::OPEN_JAW, 200.0);
    a.set(FapId::new(19).unwrap(), 100.0);
    let mut b = FapFrame::new(3);
    b.set(FapId::new(19).unwrap(), 0.0);
    let stream = stream_of(vec![a, b]);
    let mut player = Player::new(&face, &stream, &PlayOptions::default()).unwrap();
    assert_eq!(player.frame_count(), 4);
    // open_jaw held at 200 over frames 0..=3: 4 frames without a table.
    assert_eq!(
        player.missing_tables(),
        vec![(TableKey::LowLevel(FapId::OPEN_JAW), 4)]
    );
    let mut frame = player.new_frame();
    let mut lid = Vec::new();
    while player.next_frame(&mut frame) {
        lid.push(world_fp(&face, &frame, "3.1").y);
    }
    // FAP 19 (close_t_l_eyelid) held over frames 1, 2, then released at 3.
    assert_eq!(lid[0], lid[1]);
    assert_eq!(lid[1], lid[2]);
    assert!(lid[3] > lid[2] + 0.1, "{lid:?}");
}

#[test]
fn frame_range_and_fps() {
    let face = alma();
    let mut a = FapFrame::new(0);
    a.set(FapId::OPEN_JAW, 0.0);
    let mut b = FapFrame::new(10);
    b.set(FapId::OPEN_JAW, 500.0);
    let stream = stream_of(vec![a, b]);
    let opts = PlayOptions {
        fps: Some(50.0),
        frames: Some(5..100),
    };
    let mut player = Player::new(face, &stream, &opts).unwrap();
    assert_eq!(player.frame_range(), 5..21);
    assert_eq!(player.fps(), 50.0);
    let mut frame = player.new_frame();
    player.next_frame(&mut frame);
    assert_eq!(frame.index, 5);
    assert!((frame.time - 0.1).abs() < 1e-12);
    // Resampling interpolates: output frame 5 at 0.1 s is input frame 2.5 of a ramp that is
    // held at 0 until frame 9, so still 0; output frame 19 is input 9.5: half way.
    assert_eq!(frame.activations[0].value, 0.0);
    player.frame_at(19, &mut frame);
    assert_eq!(frame.activations[0].value, 250.0);
    let bad = PlayOptions {
        fps: None,
        frames: Some(11..20),
    };
    assert!(Player::new(face, &stream, &bad).is_err());
    let bad_fps = PlayOptions {
        fps: Some(f64::NAN),
        frames: None,
    };
    assert!(Player::new(face, &stream, &bad_fps).is_err());
}

#[test]
fn viseme_and_expression_activations() {
    let face = alma();
    let mut a = FapFrame::new(0);
    a.set_viseme(Some(VisemeParams {
        select1: Viseme::new(10).unwrap(),
        select2: Viseme::new(10).unwrap(),
        blend: 20,
        def: false,
    }));
    a.set_expression(Some(ExpressionParams {
        select1: Expression::new(1).unwrap(),
        intensity1: 63,
        select2: Expression::new(0).unwrap(),
        intensity2: 0,
        init_face: false,
        def: false,
    }));
    let mut player = Player::new(face, &stream_of(vec![a]), &PlayOptions::default()).unwrap();
    let mut frame = player.new_frame();
    player.next_frame(&mut frame);
    let n = frame.activations.len();
    assert_eq!(n, 70);
    assert_eq!(frame.activations[66].value, 20.0);
    assert_eq!(frame.activations[67].value, 43.0);
    assert_eq!(
        frame.activations[68].key,
        TableKey::Expression(Expression::Joy)
    );
    // Viseme 10 selected twice at 20 + 43 = full strength: same as the FAT evaluated at 63.
    let mut eval = face.evaluator().unwrap();
    let mut out = eval.output();
    eval.evaluate(
        &[
            Activation {
                key: TableKey::Viseme(Viseme::new(10).unwrap()),
                value: 63.0,
            },
            Activation {
                key: TableKey::Expression(Expression::Joy),
                value: 63.0,
            },
        ],
        &mut out,
    );
    for (mi, m) in face.meshes.iter().enumerate() {
        for (k, p) in frame.pose.positions[mi].iter().enumerate() {
            let e = m.mesh.positions[k] + out.displacements[mi][k];
            assert!((*p - e).length() < 1e-3, "mesh {mi} vertex {k}");
        }
    }
}

#[test]
fn next_frame_reuses_buffers() {
    let face = alma();
    let stream = crate::fap::read_fap_file(
        std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/samples/speech.fap")),
        &crate::fap::ReadOptions::strict(),
    )
    .unwrap()
    .0;
    let mut player = Player::new(face, &stream, &PlayOptions::default()).unwrap();
    let mut frame = PlayerFrame::default();
    assert!(player.next_frame(&mut frame));
    let ptrs = |f: &PlayerFrame| {
        let mut v: Vec<(usize, usize)> = f
            .pose
            .positions
            .iter()
            .map(|p| (p.as_ptr() as usize, p.capacity()))
            .collect();
        v.push((
            f.pose.positions.as_ptr() as usize,
            f.pose.positions.capacity(),
        ));
        v.push((f.pose.transform_locals.as_ptr() as usize, 0));
        v.push((f.transform_deltas.as_ptr() as usize, 0));
        v.push((
            f.pose.world.transforms.as_ptr() as usize,
            f.pose.world.transforms.capacity(),
        ));
        v.push((
            f.pose.world.meshes.as_ptr() as usize,
            f.pose.world.meshes.capacity(),
        ));
        v.push((f.activations.as_ptr() as usize, f.activations.capacity()));
        v
    };
    let before = ptrs(&frame);
    let mut count = 1;
    let mut moved = false;
    while player.next_frame(&mut frame) {
        assert_eq!(ptrs(&frame), before, "frame {}", frame.index);
        moved |= frame.pose.positions[0] != face.meshes[0].mesh.positions;
        count += 1;
    }
    assert_eq!(count, player.frame_count());
    assert!(moved, "speech must move the skin");
}

#[test]
fn world_positions_match_face_frames_at_neutral() {
    let face = alma();
    let mut player = Player::new(
        face,
        &stream_of(vec![FapFrame::new(0)]),
        &PlayOptions::default(),
    )
    .unwrap();
    let mut frame = player.new_frame();
    player.next_frame(&mut frame);
    let frames = face.frames();
    let mut world = Vec::new();
    frame.pose.world_positions_into(&mut world);
    for (mi, m) in face.meshes.iter().enumerate() {
        assert_eq!(frame.pose.positions[mi], m.mesh.positions);
        let v = m.mesh.vertex_count() as u32 / 2;
        assert_eq!(
            Some(world[mi][v as usize]),
            face.vertex_world(&frames, mi, v)
        );
    }
}

#[test]
fn animation_frames_match_played_frames() {
    let face = alma();
    let mut a = FapFrame::new(0);
    a.set(FapId::new(48).unwrap(), 10_000.0);
    a.set(FapId::OPEN_JAW, 300.0);
    let mut b = FapFrame::new(4);
    b.set(FapId::new(50).unwrap(), -8_000.0);
    let stream = stream_of(vec![a, b]);
    let mut player = Player::new(face, &stream, &PlayOptions::default()).unwrap();
    let anim = player.animation().unwrap();
    assert_eq!(anim.len(), 5);
    let mut frame = player.new_frame();
    let mut i = 0;
    while player.next_frame(&mut frame) {
        assert_eq!(anim[i], frame.animation_frame());
        i += 1;
    }
}
