//! Eyeballs on their own glTF nodes (issue 19 §1–2): cloned onto an avatar whose eyes are the
//! nodes `LeftEye` and `RightEye` (under a turned `Eyes` node on the `Head` joint), the eye
//! motion (FAPs 23–26) is not baked into morph targets: the patched glb records it as motion
//! of those nodes, reads back with the same FAT, and `play` turns the nodes — never a
//! rotation and a morph for one motion. Eyeballs skinned to eye joints (`LeftEye`,
//! `RightEye` under `Head`, ReadyPlayerMe style) turn those joints the same way; a partly
//! weighted eyeball stays in morph targets with a warning. Both eyeballs in one primitive of
//! the skinned body (VRM / VRoid), each on its own eye joint, turn those joints by the turn
//! fitted to the cloner's per-vertex rows (`nodeParts`); partly weighted, they stay baked
//! with a warning. So do VRoid's eyes, whose irises and highlights are more primitives (or a
//! mesh of their own) on the same joints: each joint turns its eye over all of them. The head rotations are recorded on
//! the `Head` joint and read back. The jaw joint takes `open_jaw` in play with every
//! `open_jaw` target held at zero. VRML and new-document outputs keep the eye motion.

mod support;

use std::path::{Path, PathBuf};

use fbakit::clone::face::{clone_face, CloneOptions};
use fbakit::face::{FaceModel, FaceReadOptions};
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::snapshot::{diff, DiffOptions};
use fbakit::spec::{FapId, FeaturePointId};
use glam::{Mat4, Quat, Vec3};
use serde_json::Value;
use support::avatar::{
    self, same_fat_head_on_node, Options, VroidEyes, LEFT_EYE_JOINT, LEFT_EYE_MESH_NODE,
    LEFT_EYE_NODE, RIGHT_EYE_JOINT, RIGHT_EYE_MESH_NODE, RIGHT_EYE_NODE,
};
use support::glb::floats;

const JAW_NODE: usize = 4;
const HEAD_NODE: usize = 3;

fn key(fap: u8) -> TableKey {
    TableKey::LowLevel(FapId::new(fap).unwrap())
}

/// The avatar with eye nodes (and both teeth rows in one primitive) in `dir`, and its
/// feature points.
fn write_avatar(dir: &Path, source: &FaceModel) -> (PathBuf, PathBuf) {
    write_avatar_with(
        dir,
        source,
        &Options {
            teeth: true,
            eye_nodes: true,
            ..Options::default()
        },
    )
}

/// The avatar with `opts` in `dir`, and its feature points (teeth points with the teeth).
fn write_avatar_with(dir: &Path, source: &FaceModel, opts: &Options) -> (PathBuf, PathBuf) {
    let glb = dir.join("avatar.glb");
    std::fs::write(&glb, avatar::build_with(opts).to_glb()).unwrap();
    let teeth = if opts.teeth {
        avatar::teeth_fp_lines()
    } else {
        String::new()
    };
    let csv = avatar::fp_csv(source, dir, &teeth);
    (glb, csv)
}

fn run(args: &[&std::ffi::OsStr]) {
    let o = support::cli::command().args(args).output().unwrap();
    assert!(o.status.success(), "{}", support::cli::text(&o.stderr));
}

fn clone_to(glb: &Path, csv: &Path, out: &Path, more: &[&str]) {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "clone".as_ref(),
        "alma".as_ref(),
        glb.as_os_str(),
        "--fp-target".as_ref(),
        csv.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ];
    args.extend(more.iter().map(std::ffi::OsStr::new));
    run(&args);
}

/// The JSON chunk and the BIN chunk of a glb.
fn glb_parts(p: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(p).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    let json = serde_json::from_slice(chunks.json).unwrap();
    (json, chunks.bin.unwrap_or_default().to_vec())
}

/// A stream of FAPs 23–26 only: per frame (yaw_l, yaw_r, pitch_l, pitch_r).
const GAZE: [[i32; 4]; 5] = [
    [0, 0, 0, 0],
    [20000, 20000, 0, 0],
    [-15000, -12000, 0, 0],
    [0, 0, 12000, 9000],
    [10000, -8000, -9000, 7000],
];

fn write_gaze(dir: &Path) -> PathBuf {
    let mut text = format!("2.1 gaze 25 {}\n", GAZE.len());
    let mask: Vec<&str> = (1..=68)
        .map(|f| if (23..=26).contains(&f) { "1" } else { "0" })
        .collect();
    for (i, v) in GAZE.iter().enumerate() {
        text.push_str(&mask.join(" "));
        text.push('\n');
        text.push_str(&format!("{i} {} {} {} {}\n", v[0], v[1], v[2], v[3]));
    }
    let path = dir.join("gaze.fap");
    std::fs::write(&path, text).unwrap();
    path
}

fn gaze_activations(v: &[i32; 4]) -> Vec<Activation> {
    [23u8, 24, 25, 26]
        .iter()
        .zip(v)
        .map(|(&f, &x)| Activation {
            key: key(f),
            value: f64::from(x),
        })
        .collect()
}

