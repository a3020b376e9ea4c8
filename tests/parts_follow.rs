//! Parts that are their own mesh or primitive move as the face around them: the avatar's
//! lash primitive rides on the eyelids (and not on the jaw); feature points given by
//! position snap to the skin, or to the eye part for the pupils, never to lashes or a hat.

use std::path::Path;

use fbakit::clone::face::{clone_face, CloneOptions};
use fbakit::face::{FaceModel, FaceReadOptions};
use fbakit::fat::eval::Activation;
use fbakit::fat::TableKey;
use fbakit::spec::{FapId, FeaturePointId};
use glam::Vec3;

mod support;
use support::avatar;

fn fp(s: &str) -> FeaturePointId {
    s.parse().unwrap()
}

fn read_avatar(dir: &Path, fp: &Path) -> FaceModel {
    let glb = dir.join("avatar.glb");
    std::fs::write(&glb, avatar::build().to_glb()).unwrap();
    fbakit::face::read_with(&glb, &FaceReadOptions::with_feature_points(Some(fp)))
        .unwrap()
        .0
}

/// World displacement of every vertex of every mesh at `fap` = `value`.
fn motion(face: &FaceModel, fap: u8, value: f64) -> Vec<Vec<Vec3>> {
    let neutral = face.pose(&[]).unwrap();
    let posed = face
        .pose(&[Activation {
            key: TableKey::LowLevel(FapId::new(fap).unwrap()),
            value,
        }])
        .unwrap();
    neutral
        .iter()
        .zip(&posed)
        .map(|(a, b)| a.iter().zip(b).map(|(p, q)| *q - *p).collect())
        .collect()
}

