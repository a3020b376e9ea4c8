//! An eye whose iris and eye white the user's document turns apart (issue 19 §1–2): the iris
//! is skinned to an eye joint or hangs under an eye node, while the eye white is held by
//! something the eye's joint or node does not move. Three test avatars ([`support::avatar`]):
//!
//! - **VRoid-like**: the irises (and highlights) are primitives of `Body` skinned to the eye
//!   joints `LeftEye` / `RightEye`; the eye whites are `Body`'s `eyes` primitive weighted to
//!   `Head` alone, as VRoid's `EyeWhite` is.
//! - **Iris on the eye node, white in `Body`**: the nodes `LeftEye` / `RightEye` hold iris
//!   caps; the eye whites stay in `Body`'s `eyes` primitive on `Head`.
//! - **Iris on the eye node, white on its own node**: as above, the eye whites on nodes
//!   `LeftEyeWhite` / `RightEyeWhite` under `Head`, which no eye motion names.
//!
//! The pupils (3.5, 3.6) are on the irises' poles, as an artist or `fp from-landmarks` marks
//! them. Cloned from alma with the CLI, each must come back as one eye per side: under its
//! FAPs 23–26 iris and eye white turn together, rigidly, about the eye white's centre (within
//! 1 % of the eye's radius), the joint or node turning what it holds and the rest of the eye
//! baked into per-vertex rows with the same turn; under the lid FAPs and `open_jaw` the eyes
//! stay; the document comes back whole (nodes, hierarchy, skin, meshes, vertex counts, the
//! user's animation); the glb reads back with the library clone's FAT; `play` turns the eye
//! joints or nodes as the FAT turns the iris; the files add no validator issue (no error, no
//! warning beyond the avatar's one skinned mesh under its scaled root).

mod support;

use std::path::{Path, PathBuf};

use fbakit::clone::face::{clone_face, CloneOptions};
use fbakit::face::{FaceModel, FaceReadOptions};
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::mesh::rotation_fit::fit_rotation;
use fbakit::spec::FapId;
use glam::{DVec3, Mat4, Quat, Vec3};
use serde_json::Value;
use support::avatar::{
    self, IrisNodes, Options, VroidEyes, EYE_WHITE_RADIUS, LEFT_EYE_JOINT, LEFT_EYE_NODE,
    RIGHT_EYE_JOINT, RIGHT_EYE_NODE,
};
use support::glb::floats;

fn key(fap: u8) -> TableKey {
    TableKey::LowLevel(FapId::new(fap).unwrap())
}

/// One test avatar: its options and the nodes that turn its irises (left, right).
struct Case {
    name: &'static str,
    opts: Options,
    nodes: (usize, usize),
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "vroid_white_on_head",
            opts: Options {
                vroid_eyes: Some(VroidEyes {
                    highlight_node: false,
                    iris_share: 1.0,
                }),
                white_on_head: true,
                ..Options::default()
            },
            nodes: (LEFT_EYE_JOINT, RIGHT_EYE_JOINT),
        },
        Case {
            name: "iris_node_white_in_body",
            opts: Options {
                iris_nodes: Some(IrisNodes { white_nodes: false }),
                ..Options::default()
            },
            nodes: (LEFT_EYE_NODE, RIGHT_EYE_NODE),
        },
        Case {
            name: "iris_node_white_node",
            opts: Options {
                iris_nodes: Some(IrisNodes { white_nodes: true }),
                ..Options::default()
            },
            nodes: (LEFT_EYE_NODE, RIGHT_EYE_NODE),
        },
    ]
}

/// Writes the avatar and its feature points (the pupils on the irises' poles, file metres).
fn write_case(d: &Path, source: &FaceModel, case: &Case) -> (PathBuf, PathBuf) {
    let glb = d.join(format!("{}.glb", case.name));
    std::fs::write(&glb, avatar::build_with(&case.opts).to_glb()).unwrap();
    let csv = avatar::fp_csv(source, d, "");
    let text: String = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .map(|l| {
            let at = |left: bool, id: &str| {
                let q = avatar::iris_pole(left) * 0.01;
                format!("{id},{},{},{}\n", q.x, q.y, q.z)
            };
            match l.split(',').next() {
                Some("3.5") => at(true, "3.5"),
                Some("3.6") => at(false, "3.6"),
                _ => format!("{l}\n"),
            }
        })
        .collect();
    let csv = d.join(format!("{}-fp.csv", case.name));
    std::fs::write(&csv, text).unwrap();
    (glb, csv)
}