/// World matrix of node `n` at rest, and with `local` overrides (rotation, translation).
fn node_world(
    json: &Value,
    n: usize,
    over: &dyn Fn(usize) -> Option<(Quat, Option<Vec3>)>,
) -> Mat4 {
    let nodes = json["nodes"].as_array().unwrap();
    let parent = |i: usize| {
        nodes.iter().position(|p| {
            p["children"]
                .as_array()
                .is_some_and(|c| c.iter().any(|c| c.as_u64() == Some(i as u64)))
        })
    };
    let v3 = |v: &Value, d: Vec3| {
        v.as_array().map_or(d, |a| {
            Vec3::new(
                a[0].as_f64().unwrap() as f32,
                a[1].as_f64().unwrap() as f32,
                a[2].as_f64().unwrap() as f32,
            )
        })
    };
    let local = |i: usize| {
        let node = &nodes[i];
        let mut r = node["rotation"].as_array().map_or(Quat::IDENTITY, |a| {
            let f = |k: usize| a[k].as_f64().unwrap() as f32;
            Quat::from_xyzw(f(0), f(1), f(2), f(3))
        });
        let mut t = v3(&node["translation"], Vec3::ZERO);
        if let Some((q, tr)) = over(i) {
            r = q;
            if let Some(tr) = tr {
                t = tr;
            }
        }
        Mat4::from_scale_rotation_translation(v3(&node["scale"], Vec3::ONE), r, t)
    };
    let mut m = local(n);
    let mut at = parent(n);
    while let Some(p) = at {
        m = local(p) * m;
        at = parent(p);
    }
    m
}

/// The eye's centre at rest: the bounding-box centre of the mesh holding `pupil`.
fn centre(face: &FaceModel, neutral: &[Vec<Vec3>], pupil: FeaturePointId) -> Vec3 {
    let (m, _) = face.fp_vertex(pupil).unwrap();
    let p = &neutral[m];
    let lo = p.iter().fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b));
    let hi = p
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
    (lo + hi) / 2.0
}

/// The eye's front: its pupil seen from its rest centre.
fn front(face: &FaceModel, posed: &[Vec<Vec3>], pupil: FeaturePointId, centre: Vec3) -> Vec3 {
    let (m, v) = face.fp_vertex(pupil).unwrap();
    (posed[m][v as usize] - centre).normalize()
}

#[test]
fn eye_nodes_turn_instead_of_morph_targets() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(d, &source);
    let out = d.join("out.glb");
    clone_to(&glb, &csv, &out, &[]);
    let (patched, _) = glb_parts(&out);

    // The eye meshes get no morph target; no mesh has an eyeball target.
    for m in [2, 3] {
        assert!(
            patched["meshes"][m]["primitives"][0]
                .get("targets")
                .is_none(),
            "{}",
            patched["meshes"][m]
        );
    }
    let names = patched["meshes"][0]["extras"]["targetNames"].to_string();
    assert!(!names.contains("eyeball"), "{names}");
    // The scene record says the eye nodes show the eyes' transforms and carries their motion.
    let record = &patched["scenes"][0]["extras"]["fbakit"];
    for node in [LEFT_EYE_NODE, RIGHT_EYE_NODE] {
        let t = record["transforms"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["node"] == node)
            .unwrap_or_else(|| panic!("no transform on node {node}: {}", record["transforms"]));
        assert_eq!(t["userNode"], true, "{t}");
    }
    let tables = record["transformTables"].to_string();
    for name in [
        "yaw_l_eyeball",
        "yaw_r_eyeball",
        "pitch_l_eyeball",
        "pitch_r_eyeball",
    ] {
        assert!(tables.contains(name), "{name}: {tables}");
    }

    check_eyes_round_trip_and_play(
        d,
        (&glb, &csv, &out),
        &source,
        (LEFT_EYE_NODE, RIGHT_EYE_NODE),
    );
}

/// Eyeballs skinned to eye joints (their own meshes, every vertex weighted to `LeftEye` or
/// `RightEye` under `Head`, the joints' rest frames turned away from the face's): no morph
/// target moves them, the joints show their transforms (recorded, read back with the same
/// FAT) and `play` turns the joints as the FAT turns the eyes.
#[test]
fn skinned_eyes_turn_their_eye_joints() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let opts = Options {
        skinned_eyes: Some(1.0),
        ..Options::default()
    };
    let (glb, csv) = write_avatar_with(d, &source, &opts);
    let out = d.join("out.glb");
    let o = support::cli::command()
        .args(["clone".as_ref(), "alma".as_ref(), glb.as_os_str()])
        .args(["--fp-target".as_ref(), csv.as_os_str(), "-o".as_ref()])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(!stderr.contains("eye node"), "{stderr}");
    let (patched, _) = glb_parts(&out);
    // The eye meshes get no morph target, `Body` no eyeball target.
    for m in [2, 3] {
        assert_eq!(
            patched["nodes"][[LEFT_EYE_MESH_NODE, RIGHT_EYE_MESH_NODE][m - 2]]["mesh"],
            m
        );
        assert!(
            patched["meshes"][m]["primitives"][0]
                .get("targets")
                .is_none(),
            "{}",
            patched["meshes"][m]
        );
    }
    let names = patched["meshes"][0]["extras"]["targetNames"].to_string();
    assert!(!names.contains("eyeball"), "{names}");
    let record = &patched["scenes"][0]["extras"]["fbakit"];
    for node in [LEFT_EYE_JOINT, RIGHT_EYE_JOINT] {
        let t = record["transforms"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["node"] == node)
            .unwrap_or_else(|| panic!("no transform on joint {node}: {}", record["transforms"]));
        assert_eq!(t["userNode"], true, "{t}");
    }
    check_eyes_round_trip_and_play(
        d,
        (&glb, &csv, &out),
        &source,
        (LEFT_EYE_JOINT, RIGHT_EYE_JOINT),
    );
}

