//! A glTF face written back is the user's document, whole, plus fbakit's morph targets,
//! records and animation (issue 19 §2).

mod support;

use std::path::Path;

use fbakit::face::FaceModel;
use fbakit::fat::{FaceDefMesh, FaceDefTable, TableKey};
use fbakit::spec::FapId;
use glam::Vec3;
use serde_json::Value;
use support::avatar;
use support::cli::{command, text};

fn key(name: &str) -> TableKey {
    TableKey::LowLevel(FapId::from_name(name).unwrap())
}

/// The JSON of a `.glb` or `.gltf` file.
fn json_of(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    if bytes.starts_with(b"glTF") {
        let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
        serde_json::from_slice(chunks.json).unwrap()
    } else {
        serde_json::from_slice(&bytes).unwrap()
    }
}

/// A FAT on the avatar's face: the jaw (three intervals) moves the lower skin and the whole
/// mouth, the upper eyelid (one interval) moves the lashes.
fn with_fat(mut face: FaceModel) -> FaceModel {
    let skin = face.mesh_index("Body.0").expect("skin primitive");
    let centre_y = avatar::HEAD_CENTRE.y * 0.01;
    let lower: Vec<u32> = face.meshes[skin]
        .mesh
        .positions
        .iter()
        .enumerate()
        .filter(|(_, p)| p.y < centre_y - 0.03)
        .map(|(i, _)| i as u32)
        .collect();
    assert!(!lower.is_empty());
    let jaw_entry = |mesh: &str, vertices: Vec<u32>| {
        let n = 3;
        let displacements = vertices
            .iter()
            .flat_map(|&v| {
                (0..n).map(move |j| Vec3::new(0.0, -1e-5 * (1.0 + j as f32), 2e-6 * (v % 3) as f32))
            })
            .collect();
        FaceDefMesh {
            mesh: mesh.into(),
            interval_borders: vec![-512.0, 0.0, 512.0, 1024.0],
            coord_index: vertices,
            displacements,
        }
    };
    let mouth: Vec<u32> = (0..face.meshes[face.mesh_index("Body.1").unwrap()]
        .mesh
        .vertex_count() as u32)
        .collect();
    let lashes: Vec<u32> = (0..face.meshes[face.mesh_index("Body.3").unwrap()]
        .mesh
        .vertex_count() as u32)
        .collect();
    face.fat.tables = vec![
        FaceDefTable {
            key: key("open_jaw"),
            meshes: vec![jaw_entry("Body.0", lower), jaw_entry("Body.1", mouth)],
            transforms: vec![],
        },
        FaceDefTable {
            key: key("close_t_l_eyelid"),
            meshes: vec![FaceDefMesh {
                mesh: "Body.3".into(),
                interval_borders: vec![0.0, 1000.0],
                displacements: vec![Vec3::new(0.0, -4e-6, 0.0); lashes.len()],
                coord_index: lashes,
            }],
            transforms: vec![],
        },
    ];
    face
}

