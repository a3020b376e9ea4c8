//! The player's glTF output reproduces the player: morph weights × targets give the played
//! positions, nodes give the face's world matrices, and files pass the Khronos validator.

use std::path::Path;
use std::sync::OnceLock;

use fbakit::export::gltf::{export_face, face_to_gltf, FaceMorphs};
use fbakit::face::{FaceMesh, FaceModel, FaceTransform};
use fbakit::fap::{read_fap_file, FapFrame, FapStream, ReadOptions};
use fbakit::fat::{FaceDefMesh, FaceDefTable, FaceDefTransform, TableKey};
use fbakit::gltf::GltfDocument;
use fbakit::mesh::Mesh;
use fbakit::player::{PlayOptions, Player, PlayerFrame};
use fbakit::spec::FapId;
use glam::{Affine3A, Quat, Vec3};

mod support;
use support::validator::validate;

fn alma() -> &'static FaceModel {
    static FACE: OnceLock<FaceModel> = OnceLock::new();
    FACE.get_or_init(|| fbakit::synth::alma().to_face_model())
}

fn sample(name: &str) -> FapStream {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("samples")
        .join(name);
    read_fap_file(&p, &ReadOptions::strict()).unwrap().0
}

/// Float data of a (dense) accessor.
fn floats(doc: &GltfDocument, accessor: u32) -> Vec<f32> {
    let a = &doc.root.accessors[accessor as usize];
    assert_eq!(a.component_type, 5126);
    let view = &doc.root.buffer_views[a.buffer_view.unwrap() as usize];
    let width = match a.kind.as_str() {
        "SCALAR" => 1,
        "VEC3" => 3,
        "VEC4" => 4,
        k => panic!("{k}"),
    };
    let start = view.byte_offset as usize;
    doc.bin[start..start + a.count as usize * width * 4]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

fn assert_close(mesh: &str, got: &[Vec3], want: &[Vec3]) {
    let scale = want
        .iter()
        .map(|p| p.abs().max_element())
        .fold(1.0, f32::max);
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (*g - *w).length() <= 1e-4 * scale,
            "mesh {mesh} vertex {k}: {g} vs {w}"
        );
    }
}

/// The weights written in the document's animation, frame by frame, reproduce the player's
/// positions through the targets.
#[test]
fn animation_weights_reproduce_played_positions() {
    let face = alma();
    for (stream, frames) in [
        (sample("speech.fap"), [0usize, 12, 30, 47, 70]),
        (sample("lowlevel.fap"), [3, 10, 24, 30, 49]),
    ] {
        let mut player = Player::new(face, &stream, &PlayOptions::default()).unwrap();
        let anim = player.animation().unwrap();
        let doc = face_to_gltf(face, Some(&anim)).unwrap();
        let morphs = FaceMorphs::new(face).unwrap();
        let animation = &doc.root.animations[0];
        let mut frame = PlayerFrame::default();
        for mi in 0..face.meshes.len() {
            let n = morphs.meshes[mi].len();
            if n == 0 {
                continue;
            }
            let node = doc
                .root
                .nodes
                .iter()
                .position(|nd| nd.name.as_deref() == Some(&face.meshes[mi].name))
                .unwrap() as u32;
            let ch = animation
                .channels
                .iter()
                .find(|c| c.target.node == node && c.target.path == "weights")
                .unwrap();
            let weights = floats(&doc, animation.samplers[ch.sampler as usize].output);
            // A key per frame and a closing key that holds the last frame.
            assert_eq!(weights.len(), n * (anim.len() + 1));
            assert_eq!(
                weights[n * (anim.len() - 1)..n * anim.len()],
                weights[n * anim.len()..]
            );
            for &fi in &frames {
                player.frame_at(fi, &mut frame);
                let w = &weights[fi * n..(fi + 1) * n];
                let got = morphs.apply(mi, &face.meshes[mi].mesh.positions, w);
                assert_close(&face.meshes[mi].name, &got, &frame.pose.positions[mi]);
            }
        }
        // The head rotation channel matches the player's transform local matrix.
        let head = face.transform_index("head").unwrap();
        let head_node = doc
            .root
            .nodes
            .iter()
            .position(|nd| nd.name.as_deref() == Some("head"))
            .unwrap() as u32;
        let ch = animation
            .channels
            .iter()
            .find(|c| c.target.node == head_node && c.target.path == "rotation")
            .unwrap();
        let rot = floats(&doc, animation.samplers[ch.sampler as usize].output);
        let c = face.transforms[head].center;
        for &fi in &frames {
            player.frame_at(fi, &mut frame);
            let q = Quat::from_slice(&rot[fi * 4..fi * 4 + 4]);
            let m = Affine3A::from_rotation_translation(q, c) * Affine3A::from_translation(-c);
            assert!(
                m.abs_diff_eq(frame.pose.transform_locals[head], 1e-4),
                "frame {fi}"
            );
        }
    }
}

