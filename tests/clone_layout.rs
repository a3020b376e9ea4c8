//! A one-mesh OBJ head (ICT-FaceKit's `generic_neutral_mesh.obj`: skin, eyes, teeth, gums
//! and lashes as pieces of one mesh, from `../shared/data`) cloned and handed back: the same
//! vertices in the same order, as VRML and as the user's own OBJ plus one OBJ per morph
//! target; and the cloned FAT moves each piece as it should (issue 19, §1 and §4).

#[path = "support/ict_truth.rs"]
mod ict_truth;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use fbakit::clone::face::{clone_face, CloneOptions, CloneOutcome, Part};
use fbakit::face::{FaceModel, FaceReadOptions};
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::spec::{FapId, FeaturePointId};
use glam::Vec3;
use ict_truth::ict_dir;

/// ICT's groups (vertex ranges of its README).
const TEETH: std::ops::Range<usize> = 17039..21451;
const LEFT_EYEBALL: std::ops::Range<usize> = 21451..23021;
const RIGHT_EYEBALL: std::ops::Range<usize> = 23021..24591;
const LASHES: std::ops::Range<usize> = 25351..26719;

fn fbakit(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_fbakit"))
        .args(args)
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A temporary folder with ICT's feature points (`fp from-landmarks`), and the OBJ's path.
struct Setup {
    dir: tempfile::TempDir,
    obj: PathBuf,
    fp: PathBuf,
}

fn setup() -> Option<&'static Setup> {
    static S: OnceLock<Option<Setup>> = OnceLock::new();
    S.get_or_init(|| {
        let ict = ict_dir()?;
        let dir = tempfile::tempdir().unwrap();
        let obj = ict.join("generic_neutral_mesh.obj");
        let fp = dir.path().join("fp.csv");
        let o = fbakit(&[
            "fp",
            "from-landmarks",
            s(&obj),
            "--ibug68",
            s(&ict.join("vertex_indices.json")),
            "-o",
            s(&fp),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        Some(Setup { dir, obj, fp })
    })
    .as_ref()
}

fn head(setup: &Setup) -> FaceModel {
    let opts = FaceReadOptions::with_feature_points(Some(&setup.fp));
    fbakit::face::read_with(&setup.obj, &opts).unwrap().0
}

fn cloned() -> Option<&'static (FaceModel, CloneOutcome)> {
    static C: OnceLock<Option<(FaceModel, CloneOutcome)>> = OnceLock::new();
    C.get_or_init(|| {
        let setup = setup()?;
        let head = head(setup);
        let alma = fbakit::face::read("alma").unwrap();
        let out = clone_face(&alma, &head, &CloneOptions::default()).unwrap();
        Some((head, out))
    })
    .as_ref()
}

/// Per vertex of the one mesh, its displacement at `fap` = `value`.
fn displacements(face: &FaceModel, fap: u8, value: f64) -> Vec<Vec3> {
    let key = TableKey::LowLevel(FapId::new(fap).unwrap());
    let neutral = face.pose(&[]).unwrap();
    let posed = face.pose(&[Activation { key, value }]).unwrap();
    neutral[0]
        .iter()
        .zip(&posed[0])
        .map(|(a, b)| *b - *a)
        .collect()
}

fn mean(d: &[Vec3], vs: impl Iterator<Item = usize>) -> f32 {
    let (sum, n) = vs.fold((0.0, 0), |(s, n), v| (s + d[v].length(), n + 1));
    sum / n.max(1) as f32
}

#[test]
fn the_obj_head_comes_back_vertex_for_vertex() {
    let Some((head, out)) = cloned() else { return };
    let face = &out.face;
    assert!(
        out.report.split_parts.len() >= 4,
        "{:?}",
        out.report.split_parts
    );
    assert_eq!(face.meshes.len(), 1);
    assert_eq!(face.meshes[0].mesh.positions.len(), 26_719);
    assert_eq!(face.meshes[0].mesh, head.meshes[0].mesh);
    assert_eq!(
        face.neutral_world_positions(),
        head.neutral_world_positions()
    );
}

#[test]
fn the_jaw_carries_the_lower_teeth_and_lids_the_lashes() {
    let Some((head, out)) = cloned() else { return };
    let face = &out.face;
    let fp = |id: &str| {
        head.feature_points
            .position(id.parse::<FeaturePointId>().unwrap())
            .unwrap()
    };
    let p = &head.meshes[0].mesh.positions;
    let lip_y = (fp("2.2").y + fp("2.3").y) / 2.0;
    let chin = (0..p.len())
        .min_by(|&a, &b| {
            p[a].distance(fp("2.1"))
                .total_cmp(&p[b].distance(fp("2.1")))
        })
        .unwrap();
    let d = displacements(face, 3, 1024.0); // open_jaw
    let c = d[chin].length();
    // Which teeth are upper or lower: as the clone cut them (ICT's lower incisors reach
    // above the lip line behind the upper ones).
    let cut = |part: Part| -> HashSet<usize> {
        out.report
            .split_parts
            .iter()
            .filter(|s| s.part == part)
            .flat_map(|s| s.source_vertices.iter().map(|&v| v as usize))
            .filter(|v| TEETH.contains(v))
            .collect()
    };
    let (lower_teeth, upper_teeth) = (cut(Part::LowerTeeth), cut(Part::UpperTeeth));
    assert!(lower_teeth.len() > 1000 && upper_teeth.len() > 1000);
    let below = lower_teeth.iter().filter(|&&v| p[v].y < lip_y).count();
    assert!(
        below > lower_teeth.len() / 2,
        "lower teeth mostly below the lip line"
    );
    let lower = mean(&d, lower_teeth.iter().copied());
    let upper = mean(&d, upper_teeth.iter().copied());
    eprintln!("open_jaw: chin {c:.4}, lower teeth {lower:.4}, upper teeth {upper:.5}");
    assert!(c > 0.1);
    assert!(lower >= 0.5 * c, "lower teeth {lower} vs chin {c}");
    assert!(upper < 0.05 * c, "upper teeth {upper} vs chin {c}");
    // Eyeballs stay still for the jaw and the lids.
    for fap in [3, 19, 20] {
        let d = displacements(face, fap, 1024.0);
        let eye = LEFT_EYEBALL
            .chain(RIGHT_EYEBALL)
            .map(|v| d[v].length())
            .fold(0.0, f32::max);
        assert!(eye < 1e-5, "FAP {fap} moves an eyeball by {eye}");
    }
    // close_t_l_eyelid: the upper lashes of that eye go down with the lid.
    let (l, r) = (fp("3.5"), fp("3.6"));
    let d = displacements(face, 19, 512.0);
    let lid = d.iter().map(|x| x.length()).fold(0.0, f32::max);
    let lashes: Vec<usize> = LASHES
        .filter(|&v| p[v].distance(l) < p[v].distance(r) && p[v].y > l.y)
        .collect();
    assert!(lashes.len() > 100, "{}", lashes.len());
    let moved = mean(&d, lashes.iter().copied());
    let down = lashes.iter().map(|&v| d[v].y).sum::<f32>() / lashes.len() as f32;
    eprintln!(
        "close_t_l_eyelid: lid peak {lid:.4}, upper left lashes mean {moved:.4}, down {down:.4}"
    );
    // The lashes ride on the lid's margin: 72 % of the lid's peak on average (the peak is
    // the margin's middle; the lashes towards the corners move less), 12 % when they were
    // tied to the closest skin point (often the lid's fold).
    assert!(moved > 0.65 * lid, "lashes {moved} vs lid {lid}");
    assert!(down < 0.0, "the lashes go up ({down})");
}

#[test]
fn eyeball_faps_move_only_eyeball_vertices() {
    let Some((_, out)) = cloned() else { return };
    let face = &out.face;
    for (fap, eye) in [
        (23, LEFT_EYEBALL),
        (24, RIGHT_EYEBALL),
        (25, LEFT_EYEBALL),
        (26, RIGHT_EYEBALL),
    ] {
        let eye: HashSet<usize> = eye.collect();
        let d = displacements(face, fap, 10_000.0);
        let inside = mean(&d, eye.iter().copied());
        let outside = (0..d.len())
            .filter(|v| !eye.contains(v))
            .map(|v| d[v].length())
            .fold(0.0, f32::max);
        assert!(inside > 0.01, "FAP {fap}: the eyeball moves {inside}");
        assert!(
            outside < 1e-6,
            "FAP {fap} moves other vertices by {outside}"
        );
    }
}

/// Lines that are not `v` statements.
fn non_v_lines(text: &str) -> Vec<&str> {
    text.lines()
        .filter(|l| !l.trim_start().starts_with("v "))
        .collect()
}

#[test]
fn cli_outputs_keep_the_users_obj() {
    let Some(setup) = setup() else { return };
    let d = setup.dir.path();
    let source = std::fs::read_to_string(&setup.obj).unwrap();
    let original = fbakit::mesh::obj::parse_obj_positions(&source, &setup.obj).unwrap();

    // VRML out: one mesh, every vertex in its place and order.
    let wrl = d.join("out.wrl");
    let args = ["--fp-target", s(&setup.fp), "--method", "fmc"];
    let o = fbakit(&[&["clone", "alma", s(&setup.obj), "-o", s(&wrl)], &args[..]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let back = fbakit::face::read(&wrl).unwrap();
    assert_eq!(back.meshes.len(), 1);
    assert_eq!(back.neutral_world_positions()[0], original);

    // A shape set: the user's file as the neutral, and each shape the same file with only its
    // `v` lines changed.
    let set = d.join("shapes/");
    let o = fbakit(
        &[
            &["clone", "alma", s(&setup.obj), "-o", s(&set), "--json"],
            &args[..],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["shapes"]["user_layout"], true, "{}", v["shapes"]);
    assert_eq!(
        std::fs::read_to_string(set.join("neutral.obj")).unwrap(),
        source
    );
    let shapes = v["shapes"]["shapes"].as_array().unwrap();
    assert!(shapes.len() >= 60, "{} shapes", shapes.len());
    let keep = non_v_lines(&source);
    let jaw = set.join("open_jaw.obj");
    assert!(jaw.is_file());
    for f in shapes {
        let f = Path::new(f.as_str().unwrap());
        let text = std::fs::read_to_string(f).unwrap();
        assert_eq!(non_v_lines(&text), keep, "{}", f.display());
        let pos = fbakit::mesh::obj::parse_obj_positions(&text, f).unwrap();
        assert_eq!(pos.len(), original.len());
    }
    let moved =
        fbakit::mesh::obj::parse_obj_positions(&std::fs::read_to_string(&jaw).unwrap(), &jaw)
            .unwrap();
    let lower_teeth_moved = TEETH
        .filter(|&v| moved[v].distance(original[v]) > 1e-3)
        .count();
    assert!(
        lower_teeth_moved > 500,
        "{lower_teeth_moved} teeth vertices move with the jaw"
    );
    // The set reads back as a face with a FAT.
    let o = fbakit(&[
        "face",
        "from-morphs",
        s(&set.join("neutral.obj")),
        s(&set),
        "--fp",
        s(&set.join("feature-points.csv")),
        "-o",
        s(&d.join("from-set.wrl")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // `.obj` out with ARKit names: the neutral at OUT.obj, the shapes beside it.
    let out = d.join("head-arkit.obj");
    let o = fbakit(
        &[
            &[
                "clone",
                "alma",
                s(&setup.obj),
                "-o",
                s(&out),
                "--names",
                "arkit",
            ],
            &args[..],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), source);
    let jaw_open = d.join("head-arkit_shapes/jawOpen.obj");
    let text = std::fs::read_to_string(&jaw_open).unwrap();
    assert_eq!(non_v_lines(&text), keep);
    assert_ne!(
        fbakit::mesh::obj::parse_obj_positions(&text, &jaw_open).unwrap(),
        original
    );
}

/// The same head modelled facing −z (turned 180° about y, as VRM 0.x avatars and some scans
/// are) has its eyes, teeth and gums recognised as the upright one's (they were cloned as
/// skin: no part was cut, the eyes' turns were dropped), and its clone is the upright clone
/// turned: every FAP moves every vertex as the upright clone turned 180°.
#[test]
fn a_head_facing_back_clones_as_the_upright_one_turned() {
    let Some((_, upright)) = cloned() else { return };
    let setup = setup().unwrap();
    let turn = |p: Vec3| Vec3::new(-p.x, p.y, -p.z);
    let mut head = head(setup);
    for p in &mut head.meshes[0].mesh.positions {
        *p = turn(*p);
    }
    let ids: Vec<FeaturePointId> = head.feature_points.iter().map(|p| p.id).collect();
    for id in ids {
        let mut p = head.feature_points.remove(id).unwrap();
        p.position = p.position.map(turn);
        head.feature_points.insert(p);
    }
    let alma = fbakit::face::read("alma").unwrap();
    let back = clone_face(&alma, &head, &CloneOptions::default()).unwrap();
    let parts = |o: &CloneOutcome| -> Vec<(Part, usize)> {
        o.report
            .split_parts
            .iter()
            .map(|p| (p.part, p.vertices))
            .collect()
    };
    assert_eq!(parts(&back), parts(upright));
    let keys = |f: &FaceModel| -> Vec<TableKey> { f.fat.tables.iter().map(|t| t.key).collect() };
    assert_eq!(keys(&back.face), keys(&upright.face));
    // Each table at its largest border: the turned clone's motion is the upright one's
    // turned, at every vertex (up to rounding: within 0.01 % of the motion's peak).
    let mut worst = (0.0f32, String::new());
    for t in &upright.face.fat.tables {
        let value = t
            .meshes
            .iter()
            .flat_map(|m| m.interval_borders.iter().copied())
            .fold(0.0f64, |a, b| if b.abs() > a.abs() { b } else { a });
        let at = |f: &FaceModel| -> Vec<Vec3> {
            let neutral = f.pose(&[]).unwrap();
            let posed = f.pose(&[Activation { key: t.key, value }]).unwrap();
            neutral[0]
                .iter()
                .zip(&posed[0])
                .map(|(a, b)| *b - *a)
                .collect()
        };
        let (a, b) = (at(&upright.face), at(&back.face));
        let peak = a.iter().map(|d| d.length()).fold(0.0f32, f32::max);
        if peak == 0.0 {
            continue;
        }
        let off = a
            .iter()
            .zip(&b)
            .map(|(a, b)| turn(*a).distance(*b))
            .fold(0.0f32, f32::max)
            / peak;
        if off > worst.0 {
            worst = (off, format!("{}@{value}", t.key));
        }
    }
    eprintln!(
        "facing back vs upright: worst {:.5} % of the peak ({})",
        100.0 * worst.0,
        worst.1
    );
    assert!(worst.0 < 1e-4, "{worst:?}");
}
