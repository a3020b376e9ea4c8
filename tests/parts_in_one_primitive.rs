//! Parts that share one primitive (issue 19 §1): the avatar's eyes primitive holds both
//! eyeballs, its teeth primitive both rows, its lashes primitive the lashes of both eyes. Each
//! eye turns about its own centre for its own eyeball FAPs only, rigidly within 1 % of its
//! size at the FAT's interval values; the lower row follows `open_jaw`, the upper stays; each
//! eye's lashes follow its own lid; the primitives keep their vertices in order, and the
//! patched glb validates and plays (head rotations on the `Head` node, not baked).

mod support;

use std::path::{Path, PathBuf};

use fbakit::clone::face::{clone_face, CloneOptions, CloneOutcome, Part};
use fbakit::face::{FaceModel, FaceReadOptions};
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::spec::{FapId, FeaturePointId};
use glam::{Quat, Vec3};
use support::avatar::{self, Options};

const EYES: &str = "Body.2";
const TEETH: &str = "Body.4";
/// The eyes primitive: the right eye's sphere (x < 0) first, then the left's.
const RIGHT_EYE: std::ops::Range<usize> = 0..45;
const LEFT_EYE: std::ops::Range<usize> = 45..90;
const LASHES: &str = "Body.3";
/// The lashes primitive: the right eye's eight vertices, then the left's.
const RIGHT_LASHES: std::ops::Range<usize> = 0..8;
const LEFT_LASHES: std::ops::Range<usize> = 8..16;
/// The teeth primitive: upper row, then lower row.
const UPPER: std::ops::Range<usize> = 0..14;
const LOWER: std::ops::Range<usize> = 14..28;

fn key(fap: u8) -> TableKey {
    TableKey::LowLevel(FapId::new(fap).unwrap())
}

/// The avatar with its teeth primitive as `avatar.glb` in `dir`, and its feature points.
fn write_avatar(dir: &Path, source: &FaceModel) -> (PathBuf, PathBuf) {
    write_avatar_with(dir, source, false)
}

/// [`write_avatar`], with a tongue in the teeth primitive when `tongue`.
fn write_avatar_with(dir: &Path, source: &FaceModel, tongue: bool) -> (PathBuf, PathBuf) {
    let glb = dir.join("avatar.glb");
    std::fs::write(
        &glb,
        avatar::build_with(&Options {
            teeth: true,
            tongue,
            ..Options::default()
        })
        .to_glb(),
    )
    .unwrap();
    let csv = avatar::fp_csv(source, dir, &avatar::teeth_fp_lines());
    (glb, csv)
}

fn read(glb: &Path, csv: &Path) -> FaceModel {
    fbakit::face::read_with(glb, &FaceReadOptions::with_feature_points(Some(csv)))
        .unwrap()
        .0
}

/// World positions of every mesh posed at `fap` = `value`.
fn posed(face: &FaceModel, fap: u8, value: f64) -> Vec<Vec<Vec3>> {
    face.pose(&[Activation {
        key: key(fap),
        value,
    }])
    .unwrap()
}

/// The table's interval borders on `mesh` and the midpoints between them (0 left out).
fn sample_values(face: &FaceModel, fap: u8, mesh: &str) -> Vec<f64> {
    let table = face
        .fat
        .tables
        .iter()
        .find(|t| t.key == key(fap))
        .unwrap_or_else(|| panic!("no table for FAP {fap}"));
    let entry = table
        .meshes
        .iter()
        .find(|m| m.mesh == mesh)
        .unwrap_or_else(|| panic!("FAP {fap} has no entry for {mesh}"));
    let b = &entry.interval_borders;
    let mut out: Vec<f64> = b.clone();
    out.extend(b.windows(2).map(|w| (w[0] + w[1]) / 2.0));
    out.retain(|v| *v != 0.0);
    out
}