/// Everything `input` has is in `output` unchanged, except what a patch may change: merged
/// buffers (offsets of views), appended accessors/views/targets/animations, mesh
/// `extras`/`weights` grown, the user's weight channels re-pointed, scene extras added.
fn assert_kept(input: &Value, output: &Value) {
    let obj = input.as_object().unwrap();
    for (k, v) in obj {
        match k.as_str() {
            "buffers" => assert_eq!(output["buffers"].as_array().unwrap().len(), 1),
            "bufferViews" | "accessors" => {
                let (a, b) = (v.as_array().unwrap(), output[k].as_array().unwrap());
                assert!(b.len() >= a.len(), "{k} shrank");
                for (i, (x, y)) in a.iter().zip(b).enumerate() {
                    let (mut x, mut y) = (x.clone(), y.clone());
                    if k == "bufferViews" {
                        for o in [&mut x, &mut y] {
                            let o = o.as_object_mut().unwrap();
                            o.remove("buffer");
                            o.remove("byteOffset");
                        }
                    }
                    assert_eq!(x, y, "{k}[{i}] changed");
                }
            }
            "meshes" => {
                for (m, (x, y)) in v
                    .as_array()
                    .unwrap()
                    .iter()
                    .zip(output[k].as_array().unwrap())
                    .enumerate()
                {
                    for (f, xv) in x.as_object().unwrap() {
                        match f.as_str() {
                            "primitives" => {
                                for (p, (xp, yp)) in xv
                                    .as_array()
                                    .unwrap()
                                    .iter()
                                    .zip(y[f].as_array().unwrap())
                                    .enumerate()
                                {
                                    for (pf, pv) in xp.as_object().unwrap() {
                                        if pf == "targets" {
                                            let yt = yp[pf].as_array().unwrap();
                                            assert_eq!(
                                                &yt[..pv.as_array().unwrap().len()],
                                                &pv.as_array().unwrap()[..],
                                                "meshes[{m}].primitives[{p}] targets"
                                            );
                                        } else {
                                            assert_eq!(
                                                pv, &yp[pf],
                                                "meshes[{m}].primitives[{p}].{pf}"
                                            );
                                        }
                                    }
                                }
                            }
                            "extras" => {
                                for (ek, ev) in xv.as_object().unwrap() {
                                    if ek == "targetNames" {
                                        let ya = y[f][ek].as_array().unwrap();
                                        assert_eq!(
                                            &ya[..ev.as_array().unwrap().len()],
                                            &ev.as_array().unwrap()[..]
                                        );
                                    } else {
                                        assert_eq!(ev, &y[f][ek], "meshes[{m}].extras.{ek}");
                                    }
                                }
                            }
                            "weights" => {
                                let ya = y[f].as_array().unwrap();
                                assert_eq!(
                                    &ya[..xv.as_array().unwrap().len()],
                                    &xv.as_array().unwrap()[..]
                                );
                            }
                            _ => assert_eq!(xv, &y[f], "meshes[{m}].{f}"),
                        }
                    }
                }
            }
            "animations" => {
                let b = output[k].as_array().unwrap();
                for (i, x) in v.as_array().unwrap().iter().enumerate() {
                    assert_eq!(x["channels"], b[i]["channels"], "animations[{i}].channels");
                    assert_eq!(x["name"], b[i]["name"]);
                    for (s, (xs, ys)) in x["samplers"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .zip(b[i]["samplers"].as_array().unwrap())
                        .enumerate()
                    {
                        assert_eq!(xs["input"], ys["input"], "animations[{i}].samplers[{s}]");
                        assert_eq!(xs["interpolation"], ys["interpolation"]);
                    }
                }
            }
            "scenes" => {
                for (s, (x, y)) in v
                    .as_array()
                    .unwrap()
                    .iter()
                    .zip(output[k].as_array().unwrap())
                    .enumerate()
                {
                    for (f, xv) in x.as_object().unwrap() {
                        if f == "extras" {
                            for (ek, ev) in xv.as_object().unwrap() {
                                assert_eq!(ev, &y[f][ek], "scenes[{s}].extras.{ek}");
                            }
                        } else {
                            assert_eq!(xv, &y[f], "scenes[{s}].{f}");
                        }
                    }
                }
            }
            _ => assert_eq!(v, &output[k], "`{k}` changed"),
        }
    }
}

fn fat_close(a: &fbakit::fat::Fat, b: &fbakit::fat::Fat) {
    assert_eq!(a.tables.len(), b.tables.len());
    for (x, y) in a.tables.iter().zip(&b.tables) {
        assert_eq!(x.key, y.key);
        assert_eq!(x.meshes.len(), y.meshes.len(), "{:?}", x.key);
        for (p, q) in x.meshes.iter().zip(&y.meshes) {
            assert_eq!(p.mesh, q.mesh);
            assert_eq!(p.interval_borders, q.interval_borders);
            assert_eq!(p.coord_index, q.coord_index, "{} {:?}", p.mesh, x.key);
            for (d, e) in p.displacements.iter().zip(&q.displacements) {
                assert!(
                    (*d - *e).length() <= 1e-4 * d.length().max(1e-6),
                    "{} {d} {e}",
                    p.mesh
                );
            }
        }
    }
}

#[test]
fn avatar_reads_in_its_rest_pose() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("avatar.glb");
    let a = avatar::build();
    std::fs::write(&path, a.to_glb()).unwrap();
    let face = fbakit::face::read(&path).unwrap();
    let names: Vec<&str> = face.meshes.iter().map(|m| m.name.as_str()).collect();
    // Depth first: the hat hangs under the head joint, before the armature's Body node.
    assert_eq!(names, ["Hat", "Body.0", "Body.1", "Body.2", "Body.3"]);
    // The 0.01-scaled armature places the skin in metres.
    let skin = &face.meshes[1].mesh.positions;
    assert!((skin[0] - a.prims[0].positions[0] * 0.01).length() < 1e-5);
    // The mouth follows the jaw's rest, 70 % of half a centimetre below its bind.
    let mouth = &face.meshes[2].mesh.positions;
    let want = a.prims[1].positions[0] * 0.01 - Vec3::new(0.0, 0.7 * 0.005, 0.0);
    assert!((mouth[0] - want).length() < 1e-5, "{} {}", mouth[0], want);
    // The hat hangs under the head joint: (0, 160, 0) cm + its own 8 cm.
    let hat = &face.meshes[0].mesh.positions;
    assert!(
        (hat[4] - Vec3::new(0.0, 1.8, 0.0)).length() < 1e-5,
        "{}",
        hat[4]
    );
    let source = face.gltf_source.as_ref().expect("document kept");
    assert_eq!(source.parts.len(), 5);
}