fn tiny_face() -> FaceModel {
    let mut face = FaceModel::new("tiny");
    let mut root = FaceTransform::new("root", None, Vec3::new(1.0, 2.0, 3.0));
    root.translation = Vec3::new(0.5, 0.0, -1.0);
    root.rotation = Quat::from_rotation_z(0.3);
    root.scale = Vec3::new(2.0, 1.0, 0.5);
    let mut child = FaceTransform::new("child", Some(0), Vec3::new(-1.0, 0.0, 4.0));
    child.rotation = Quat::from_rotation_x(-0.7);
    let plain = FaceTransform::new("plain", Some(1), Vec3::ZERO);
    face.transforms = vec![root, child, plain];
    let tri = |name: &str, t: usize| FaceMesh {
        name: name.into(),
        transform: Some(t),
        mesh: Mesh::from_triangles(name, vec![Vec3::ZERO, Vec3::X, Vec3::Y], &[[0, 1, 2]]),
        color: Some([0.9, 0.2, 0.1]),
    };
    face.meshes = vec![tri("a", 0), tri("b", 1), tri("c", 2)];
    // The worked example of the fact sheet (borders -400 0 300 900) on vertex 1 of `a`, a
    // single-interval table on `b`, and a rotation of `child`.
    let mut t = FaceDefTable::new(TableKey::LowLevel(FapId::OPEN_JAW));
    t.meshes.push(FaceDefMesh {
        mesh: "a".into(),
        interval_borders: vec![-400.0, 0.0, 300.0, 900.0],
        coord_index: vec![1],
        displacements: vec![
            Vec3::new(0.0, 0.002, 0.0),
            Vec3::new(0.0, -0.001, 0.0),
            Vec3::new(0.0, -0.003, 0.001),
        ],
    });
    let mut u = FaceDefTable::new(TableKey::LowLevel(FapId::new(4).unwrap()));
    u.meshes.push(FaceDefMesh {
        mesh: "b".into(),
        interval_borders: vec![0.0, 50.0],
        coord_index: vec![2, 0],
        displacements: vec![Vec3::new(0.01, 0.0, 0.0), Vec3::new(0.0, 0.0, -0.02)],
    });
    u.transforms
        .push(FaceDefTransform::rotation("child", Vec3::Y, 1e-3));
    face.fat.tables = vec![t, u];
    face
}

