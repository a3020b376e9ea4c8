//! Unit tests of the builder's checks and layout decisions.

use glam::{Quat, Vec3};

use super::json;
use super::*;

fn tri() -> MeshData<'static> {
    MeshData::new("tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
}

fn err_text(r: crate::error::Result<impl std::fmt::Debug>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn bad_meshes_are_rejected_with_the_mesh_named() {
    let mut s = SceneBuilder::new("t");
    let empty = MeshData::new("void", Vec::new(), Vec::new());
    assert!(err_text(s.add_mesh(empty)).contains("glTF mesh `void`: no vertices"));
    let no_tris = MeshData::new("dots", vec![Vec3::ZERO], Vec::new());
    assert!(err_text(s.add_mesh(no_tris)).contains("no triangles"));
    let mut nan = tri();
    nan.positions.to_mut()[1].x = f32::NAN;
    assert!(err_text(s.add_mesh(nan)).contains("non-finite vertex position"));
    let far = MeshData::new("far", vec![Vec3::ZERO], vec![[0, 0, 3]]);
    assert!(err_text(s.add_mesh(far)).contains("refers past the 1 vertices"));
    let short_normals = tri().with_normals(vec![Vec3::Z]);
    assert!(err_text(s.add_mesh(short_normals)).contains("1 normals for 3 vertices"));
    let zero_normal = tri().with_normals(vec![Vec3::Z, Vec3::Z, Vec3::ZERO]);
    assert!(err_text(s.add_mesh(zero_normal)).contains("zero-length normal"));
    let inf_target = tri().with_dense_target("t", vec![Vec3::ZERO, Vec3::INFINITY, Vec3::ZERO]);
    assert!(err_text(s.add_mesh(inf_target)).contains("morph target `t`: non-finite offset"));
    let bad_sparse = tri().with_sparse_target("s", vec![5], vec![Vec3::X]);
    assert!(err_text(s.add_mesh(bad_sparse)).contains("vertex 5 is past"));
    let uneven = tri().with_sparse_target("s", vec![0, 1], vec![Vec3::X]);
    assert!(err_text(s.add_mesh(uneven)).contains("2 vertices but 1 offsets"));
    let mut bright = tri();
    bright.material.base_color[0] = 1.5;
    assert!(err_text(s.add_mesh(bright)).contains("0..=1"));
    // Nothing invalid was kept.
    assert!(s.add_mesh(tri()).unwrap().index() == 0);
}

#[test]
fn bad_nodes_and_animations_are_rejected() {
    let mut s = SceneBuilder::new("t");
    let m = s
        .add_mesh(tri().with_dense_target("d", vec![Vec3::X; 3]))
        .unwrap();
    let plain = s.add_mesh(tri()).unwrap();
    let a = s.add_node(NodeData::new("a").with_mesh(m)).unwrap();
    let b = s.add_node(NodeData::new("b").with_mesh(plain)).unwrap();
    let ghost = NodeData::new("c").with_parent(NodeId(7));
    assert!(err_text(s.add_node(ghost)).contains("parent is not an earlier node"));
    let nan = NodeData::new("n").with_translation(Vec3::NAN);
    assert!(err_text(s.add_node(nan)).contains("non-finite transform"));
    let zero_rot = NodeData::new("z").with_rotation(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0));
    assert!(err_text(s.add_node(zero_rot)).contains("zero-length rotation"));

    let channel = |node, times: Vec<f32>, values| ChannelData {
        node,
        times,
        values,
        interpolation: Interpolation::Linear,
    };
    let anim = |channels| AnimationData {
        name: "x".into(),
        channels,
    };
    let w = |v: Vec<f32>| ChannelValues::Weights(v);
    assert!(err_text(s.add_animation(anim(vec![]))).contains("no channels"));
    let no_morphs = channel(b, vec![0.0], w(vec![1.0]));
    assert!(err_text(s.add_animation(anim(vec![no_morphs]))).contains("has no morph targets"));
    let count = channel(a, vec![0.0, 1.0], w(vec![1.0]));
    assert!(err_text(s.add_animation(anim(vec![count]))).contains("do not match 2 keyframe"));
    let back = channel(a, vec![1.0, 1.0], w(vec![0.0, 1.0]));
    assert!(err_text(s.add_animation(anim(vec![back]))).contains("strictly increasing"));
    let negative = channel(a, vec![-1.0], w(vec![0.0]));
    assert!(err_text(s.add_animation(anim(vec![negative]))).contains(">= 0"));
    let nan = channel(a, vec![0.0], w(vec![f32::NAN]));
    assert!(err_text(s.add_animation(anim(vec![nan]))).contains("non-finite"));
    let twice = vec![
        channel(a, vec![0.0], w(vec![0.0])),
        channel(a, vec![0.5], w(vec![1.0])),
    ];
    assert!(err_text(s.add_animation(anim(twice))).contains("already has a weights channel"));
    let unknown = channel(NodeId(9), vec![0.0], ChannelValues::Scale(vec![Vec3::ONE]));
    assert!(err_text(s.add_animation(anim(vec![unknown]))).contains("unknown node"));
}