/// The JSON chunk and the BIN chunk of a glb.
fn glb_parts(p: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(p).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    let json = serde_json::from_slice(chunks.json).unwrap();
    (json, chunks.bin.unwrap_or_default().to_vec())
}

/// World matrix of node `n` at rest, or with a local rotation (and translation) override.
fn node_world(json: &Value, n: usize, over: Option<(Quat, Option<Vec3>)>) -> Mat4 {
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
        if let Some((q, tr)) = over.filter(|_| i == n) {
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

/// One eye's vertices over the face's meshes (mesh, vertex), split into the eye white (on the
/// white's sphere) and the layers in front of it (iris, highlight), found by their rest
/// positions about the eye's centre (file metres); vertices in no polygon left out.
struct EyeVertices {
    centre: Vec3,
    radius: f32,
    white: Vec<(usize, usize)>,
    layers: Vec<(usize, usize)>,
}

fn eye_vertices(face: &FaceModel, left: bool) -> EyeVertices {
    let centre = avatar::eye_centre(left) * 0.01;
    let radius = EYE_WHITE_RADIUS * 0.01;
    let (mut white, mut layers) = (Vec::new(), Vec::new());
    for (m, ps) in face.neutral_world_positions().iter().enumerate() {
        // A vertex in no polygon is never seen and never moves (a sphere's unused pole copy).
        let mut used = vec![false; ps.len()];
        for &v in face.meshes[m].mesh.polygons.indices() {
            used[v as usize] = true;
        }
        for (v, p) in ps.iter().enumerate().filter(|(v, _)| used[*v]) {
            let d = p.distance(centre);
            if (d - radius).abs() < 0.002 * radius {
                white.push((m, v));
            } else if d > radius && d < 1.12 * radius {
                layers.push((m, v));
            }
        }
    }
    EyeVertices {
        centre,
        radius,
        white,
        layers,
    }
}

/// The FAP's extreme interval borders in `face`'s FAT and their halves (±[`TURN`] and halves
/// when the table moves no mesh).
fn values(face: &FaceModel, fap: u8) -> Vec<f64> {
    const TURN: f64 = 20_000.0;
    let Some(t) = face.fat.tables.iter().find(|t| t.key == key(fap)) else {
        return Vec::new();
    };
    let all = t
        .meshes
        .iter()
        .flat_map(|m| m.interval_borders.iter().copied());
    let lo = all.clone().fold(0.0, f64::min);
    let hi = all.fold(0.0, f64::max);
    let (lo, hi) = if t.meshes.is_empty() {
        (-TURN, TURN)
    } else {
        (lo, hi)
    };
    [lo, lo / 2.0, hi / 2.0, hi]
        .into_iter()
        .filter(|v| *v != 0.0)
        .collect()
}

/// The best rigid motion of `rest` onto `moved`: its largest miss, and where it takes `point`.
fn rigid(rest: &[Vec3], moved: &[Vec3], point: Vec3) -> (f32, Vec3) {
    let n = rest.len() as f64;
    let cp = rest.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / n;
    let cq = moved.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / n;
    let fit = fit_rotation(
        rest.iter()
            .zip(moved)
            .map(|(p, q)| (p.as_dvec3() - cp, q.as_dvec3() - cq)),
    )
    .unwrap();
    let miss = rest
        .iter()
        .zip(moved)
        .map(|(p, q)| (fit.rotation * (p.as_dvec3() - cp) + cq - q.as_dvec3()).length() as f32)
        .fold(0.0, f32::max);
    let at = fit.rotation * (point.as_dvec3() - cp) + cq;
    (miss, at.as_vec3())
}

fn largest_move(rest: &[Vec3], moved: &[Vec3]) -> f32 {
    rest.iter()
        .zip(moved)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f32::max)
}

fn at(ps: &[Vec<Vec3>], vs: &[(usize, usize)]) -> Vec<Vec3> {
    vs.iter().map(|&(m, v)| ps[m][v]).collect()
}

/// Checks the eyes of `face` (file metres): each eye's FAPs turn its iris and white as one
/// about the white's centre and leave the other eye; lid FAPs and `open_jaw` leave both.
/// Returns the failures.
fn check_eyes(label: &str, face: &FaceModel) -> Vec<String> {
    let mut failures = Vec::new();
    let rest = face.pose(&[]).unwrap();
    let eyes = [eye_vertices(face, true), eye_vertices(face, false)];
    for (side, e) in ["left", "right"].iter().zip(&eyes) {
        assert!(
            e.white.len() >= 40 && !e.layers.is_empty(),
            "{label} {side}: {} white, {} layer vertices",
            e.white.len(),
            e.layers.len()
        );
    }
    for (k, (faps, lids)) in [([23u8, 25], [19u8, 21]), ([24, 26], [20, 22])]
        .into_iter()
        .enumerate()
    {
        let e = &eyes[k];
        let other = &eyes[1 - k];
        let all: Vec<(usize, usize)> = [e.white.clone(), e.layers.clone()].concat();
        let r = e.radius;
        for fap in faps {
            let vals = values(face, fap);
            if vals.is_empty() {
                failures.push(format!("{label}: no table for FAP {fap}"));
            }
            for value in vals {
                let moved = face
                    .pose(&[Activation {
                        key: key(fap),
                        value,
                    }])
                    .unwrap();
                let (miss, c) = rigid(&at(&rest, &all), &at(&moved, &all), e.centre);
                let turned = largest_move(&at(&rest, &e.layers), &at(&moved, &e.layers));
                let white = largest_move(&at(&rest, &e.white), &at(&moved, &e.white));
                let off = c.distance(e.centre);
                let others = largest_move(&at(&rest, &other.white), &at(&moved, &other.white)).max(
                    largest_move(&at(&rest, &other.layers), &at(&moved, &other.layers)),
                );
                eprintln!(
                    "{label} FAP {fap} @{value}: iris moved {:.4} r, white {:.4} r, rigid miss \
                     {:.5} r, centre off {:.5} r, other eye {:.5} r",
                    turned / r,
                    white / r,
                    miss / r,
                    off / r,
                    others / r
                );
                let mut check = |ok: bool, what: &str| {
                    if !ok {
                        failures.push(format!("{label} FAP {fap} @{value}: {what}"));
                    }
                };
                check(turned > 0.05 * r, "the iris does not turn");
                check(white > 0.01 * r, "the eye white does not turn");
                check(miss <= 0.01 * r, "iris and eye white do not turn as one");
                check(off <= 0.01 * r, "not about the eye white's centre");
                check(others <= 0.01 * r, "the other eye moves");
            }
        }
        for fap in lids.into_iter().chain([3]) {
            for value in values(face, fap) {
                let moved = face
                    .pose(&[Activation {
                        key: key(fap),
                        value,
                    }])
                    .unwrap();
                let m = largest_move(&at(&rest, &all), &at(&moved, &all));
                eprintln!("{label} FAP {fap} @{value}: eye moved {:.5} r", m / r);
                if m > 0.01 * r {
                    failures.push(format!("{label} FAP {fap} @{value}: the eye moves"));
                }
            }
        }
    }
    failures
}

/// The document's structure fbakit must keep: per node its name, mesh, skin, children and
/// rest transform; the skins' joints; per mesh its primitives' vertex counts and attributes;
/// the user's animations, materials, textures, cameras.
fn structure(json: &Value) -> Value {
    let nodes: Vec<Value> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            serde_json::json!([
                n["name"],
                n["mesh"],
                n["skin"],
                n["children"],
                n["translation"],
                n["rotation"],
                n["scale"],
                n["extras"]
            ])
        })
        .collect();
    let meshes: Vec<Value> = json["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            let prims: Vec<Value> = m["primitives"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| {
                    let mut attrs: Vec<&String> =
                        p["attributes"].as_object().unwrap().keys().collect();
                    attrs.sort();
                    let count = |a: &Value| {
                        json["accessors"][a.as_u64().unwrap() as usize]["count"].clone()
                    };
                    serde_json::json!([
                        attrs,
                        count(&p["attributes"]["POSITION"]),
                        count(&p["indices"]),
                        p["material"]
                    ])
                })
                .collect();
            serde_json::json!([m["name"], prims])
        })
        .collect();
    let skins: Vec<Value> = json["skins"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| serde_json::json!([s["name"], s["joints"], s["skeleton"]]))
        .collect();
    let user_animations: Vec<Value> = json["animations"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["name"] != "play")
        .map(|a| serde_json::json!([a["name"], a["channels"]]))
        .collect();
    serde_json::json!({
        "nodes": nodes,
        "meshes": meshes,
        "skins": skins,
        "animations": user_animations,
        "materials": json["materials"],
        "textures": json["textures"],
        "cameras": json["cameras"],
        "scenes": json["scenes"].as_array().unwrap().iter().map(|s| s["nodes"].clone()).collect::<Vec<_>>(),
    })
}