#[test]
fn baked_interval_targets_follow_the_piecewise_rule() {
    let face = tiny_face();
    let morphs = FaceMorphs::new(&face).unwrap();
    let names: Vec<&str> = morphs.meshes[0].iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["open_jaw#0", "open_jaw#1", "open_jaw#2"]);
    assert_eq!(morphs.meshes[1][0].name, "lower_t_midlip");
    assert_eq!(morphs.meshes[1][0].span, 50.0);
    let key = TableKey::LowLevel(FapId::OPEN_JAW);
    let mut w = Vec::new();
    for (p, want) in [
        (600.0, Vec3::new(0.0, -1.2, 0.3)),
        (100.0, Vec3::new(0.0, -0.1, 0.0)),
        (-200.0, Vec3::new(0.0, -0.4, 0.0)),
        (1000.0, Vec3::new(0.0, -2.4, 0.7)),
        (-500.0, Vec3::new(0.0, -1.0, 0.0)),
    ] {
        let act = [fbakit::fat::eval::Activation { key, value: p }];
        morphs.weights_into(0, &act, &mut w);
        let got = morphs.apply(0, &face.meshes[0].mesh.positions, &w)[1] - Vec3::X;
        assert!((got - want).length() < 1e-5, "P = {p}: {got} vs {want}");
    }
    // Weights run 0..1 within an interval: P = 600 covers all of [0, 300] and half of
    // [300, 900].
    let act = [fbakit::fat::eval::Activation { key, value: 600.0 }];
    morphs.weights_into(0, &act, &mut w);
    assert_eq!(w, [0.0, 1.0, 0.5]);
    // The player agrees.
    let mut f = FapFrame::new(0);
    f.set(FapId::OPEN_JAW, 600.0);
    f.set(FapId::new(4).unwrap(), -20.0);
    let stream = FapStream {
        frames: vec![f],
        ..FapStream::new("t", 25.0)
    };
    let mut player = Player::new(&face, &stream, &PlayOptions::default()).unwrap();
    let mut frame = player.new_frame();
    player.next_frame(&mut frame);
    for mi in 0..2 {
        morphs.weights_into(mi, &frame.activations, &mut w);
        let got = morphs.apply(mi, &face.meshes[mi].mesh.positions, &w);
        assert_close("tiny", &got, &frame.pose.positions[mi]);
    }
}

/// World matrices of the glTF nodes (TRS products down the hierarchy).
fn node_worlds(doc: &GltfDocument) -> Vec<Affine3A> {
    let nodes = &doc.root.nodes;
    let mut parent = vec![None; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        for &c in &n.children {
            parent[c as usize] = Some(i);
        }
    }
    let local = |i: usize| {
        let n = &nodes[i];
        Affine3A::from_scale_rotation_translation(
            Vec3::from(n.scale.unwrap_or([1.0; 3])),
            Quat::from_array(n.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0])),
            Vec3::from(n.translation.unwrap_or([0.0; 3])),
        )
    };
    (0..nodes.len())
        .map(|i| {
            let mut m = local(i);
            let mut p = parent[i];
            while let Some(j) = p {
                m = local(j) * m;
                p = parent[j];
            }
            m
        })
        .collect()
}

#[test]
fn pivot_nodes_reproduce_vrml_centres() {
    let face = tiny_face();
    let doc = face_to_gltf(&face, None).unwrap();
    let worlds = node_worlds(&doc);
    let frames = face.frames();
    for (mi, m) in face.meshes.iter().enumerate() {
        let node = doc
            .root
            .nodes
            .iter()
            .position(|n| n.name.as_deref() == Some(&m.name))
            .unwrap();
        assert!(
            worlds[node].abs_diff_eq(frames.meshes[mi], 1e-5),
            "{}: {:?} vs {:?}",
            m.name,
            worlds[node],
            frames.meshes[mi]
        );
    }
    let names: Vec<&str> = doc
        .root
        .nodes
        .iter()
        .map(|n| n.name.as_deref().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "root",
            "root_pivot",
            "child",
            "child_pivot",
            "plain",
            "a",
            "b",
            "c"
        ]
    );
    // A scaleOrientation cannot be represented: warned about.
    let mut skew = face.clone();
    skew.transforms[0].scale_orientation = Quat::from_rotation_y(0.4);
    let e = export_face(&skew, None).unwrap();
    assert_eq!(e.warnings.len(), 1, "{:?}", e.warnings);
    assert!(e.warnings[0].message.contains("scaleOrientation"));
}

#[test]
fn played_alma_passes_the_khronos_validator() {
    let face = alma();
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for (stream, ext) in [("speech.fap", "glb"), ("lowlevel.fap", "gltf")] {
        let player = Player::new(face, &sample(stream), &PlayOptions::default()).unwrap();
        let anim = player.animation().unwrap();
        let p = dir.path().join(format!("{stream}.{ext}"));
        face_to_gltf(face, Some(&anim)).unwrap().write(&p).unwrap();
        files.push(p);
    }
    let p = dir.path().join("tiny.glb");
    face_to_gltf(&tiny_face(), None).unwrap().write(&p).unwrap();
    files.push(p);
    let Some(reports) = validate(&files) else {
        return;
    };
    for r in &reports {
        assert_eq!(r["errors"], 0, "{r:#}");
        assert_eq!(r["warnings"], 0, "{r:#}");
    }
}