/// An eyeball weighted to its eye joint by 60 % only (the rest to `Head`) cannot be turned by
/// the joint: its motion stays in morph targets, with one warning per joint naming it and why.
#[test]
fn a_partly_weighted_eyeball_stays_in_morph_targets_and_is_said_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let opts = Options {
        skinned_eyes: Some(0.6),
        ..Options::default()
    };
    let (glb, csv) = write_avatar_with(d, &source, &opts);
    let out = d.join("out.glb");
    let o = support::cli::command()
        .args(["clone".as_ref(), "alma".as_ref(), glb.as_os_str()])
        .args(["--fp-target".as_ref(), csv.as_os_str(), "-o".as_ref()])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    for joint in ["LeftEye", "RightEye"] {
        let said = format!("eye node `{joint}` is not turned (mesh ");
        assert_eq!(stderr.matches(&said).count(), 1, "{joint}: {stderr}");
    }
    assert!(stderr.contains("by 60 % only"), "{stderr}");
    let (patched, _) = glb_parts(&out);
    for (m, name) in [(2, "yaw_l_eyeball"), (3, "yaw_r_eyeball")] {
        let names = patched["meshes"][m]["extras"]["targetNames"].to_string();
        assert!(names.contains(name), "{names}");
    }
    let transforms = &patched["scenes"][0]["extras"]["fbakit"]["transforms"];
    assert!(
        !transforms
            .as_array()
            .unwrap()
            .iter()
            .any(|t| t["node"] == LEFT_EYE_JOINT || t["node"] == RIGHT_EYE_JOINT),
        "{transforms}"
    );
}

/// The head rotations (48–50) are recorded on the `Head` joint, read back, and played there:
/// the nose tip moves as the FAT read back from the written file moves it.
#[test]
fn head_rotations_are_recorded_on_the_head_node_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(d, &source);
    let out = d.join("out.glb");
    clone_to(&glb, &csv, &out, &[]);
    let (patched, _) = glb_parts(&out);
    let record = &patched["scenes"][0]["extras"]["fbakit"];
    let head = record["transforms"]
        .as_array()
        .unwrap()
        .iter()
        .position(|t| t["node"] == HEAD_NODE)
        .unwrap_or_else(|| panic!("no transform on Head: {}", record["transforms"]));
    assert_eq!(record["transforms"][head]["userNode"], true);
    let tables = record["transformTables"].to_string();
    for name in ["head_pitch", "head_yaw", "head_roll"] {
        assert!(tables.contains(name), "{name}: {tables}");
    }
    let names = patched["meshes"][0]["extras"]["targetNames"].to_string();
    assert!(!names.contains("head_"), "{names}");
    let back = fbakit::face::read(&out).unwrap();
    for fap in [48u8, 49, 50] {
        assert!(
            back.fat
                .tables
                .iter()
                .any(|t| t.key == key(fap) && !t.transforms.is_empty()),
            "FAP {fap} not read back"
        );
    }

    // Played from the written file alone: the `Head` joint turns the nose tip as the FAT does.
    let values = [
        [0, 0, 0],
        [15000, 0, 0],
        [0, 20000, 0],
        [0, 0, -18000],
        [8000, -9000, 7000],
    ];
    let mut text = format!("2.1 head 25 {}\n", values.len());
    let mask: Vec<&str> = (1..=68)
        .map(|f| if (48..=50).contains(&f) { "1" } else { "0" })
        .collect();
    for (i, v) in values.iter().enumerate() {
        text.push_str(&mask.join(" "));
        text.push_str(&format!("\n{i} {} {} {}\n", v[0], v[1], v[2]));
    }
    let stream = d.join("head.fap");
    std::fs::write(&stream, text).unwrap();
    let played = d.join("played.glb");
    run(&[
        "play".as_ref(),
        out.as_os_str(),
        stream.as_os_str(),
        "-o".as_ref(),
        played.as_os_str(),
    ]);
    let (pj, bin) = glb_parts(&played);
    let play = support::glb::play_animation(&pj);
    let channel = |path: &str| {
        play["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["node"] == HEAD_NODE && c["target"]["path"] == path)
            .map(|c| {
                let s = &play["samplers"][c["sampler"].as_u64().unwrap() as usize];
                floats(&pj, &bin, s["output"].as_u64().unwrap() as usize)
            })
    };
    let rot = channel("rotation").expect("Head turns");
    let tr = channel("translation");
    let rest_world = node_world(&pj, HEAD_NODE, &|_| None);
    let (m, v) = back.fp_vertex(FeaturePointId::FP_9_3).unwrap();
    let nose = back.neutral_world_positions()[m][v as usize];
    for (k, vals) in values.iter().enumerate() {
        let q = Quat::from_slice(&rot[4 * k..4 * k + 4]);
        let t = tr.as_ref().map(|t| Vec3::from_slice(&t[3 * k..3 * k + 3]));
        let world = node_world(&pj, HEAD_NODE, &|i| (i == HEAD_NODE).then_some((q, t)));
        let got = (world * rest_world.inverse()).transform_point3(nose);
        let a: Vec<Activation> = [48u8, 49, 50]
            .iter()
            .zip(vals)
            .map(|(&f, &x)| Activation {
                key: key(f),
                value: f64::from(x),
            })
            .collect();
        let want = back.pose(&a).unwrap()[m][v as usize];
        let moved = want.distance(nose);
        eprintln!("frame {k}: played nose {got}, FAT {want} (moved {moved})");
        assert!(
            got.distance(want) <= 0.01 * moved + 1e-5,
            "frame {k}: played {got}, FAT {want}"
        );
    }
    // Head yaw alone (frame 2) turns the nose to the face's left (+x) as the standard's
    // direction says for a positive value.
    let yaw_axis = FapId::new(49).unwrap().info().rotation_axis().unwrap();
    let q = Quat::from_slice(&rot[8..12]);
    let t = tr.as_ref().map(|t| Vec3::from_slice(&t[6..9]));
    let world = node_world(&pj, HEAD_NODE, &|i| (i == HEAD_NODE).then_some((q, t)));
    let got = (world * rest_world.inverse()).transform_point3(nose);
    let standard = Quat::from_axis_angle(yaw_axis, 0.2) * Vec3::Z;
    assert_eq!(
        (got.x - nose.x).signum(),
        standard.x.signum(),
        "{got} {nose}"
    );
}

