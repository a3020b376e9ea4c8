//! glTF files as other tools write them: the bundled ICT head and a two-mesh test scene
//! rewritten by `gltf-transform` (quantize, meshopt, draco, weld, reorder, unweld) must read
//! back with the original's positions (vertex for vertex where the tool keeps the order, as
//! point sets where it reorders or splits) and morph targets, or be refused with exit 2 naming
//! the extension. Skipped with a note when `gltf-transform` is absent (see
//! `tests/support/gltf_transform.rs`).

mod support;

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use fbakit::face::FaceReadOptions;
use fbakit::rig::gltf_read::read_gltf;
use fbakit::rig::Rig;
use glam::{IVec3, Vec3};
use support::cli::{command, text};
use support::gltf_transform;

const ICT: &str = "samples/faces/ict-head/ict-head.glb";
const ICT_FP: &str = "samples/faces/ict-head/ict-head-fp.csv";

fn manifest(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// Every vertex of the rig in world space, mesh after mesh.
fn points(rig: &Rig) -> Vec<Vec3> {
    rig.meshes
        .iter()
        .flat_map(|m| m.mesh.positions.iter().copied())
        .collect()
}

/// Each mesh's world positions and its shapes' dense offsets (by shape name), keyed by rank
/// in (vertex count, centroid) order: tools write meshes and nodes in another order and may
/// move a mesh to a new unnamed node (quantize does, to carry the dequantisation transform).
struct Meshes(BTreeMap<String, (Vec<Vec3>, Shapes)>);

/// Dense offsets per shape name.
type Shapes = BTreeMap<String, Vec<Vec3>>;

fn meshes(rig: &Rig) -> Meshes {
    let mut order: Vec<(usize, usize, [i64; 3])> = rig
        .meshes
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let p = &m.mesh.positions;
            let c = p.iter().copied().sum::<Vec3>() / p.len() as f32;
            (p.len(), i, (c * 1000.0).round().as_i64vec3().to_array())
        })
        .collect();
    order.sort_by_key(|&(n, _, c)| (n, c));
    let mut out = BTreeMap::new();
    for (rank, &(_, i, _)) in order.iter().enumerate() {
        let m = &rig.meshes[i];
        let n = m.mesh.positions.len();
        let mut shapes = BTreeMap::new();
        for s in &rig.shapes {
            let mut d = vec![Vec3::ZERO; n];
            for delta in s.deltas.iter().filter(|d| d.mesh == i) {
                for (&v, &o) in delta.vertices.iter().zip(&delta.offsets) {
                    d[v as usize] += o;
                }
            }
            shapes.insert(s.name.clone(), d);
        }
        out.insert(format!("mesh {rank}"), (m.mesh.positions.clone(), shapes));
    }
    Meshes(out)
}

/// The bounding-box diagonal of `p`.
fn size(p: &[Vec3]) -> f32 {
    let (lo, hi) = p.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    (hi - lo).length()
}

/// Points in cells of `tol`, for nearest-point look-ups within `tol`.
struct Grid<'a> {
    tol: f32,
    points: &'a [Vec3],
    cells: HashMap<IVec3, Vec<usize>>,
}

impl<'a> Grid<'a> {
    fn new(points: &'a [Vec3], tol: f32) -> Self {
        let mut cells: HashMap<IVec3, Vec<usize>> = HashMap::new();
        for (i, &p) in points.iter().enumerate() {
            cells
                .entry((p / tol).floor().as_ivec3())
                .or_default()
                .push(i);
        }
        Grid { tol, points, cells }
    }

    /// The nearest point within `tol` of `p`.
    fn nearest(&self, p: Vec3) -> Option<usize> {
        let c = (p / self.tol).floor().as_ivec3();
        let mut best: Option<(f32, usize)> = None;
        for x in -1..=1 {
            for y in -1..=1 {
                for z in -1..=1 {
                    for &i in self
                        .cells
                        .get(&(c + IVec3::new(x, y, z)))
                        .into_iter()
                        .flatten()
                    {
                        let d = self.points[i].distance(p);
                        if d <= self.tol && best.is_none_or(|(bd, _)| d < bd) {
                            best = Some((d, i));
                        }
                    }
                }
            }
        }
        best.map(|(_, i)| i)
    }
}

/// Compares the rewritten meshes `b` with the original `a`: positions within `tol` (vertex for
/// vertex when `order` is kept, else each vertex's nearest twin, both ways), and every shape's
/// offset at each vertex (or its twin) within `tol` plus 2^-9 of the shape's largest offset.
fn compare(a: &Meshes, b: &Meshes, tol: f32, keeps: Keeps) -> Result<(), String> {
    let names_a: Vec<_> = a.0.keys().collect();
    let names_b: Vec<_> = b.0.keys().collect();
    if names_a != names_b {
        return Err(format!("meshes {names_b:?}, expected {names_a:?}"));
    }
    for (name, (pa, sa)) in &a.0 {
        let (pb, sb) = &b.0[name];
        // For each vertex of b, its vertex in a.
        let twin: Vec<usize> =
            match keeps {
                Keeps::Order => {
                    if pa.len() != pb.len() {
                        return Err(format!(
                            "{name}: {} vertices, expected {}",
                            pb.len(),
                            pa.len()
                        ));
                    }
                    (0..pa.len()).collect()
                }
                Keeps::Points => {
                    let grid_b = Grid::new(pb, tol);
                    if let Some(i) = (0..pa.len()).find(|&i| grid_b.nearest(pa[i]).is_none()) {
                        return Err(format!("{name}: original vertex {i} at {} is gone", pa[i]));
                    }
                    let grid_a = Grid::new(pa, tol);
                    let mut twin = Vec::with_capacity(pb.len());
                    for (j, &p) in pb.iter().enumerate() {
                        twin.push(grid_a.nearest(p).ok_or_else(|| {
                            format!("{name}: rewritten vertex {j} at {p} is new")
                        })?);
                    }
                    twin
                }
            };
        for (j, &i) in twin.iter().enumerate() {
            if pa[i].distance(pb[j]) > tol {
                return Err(format!("{name}: vertex {j} at {} vs {}", pb[j], pa[i]));
            }
        }
        if sa.keys().ne(sb.keys()) {
            return Err(format!(
                "{name}: shapes {:?}, expected {:?}",
                sb.keys(),
                sa.keys()
            ));
        }
        for (shape, da) in sa {
            let db = &sb[shape];
            let scale = da.iter().map(|v| v.length()).fold(0.0, f32::max);
            let dtol = tol + scale * 2f32.powi(-9);
            for (j, &i) in twin.iter().enumerate() {
                if da[i].distance(db[j]) > dtol {
                    return Err(format!(
                        "{name}: shape {shape}: vertex {j} moves {} instead of {}",
                        db[j], da[i]
                    ));
                }
            }
        }
    }
    Ok(())
}

