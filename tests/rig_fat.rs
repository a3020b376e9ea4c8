//! Rig → FAT: calibration on a small synthetic rig with exact expectations, and on the real
//! ICT-FaceKit rig (feature points derived here from its iBUG landmark vertices; skipped when
//! `../shared/data/ict-facekit` is absent).

use std::path::{Path, PathBuf};

use fbakit::clone::eval::compliance;
use fbakit::fat::TableKey;
use fbakit::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use fbakit::mesh::{Mesh, Polygons};
use fbakit::rig::fap_map::{parse_fap_map, FapMap};
use fbakit::rig::fat_build::face_from_rig;
use fbakit::rig::{BlendShape, Rig, RigMesh, ShapeDelta};
use fbakit::spec::FeaturePointId;
use glam::Vec3;

fn fp(label: &str) -> FeaturePointId {
    label.parse().unwrap()
}

/// Vertices of the synthetic face, each a feature point (mm): ES0 60, IRISD0 10, ENS0 40,
/// MNS0 20, MW0 50.
const POINTS: [(&str, [f32; 3]); 11] = [
    ("3.5", [30.0, 40.0, 0.0]),
    ("3.6", [-30.0, 40.0, 0.0]),
    ("3.1", [30.0, 45.0, 0.0]),
    ("3.3", [30.0, 35.0, 0.0]),
    ("9.15", [0.0, 0.0, 0.0]),
    ("2.2", [0.0, -20.0, 0.0]),
    ("8.3", [25.0, -25.0, 0.0]),
    ("8.4", [-25.0, -25.0, 0.0]),
    ("2.1", [0.0, -60.0, 0.0]),
    ("2.4", [20.0, -25.0, 0.0]),
    // Not a feature point: halfway between 2.4 and 8.3.
    ("-", [22.5, -25.0, 0.0]),
];

fn shape(name: &str, moves: &[(usize, [f32; 3])]) -> BlendShape {
    BlendShape {
        name: name.into(),
        default_weight: 0.0,
        deltas: vec![ShapeDelta {
            mesh: 0,
            vertices: moves.iter().map(|m| m.0 as u32).collect(),
            offsets: moves.iter().map(|m| Vec3::from(m.1)).collect(),
        }],
    }
}

fn synthetic_rig() -> (Rig, FeaturePointSet) {
    let positions: Vec<Vec3> = POINTS.iter().map(|p| Vec3::from(p.1)).collect();
    let tris: Vec<[u32; 3]> = (1..positions.len() as u32 - 1)
        .map(|i| [0, i, i + 1])
        .collect();
    let mesh = Mesh {
        name: "face".into(),
        positions,
        polygons: Polygons::from_triangles(&tris),
        ..Mesh::default()
    };
    let rig = Rig {
        name: "synthetic".into(),
        meshes: vec![RigMesh {
            name: "face".into(),
            mesh,
        }],
        shapes: vec![
            shape("jawOpen", &[(8, [0.0, -10.0, -2.0])]),
            shape(
                "mouthSmile_L",
                &[
                    (6, [1.0, 5.0, 0.0]),
                    (9, [1.0, 4.0, 0.0]),
                    (10, [1.0, 4.0, 0.0]),
                ],
            ),
            shape(
                "mouthFrown_L",
                &[(6, [0.0, -2.5, 0.0]), (9, [0.0, -2.0, 0.0])],
            ),
            shape("eyeBlink_L", &[(2, [0.0, -5.0, 0.0])]),
            shape("jawLeft", &[(8, [0.01, 0.0, 0.0])]),
            shape("aa", &[(5, [0.0, -3.0, 0.0])]),
            shape("tailWag", &[(4, [1.0, 0.0, 0.0])]),
        ],
        warnings: vec![],
        source: None,
    };
    let mut points = FeaturePointSet::new();
    for (i, (label, p)) in POINTS.iter().enumerate() {
        if *label != "-" {
            let mut point = FeaturePoint::at(fp(label), Vec3::from(*p));
            point.binding = Some(VertexBinding::vertex(i as u32));
            points.insert(point);
        }
    }
    (rig, points)
}