/// The clone `out` of `source` onto the avatar `glb` (feature points `csv`) reads back with
/// the clone's FAT; played with a gaze stream, eye nodes `left` and `right` turn each eyeball
/// as the FAT does (within 1 %, in the standard's directions) and no weights are keyed on
/// them; the files add no validator issue.
fn check_eyes_round_trip_and_play(
    d: &Path,
    (glb, csv, out): (&Path, &Path, &Path),
    source: &FaceModel,
    (left, right): (usize, usize),
) {
    // Read back: the same FAT as the clone's, the eye turns the eye nodes take included. The
    // clone turns this face's head per vertex (it has no head transform and gets none); the
    // written file turns it on the `Head` node instead, one rotation per head FAP.
    let target = fbakit::face::read_with(glb, &FaceReadOptions::with_feature_points(Some(csv)))
        .unwrap()
        .0;
    let cloned = clone_face(source, &target, &CloneOptions::default())
        .unwrap()
        .face;
    let back = fbakit::face::read(out).unwrap();
    let report = same_fat_head_on_node(&cloned, &back);
    assert!(report.equal, "{report}");

    // Play a gaze stream: both eye nodes turn, no weight is keyed for eyeball targets.
    let gaze = write_gaze(d);
    let played = d.join("played.glb");
    run(&[
        "play".as_ref(),
        out.as_os_str(),
        gaze.as_os_str(),
        "-o".as_ref(),
        played.as_os_str(),
    ]);
    let (pj, bin) = glb_parts(&played);
    let play = support::glb::play_animation(&pj);
    let channel = |node: usize, path: &str| {
        play["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["node"] == node && c["target"]["path"] == path)
            .map(|c| {
                let s = &play["samplers"][c["sampler"].as_u64().unwrap() as usize];
                floats(&pj, &bin, s["output"].as_u64().unwrap() as usize)
            })
    };
    let eyes = [
        (left, FeaturePointId::FP_3_5, 0usize, 2usize),
        (right, FeaturePointId::FP_3_6, 1, 3),
    ];
    for (node, pupil, yaw, pitch) in eyes {
        let rot = channel(node, "rotation").unwrap_or_else(|| panic!("node {node} not turned"));
        let tr = channel(node, "translation");
        assert!(rot.len() >= 4 * GAZE.len());
        let rest_world = node_world(&pj, node, &|_| None);
        // The eye's centre in the node's frame: the pupil's mesh's bounding-box centre.
        let neutral = back.neutral_world_positions();
        let c = centre(&back, &neutral, pupil);
        let rest_front = front(&back, &neutral, pupil, c);
        for (k, v) in GAZE.iter().enumerate() {
            let q = Quat::from_slice(&rot[4 * k..4 * k + 4]);
            let t = tr.as_ref().map(|t| Vec3::from_slice(&t[3 * k..3 * k + 3]));
            let world = node_world(&pj, node, &|i| (i == node).then_some((q, t)));
            // Played: the node's motion applied to the eye's rest positions (file = face frame;
            // a skinned eyeball is placed by its joint's world matrix times its inverse bind
            // matrix, so it moves with the joint's world matrix as a child mesh does).
            let (m, _) = back.fp_vertex(pupil).unwrap();
            let motion = world * rest_world.inverse();
            let played_pos: Vec<Vec3> = neutral[m]
                .iter()
                .map(|&p| motion.transform_point3(p))
                .collect();
            let mut posed_played = neutral.clone();
            posed_played[m] = played_pos;
            let got = front(&back, &posed_played, pupil, c);
            // The FAT's own eye turn (the face read back, posed).
            let want = front(&back, &back.pose(&gaze_activations(v)).unwrap(), pupil, c);
            let angle = rest_front.angle_between(want);
            eprintln!(
                "node {node} frame {k}: played front {got}, FAT front {want} ({angle} rad turn)"
            );
            assert!(
                got.distance(want) <= 0.01 * angle.max(1e-3) + 1e-4,
                "frame {k}: played {got}, FAT {want}"
            );
            // The standard's directions: positive yaw turns the gaze to the face's left
            // (+x), positive pitch down (−y); the played turn has the FAT's angle.
            let (y, p) = (f64::from(v[yaw]) * 1e-5, f64::from(v[pitch]) * 1e-5);
            if y != 0.0 {
                assert_eq!(
                    (got.x - rest_front.x).signum(),
                    y.signum() as f32,
                    "frame {k}"
                );
            }
            if p != 0.0 {
                assert_eq!(
                    (got.y - rest_front.y).signum(),
                    -p.signum() as f32,
                    "frame {k}"
                );
            }
            if y == 0.0 || p == 0.0 {
                let turn = Quat::from_rotation_y(y as f32) * Quat::from_rotation_x(p as f32);
                let standard = (turn * rest_front).normalize();
                assert!(
                    got.distance(standard) < 0.01 * angle + 1e-4,
                    "frame {k}: played {got}, the standard's turn {standard}"
                );
            }
        }
    }
    // No morph weights for eyeball motion: no weights channel drives an eye mesh, and the
    // eye meshes' nodes are not keyed by weights.
    for node in [left, right] {
        assert!(channel(node, "weights").is_none());
    }

    // No new validator issue.
    let files = [glb.to_path_buf(), out.to_path_buf(), played.clone()];
    let Some(reports) = support::validator::validate(&files) else {
        return;
    };
    let issues = |r: &Value| (r["errors"].clone(), r["warnings"].clone());
    assert_eq!(issues(&reports[0]), issues(&reports[1]), "{}", reports[1]);
    assert_eq!(issues(&reports[0]), issues(&reports[2]), "{}", reports[2]);
}

/// The jaw joint takes `open_jaw` in play: it turns, and every `open_jaw` target (the lower
/// teeth's included) stays at weight zero, so the teeth do not move twice.
#[test]
fn the_jaw_joint_and_open_jaw_targets_never_both_move() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(d, &source);
    let out = d.join("out.glb");
    clone_to(&glb, &csv, &out, &[]);
    let (patched, _) = glb_parts(&out);
    let names: Vec<String> = patched["meshes"][0]["extras"]["targetNames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap().to_string())
        .collect();
    let jaw_targets: Vec<usize> = names
        .iter()
        .enumerate()
        .filter(|(_, n)| n.starts_with("open_jaw"))
        .map(|(i, _)| i)
        .collect();
    assert!(!jaw_targets.is_empty(), "{names:?}");
    let played = d.join("played.glb");
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap");
    // Named: the avatar's `Jaw` carries its mouth but not the chin, so found by its name
    // alone it would leave the jaw FAPs to the morph targets.
    run(&[
        "play".as_ref(),
        out.as_os_str(),
        sample.as_os_str(),
        "--jaw-node".as_ref(),
        "Jaw".as_ref(),
        "-o".as_ref(),
        played.as_os_str(),
    ]);
    let (pj, bin) = glb_parts(&played);
    let play = pj["animations"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == "play")
        .unwrap();
    let output_of = |node: usize, path: &str| {
        play["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["node"] == node && c["target"]["path"] == path)
            .map(|c| {
                let s = &play["samplers"][c["sampler"].as_u64().unwrap() as usize];
                floats(&pj, &bin, s["output"].as_u64().unwrap() as usize)
            })
    };
    let rot = output_of(JAW_NODE, "rotation").expect("the jaw joint turns");
    let turned = rot
        .chunks(4)
        .map(|q| Quat::from_slice(q).angle_between(Quat::from_slice(&rot[..4])))
        .fold(0.0, f32::max);
    assert!(turned > 0.01, "the jaw turns at most {turned} rad");
    let weights = output_of(5, "weights").expect("Body's weights are keyed");
    let total = names.len();
    assert_eq!(weights.len() % total, 0);
    for (k, frame) in weights.chunks(total).enumerate() {
        for &i in &jaw_targets {
            assert_eq!(frame[i], 0.0, "frame {k}: {} at {}", names[i], frame[i]);
        }
    }
}

/// Cloned to VRML or to a new glb, the eyes are transforms (nodes of fbakit's own) and turn.
#[test]
fn vrml_and_new_documents_keep_the_eye_motion() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(d, &source);
    let wrl = d.join("out.wrl");
    clone_to(&glb, &csv, &wrl, &[]);
    let new = d.join("new.glb");
    clone_to(&glb, &csv, &new, &["--new-document"]);
    for out in [wrl, new] {
        let face = fbakit::face::read(&out).unwrap();
        let neutral = face.neutral_world_positions();
        for (pupil, fap, other) in [
            (FeaturePointId::FP_3_5, 23u8, FeaturePointId::FP_3_6),
            (FeaturePointId::FP_3_6, 24, FeaturePointId::FP_3_5),
        ] {
            let posed = face
                .pose(&[Activation {
                    key: key(fap),
                    value: 20000.0,
                }])
                .unwrap();
            let c = centre(&face, &neutral, pupil);
            let (before, after) = (
                front(&face, &neutral, pupil, c),
                front(&face, &posed, pupil, c),
            );
            let want = (Quat::from_rotation_y(0.2) * before).normalize();
            assert!(
                after.distance(want) < 0.01 * 0.2,
                "{}: FAP {fap} turns the eye to {after}, not {want}",
                out.display()
            );
            let (m, _) = face.fp_vertex(other).unwrap();
            assert!(
                neutral[m]
                    .iter()
                    .zip(&posed[m])
                    .all(|(a, b)| a.distance(*b) < 1e-6),
                "{}: FAP {fap} moves the other eye",
                out.display()
            );
        }
    }
}

/// A node named as an eye whose mesh is no eyeball (the hat: no pupil on it) is not used,
/// with a warning; the other eye node still turns its eye, and the unused eye's motion stays
/// in morph targets of its mesh.
#[test]
fn an_eye_node_without_its_eyeball_is_not_used_and_said_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(d, &source);
    let out = d.join("out.glb");
    let o = support::cli::command()
        .args(["clone".as_ref(), "alma".as_ref(), glb.as_os_str()])
        .args(["--fp-target".as_ref(), csv.as_os_str()])
        .args(["--eye-nodes", "Hat,RightEye", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("eye node `Hat` is not turned (its mesh holds no pupil 3.5)"),
        "{stderr}"
    );
    assert!(!stderr.contains("RightEye"), "{stderr}");
    let (patched, _) = glb_parts(&out);
    let transforms = patched["scenes"][0]["extras"]["fbakit"]["transforms"].clone();
    let on = |node: usize| {
        transforms
            .as_array()
            .unwrap()
            .iter()
            .any(|t| t["node"] == node && t["userNode"] == true)
    };
    assert!(
        on(RIGHT_EYE_NODE) && !on(LEFT_EYE_NODE) && !on(6),
        "{transforms}"
    );
    let left_targets = patched["meshes"][2]["extras"]["targetNames"].to_string();
    assert!(left_targets.contains("yaw_l_eyeball"), "{left_targets}");
    assert!(patched["meshes"][3]["primitives"][0]
        .get("targets")
        .is_none());
}

/// `face export` takes the node options as `clone` does: a face read back from a patched
/// avatar, exported with `--head-node Neck`, shows its head rotations on `Neck` as a clone
/// with that option does (and on `Head` without it); `--eye-nodes Hat,RightEye` warns about
/// the hat as the clone does.
#[test]
fn face_export_takes_the_node_options_as_clone_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(d, &source);
    let out = d.join("out.glb");
    clone_to(&glb, &csv, &out, &[]);
    let cloned = d.join("cloned-neck.glb");
    clone_to(&glb, &csv, &cloned, &["--head-node", "Neck"]);
    let export = |name: &str, more: &[&str]| {
        let path = d.join(name);
        let o = support::cli::command()
            .args([
                "face".as_ref(),
                "export".as_ref(),
                out.as_os_str(),
                "-o".as_ref(),
            ])
            .arg(&path)
            .args(more)
            .output()
            .unwrap();
        let stderr = support::cli::text(&o.stderr);
        assert!(o.status.success(), "{stderr}");
        (path, stderr)
    };
    let (neck, _) = export("neck.glb", &["--head-node", "Neck"]);
    let (plain, _) = export("plain.glb", &[]);
    // Per transform name, its node and whether it is the user's.
    let shown = |p: &Path| {
        let (json, _) = glb_parts(p);
        let mut list: Vec<(String, Value, Value)> = json["scenes"][0]["extras"]["fbakit"]
            ["transforms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| {
                (
                    t["name"].as_str().unwrap().to_string(),
                    t["node"].clone(),
                    t["userNode"].clone(),
                )
            })
            .collect();
        list.sort_by(|a, b| a.0.cmp(&b.0));
        list
    };
    let on_neck = shown(&neck);
    assert_eq!(on_neck, shown(&cloned));
    assert!(
        on_neck.iter().any(|(_, n, u)| *n == 2 && *u == true),
        "{on_neck:?}"
    );
    let on_head = shown(&plain);
    assert_eq!(on_head, shown(&out));
    assert!(
        on_head
            .iter()
            .any(|(_, n, u)| *n == HEAD_NODE && *u == true),
        "{on_head:?}"
    );
    let (_, stderr) = export("hat.glb", &["--eye-nodes", "Hat,RightEye"]);
    assert!(
        stderr.contains("eye node `Hat` is not turned (its mesh holds no pupil 3.5)"),
        "{stderr}"
    );
}