/// A stream of FAPs 23–26 only: per frame (yaw_l, yaw_r, pitch_l, pitch_r).
const GAZE: [[i32; 4]; 4] = [
    [0, 0, 0, 0],
    [20000, 20000, 0, 0],
    [0, 0, 12000, -9000],
    [-15000, 8000, -9000, 7000],
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

/// `play` on `out`: each eye's node or joint turns its iris as the FAT (`back`) does, within
/// 1 % of the eye's radius, at every frame of the gaze stream.
fn check_play(
    d: &Path,
    label: &str,
    out: &Path,
    back: &FaceModel,
    nodes: (usize, usize),
) -> PathBuf {
    let gaze = write_gaze(d);
    let played = d.join(format!("{label}-played.glb"));
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
    assert!(o.status.success(), "{}", support::cli::text(&o.stderr));
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
    let rest = back.pose(&[]).unwrap();
    for (node, left) in [(nodes.0, true), (nodes.1, false)] {
        let e = eye_vertices(back, left);
        let rot =
            channel(node, "rotation").unwrap_or_else(|| panic!("{label}: node {node} not turned"));
        let tr = channel(node, "translation");
        let rest_world = node_world(&pj, node, None);
        for (k, v) in GAZE.iter().enumerate() {
            let q = Quat::from_slice(&rot[4 * k..4 * k + 4]);
            let t = tr.as_ref().map(|t| Vec3::from_slice(&t[3 * k..3 * k + 3]));
            let motion = node_world(&pj, node, Some((q, t))) * rest_world.inverse();
            let want = at(&back.pose(&gaze_activations(v)).unwrap(), &e.layers);
            let played: Vec<Vec3> = at(&rest, &e.layers)
                .iter()
                .map(|&p| motion.transform_point3(p))
                .collect();
            let off = largest_move(&played, &want);
            eprintln!(
                "{label} node {node} frame {k}: played iris off the FAT's by {:.5} r",
                off / e.radius
            );
            assert!(
                off <= 0.01 * e.radius,
                "{label} node {node} frame {k}: played iris off by {:.4} r",
                off / e.radius
            );
        }
    }
    played
}

/// Each avatar cloned from alma (CLI): one eye per side, the document whole, read back with
/// the library clone's FAT, played by its eye joints or nodes, validator clean.
#[test]
fn iris_and_eye_white_held_apart_turn_as_one_eye() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = fbakit::face::read("alma").unwrap();
    let mut failures = Vec::new();
    let mut files = Vec::new();
    for case in cases() {
        let (glb, csv) = write_case(d, &source, &case);
        let out = d.join(format!("{}-out.glb", case.name));
        let o = support::cli::command()
            .args(["clone".as_ref(), "alma".as_ref(), glb.as_os_str()])
            .args(["--fp-target".as_ref(), csv.as_os_str(), "-o".as_ref()])
            .arg(&out)
            .output()
            .unwrap();
        let stderr = support::cli::text(&o.stderr);
        eprintln!("{}: {stderr}", case.name);
        assert!(o.status.success(), "{}: {stderr}", case.name);
        if stderr.contains("is not turned") {
            failures.push(format!("{}: an eye node is not turned", case.name));
        }
        // The document comes back whole.
        let (input, _) = glb_parts(&glb);
        let (patched, _) = glb_parts(&out);
        assert_eq!(structure(&input), structure(&patched), "{}", case.name);
        // Read back: the library clone's FAT.
        let target =
            fbakit::face::read_with(&glb, &FaceReadOptions::with_feature_points(Some(&csv)))
                .unwrap()
                .0;
        let cloned = clone_face(&source, &target, &CloneOptions::default())
            .unwrap()
            .face;
        let back = fbakit::face::read(&out).unwrap();
        failures.extend(check_eyes(&format!("{} (clone)", case.name), &cloned));
        failures.extend(check_eyes(&format!("{} (read back)", case.name), &back));
        let report = support::avatar::same_fat_head_on_node(&cloned, &back);
        assert!(report.equal, "{}: {report}", case.name);
        if !failures.is_empty() {
            continue;
        }
        let played = check_play(d, case.name, &out, &back, case.nodes);
        files.extend([glb, out, played]);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Per avatar (input, clone, played): no error, and no warning the input lacks (the
    // avatar's skinned `Body` under the 0.01-scaled `Armature` is the one it has by design).
    if let Some(reports) = support::validator::validate(&files) {
        for (f, r) in files.chunks(3).zip(reports.chunks(3)) {
            for (file, report) in f.iter().zip(r) {
                assert_eq!(report["errors"], 0, "{}: {report}", file.display());
                assert_eq!(
                    report["warnings"],
                    r[0]["warnings"],
                    "{}: {report}",
                    file.display()
                );
            }
            assert!(r[0]["warnings"].as_u64().unwrap() <= 1, "{}", r[0]);
        }
    }
}