fn max_move(a: &[Vec3], b: &[Vec3], range: std::ops::Range<usize>) -> f32 {
    range.map(|v| a[v].distance(b[v])).fold(0.0, f32::max)
}

fn size(p: &[Vec3]) -> f32 {
    let lo = p.iter().fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b));
    let hi = p
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
    (hi - lo).length()
}

/// Each eye turns about its centre by the FAP's angle (AU = 1e-5 rad about the standard's
/// axis), within 1 % of its size, at every border and mid-interval value; the other eye and
/// every other mesh stay.
fn check_eyes(face: &FaceModel) {
    let eyes = face.mesh_index(EYES).unwrap();
    let neutral = face.neutral_world_positions();
    let n = &neutral[eyes];
    // The sphere's first pole vertex is in no triangle: invisible, it never moves.
    let mut used = vec![false; n.len()];
    for poly in face.meshes[eyes].mesh.polygons.iter() {
        for &v in poly {
            used[v as usize] = true;
        }
    }
    for (fap, own, other) in [
        (23u8, LEFT_EYE, RIGHT_EYE),
        (24, RIGHT_EYE, LEFT_EYE),
        (25, LEFT_EYE, RIGHT_EYE),
        (26, RIGHT_EYE, LEFT_EYE),
    ] {
        let pts: Vec<Vec3> = n[own.clone()].to_vec();
        let centre = {
            let lo = pts
                .iter()
                .fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b));
            let hi = pts
                .iter()
                .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
            (lo + hi) / 2.0
        };
        let eye_size = size(&pts);
        let axis = FapId::new(fap).unwrap().info().rotation_axis().unwrap();
        let values = sample_values(face, fap, EYES);
        assert!(values.len() >= 2, "FAP {fap}: {values:?}");
        for value in values {
            let p = posed(face, fap, value);
            let turn = Quat::from_axis_angle(axis, (value * 1e-5) as f32);
            let err = own
                .clone()
                .filter(|&v| used[v])
                .map(|v| {
                    let want = centre + turn * (n[v] - centre);
                    p[eyes][v].distance(want)
                })
                .fold(0.0, f32::max);
            let moved = max_move(n, &p[eyes], own.clone());
            let want = own
                .clone()
                .map(|v| (turn * (n[v] - centre)).distance(n[v] - centre))
                .fold(0.0, f32::max);
            assert!(
                moved > 0.5 * want,
                "FAP {fap} at {value}: moves {moved}, not {want}"
            );
            assert!(
                err < 0.01 * eye_size,
                "FAP {fap} at {value}: off the rigid turn by {:.3} % of the eye",
                100.0 * err / eye_size
            );
            assert!(
                max_move(n, &p[eyes], other.clone()) < 1e-6 * eye_size,
                "FAP {fap} moves the other eye"
            );
            for (m, (a, b)) in neutral.iter().zip(&p).enumerate() {
                if m != eyes {
                    assert!(
                        max_move(a, b, 0..a.len()) < 1e-6,
                        "FAP {fap} moves {}",
                        face.meshes[m].name
                    );
                }
            }
        }
    }
    // No eyeball moves for the lids, the brows or the jaw.
    for fap in [3u8, 19, 20, 21, 22, 31, 32] {
        if !face.fat.tables.iter().any(|t| t.key == key(fap)) {
            continue;
        }
        let p = posed(face, fap, 500.0);
        assert!(
            max_move(n, &p[eyes], 0..n.len()) < 1e-6,
            "FAP {fap} moves an eyeball"
        );
    }
}

/// How far `face`'s lower teeth drop (mean over the row's vertices, down the y axis) per
/// unit of its chin's (2.1) drop at `open_jaw` = `value`.
fn teeth_per_chin(face: &FaceModel, lower: &[usize], value: f64) -> f32 {
    let neutral = face.neutral_world_positions();
    let p = posed(face, 3, value);
    let (cm, cv) = face.fp_vertex(FeaturePointId::FP_2_1).unwrap();
    let chin = neutral[cm][cv as usize].y - p[cm][cv as usize].y;
    let drop = lower
        .iter()
        .map(|&m| {
            let (a, b) = (&neutral[m], &p[m]);
            a.iter().zip(b).map(|(x, y)| x.y - y.y).sum::<f32>() / a.len() as f32
        })
        .sum::<f32>()
        / lower.len() as f32;
    drop / chin
}