fn key(name: &str) -> TableKey {
    TableKey::from_name(name).unwrap()
}

#[test]
fn synthetic_rig_calibrates_exactly() {
    let (rig, points) = synthetic_rig();
    let (face, report) = face_from_rig(&rig, Some(points), &FapMap::arkit()).unwrap();
    let value = |fap: &str, sign: char| {
        report
            .calibrated
            .iter()
            .find(|c| c.fap == fap && c.sign == sign)
            .map(|c| c.value)
    };
    // MNS = 20 / 1024: jawOpen drops 2.1 by 10 → 512 MNS.
    assert!((value("open_jaw", '+').unwrap() - 512.0).abs() < 1e-6);
    // Smile lifts 2.4 by 4 (204.8 MNS), frown lowers it by 2 (−102.4): two intervals.
    assert!((value("raise_l_cornerlip", '+').unwrap() - 204.8).abs() < 1e-4);
    assert!((value("raise_l_cornerlip", '-').unwrap() + 102.4).abs() < 1e-4);
    // The outer corner 8.3 measures the same shapes (5 and −2.5 → 256, −128).
    assert!((value("raise_l_cornerlip_o", '+').unwrap() - 256.0).abs() < 1e-4);
    // IRISD = 10 / 1024: the blink lowers 3.1 by 5 → 512.
    assert!((value("close_t_l_eyelid", '+').unwrap() - 512.0).abs() < 1e-4);
    let t = face.fat.table(key("raise_l_cornerlip")).unwrap();
    let borders = &t.meshes[0].interval_borders;
    assert_eq!(borders.len(), 3);
    // Borders are whole FAP values (VRML's intervalBorders is MFInt32): the nearest ones to
    // the calibrated −102.4 and 204.8, with the motion per FAP unit unchanged (below).
    assert_eq!(borders, &vec![-102.0, 0.0, 205.0]);
    // The vertex halfway between 2.4 and 8.3 is shared half and half between FAPs 12 and 59.
    let slot = t.meshes[0]
        .coord_index
        .iter()
        .position(|&v| v == 10)
        .unwrap();
    let rate = t.meshes[0].rate(slot, 1);
    assert!(
        (rate - Vec3::new(0.5, 2.0, 0.0) / 204.8).length() < 1e-6,
        "{rate}"
    );
    // ... and 2.4 itself belongs to FAP 12 only.
    let t59 = face.fat.table(key("raise_l_cornerlip_o")).unwrap();
    assert!(!t59.meshes[0].coord_index.contains(&9));
    // jawLeft barely moves the chin: reported, not calibrated.
    let jaw_left = report
        .unmapped
        .iter()
        .find(|u| u.key == "shift_jaw (-)")
        .unwrap();
    assert!(
        jaw_left.reason.contains("jawLeft moves feature point 2.1"),
        "{}",
        jaw_left.reason
    );
    // VRM aa realises viseme 10; other visemes come from low-level FAPs.
    let aa = report
        .high_level
        .iter()
        .find(|h| h.key == "viseme_10")
        .unwrap();
    assert_eq!(aa.source, "shape aa");
    assert!(face.fat.table(key("viseme_10")).is_some());
    assert!(report
        .high_level
        .iter()
        .any(|h| h.source.starts_with("low-level FAPs")));
    assert_eq!(report.unused_shapes, vec!["jawLeft", "tailWag"]);
    // Compliance is exact along every calibrated direction.
    let c = compliance(&face).unwrap();
    assert_eq!(c.faps.len(), 4, "{:?}", c.faps);
    assert!(c.worst < 1e-5, "worst {}", c.worst);
    insta::assert_yaml_snapshot!("synthetic_rig_report", report);
}