#[test]
fn avatar_comes_back_whole_with_its_fat() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("avatar.glb");
    let a = avatar::build();
    std::fs::write(&input, a.to_glb()).unwrap();
    let face = with_fat(fbakit::face::read(&input).unwrap());
    let out = dir.path().join("out.glb");
    let warnings = fbakit::export::write_face(&out, &face).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let (x, y) = (json_of(&input), json_of(&out));
    assert_kept(&x, &y);
    // Every primitive of Body carries the same list: Blink + the new targets.
    let names = y["meshes"][0]["extras"]["targetNames"].as_array().unwrap();
    assert_eq!(names[0], "Blink");
    assert!(names.len() > 1);
    for p in y["meshes"][0]["primitives"].as_array().unwrap() {
        assert_eq!(p["targets"].as_array().unwrap().len(), names.len());
    }
    assert_eq!(
        y["meshes"][0]["weights"].as_array().unwrap().len(),
        names.len()
    );
    // The user's Blink channel got one zero per new target.
    let widened = &y["animations"][0]["samplers"][1]["output"];
    let count = y["accessors"][widened.as_u64().unwrap() as usize]["count"]
        .as_u64()
        .unwrap();
    assert_eq!(count as usize, 3 * names.len());
    // Read back: same meshes in the same order, same positions, same FAT.
    let back = fbakit::face::read(&out).unwrap();
    assert_eq!(back.meshes.len(), face.meshes.len());
    for (p, q) in face.meshes.iter().zip(&back.meshes) {
        assert_eq!(p.name, q.name);
        assert_eq!(p.mesh.positions, q.mesh.positions);
        assert_eq!(p.mesh.polygons, q.mesh.polygons);
    }
    fat_close(&face.fat, &back.fat);
    // Written again, the second patch appends nothing the first did not have.
    let again = dir.path().join("again.glb");
    fbakit::export::write_face(&again, &back).unwrap();
    let third = fbakit::face::read(&again).unwrap();
    fat_close(&face.fat, &third.fat);
}