/// The lower row goes down with the chin under `open_jaw`, rigidly, as far per unit of chin
/// drop as the source's (alma's) lower teeth do; the upper row stays.
fn check_teeth(face: &FaceModel) {
    let source = fbakit::face::read("alma").unwrap();
    let source_lower: Vec<usize> = fbakit::clone::face::identify_parts(&source)
        .parts
        .get(&Part::LowerTeeth)
        .cloned()
        .unwrap();
    let teeth = face.mesh_index(TEETH).unwrap();
    let neutral = face.neutral_world_positions();
    let n = &neutral[teeth];
    let (cm, cv) = face.fp_vertex(FeaturePointId::FP_2_1).unwrap();
    let row_size = size(&n[LOWER]);
    for value in sample_values(face, 3, TEETH)
        .into_iter()
        .filter(|v| *v > 0.0)
    {
        let p = posed(face, 3, value);
        let chin = neutral[cm][cv as usize].y - p[cm][cv as usize].y;
        let drop = LOWER.map(|v| n[v].y - p[teeth][v].y).sum::<f32>() / LOWER.len() as f32;
        eprintln!("open_jaw {value}: chin down {chin}, lower teeth down {drop}");
        assert!(chin > 0.0);
        // The row drops about 3× the chin, as alma's own lower teeth do (its `jaw_tf` turns
        // 1 rad at 1024 while its chin point drops 1024 MNS): the clone keeps the source's
        // relation. The two rows sit at different places relative to their hinges, and a
        // 1 rad turn makes the vertical drop depend on that: measured 12 % (value 128) to 31 %
        // (1024) above alma's, hence 35 %. A row turned by an angle that does not fit the
        // FAPU-scaled chin (issue 19) moves this ratio by the mismatch.
        let want = teeth_per_chin(&source, &source_lower, value);
        eprintln!("  per chin: {} (alma {want})", drop / chin);
        assert!(
            (drop / chin - want).abs() < 0.35 * want,
            "open_jaw {value}: chin {chin}, lower teeth {drop}: {} per chin, alma {want}",
            drop / chin
        );
        // Rigid: distances within the row kept to 1 % of its size.
        let stretch = LOWER
            .flat_map(|a| LOWER.map(move |b| (a, b)))
            .map(|(a, b)| (n[a].distance(n[b]) - p[teeth][a].distance(p[teeth][b])).abs())
            .fold(0.0, f32::max);
        assert!(
            stretch < 0.01 * row_size,
            "lower row stretched by {stretch}"
        );
        assert!(
            max_move(n, &p[teeth], UPPER) < 1e-6,
            "open_jaw moves the upper teeth"
        );
    }
    // The eyeballs and the lids leave the teeth alone.
    for fap in [19u8, 23, 24] {
        if face.fat.tables.iter().any(|t| t.key == key(fap)) {
            let p = posed(face, fap, 500.0);
            assert!(max_move(n, &p[teeth], 0..n.len()) < 1e-6, "FAP {fap}");
        }
    }
}

fn cloned(dir: &Path) -> (FaceModel, CloneOutcome) {
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(dir, &source);
    let target = read(&glb, &csv);
    let out = clone_face(&source, &target, &CloneOptions::default()).unwrap();
    (target, out)
}