#[test]
fn eyeball_rotation_is_calibrated_in_au() {
    let (mut rig, mut points) = synthetic_rig();
    // A separate eyeball piece (tetrahedron about c) whose front vertex is the left pupil.
    let c = Vec3::new(30.0, 40.0, -10.0);
    let ball = [
        Vec3::new(30.0, 40.0, 0.0),
        Vec3::new(40.0, 40.0, -10.0),
        Vec3::new(30.0, 50.0, -10.0),
        Vec3::new(20.0, 40.0, -10.0),
    ];
    let mesh = &mut rig.meshes[0].mesh;
    let first = mesh.positions.len() as u32;
    mesh.positions.extend(ball);
    for t in [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]] {
        mesh.polygons.push(&t.map(|k| first + k));
    }
    let turn = glam::Quat::from_axis_angle(Vec3::Y, 0.3);
    rig.shapes.push(BlendShape {
        name: "eyeLookOut_L".into(),
        default_weight: 0.0,
        deltas: vec![ShapeDelta {
            mesh: 0,
            vertices: (first..first + 4).collect(),
            offsets: ball.iter().map(|&p| turn * (p - c) + c - p).collect(),
        }],
    });
    let mut pupil = FeaturePoint::at(fp("3.5"), ball[0]);
    pupil.binding = Some(VertexBinding::vertex(first));
    points.insert(pupil);
    let (face, report) = face_from_rig(&rig, Some(points), &FapMap::arkit()).unwrap();
    let yaw = report
        .calibrated
        .iter()
        .find(|c| c.fap == "yaw_l_eyeball")
        .expect("yaw_l_eyeball calibrated");
    assert_eq!(yaw.unit, "AU");
    assert!((yaw.value - 30_000.0).abs() < 1.0, "{}", yaw.value);
    assert!(face.fat.table(key("yaw_l_eyeball")).is_some());
    // Looking in is absent from this rig: reported.
    assert!(report.unmapped.iter().any(|u| u.key == "yaw_l_eyeball (-)"));
}

#[test]
fn without_feature_points_only_named_high_level_keys() {
    let (rig, _) = synthetic_rig();
    let (face, report) = face_from_rig(&rig, None, &FapMap::arkit()).unwrap();
    assert!(report.calibrated.is_empty());
    assert_eq!(face.fat.keys(), vec![key("viseme_10")]);
    assert!(report
        .unmapped
        .iter()
        .any(|u| u.key == "open_jaw (+)" && u.reason.contains("no feature points")));
}

#[test]
fn custom_map_naming_missing_shapes_is_located() {
    let (rig, _) = synthetic_rig();
    let p = Path::new("custom.csv");
    let map = parse_fap_map(
        "fap,positive,negative,reasoning\nopen_jaw,jawOpen,,ok\nraise_l_cornerlip,grin,,no\n",
        p,
    )
    .unwrap();
    let e = map.check_against(&rig, p).unwrap_err().to_string();
    assert!(e.starts_with("custom.csv:3: unknown shape `grin`"), "{e}");
}

fn ict_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/ict-facekit");
    if dir.join("generic_neutral_mesh.obj").is_file() {
        Some(dir)
    } else {
        eprintln!("skipping: {} is absent", dir.display());
        None
    }
}

/// ICT's face region (vertex ids 0..=9408).
const ICT_FACE: std::ops::Range<usize> = 0..9409;