#[test]
fn external_gltf_gets_its_own_bin_and_images() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("in");
    std::fs::create_dir_all(&src).unwrap();
    let input = avatar::build().write_gltf(&src, "avatar");
    let face = with_fat(fbakit::face::read(&input).unwrap());
    let out_dir = dir.path().join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    let out = out_dir.join("patched.gltf");
    fbakit::export::write_face(&out, &face).unwrap();
    let y = json_of(&out);
    assert_eq!(y["buffers"][0]["uri"], "patched.bin");
    assert!(out_dir.join("patched.bin").is_file());
    assert!(out_dir.join("textures/skin.png").is_file());
    assert_kept(&json_of(&input), &y);
    let back = fbakit::face::read(&out).unwrap();
    fat_close(&face.fat, &back.fat);
}

#[test]
fn patched_avatar_plays_into_its_own_document() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("avatar.glb");
    std::fs::write(&input, avatar::build().to_glb()).unwrap();
    let face = with_fat(fbakit::face::read(&input).unwrap());
    let patched = dir.path().join("patched.glb");
    fbakit::export::write_face(&patched, &face).unwrap();
    let played = dir.path().join("played.glb");
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap");
    let out = command()
        .args([
            "play".as_ref(),
            patched.as_os_str(),
            sample.as_os_str(),
            "-o".as_ref(),
            played.as_os_str(),
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (x, y) = (json_of(&patched), json_of(&played));
    let anims = y["animations"].as_array().unwrap();
    assert_eq!(anims.len(), 2, "the user's animation and `play`");
    assert_eq!(anims[1]["name"], "play");
    let ch = &anims[1]["channels"][0];
    assert_eq!(ch["target"]["node"], 5, "weights on the Body node");
    // The stream's head pitch and yaw turn the node named Head (the FAT has no table for them).
    let head: Vec<&Value> = anims[1]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["target"]["path"] == "rotation")
        .collect();
    assert_eq!(head.len(), 1);
    assert_eq!(head[0]["target"]["node"], 3);
    // Named nodes: the hat turns instead.
    let hat = dir.path().join("hat.glb");
    let out = command()
        .args([
            "play".as_ref(),
            patched.as_os_str(),
            sample.as_os_str(),
            "-o".as_ref(),
            hat.as_os_str(),
            "--head-node".as_ref(),
            "Hat".as_ref(),
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let y2 = json_of(&hat);
    let rot: Vec<&Value> = y2["animations"][1]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["target"]["path"] == "rotation")
        .collect();
    assert_eq!(rot[0]["target"]["node"], 6);
    // Played from a patched file: the targets are not added a second time.
    assert_eq!(
        x["meshes"][0]["extras"]["targetNames"],
        y["meshes"][0]["extras"]["targetNames"]
    );
}

#[test]
fn validator_finds_no_new_issue() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("avatar.glb");
    std::fs::write(&input, avatar::build().to_glb()).unwrap();
    let face = with_fat(fbakit::face::read(&input).unwrap());
    let out = dir.path().join("out.glb");
    fbakit::export::write_face(&out, &face).unwrap();
    let ext = avatar::build().write_gltf(dir.path(), "ext");
    let face = with_fat(fbakit::face::read(&ext).unwrap());
    let out2 = dir.path().join("out2.gltf");
    fbakit::export::write_face(&out2, &face).unwrap();
    let Some(reports) =
        support::validator::validate(&[input.clone(), out.clone(), ext.clone(), out2.clone()])
    else {
        return;
    };
    let issues = support::validator::issue_codes;
    if std::env::var_os("FBAKIT_SHOW_VALIDATOR").is_some() {
        for r in &reports {
            eprintln!("{r}");
        }
    }
    assert_eq!(issues(&reports[0]), issues(&reports[1]), "{}", reports[1]);
    assert_eq!(issues(&reports[2]), issues(&reports[3]), "{}", reports[3]);
}