#[test]
fn each_part_of_a_shared_primitive_moves_alone() {
    let dir = tempfile::tempdir().unwrap();
    let (target, out) = cloned(dir.path());
    let parts: Vec<(Part, &str)> = out
        .report
        .split_parts
        .iter()
        .map(|s| (s.part, s.from.as_str()))
        .collect();
    assert_eq!(
        parts,
        [
            (Part::LeftEye, EYES),
            (Part::RightEye, EYES),
            (Part::UpperTeeth, TEETH),
            (Part::LowerTeeth, TEETH)
        ],
        "{}",
        out.report
    );
    // The primitives come back whole: same meshes, vertex counts and positions in order.
    let face = &out.face;
    assert_eq!(face.meshes.len(), target.meshes.len());
    let (a, b) = (
        target.neutral_world_positions(),
        face.neutral_world_positions(),
    );
    for (m, t) in face.meshes.iter().zip(&target.meshes) {
        assert_eq!(m.name, t.name);
        assert_eq!(m.mesh.polygons, t.mesh.polygons, "{}", m.name);
    }
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.len(), y.len());
        assert!(x.iter().zip(y).all(|(p, q)| p.distance(*q) < 1e-6));
    }
    assert!(
        out.report.rigid.baked_transforms.len() >= 3,
        "{:?}",
        out.report.rigid
    );
    check_eyes(face);
    check_teeth(face);
}

/// Without teeth feature points (9.8–9.11: iBUG-68 landmarks give none) the teeth primitive
/// is still cut into its rows, by their side of the lip line: the lower row follows the jaw,
/// the upper stays, and the primitive keeps its vertices in order.
#[test]
fn teeth_rows_are_found_without_teeth_points() {
    let dir = tempfile::tempdir().unwrap();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, _) = write_avatar(dir.path(), &source);
    let csv = avatar::fp_csv(&source, dir.path(), "");
    let target = read(&glb, &csv);
    for id in ["9.8", "9.9", "9.10", "9.11"] {
        assert!(target.feature_points.get(id.parse().unwrap()).is_none());
    }
    let out = clone_face(&source, &target, &CloneOptions::default()).unwrap();
    let teeth: Vec<(Part, usize)> = out
        .report
        .split_parts
        .iter()
        .filter(|s| s.from == TEETH)
        .map(|s| (s.part, s.vertices))
        .collect();
    assert_eq!(
        teeth,
        [(Part::UpperTeeth, 14), (Part::LowerTeeth, 14)],
        "{}",
        out.report
    );
    let split = out
        .report
        .split_parts
        .iter()
        .find(|s| s.part == Part::LowerTeeth)
        .unwrap();
    assert_eq!(
        split.source_vertices,
        LOWER.map(|v| v as u32).collect::<Vec<_>>()
    );
    let face = &out.face;
    assert_eq!(face.meshes.len(), target.meshes.len());
    for (m, t) in face.meshes.iter().zip(&target.meshes) {
        assert_eq!(m.mesh.positions.len(), t.mesh.positions.len(), "{}", m.name);
        assert_eq!(m.mesh.polygons, t.mesh.polygons, "{}", m.name);
    }
    check_teeth(face);
}