/// An eye joint that also moves the skin (here `Head` named as the left eye: the face's skin
/// is weighted to it) does not turn the left eyeball: a warning says so, the left eye's
/// motion stays in morph targets, and the right eye joint still turns its eyeball.
#[test]
fn an_eye_joint_that_moves_skin_too_is_not_used() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let opts = Options {
        skinned_eyes: Some(1.0),
        ..Options::default()
    };
    let (glb, csv) = write_avatar_with(d, &source, &opts);
    let out = d.join("out.glb");
    let o = support::cli::command()
        .args(["clone".as_ref(), "alma".as_ref(), glb.as_os_str()])
        .args(["--fp-target".as_ref(), csv.as_os_str()])
        .args(["--eye-nodes", "Head,RightEye", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("eye node `Head` is not turned (its mesh carries skin"),
        "{stderr}"
    );
    assert!(!stderr.contains("RightEye"), "{stderr}");
    let (patched, _) = glb_parts(&out);
    let names = patched["meshes"][2]["extras"]["targetNames"].to_string();
    assert!(names.contains("yaw_l_eyeball"), "{names}");
    assert!(patched["meshes"][3]["primitives"][0]
        .get("targets")
        .is_none());
    let transforms = &patched["scenes"][0]["extras"]["fbakit"]["transforms"];
    assert!(
        transforms
            .as_array()
            .unwrap()
            .iter()
            .any(|t| t["node"] == RIGHT_EYE_JOINT && t["userNode"] == true),
        "{transforms}"
    );
}