#[test]
fn lash_primitive_follows_the_eyelid_not_the_jaw() {
    let source = fbakit::face::read("alma").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let csv = avatar::fp_csv(&source, dir.path(), "");
    let target = read_avatar(dir.path(), &csv);
    let out = clone_face(&source, &target, &CloneOptions::default()).unwrap();
    let face = &out.face;
    // The lashes and the mouth (no feature point of its own, on the skin's inside) ride on
    // the skin; the eyes are a part, the hat too large.
    assert_eq!(
        out.report.attached_meshes,
        ["Body.1", "Body.3"],
        "{}",
        out.report
    );
    // The hat is too large to ride on the skin: rigid, named in the warning.
    assert!(
        out.report
            .warnings
            .iter()
            .any(|w| w.message.contains("meshes Hat are neither skin nor a part")),
        "{}",
        out.report
    );
    let lashes = face.mesh_index("Body.3").unwrap();
    let neutral = face.neutral_world_positions();
    let left: Vec<usize> = (0..neutral[lashes].len())
        .filter(|&v| neutral[lashes][v].x > 0.0)
        .collect();
    let right: Vec<usize> = (0..neutral[lashes].len())
        .filter(|&v| neutral[lashes][v].x < 0.0)
        .collect();
    let mean =
        |vs: &[usize], m: &[Vec3]| vs.iter().map(|&v| m[v].length()).sum::<f32>() / vs.len() as f32;
    // The skin vertex nearest each left lash vertex: what the lid around the lashes does.
    let skin = face.mesh_index("Body.0").unwrap();
    let under: Vec<usize> = left
        .iter()
        .map(|&v| {
            let p = neutral[lashes][v];
            (0..neutral[skin].len())
                .min_by(|&a, &b| {
                    neutral[skin][a]
                        .distance(p)
                        .total_cmp(&neutral[skin][b].distance(p))
                })
                .unwrap()
        })
        .collect();
    // The avatar's skin is a coarse sphere (3 cm between vertices): its upper lid point
    // shares its vertex with the inner eye corner, so close_t_l_eyelid is the guard's repair
    // (the point moved alone), and the lashes follow that point; the brows move the skin
    // above the left lashes.
    let mut moved = 0;
    for fap in [19u8, 31, 33] {
        let key = TableKey::LowLevel(FapId::new(fap).unwrap());
        let Some(table) = face.fat.tables.iter().find(|t| t.key == key) else {
            continue;
        };
        let value = table
            .meshes
            .iter()
            .flat_map(|m| m.interval_borders.iter().copied())
            .fold(0.0f64, |a, b| a.max(b.abs()));
        let d = motion(face, fap, value);
        let skin_motion =
            under.iter().map(|&v| d[skin][v].length()).sum::<f32>() / under.len() as f32;
        let (lm, lv) = face.fp_vertex(fp("3.1")).unwrap();
        let lid_motion = d[lm][lv as usize].length();
        let lash_motion = mean(&left, &d[lashes]);
        eprintln!(
            "FAP {fap} at {value}: skin under the lashes {skin_motion}, lid point {lid_motion}, lashes {lash_motion}"
        );
        if fap == 19 {
            // The lashes ride on the lid's margin (the lid point), not on the skin closest
            // to them (the fold above the lid, which hardly moves).
            assert!(
                lash_motion > 0.8 * lid_motion && lash_motion < 1.2 * lid_motion,
                "FAP {fap}: lid point {lid_motion}, lashes {lash_motion}"
            );
        } else {
            // The brows lift the margin less than the fold above it.
            assert!(
                lash_motion < 2.0 * skin_motion,
                "FAP {fap}: skin {skin_motion}, lashes {lash_motion}"
            );
        }
        // Never down with the brow, and the right eye's lashes stay.
        let up = left.iter().map(|&v| d[lashes][v].y).sum::<f32>();
        assert!(up >= 0.0 || fap == 19, "FAP {fap}: lashes go down");
        assert!(mean(&right, &d[lashes]) <= 0.1 * lash_motion);
        moved += usize::from(lash_motion > 0.0);
    }
    assert!(moved >= 1);
    // open_jaw moves the chin, not the lashes.
    let jaw = motion(face, 3, 1000.0);
    let (m21, v21) = face.fp_vertex(fp("2.1")).unwrap();
    let chin = jaw[m21][v21 as usize].length();
    let lash_jaw = jaw[lashes].iter().map(|d| d.length()).fold(0.0, f32::max);
    eprintln!("open_jaw: chin {chin}, lashes {lash_jaw}");
    assert!(chin > 0.0);
    assert!(lash_jaw < 0.02 * chin, "chin {chin}, lashes {lash_jaw}");
    // The mouth's lower side goes down with the skin around it (the lower lip's inside, a
    // fifth of the chin's motion on this avatar).
    let mouth = face.mesh_index("Body.1").unwrap();
    let mouth_jaw = jaw[mouth].iter().map(|d| -d.y).fold(0.0, f32::max);
    eprintln!("open_jaw: mouth down by {mouth_jaw}");
    assert!(mouth_jaw > 0.1 * chin, "chin {chin}, mouth {mouth_jaw}");
    // The patched glb gives the lash primitive its motion.
    let glb = dir.path().join("out.glb");
    fbakit::export::write_face(&glb, face).unwrap();
    let back = fbakit::face::read(&glb).unwrap();
    let lid = motion(face, 19, 512.0);
    let back_lid = motion(&back, 19, 512.0);
    let back_lashes = back.mesh_index("Body.3").unwrap();
    let (before, again) = (
        mean(&left, &lid[lashes]),
        mean(&left, &back_lid[back_lashes]),
    );
    assert!(before > 0.0);
    assert!(
        (again - before).abs() < 0.01 * before,
        "{again} vs {before}"
    );
}