/// What a rewrite should keep.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Keeps {
    /// Vertex order (quantize).
    Order,
    /// Only the vertices as a set (meshopt and reorder reorder; weld merges; unweld splits).
    Points,
}

/// Rewrites `input` with each step and checks what it keeps.
fn check_rewrites(input: &Path, dir: &Path, steps: &[(&str, &[&str], Keeps)]) {
    let Some(gt) = gltf_transform::find() else {
        return;
    };
    let original = read_gltf(input).unwrap();
    // 14-bit positions (the quantize default) over the bounding box, with margin.
    let tol = size(&points(&original)) * 2f32.powi(-12);
    let before = meshes(&original);
    for (i, (cmd, args, keeps)) in steps.iter().enumerate() {
        let out = dir.join(format!("{i}-{cmd}.glb"));
        gltf_transform::run(&gt, cmd, input, &out, args);
        let rig = read_gltf(&out).unwrap_or_else(|e| panic!("{cmd} {args:?}: {e}"));
        let what = format!("{} after `{cmd} {}`", input.display(), args.join(" "));
        compare(&before, &meshes(&rig), tol, *keeps).unwrap_or_else(|e| panic!("{what}: {e}"));
        let warned = rig
            .warnings
            .iter()
            .any(|w| w.message.contains("EXT_meshopt_compression"));
        assert_eq!(
            warned,
            *cmd == "meshopt",
            "{what}: warnings {:?}",
            rig.warnings
        );
    }
}

const REWRITES: &[(&str, &[&str], Keeps)] = &[
    ("quantize", &[], Keeps::Order),
    ("quantize", &["--vertex-layout", "separate"], Keeps::Order),
    ("meshopt", &[], Keeps::Points),
    ("meshopt", &["--level", "medium"], Keeps::Points),
    ("weld", &[], Keeps::Points),
    ("reorder", &[], Keeps::Points),
    ("unweld", &[], Keeps::Points),
];

#[test]
fn the_ict_head_rewritten_by_gltf_transform_reads_the_same() {
    let dir = tempfile::tempdir().unwrap();
    check_rewrites(&manifest(ICT), dir.path(), REWRITES);
}

#[test]
fn a_two_mesh_scene_rewritten_by_gltf_transform_reads_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("scene.glb");
    let doc = support::gltf_scenes::two_mesh_scene();
    std::fs::write(&input, doc.to_glb().unwrap()).unwrap();
    check_rewrites(&input, dir.path(), REWRITES);
}

#[test]
fn a_quantized_head_builds_the_same_fat_as_the_original() {
    // quantize keeps the vertex order, so the feature points' vertex ids still fit.
    let Some(gt) = gltf_transform::find() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = gltf_transform::run(
        &gt,
        "quantize",
        &manifest(ICT),
        &dir.path().join("q.glb"),
        &[],
    );
    let opts = FaceReadOptions::with_feature_points(Some(&manifest(ICT_FP)));
    let (a, _) = fbakit::face::read_with(manifest(ICT), &opts).unwrap();
    let (b, _) = fbakit::face::read_with(&out, &opts).unwrap();
    assert!(!a.fat.tables.is_empty());
    assert_eq!(a.fat.tables.len(), b.fat.tables.len());
    assert_eq!(a.feature_points.len(), b.feature_points.len());
}

#[test]
fn draco_is_refused_naming_the_extension_and_reads_after_copy() {
    let Some(gt) = gltf_transform::find() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("scene.glb");
    let doc = support::gltf_scenes::two_mesh_scene();
    std::fs::write(&input, doc.to_glb().unwrap()).unwrap();
    let draco = gltf_transform::run(&gt, "draco", &input, &dir.path().join("d.glb"), &[]);
    let out = command()
        .args(["face", "info"])
        .arg(&draco)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("d.glb")
            && err.contains("`KHR_draco_mesh_compression`")
            && err.contains("gltf-transform/cli copy"),
        "{err}"
    );
    // The advice works: `copy` writes it without Draco, and the points are the original's.
    let plain = gltf_transform::run(&gt, "copy", &draco, &dir.path().join("p.glb"), &[]);
    let a = read_gltf(&input).unwrap();
    let tol = size(&points(&a)) * 2f32.powi(-10);
    let b = read_gltf(&plain).unwrap();
    compare(&meshes(&a), &meshes(&b), tol, Keeps::Points).unwrap();
}