#[test]
fn unplaced_mesh_is_an_error_at_build() {
    let mut s = SceneBuilder::new("t");
    s.add_mesh(tri()).unwrap();
    assert!(err_text(s.build()).contains("`tri` is not shown by any node"));
}

#[test]
fn normals_are_area_weighted() {
    // Two triangles sharing vertex 0: a big one facing +Z and a small one facing +X.
    let p = [
        Vec3::ZERO,
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::new(0.0, 0.0, 0.1),
    ];
    let n = area_weighted_normals(&p, &[[0, 1, 2], [0, 3, 4]]);
    let expected = Vec3::new(0.01 / 2.0, 0.0, 4.0 / 2.0).normalize();
    assert!((n[0] - expected).length() < 1e-6, "{:?}", n[0]);
    assert_eq!(n[1], Vec3::Z);
    // Vertices on no triangle fall back to +Z rather than NaN.
    let n = area_weighted_normals(&[Vec3::ZERO, Vec3::X], &[]);
    assert_eq!(n, vec![Vec3::Z, Vec3::Z]);
}

fn one_mesh(mesh: MeshData<'static>) -> GltfDocument {
    let mut s = SceneBuilder::new("t");
    let m = s.add_mesh(mesh).unwrap();
    s.add_node(NodeData::new("n").with_mesh(m)).unwrap();
    s.build().unwrap()
}

fn position_target(doc: &GltfDocument, t: usize) -> &json::Accessor {
    let attrs = &doc.root.meshes[0].primitives[0].targets[t];
    assert_eq!(attrs[0].0, "POSITION");
    &doc.root.accessors[attrs[0].1 as usize]
}

#[test]
fn targets_are_sparse_only_when_smaller() {
    let n = 100;
    let positions: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
    let tris: Vec<[u32; 3]> = (0..n as u32 - 2).map(|i| [i, i + 1, i + 2]).collect();
    let mut full = vec![Vec3::Y; n];
    full[0] = Vec3::ZERO;
    let mesh = MeshData::new("m", positions, tris)
        .with_sparse_target("few", vec![3, 1], vec![Vec3::X, -Vec3::X])
        .with_dense_target("most", full)
        .with_sparse_target("none", vec![4], vec![Vec3::ZERO]);
    let doc = one_mesh(mesh);
    let few = position_target(&doc, 0);
    assert_eq!(few.buffer_view, None);
    let sp = few.sparse.as_ref().unwrap();
    assert_eq!(sp.count, 2);
    assert_eq!(sp.indices.component_type, json::UNSIGNED_BYTE);
    assert_eq!(few.min, vec![-1.0, 0.0, 0.0]);
    assert_eq!(few.max, vec![1.0, 0.0, 0.0]);
    let most = position_target(&doc, 1);
    assert!(most.sparse.is_none() && most.buffer_view.is_some());
    assert_eq!(most.min, vec![0.0, 0.0, 0.0]);
    assert_eq!(most.max, vec![0.0, 1.0, 0.0]);
    // A target that moves nothing is an all-zero accessor without data.
    let none = position_target(&doc, 2);
    assert!(none.sparse.is_none() && none.buffer_view.is_none());
    assert_eq!(none.min, vec![0.0; 3]);
    // Sparse views have no target; vertex views do.
    let idx_view = &doc.root.buffer_views[sp.indices.buffer_view as usize];
    assert_eq!(idx_view.target, None);
    let dense_view = &doc.root.buffer_views[most.buffer_view.unwrap() as usize];
    assert_eq!(dense_view.target, Some(json::ARRAY_BUFFER));
    let names = &doc.root.meshes[0].extras.as_ref().unwrap()["targetNames"];
    assert_eq!(names, &serde_json::json!(["few", "most", "none"]));
    assert_eq!(doc.root.meshes[0].weights, vec![0.0; 3]);
}