#[test]
fn generated_glb_reads_back_with_its_fat() {
    let dir = tempfile::tempdir().unwrap();
    let face = fbakit::synth::alma().to_face_model();
    let glb = dir.path().join("alma.glb");
    fbakit::export::write_face(&glb, &face).unwrap();
    let back = fbakit::face::read(&glb).unwrap();
    // The file is in metres; the face comes back in its own units and transforms
    // (`faceUnit` and `transforms` in the scene record), feature points included, without --fp.
    let json = json_of(&glb);
    let (k, _) = fbakit::face::units::metres_factor(&face, None);
    assert_eq!(
        json["scenes"][0]["extras"]["fbakit"]["faceUnit"],
        serde_json::json!(k)
    );
    assert_eq!(back.transforms, face.transforms);
    assert_eq!(back.feature_points.len(), face.feature_points.len());
    let mut compared = 0;
    for table in &face.fat.tables {
        let Some(got) = back.fat.tables.iter().find(|t| t.key == table.key) else {
            assert!(table.meshes.is_empty(), "{:?} lost", table.key);
            continue;
        };
        for m in &table.meshes {
            let g = got
                .meshes
                .iter()
                .find(|g| g.mesh == m.mesh)
                .expect("entry kept");
            assert_eq!(g.interval_borders, m.interval_borders);
            let n = m.interval_count();
            for (slot, v) in m.coord_index.iter().enumerate() {
                let Ok(gs) = g.coord_index.binary_search(v) else {
                    // Not moved in any interval: nothing to write.
                    assert!((0..n).all(|j| m.displacements[slot * n + j] == Vec3::ZERO));
                    continue;
                };
                for j in 0..n {
                    let want = m.displacements[slot * n + j];
                    let have = g.displacements[gs * n + j];
                    assert!(
                        (want - have).length() <= 1e-4 * want.length() + 1e-9,
                        "{:?} {} {want} {have}",
                        table.key,
                        m.mesh
                    );
                    compared += 1;
                }
            }
        }
    }
    assert!(compared > 1000, "{compared}");
}

#[test]
fn exported_ict_keeps_its_vertices_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ict.glb");
    let run = command()
        .args([
            "face".as_ref(),
            "export".as_ref(),
            "ict".as_ref(),
            "-o".as_ref(),
            out.as_os_str(),
        ])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", text(&run.stderr));
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/faces/ict-head/ict-head.glb");
    let (x, y) = (json_of(&input), json_of(&out));
    assert_kept(&x, &y);
    let (a, b) = (
        fbakit::face::read(&input).unwrap(),
        fbakit::face::read(&out).unwrap(),
    );
    assert_eq!(a.meshes.len(), b.meshes.len());
    for (p, q) in a.meshes.iter().zip(&b.meshes) {
        assert_eq!(p.mesh.positions, q.mesh.positions);
        assert_eq!(p.mesh.polygons, q.mesh.polygons);
    }
    // The FAT built from ICT's shapes (with its feature points) came along in the extras.
    let ict = fbakit::face::read("ict").unwrap();
    assert_eq!(
        b.fat.tables.len(),
        ict.fat
            .tables
            .iter()
            .filter(|t| !t.meshes.is_empty())
            .count()
    );
    assert_eq!(b.feature_points.len(), ict.feature_points.len());
}

#[test]
fn target_names_that_do_not_match_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = avatar::build();
    a.json["meshes"][0]["extras"]["targetNames"] = serde_json::json!(["Blink", "Extra"]);
    let input = dir.path().join("bad.glb");
    std::fs::write(&input, a.to_glb()).unwrap();
    let out = dir.path().join("out.glb");
    let run = support::cli::face_export(&input, &out);
    assert_eq!(run.status.code(), Some(2), "{}", text(&run.stderr));
    let err = text(&run.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("bad.glb") && err.contains("meshes[0].extras.targetNames"),
        "{err}"
    );
    assert!(!out.exists());
}