/// A tongue in the teeth primitive (as ReadyPlayerMe's `Wolf3D_Teeth` has it), with and
/// without teeth feature points: the jaw carries it under `open_jaw` as it carries the lower
/// row (rigidly, dropping as far as the row's middle within a third), lip, eyeball and lid
/// FAPs leave it still, and the primitive keeps its vertices in order.
#[test]
fn a_tongue_in_the_teeth_primitive_rides_the_jaw() {
    let source = fbakit::face::read("alma").unwrap();
    for teeth_points in [true, false] {
        let dir = tempfile::tempdir().unwrap();
        let (glb, with_points) = write_avatar_with(dir.path(), &source, true);
        let csv = if teeth_points {
            with_points
        } else {
            avatar::fp_csv(&source, dir.path(), "")
        };
        let target = read(&glb, &csv);
        let out = clone_face(&source, &target, &CloneOptions::default()).unwrap();
        let face = &out.face;
        let teeth = face.mesh_index(TEETH).unwrap();
        assert_eq!(
            face.meshes[teeth].mesh.positions.len(),
            avatar::TONGUE.end,
            "{teeth_points}"
        );
        assert_eq!(
            face.meshes[teeth].mesh.polygons,
            target.meshes[teeth].mesh.polygons
        );
        let neutral = face.neutral_world_positions();
        let n = &neutral[teeth];
        let (cm, cv) = face.fp_vertex(FeaturePointId::FP_2_1).unwrap();
        let tongue_size = size(&n[avatar::TONGUE]);
        // The dome's pole vertex 0 is in no triangle (the sphere's pole fan starts at 1):
        // drawn by nothing, it keeps its place.
        let drawn: std::collections::BTreeSet<usize> = face.meshes[teeth]
            .mesh
            .polygons
            .iter()
            .flatten()
            .map(|&v| v as usize)
            .collect();
        let tongue_vertices: Vec<usize> = avatar::TONGUE.filter(|v| drawn.contains(v)).collect();
        assert_eq!(tongue_vertices.len(), avatar::TONGUE.len() - 1);
        let mut opened = 0;
        for value in sample_values(face, 3, TEETH)
            .into_iter()
            .filter(|v| *v > 0.0)
        {
            let p = posed(face, 3, value);
            let chin = neutral[cm][cv as usize].y - p[cm][cv as usize].y;
            let row = LOWER.map(|v| n[v].y - p[teeth][v].y).sum::<f32>() / LOWER.len() as f32;
            let tongue = tongue_vertices
                .iter()
                .map(|&v| n[v].y - p[teeth][v].y)
                .sum::<f32>()
                / tongue_vertices.len() as f32;
            eprintln!(
                "teeth points {teeth_points}, open_jaw {value}: chin {chin}, lower row {row}, tongue {tongue}"
            );
            assert!(chin > 0.0 && row > 0.0);
            // The tongue sits further back than the row, nearer the hinge: it drops less.
            assert!(
                tongue > 0.3 * row && tongue < 1.1 * row,
                "teeth points {teeth_points}, open_jaw {value}: tongue {tongue}, row {row}"
            );
            let stretch = tongue_vertices
                .iter()
                .flat_map(|&a| tongue_vertices.iter().map(move |&b| (a, b)))
                .map(|(a, b)| (n[a].distance(n[b]) - p[teeth][a].distance(p[teeth][b])).abs())
                .fold(0.0, f32::max);
            assert!(
                stretch < 0.01 * tongue_size,
                "tongue stretched by {stretch} (size {tongue_size})"
            );
            assert!(max_move(n, &p[teeth], UPPER) < 1e-6);
            opened += 1;
        }
        assert!(opened > 0, "no open_jaw sample");
        // raise_b_midlip, stretch_l_cornerlip, eyeball yaw, upper lid.
        for fap in [5u8, 6, 19, 23] {
            if face.fat.tables.iter().any(|t| t.key == key(fap)) {
                let p = posed(face, fap, 500.0);
                assert!(
                    max_move(n, &p[teeth], avatar::TONGUE) < 1e-6,
                    "teeth points {teeth_points}: FAP {fap} moves the tongue"
                );
            }
        }
    }
}