/// Feature points of the ICT neutral from its iBUG-68 landmark vertices (sides by the sign
/// of x: +x is the face's left), lid mid-points as the face vertex nearest the mean of the two
/// lid landmarks, pupils as the most forward iris vertex of each eyeball.
fn ict_feature_points(rig: &Rig, dir: &Path) -> FeaturePointSet {
    let ids: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("vertex_indices.json")).unwrap())
            .unwrap();
    let lm: Vec<u32> = ids["idx_to_landmark_verts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as u32)
        .collect();
    let pos = &rig.meshes[0].mesh.positions;
    let at = |n: usize| lm[n - 1];
    let p = |v: u32| pos[v as usize];
    let nearest = |target: Vec3| -> u32 {
        ICT_FACE
            .clone()
            .min_by(|&a, &b| pos[a].distance(target).total_cmp(&pos[b].distance(target)))
            .unwrap() as u32
    };
    let mut set = FeaturePointSet::new();
    let mut put = |label: &str, v: u32| {
        let mut point = FeaturePoint::at(fp(label), pos[v as usize]);
        point.binding = Some(VertexBinding::vertex(v));
        set.insert(point);
    };
    // (left, right) pairs by x sign.
    let lr = |a: u32, b: u32| if p(a).x > p(b).x { (a, b) } else { (b, a) };
    put("2.1", at(9));
    put("2.2", at(63));
    put("2.3", at(67));
    let (l, r) = lr(at(61), at(65));
    put("2.4", l);
    put("2.5", r);
    let (l, r) = lr(at(62), at(64));
    put("2.6", l);
    put("2.7", r);
    let (l, r) = lr(at(66), at(68));
    put("2.8", l);
    put("2.9", r);
    put("8.1", at(52));
    put("8.2", at(58));
    let (l, r) = lr(at(49), at(55));
    put("8.3", l);
    put("8.4", r);
    let (l, r) = lr(at(51), at(53));
    put("8.5", l);
    put("8.6", r);
    let (l, r) = lr(at(59), at(57));
    put("8.7", l);
    put("8.8", r);
    put("9.15", at(34));
    put("9.3", at(31));
    let (l, r) = lr(at(32), at(36));
    put("9.1", l);
    put("9.2", r);
    let (l, r) = lr(at(23), at(22));
    put("4.1", l);
    put("4.2", r);
    let (l, r) = lr(at(25), at(20));
    put("4.3", l);
    put("4.4", r);
    let (l, r) = lr(at(27), at(18));
    put("4.5", l);
    put("4.6", r);
    // Eyes: landmarks 37–42 and 43–48; upper lid 2nd/3rd, lower lid 5th/6th of each.
    let mid = |a: usize, b: usize| nearest((p(at(a)) + p(at(b))) / 2.0);
    let (eye_a_up, eye_a_low) = (mid(38, 39), mid(41, 42));
    let (eye_b_up, eye_b_low) = (mid(44, 45), mid(47, 48));
    let ((lu, ll), (ru, rl)) = if p(at(44)).x > p(at(38)).x {
        ((eye_b_up, eye_b_low), (eye_a_up, eye_a_low))
    } else {
        ((eye_a_up, eye_a_low), (eye_b_up, eye_b_low))
    };
    put("3.1", lu);
    put("3.3", ll);
    put("3.2", ru);
    put("3.4", rl);
    // Pupils: the most forward vertex of each eyeball (21451–23020, 23021–24590).
    let front = |r: std::ops::Range<usize>| {
        r.max_by(|&a, &b| pos[a].z.total_cmp(&pos[b].z)).unwrap() as u32
    };
    let (l, r) = lr(front(21451..23021), front(23021..24591));
    put("3.5", l);
    put("3.6", r);
    set
}