/// The avatar with `opts` (an eye layout on the two eye joints), cloned from alma into `d`:
/// the glb and csv written, the output path and the clone's stderr.
fn clone_eyes_with(
    d: &Path,
    source: &FaceModel,
    opts: &Options,
) -> (PathBuf, PathBuf, PathBuf, String) {
    let (glb, csv) = write_avatar_with(d, source, opts);
    let out = d.join("out.glb");
    let o = support::cli::command()
        .args(["clone".as_ref(), "alma".as_ref(), glb.as_os_str()])
        .args(["--fp-target".as_ref(), csv.as_os_str(), "-o".as_ref()])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    (glb, csv, out, stderr)
}

/// The eyes' turn FAPs (23–26) as table names.
const TURNS: [&str; 4] = [
    "yaw_l_eyeball",
    "yaw_r_eyeball",
    "pitch_l_eyeball",
    "pitch_r_eyeball",
];

/// Every mesh's target names in a document.
fn all_target_names(json: &Value) -> String {
    json["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["extras"]["targetNames"].to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Eyeballs weighted wholly to their eye joints, their vertices in the face meshes
/// `eye_meshes` (each holding both eyes): cloned from alma, the joints show the eyes' turns.
/// No mesh has a target for the turns (every row of every eyeball mesh left them), the scene
/// record lists each eyeball as a part its joint turns (`nodeParts`) over all of
/// `eye_meshes`, the glb reads back with the clone's FAT (`face diff` equal), and `play`
/// turns the joints so that the eyeballs posed by them (joint world × inverse bind, i.e. the
/// joint's motion applied to the rest vertices) land where the FAT read back puts them
/// within 1 % of the eyeball's size (2.4 cm across: the joint composes yaw and pitch where
/// the FAT adds their displacements, 0.5 % at the stream's 0.13 rad mixed frame). The files
/// add no validator issue, and three.js and Blender load the played one with its `play` clip.
fn check_eye_joints_turn(opts: &Options, eye_meshes: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv, out, stderr) = clone_eyes_with(d, &source, opts);
    assert!(!stderr.contains("eye node"), "{stderr}");
    let (patched, _) = glb_parts(&out);
    // No target for the turns (23–26); the thrusts (27, 28) stay targets.
    let names = all_target_names(&patched);
    assert!(!TURNS.iter().any(|t| names.contains(t)), "{names}");
    let record = &patched["scenes"][0]["extras"]["fbakit"];
    let parts = record["nodeParts"].as_array().expect("nodeParts");
    assert_eq!(parts.len(), 2, "{}", record["nodeParts"]);
    let part_of = |node: usize| {
        parts
            .iter()
            .find(|p| p["node"] == node)
            .unwrap_or_else(|| panic!("no part on joint {node}"))
    };
    for (node, keys) in [
        (LEFT_EYE_JOINT, ["yaw_l_eyeball", "pitch_l_eyeball"]),
        (RIGHT_EYE_JOINT, ["yaw_r_eyeball", "pitch_r_eyeball"]),
    ] {
        let p = part_of(node);
        assert_eq!(p["userNode"], true);
        let tables = p["tables"].to_string();
        for k in keys {
            assert!(tables.contains(k), "{k}: {tables}");
        }
        let meshes: Vec<&str> = p["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["mesh"].as_str().unwrap())
            .collect();
        assert_eq!(meshes, eye_meshes, "joint {node}");
    }

    // Read back: the clone's FAT.
    let target = fbakit::face::read_with(&glb, &FaceReadOptions::with_feature_points(Some(&csv)))
        .unwrap()
        .0;
    let cloned = clone_face(&source, &target, &CloneOptions::default())
        .unwrap()
        .face;
    let back = fbakit::face::read(&out).unwrap();
    let report = same_fat_head_on_node(&cloned, &back);
    assert!(report.equal, "{report}");
    if let [_] = eye_meshes {
        // A file of the first schema (one `mesh` and its `vertices` on each entry) reads the
        // same.
        let (mut json, bin) = glb_parts(&out);
        for p in json["scenes"][0]["extras"]["fbakit"]["nodeParts"]
            .as_array_mut()
            .unwrap()
        {
            let m = p["meshes"][0].clone();
            let p = p.as_object_mut().unwrap();
            p.remove("meshes");
            p.insert("mesh".into(), m["mesh"].clone());
            p.insert("vertices".into(), m["vertices"].clone());
        }
        let old = d.join("old-schema.glb");
        let glb = avatar::Avatar {
            json,
            bin,
            prims: Vec::new(),
        }
        .to_glb();
        std::fs::write(&old, glb).unwrap();
        let report = diff(
            &back,
            &fbakit::face::read(&old).unwrap(),
            &DiffOptions::default(),
        );
        assert!(report.equal, "{report}");
    }

    // Play a gaze stream: the joints turn the eyeballs where the FAT puts them.
    let gaze = write_gaze(d);
    let played = d.join("played.glb");
    let o = support::cli::command()
        .args([
            "play".as_ref(),
            out.as_os_str(),
            gaze.as_os_str(),
            "-o".as_ref(),
        ])
        .arg(&played)
        .output()
        .unwrap();
    let play_err = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{play_err}");
    assert!(!play_err.contains("eye node"), "{play_err}");
    let (pj, bin) = glb_parts(&played);
    let names = all_target_names(&pj);
    assert!(!TURNS.iter().any(|t| names.contains(t)), "{names}");
    let play = support::glb::play_animation(&pj);
    let channel = |node: usize, path: &str| {
        play["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["node"] == node && c["target"]["path"] == path)
            .map(|c| {
                let s = &play["samplers"][c["sampler"].as_u64().unwrap() as usize];
                floats(&pj, &bin, s["output"].as_u64().unwrap() as usize)
            })
    };
    let neutral = back.neutral_world_positions();
    for node in [LEFT_EYE_JOINT, RIGHT_EYE_JOINT] {
        // The eyeball's vertices over its meshes: (face mesh, vertex).
        let vertices: Vec<(usize, usize)> = part_of(node)["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|m| {
                let mi = back.mesh_index(m["mesh"].as_str().unwrap()).unwrap();
                m["vertices"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(move |v| (mi, v.as_u64().unwrap() as usize))
            })
            .collect();
        let rest: Vec<Vec3> = vertices.iter().map(|&(m, v)| neutral[m][v]).collect();
        let lo = rest
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b));
        let hi = rest
            .iter()
            .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
        let size = (hi - lo).max_element();
        let rot = channel(node, "rotation").unwrap_or_else(|| panic!("joint {node} not turned"));
        let tr = channel(node, "translation");
        assert!(rot.len() >= 4 * GAZE.len());
        let rest_world = node_world(&pj, node, &|_| None);
        let mut worst = 0.0f32;
        for (k, v) in GAZE.iter().enumerate() {
            let q = Quat::from_slice(&rot[4 * k..4 * k + 4]);
            let t = tr.as_ref().map(|t| Vec3::from_slice(&t[3 * k..3 * k + 3]));
            let world = node_world(&pj, node, &|i| (i == node).then_some((q, t)));
            let motion = world * rest_world.inverse();
            let posed = back.pose(&gaze_activations(v)).unwrap();
            let mut moved = 0.0f32;
            for (&(mi, vi), &p) in vertices.iter().zip(&rest) {
                let got = motion.transform_point3(p);
                let want = posed[mi][vi];
                moved = moved.max(want.distance(p));
                worst = worst.max(got.distance(want) / size);
            }
            eprintln!("joint {node} frame {k}: FAT moves the eyeball {moved}, worst {worst}");
            if v.iter().any(|&x| x != 0) {
                assert!(
                    moved > 0.02 * size,
                    "frame {k}: the FAT does not turn the eye"
                );
            }
        }
        assert!(
            worst <= 0.01,
            "joint {node}: off by {worst} of the eyeball's size"
        );
    }
    // No turn weights are keyed: the played meshes have no target for them at all.
    assert!(channel(LEFT_EYE_JOINT, "weights").is_none());

    let files = [glb.clone(), out.clone(), played.clone()];
    if let Some(reports) = support::validator::validate(&files) {
        let issues = |r: &Value| (r["errors"].clone(), r["warnings"].clone());
        assert_eq!(issues(&reports[0]), issues(&reports[1]), "{}", reports[1]);
        assert_eq!(issues(&reports[0]), issues(&reports[2]), "{}", reports[2]);
    }
    if let Some(text) = support::node_check::run_node_check(
        "gltf-loaders-check.mjs",
        [&played],
        &[
            ("THREE_DIR", "target/gltf-loaders"),
            ("VIEWER_BROWSER_DIR", "target/viewer-browser"),
        ],
        "GLTF_LOADERS_REQUIRED",
        "three.js loader",
    ) {
        let r: Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
        assert!(r.get("loadError").is_none(), "{}", r["loadError"]);
        assert_eq!(r["pageErrors"], Value::Array(vec![]), "{r}");
        let clip = r["animations"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["name"] == "play")
            .unwrap_or_else(|| panic!("no play clip: {r}"));
        assert!(
            clip["tracks"].as_array().is_some_and(|t| !t.is_empty()),
            "{clip}"
        );
    }
    if let Some(r) = support::blender::import_in_blender(&[&played]) {
        let actions = r[0]["actions"].to_string();
        assert!(actions.contains("play"), "{actions}");
    }
}

/// Both eyeballs in one primitive of the skinned `Body`, each weighted wholly to its eye joint
/// (VRM): the joints show the eyes' turns ([`check_eye_joints_turn`]).
#[test]
fn eyeballs_in_one_primitive_turn_their_two_eye_joints() {
    check_eye_joints_turn(
        &Options {
            vrm_eyes: Some(1.0),
            ..Options::default()
        },
        &["Body.2"],
    );
}

/// VRoid's eyes: the eye whites in `Body`'s `eyes` primitive, the irises and the highlights
/// (floating in front) in two more primitives of `Body`, all on the eye joints: each joint
/// turns its eye over the three primitives ([`check_eye_joints_turn`]).
#[test]
fn eyes_over_three_primitives_turn_their_two_eye_joints() {
    check_eye_joints_turn(
        &Options {
            vroid_eyes: Some(VroidEyes {
                highlight_node: false,
                iris_share: 1.0,
            }),
            ..Options::default()
        },
        &["Body.2", "Body.4", "Body.5"],
    );
}

/// As [`eyes_over_three_primitives_turn_their_two_eye_joints`] with the highlights in a
/// mesh node of their own, skinned to the same joints.
#[test]
fn eyes_over_two_meshes_turn_their_two_eye_joints() {
    check_eye_joints_turn(
        &Options {
            vroid_eyes: Some(VroidEyes {
                highlight_node: true,
                iris_share: 1.0,
            }),
            ..Options::default()
        },
        &["Body.2", "Body.4", "EyeHighlight"],
    );
}

/// VRoid's eyes with the irises weighted to their eye joints by 60 % only (the eye whites and
/// highlights wholly): the joints cannot turn them; the eye motion stays baked in morph
/// targets, with one warning per joint naming the iris primitive.
#[test]
fn eyes_over_three_primitives_partly_weighted_stay_baked_and_are_said_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let opts = Options {
        vroid_eyes: Some(VroidEyes {
            highlight_node: false,
            iris_share: 0.6,
        }),
        ..Options::default()
    };
    let (_, _, out, stderr) = clone_eyes_with(d, &source, &opts);
    for joint in ["LeftEye", "RightEye"] {
        let said =
            format!("eye node `{joint}` is not turned (the eyeball in mesh `Body.4` is weighted");
        assert_eq!(stderr.matches(&said).count(), 1, "{joint}: {stderr}");
    }
    assert!(stderr.contains("by 60 % only"), "{stderr}");
    let (patched, _) = glb_parts(&out);
    let names = patched["meshes"][0]["extras"]["targetNames"].to_string();
    for name in TURNS {
        assert!(names.contains(name), "{name}: {names}");
    }
    assert!(patched["scenes"][0]["extras"]["fbakit"]
        .get("nodeParts")
        .is_none());
}

/// Both eyeballs in one primitive weighted to their eye joints by 60 % only: the joints
/// cannot turn them; the eye motion stays baked in morph targets, with one warning per joint
/// saying why.
#[test]
fn eyeballs_in_one_primitive_partly_weighted_stay_baked_and_are_said_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let opts = Options {
        vrm_eyes: Some(0.6),
        ..Options::default()
    };
    let (_, _, out, stderr) = clone_eyes_with(d, &source, &opts);
    for joint in ["LeftEye", "RightEye"] {
        let said = format!("eye node `{joint}` is not turned (the eyeball in mesh ");
        assert_eq!(stderr.matches(&said).count(), 1, "{joint}: {stderr}");
    }
    assert!(stderr.contains("by 60 % only"), "{stderr}");
    let (patched, _) = glb_parts(&out);
    let names = patched["meshes"][0]["extras"]["targetNames"].to_string();
    for name in ["yaw_l_eyeball", "yaw_r_eyeball", "pitch_l_eyeball"] {
        assert!(names.contains(name), "{name}: {names}");
    }
    assert!(patched["scenes"][0]["extras"]["fbakit"]
        .get("nodeParts")
        .is_none());
}