/// The test avatar without `scene` and `scenes`, written as `dir/noscene.glb`.
fn sceneless_avatar(dir: &std::path::Path) -> std::path::PathBuf {
    let mut a = avatar::build();
    let o = a.json.as_object_mut().unwrap();
    o.remove("scene");
    o.remove("scenes");
    let input = dir.join("noscene.glb");
    std::fs::write(&input, a.to_glb()).unwrap();
    input
}

#[test]
fn a_file_without_scenes_reads_every_mesh_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let input = sceneless_avatar(dir.path());
    let (face, report) = fbakit::face::read_with(&input, &Default::default()).unwrap();
    assert_eq!(face.meshes.len(), 5);
    assert!(
        report
            .diagnostics
            .iter()
            .any(|d| d.message.contains("no scene")),
        "{:?}",
        report.diagnostics
    );
}

/// What the reader noticed is said by the commands users run, once and with the file named
/// once: `clone` onto a file without a scene warns (it said nothing), `face info` lists it
/// without `warning: FILE:` twice.
#[test]
fn reader_warnings_are_said_once_by_clone_and_face_info() {
    let dir = tempfile::tempdir().unwrap();
    let input = sceneless_avatar(dir.path());
    let alma = fbakit::face::read("alma").unwrap();
    let fp = avatar::fp_csv(&alma, dir.path(), "");
    let stderr = support::cli::clone_alma_to(&input, &fp, &dir.path().join("out.glb"));
    let said: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("the file has no scene"))
        .collect();
    assert_eq!(said.len(), 1, "{stderr}");
    assert_eq!(said[0].matches("noscene.glb").count(), 1, "{}", said[0]);
    assert!(said[0].starts_with("warning: "), "{}", said[0]);
    let o = command()
        .args(["face".as_ref(), "info".as_ref(), input.as_os_str()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let line = out
        .lines()
        .find(|l| l.contains("the file has no scene"))
        .unwrap_or_else(|| panic!("{out}"));
    assert_eq!(line.matches("noscene.glb").count(), 1, "{line}");
    assert_eq!(line.matches("warning:").count(), 1, "{line}");
}

/// The avatar's face with its FAT and feature points (metres, the file's world frame) for
/// the FAP units and the chin.
fn with_points(face: FaceModel) -> FaceModel {
    let mut face = with_fat(face);
    let c = avatar::HEAD_CENTRE * 0.01;
    let at = |x: f32, y: f32, z: f32| c + Vec3::new(x, y, z) * 0.01;
    for (id, p) in [
        ("2.1", at(0.0, -9.0, 4.0)),
        ("2.2", at(0.0, -4.0, 9.0)),
        ("3.1", at(3.2, 2.6, 8.6)),
        ("3.3", at(3.2, 1.4, 8.6)),
        ("3.5", at(3.2, 2.0, 8.7)),
        ("3.6", at(-3.2, 2.0, 8.7)),
        ("8.3", at(2.5, -4.0, 8.8)),
        ("8.4", at(-2.5, -4.0, 8.8)),
        ("9.15", at(0.0, -2.0, 9.5)),
    ] {
        face.feature_points.insert(fbakit::fdp::FeaturePoint {
            id: id.parse().unwrap(),
            position: Some(p),
            binding: None,
        });
    }
    face
}

#[test]
fn the_jaw_joint_takes_the_jaw_faps_over_from_the_morphs() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("avatar.glb");
    std::fs::write(&input, avatar::build().to_glb()).unwrap();
    let face = with_points(fbakit::face::read(&input).unwrap());
    let patched = dir.path().join("patched.glb");
    fbakit::export::write_face(&patched, &face).unwrap();
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/lowlevel.fap");
    let play = |out: &Path, extra: &[&str]| {
        let mut cmd = command();
        cmd.args([
            "play".as_ref(),
            patched.as_os_str(),
            sample.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ]);
        cmd.args(extra);
        let o = cmd.output().unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
        (json_of(out), text(&o.stderr))
    };
    let (stream, _) =
        fbakit::fap::read_stream_file(&sample, &fbakit::fap::ReadOptions::lenient()).unwrap();
    let open = |frame: usize| {
        stream.frames[frame]
            .value(FapId::new(3).unwrap())
            .unwrap_or(0.0)
    };
    let opened = (0..stream.frames.len()).find(|&i| open(i) > 50.0).unwrap();
    // The avatar's `Jaw` carries its mouth primitive but not the chin (2.1, on the skin,
    // weighted to `Head` alone): found by its name it is not used (the chin would stay still);
    // named, it is, with a warning.
    let out = dir.path().join("found.glb");
    let (y, stderr) = play(&out, &[]);
    assert!(
        stderr.contains("carries feature point 2.1 by 0 % only") && stderr.contains("stay morph"),
        "{stderr}"
    );
    let jaw = y["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n["name"] == "Jaw")
        .unwrap();
    assert!(
        !y["animations"][1]["channels"]
            .as_array()
            .unwrap()
            .iter()
            .any(|c| c["target"]["node"] == jaw),
        "found: the jaw is animated"
    );
    {
        let (name, extra) = ("named", &["--jaw-node", "Jaw"][..]);
        let out = dir.path().join(format!("{name}.glb"));
        let (y, stderr) = play(&out, extra);
        assert!(stderr.contains("as --jaw-node asks"), "{stderr}");
        let jaw = y["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .position(|n| n["name"] == "Jaw")
            .unwrap();
        let anim = &y["animations"][1];
        let channel = |path: &str| {
            anim["channels"]
                .as_array()
                .unwrap()
                .iter()
                .find(|c| c["target"]["node"] == jaw && c["target"]["path"] == path)
                .cloned()
        };
        let rotation = channel("rotation").unwrap_or_else(|| panic!("{name}: no jaw turn"));
        assert!(channel("translation").is_some(), "{name}: no jaw move");
        // The turn follows open_jaw: identity where the jaw is closed, about +x when open.
        let values = sampler_output(&out, &y, anim, &rotation, 4);
        let q = |i: usize| glam::Quat::from_slice(&values[i * 4..i * 4 + 4]);
        let rest = glam::Quat::IDENTITY;
        assert!(
            q(0).angle_between(rest) < 1e-4,
            "{name}: frame 0 {:?}",
            q(0)
        );
        let turned = q(opened).angle_between(rest);
        assert!(
            turned > 0.01,
            "{name}: open_jaw {} turns {turned}",
            open(opened)
        );
        // The open_jaw targets are held at zero: no morph for the same motion.
        let names: Vec<String> =
            serde_json::from_value(y["meshes"][0]["extras"]["targetNames"].clone()).unwrap();
        let weights_channel = anim["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["path"] == "weights")
            .cloned()
            .unwrap();
        let w = sampler_output(&out, &y, anim, &weights_channel, names.len());
        let jaw_targets: Vec<usize> = names
            .iter()
            .enumerate()
            .filter(|(_, n)| n.starts_with("open_jaw"))
            .map(|(i, _)| i)
            .collect();
        assert!(!jaw_targets.is_empty());
        for frame in w.chunks(names.len()) {
            for &t in &jaw_targets {
                assert_eq!(frame[t], 0.0, "{name}: {} animated", names[t]);
            }
        }
        let lid = names.iter().position(|n| n == "close_t_l_eyelid").unwrap();
        assert!(
            w.chunks(names.len()).any(|f| f[lid] != 0.0),
            "{name}: lids still morph"
        );
    }
    // No new validator issue.
    let out = dir.path().join("found.glb");
    let Some(reports) = support::validator::validate(&[input.clone(), out.clone()]) else {
        return;
    };
    let issues = support::validator::issue_codes;
    assert_eq!(issues(&reports[0]), issues(&reports[1]), "{}", reports[1]);
}

/// The floats of a channel's sampler output (`width` per key) from a `.glb`.
fn sampler_output(
    path: &Path,
    json: &Value,
    anim: &Value,
    channel: &Value,
    width: usize,
) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let bin = &bytes[20 + json_len + 8..];
    let sampler = &anim["samplers"][channel["sampler"].as_u64().unwrap() as usize];
    let acc = &json["accessors"][sampler["output"].as_u64().unwrap() as usize];
    let view = &json["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
        + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let count = acc["count"].as_u64().unwrap() as usize;
    let n = if acc["type"] == "SCALAR" {
        count
    } else {
        count * width
    };
    assert!(acc["type"] == "SCALAR" || acc["type"] == "VEC4");
    let _ = width;
    (0..n)
        .map(|i| f32::from_le_bytes(bin[start + i * 4..start + i * 4 + 4].try_into().unwrap()))
        .collect()
}

/// A node found by the name `Head` that does not carry the face (here the hat, renamed; the
/// real head joint renamed `Skull`) does not take the head rotations: they stay morph targets,
/// with a warning. Named with `--head-node`, it takes them, with a warning.
#[test]
fn a_head_node_that_does_not_carry_the_face_is_not_taken_by_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = avatar::build();
    a.json["nodes"][3]["name"] = "Skull".into();
    a.json["nodes"][6]["name"] = "Head".into();
    let input = dir.path().join("avatar.glb");
    std::fs::write(&input, a.to_glb()).unwrap();
    let alma = fbakit::face::read("alma").unwrap();
    let fp = avatar::fp_csv(&alma, dir.path(), "");
    let clone = |out: &Path, extra: &[&str]| {
        let o = command()
            .args(["clone".as_ref(), "alma".as_ref(), input.as_os_str()])
            .args(["--fp-target".as_ref(), fp.as_os_str()])
            .args(["-o".as_ref(), out.as_os_str()])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
        let names = json_of(out)["meshes"][0]["extras"]["targetNames"].to_string();
        (names, text(&o.stderr))
    };
    let (names, stderr) = clone(&dir.path().join("found.glb"), &[]);
    assert!(
        stderr.contains("head node `Head` carries feature point 9.3 by 0 % only")
            && stderr.contains("head rotations stay morph targets"),
        "{stderr}"
    );
    assert!(names.contains("head_pitch"), "{names}");
    let (names, stderr) = clone(&dir.path().join("named.glb"), &["--head-node", "Head"]);
    assert!(stderr.contains("as --head-node asks"), "{stderr}");
    assert!(!names.contains("head_"), "{names}");
    // The real head joint, named: taken without a word.
    let (names, stderr) = clone(&dir.path().join("skull.glb"), &["--head-node", "Skull"]);
    assert!(!stderr.contains("head node"), "{stderr}");
    assert!(!names.contains("head_"), "{names}");
}

/// Float skin joints (glTF allows unsigned byte/short only) are refused with the accessor's
/// place, never handed to the reader (which panicked on them).
#[test]
fn float_joints_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = avatar::build();
    // The mouth primitive, whose vertices the jaw and head joints share (read per vertex):
    // its JOINTS_0 pointed at a float VEC4 accessor of the right size (its weights').
    let mouth = &mut a.json["meshes"][0]["primitives"][1]["attributes"];
    mouth["JOINTS_0"] = mouth["WEIGHTS_0"].clone();
    let input = dir.path().join("float-joints.glb");
    std::fs::write(&input, a.to_glb()).unwrap();
    let out = dir.path().join("out.glb");
    let run = support::cli::face_export(&input, &out);
    assert_eq!(run.status.code(), Some(2), "{}", text(&run.stderr));
    let err = text(&run.stderr);
    assert!(
        err.contains("float-joints.glb") && err.contains("JOINTS_0"),
        "{err}"
    );
    assert!(!out.exists());
}