#[test]
fn ict_rig_becomes_a_compliant_fat_face() {
    let Some(dir) = ict_dir() else { return };
    let rig = fbakit::rig::read_rig(&dir).unwrap();
    let points = ict_feature_points(&rig, &dir);
    let (face, report) = face_from_rig(&rig, Some(points), &FapMap::arkit()).unwrap();
    // Its visemes look like speech (mouth figures in the face's own MNS0 and width).
    let shapes = fbakit::face::mouth::viseme_shapes(&face).expect("lip points");
    assert_eq!(shapes.len(), 14);
    let bad = fbakit::face::mouth::viseme_problems(&shapes);
    assert!(bad.is_empty(), "full ICT rig visemes: {bad:?}");
    for c in &report.calibrated {
        eprintln!(
            "{} {} {:?} {} {:.1} {}",
            c.fap, c.sign, c.shapes, c.feature_point, c.value, c.unit
        );
    }
    for u in &report.unmapped {
        eprintln!("unmapped {}: {}", u.key, u.reason);
    }
    eprintln!("unused {:?}", report.unused_shapes);
    let calibrated = |fap: &str, sign: char| {
        report
            .calibrated
            .iter()
            .any(|c| c.fap == fap && c.sign == sign)
    };
    for (fap, sign) in [
        ("open_jaw", '+'),
        ("raise_l_cornerlip", '+'),
        ("raise_l_cornerlip", '-'),
        ("raise_r_cornerlip", '+'),
        ("close_t_l_eyelid", '+'),
        ("close_t_r_eyelid", '+'),
        ("raise_l_i_eyebrow", '+'),
        ("raise_l_cornerlip_o", '+'),
        ("stretch_l_cornerlip", '-'),
    ] {
        assert!(calibrated(fap, sign), "{fap} ({sign}) not calibrated");
    }
    // ICT's eyeLook shapes move lids and skin but not the eyeballs (its runtime turns them):
    // the eyeball and head FAPs are the standard's rotations about the head's own eyeball
    // centres and neck, not faked from the shapes.
    assert!(
        !report
            .unmapped
            .iter()
            .any(|u| u.key.starts_with("yaw_l_eyeball")),
        "{:?}",
        report.unmapped
    );
    let turns = report
        .standard_rotations
        .as_ref()
        .expect("standard rotations");
    for n in [23u8, 24, 25, 26, 48, 49, 50] {
        let k = fbakit::fat::TableKey::LowLevel(fbakit::spec::FapId::new(n).unwrap());
        assert!(turns.added.contains(&k), "FAP {n}: {turns:?}");
    }
    // jawOpen drops the chin by about half the mouth–nose distance or more.
    let jaw = report
        .calibrated
        .iter()
        .find(|c| c.fap == "open_jaw")
        .unwrap();
    assert!(jaw.value > 300.0, "{}", jaw.value);
    // Eye rotations are angles of a few degrees to a few tens of degrees (AU = 1e-5 rad).
    for c in report.calibrated.iter().filter(|c| c.unit == "AU") {
        assert!(
            (5_000.0..80_000.0).contains(&c.value.abs()),
            "{} {}",
            c.fap,
            c.value
        );
    }
    let c = compliance(&face).unwrap();
    assert!(c.faps.len() >= 25, "{} FAPs measured", c.faps.len());
    assert!(c.worst < 1e-4, "compliance worst {}", c.worst);
    assert!(report.unused_shapes.iter().any(|s| s == "PupilDilate_L"));
    // Every viseme and expression has a table.
    assert_eq!(report.high_level.len(), 20, "{:?}", report.high_level);
}

#[test]
fn custom_map_lists_faps_it_has_no_row_for() {
    let (rig, points) = synthetic_rig();
    let p = Path::new("custom.csv");
    let map = parse_fap_map(
        "fap,positive,negative,reasoning\nopen_jaw,jawOpen,,the jaw\nviseme_10,aa,,VRM aa\n",
        p,
    )
    .unwrap();
    map.check_against(&rig, p).unwrap();
    let (face, report) = face_from_rig(&rig, Some(points), &map).unwrap();
    assert_eq!(report.calibrated.len(), 1);
    assert!(face.fat.table(key("open_jaw")).is_some());
    let no_row = report
        .unmapped
        .iter()
        .filter(|u| u.reason == "no row in the map")
        .count();
    // The head's three rotations are the standard's (the synthetic rig has no eyeballs).
    assert_eq!(no_row, 62);
    assert!(face.fat.table(key("head_yaw")).is_some());
    assert!(report.unused_shapes.contains(&"mouthSmile_L".to_string()));
}