#[test]
fn positions_snap_to_the_skin_and_the_pupils_to_the_eyes() {
    let source = fbakit::face::read("alma").unwrap();
    let dir = tempfile::tempdir().unwrap();
    // 3.1 and 3.3 given exactly at lash vertices (the nearest vertex of all), 3.5 at the left
    // pupil.
    let lash = avatar::body_prims()[3].positions.clone();
    let world = |p: Vec3| p * 0.01;
    let (a, b) = (world(lash[1]), world(lash[2]));
    let extra = format!("3.1,{},{},{}\n", a.x, a.y, a.z);
    let csv = avatar::fp_csv(&source, dir.path(), "");
    // Replace the 3.1 row and the 3.3 row by lash positions.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut body: String = text
        .lines()
        .filter(|l| !l.starts_with("3.1,") && !l.starts_with("3.3,"))
        .map(|l| format!("{l}\n"))
        .collect();
    body.push_str(&extra);
    body.push_str(&format!("3.3,{},{},{}\n", b.x, b.y, b.z));
    std::fs::write(&csv, body).unwrap();
    let face = read_avatar(dir.path(), &csv);
    let skin = face.mesh_index("Body.0").unwrap();
    let eyes = face.mesh_index("Body.2").unwrap();
    for p in face.feature_points.iter() {
        let (m, _) = face.fp_vertex(p.id).unwrap();
        let want = if ["3.5", "3.6"].contains(&p.id.to_string().as_str()) {
            eyes
        } else {
            skin
        };
        assert_eq!(m, want, "{} on {}", p.id, face.meshes[m].name);
    }
    // The snap distance of the lash-placed points is the skin's, reported.
    let o = support::cli::fbakit(&[
        "face",
        "info",
        dir.path().join("avatar.glb").to_str().unwrap(),
        "--fp",
        csv.to_str().unwrap(),
    ]);
    let err = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("feature point 3.1 snapped") && err.contains("of `Body.0`"),
        "{err}"
    );
}

#[test]
fn obj_shape_sets_carry_their_materials_and_textures() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // bruno as one OBJ with a material library, a texture beside it in a subfolder, feature
    // points by position.
    let bruno = fbakit::face::read("bruno").unwrap();
    let plain = d.join("plain.obj");
    fbakit::face::write(&plain, &bruno).unwrap();
    let src = d.join("src");
    std::fs::create_dir_all(src.join("tex")).unwrap();
    let text = std::fs::read_to_string(&plain).unwrap();
    let obj = src.join("head.obj");
    std::fs::write(&obj, format!("mtllib head.mtl\nusemtl skin\n{text}")).unwrap();
    let mtl = "newmtl skin\nKd 0.8 0.7 0.6\nmap_Kd -s 1 1 1 tex/skin.png\nmap_Bump ../escape.png\n";
    std::fs::write(src.join("head.mtl"), mtl).unwrap();
    std::fs::write(src.join("tex/skin.png"), b"not really a png").unwrap();
    let mut csv = String::from("fp,x,y,z\n");
    for p in bruno.feature_points.iter() {
        let q = p.position.unwrap();
        csv.push_str(&format!("{},{},{},{}\n", p.id, q.x, q.y, q.z));
    }
    let fp_csv = d.join("fp.csv");
    std::fs::write(&fp_csv, csv).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let set = d.join("out/");
    let o = support::cli::fbakit(&[
        "clone",
        "alma",
        &s(&obj),
        "--fp-target",
        &s(&fp_csv),
        "-o",
        &s(&set),
        "--json",
    ]);
    let err = support::cli::text(&o.stderr);
    assert!(o.status.success(), "{err}");
    let neutral = std::fs::read_to_string(set.join("neutral.obj")).unwrap();
    assert!(neutral.starts_with("mtllib head.mtl\nusemtl skin\n"));
    assert_eq!(std::fs::read_to_string(set.join("head.mtl")).unwrap(), mtl);
    assert_eq!(
        std::fs::read(set.join("tex/skin.png")).unwrap(),
        b"not really a png"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        v["shapes"]["materials"].as_array().unwrap().len(),
        2,
        "{}",
        v["shapes"]
    );
    // `map_Bump ../escape.png` reaches out of the folder: warned about, not copied.
    let warned = v["write_warnings"].to_string();
    assert!(
        warned.contains("`../escape.png` lies outside the file's folder"),
        "{warned}"
    );
    assert!(!d.join("escape.png").exists());
    // `.obj` out: the libraries beside the neutral and in its shapes folder.
    let out = d.join("o2/head-out.obj");
    std::fs::create_dir_all(d.join("o2")).unwrap();
    let o = support::cli::fbakit(&[
        "clone",
        "alma",
        &s(&obj),
        "--fp-target",
        &s(&fp_csv),
        "-o",
        &s(&out),
        "--names",
        "fat",
    ]);
    assert!(o.status.success(), "{}", support::cli::text(&o.stderr));
    assert!(d.join("o2/head.mtl").is_file());
    assert!(d.join("o2/head-out_shapes/head.mtl").is_file());
    assert!(d.join("o2/tex/skin.png").is_file());
}