/// The lids close although the avatar's coarse skin holds each upper lid point on the same
/// vertex as an eye corner (the guard moves the point itself), and the lashes primitive's
/// two halves each follow their own lid.
#[test]
fn lids_close_and_each_eyes_lashes_follow_their_own() {
    let dir = tempfile::tempdir().unwrap();
    let (_, out) = cloned(dir.path());
    let face = &out.face;
    let lashes = face.mesh_index(LASHES).unwrap();
    let neutral = face.neutral_world_positions();
    let n = &neutral[lashes];
    for (fap, lid, own, other) in [
        (19u8, "3.1", LEFT_LASHES, RIGHT_LASHES),
        (20, "3.2", RIGHT_LASHES, LEFT_LASHES),
    ] {
        let (m, v) = face.fp_vertex(lid.parse().unwrap()).unwrap();
        let p = posed(face, fap, 1024.0);
        let down = neutral[m][v as usize].y - p[m][v as usize].y;
        assert!(
            down > 0.0,
            "FAP {fap}: the lid point {lid} does not go down ({down})"
        );
        let lash = own.clone().map(|v| n[v].y - p[lashes][v].y).sum::<f32>() / 8.0;
        eprintln!("FAP {fap}: lid {lid} down {down}, its lashes down {lash}");
        // They ride on their lid's margin: 86 % of the lid point's drop (12–28 % when tied
        // to the closest skin point, the fold above the lid on this coarse skin).
        assert!(lash > 0.8 * down, "FAP {fap}: lashes {lash}, lid {down}");
        assert!(
            max_move(n, &p[lashes], other.clone()) < 1e-6,
            "FAP {fap} moves the other eye's lashes"
        );
    }
}

#[test]
fn the_patched_glb_keeps_the_primitives_validates_and_plays() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let (glb, csv) = write_avatar(d, &source);
    let out = d.join("out.glb");
    let o = support::cli::command()
        .args(["clone".as_ref(), "alma".as_ref(), glb.as_os_str()])
        .args([
            "--fp-target".as_ref(),
            csv.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", support::cli::text(&o.stderr));
    // Every primitive's vertices as they were, in order.
    let (before, after) = (
        fbakit::face::read(&glb).unwrap(),
        fbakit::face::read(&out).unwrap(),
    );
    let (a, b) = (
        before.neutral_world_positions(),
        after.neutral_world_positions(),
    );
    assert_eq!(a.len(), b.len());
    for (m, (x, y)) in before.meshes.iter().zip(a.iter().zip(&b)) {
        assert_eq!(x.len(), y.len(), "{}", m.name);
        assert!(
            x.iter().zip(y).all(|(p, q)| p.distance(*q) < 1e-6),
            "{}",
            m.name
        );
    }
    // The FAT read back from the morph targets moves the parts as the clone did.
    check_eyes(&after);
    check_teeth(&after);
    // Plays.
    let played = d.join("played.glb");
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap");
    let o = support::cli::command()
        .args(["play".as_ref(), out.as_os_str(), sample.as_os_str()])
        .args(["-o".as_ref(), played.as_os_str()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", support::cli::text(&o.stderr));
    // The avatar has a `Head` node (3): head rotations turn it when played, no morph target
    // bakes them (the hat, a child of the node, has none).
    let json_of = |p: &Path| {
        let bytes = std::fs::read(p).unwrap();
        let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
        serde_json::from_slice::<serde_json::Value>(chunks.json).unwrap()
    };
    let (patched, played_json) = (json_of(&out), json_of(&played));
    let names = patched["meshes"][0]["extras"]["targetNames"].to_string();
    assert!(
        names.contains("open_jaw") && !names.contains("head_"),
        "{names}"
    );
    assert!(patched["meshes"][1]["primitives"][0]
        .get("targets")
        .is_none());
    let play = played_json["animations"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == "play")
        .unwrap();
    assert!(
        play["channels"]
            .as_array()
            .unwrap()
            .iter()
            .any(|c| c["target"]["node"] == 3 && c["target"]["path"] == "rotation"),
        "{}",
        play["channels"]
    );
    // No new validator issue.
    let Some(reports) = support::validator::validate(&[glb.clone(), out.clone(), played.clone()])
    else {
        return;
    };
    // Errors and warnings counted (the message list is cut after a hundred infos).
    let issues = |r: &serde_json::Value| (r["errors"].clone(), r["warnings"].clone());
    assert_eq!(issues(&reports[0]), issues(&reports[1]), "{}", reports[1]);
    assert_eq!(issues(&reports[0]), issues(&reports[2]), "{}", reports[2]);
}