#[test]
fn index_width_follows_vertex_count() {
    let idx_type = |n: usize| {
        let doc = one_mesh(MeshData::new(
            "m",
            vec![Vec3::ZERO; n],
            vec![[0, 1, n as u32 - 1]],
        ));
        let p = &doc.root.meshes[0].primitives[0];
        let a = &doc.root.accessors[p.indices.unwrap() as usize];
        let view = &doc.root.buffer_views[a.buffer_view.unwrap() as usize];
        assert_eq!(view.target, Some(json::ELEMENT_ARRAY_BUFFER));
        a.component_type
    };
    assert_eq!(idx_type(3), json::UNSIGNED_SHORT);
    assert_eq!(idx_type(65535), json::UNSIGNED_SHORT);
    // Index 65535 would be the u16 primitive-restart value.
    assert_eq!(idx_type(65536), json::UNSIGNED_INT);
}

#[test]
fn hierarchy_transforms_and_shared_times() {
    let mut s = SceneBuilder::new("scene");
    let m = s
        .add_mesh(tri().with_dense_target("d", vec![Vec3::X; 3]))
        .unwrap();
    let root = s.add_node(NodeData::new("root").with_mesh(m)).unwrap();
    let child = s
        .add_node(
            NodeData::new("child")
                .with_parent(root)
                .with_rotation(Quat::from_xyzw(0.0, 0.0, 0.0, 2.0))
                .with_scale(Vec3::splat(2.0)),
        )
        .unwrap();
    let other_root = s.add_node(NodeData::new("")).unwrap();
    let times = vec![0.0, 0.1, 0.2];
    s.add_animation(AnimationData {
        name: "a".into(),
        channels: vec![
            ChannelData {
                node: root,
                times: times.clone(),
                values: ChannelValues::Weights(vec![0.0, 1.0, 0.0]),
                interpolation: Interpolation::Step,
            },
            ChannelData {
                node: child,
                times: times.clone(),
                values: ChannelValues::Rotation(vec![Quat::from_rotation_z(0.5) * 3.0; 3]),
                interpolation: Interpolation::Linear,
            },
        ],
    })
    .unwrap();
    let doc = s.build().unwrap();
    let r = &doc.root;
    assert_eq!(r.asset.generator.as_deref(), Some("fbakit"));
    assert_eq!(r.scenes[0].nodes, vec![0, other_root.index() as u32]);
    assert_eq!(r.nodes[0].children, vec![1]);
    // The identity rotation (after normalising) and unit scale are not written.
    assert_eq!(r.nodes[1].rotation, None);
    assert_eq!(r.nodes[1].scale, Some([2.0; 3]));
    assert_eq!(r.nodes[2].name, None);
    let a = &r.animations[0];
    assert_eq!(
        a.samplers[0].input, a.samplers[1].input,
        "equal times share an accessor"
    );
    assert_eq!(a.samplers[0].interpolation.as_deref(), Some("STEP"));
    assert_eq!(a.samplers[1].interpolation, None);
    let input = &r.accessors[a.samplers[0].input as usize];
    assert_eq!(
        (input.min.clone(), input.max.clone()),
        (vec![0.0], vec![0.2])
    );
    assert_eq!(a.channels[1].target.path, "rotation");
    assert_eq!(r.buffers[0].byte_length as usize, doc.bin.len());
    for v in &r.buffer_views {
        assert_eq!(v.byte_offset % 4, 0);
        assert!(v.byte_offset + v.byte_length <= r.buffers[0].byte_length);
    }
}
