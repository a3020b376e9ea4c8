//! Structural checks of written glTF files without external tools: GLB header and chunks,
//! JSON fields, accessor bounds and byte lengths, and the binary data read back.

mod support;

use fbakit::gltf::container::{base64_decode, DATA_URI_PREFIX, GLB_MAGIC};
use fbakit::gltf::json::{self, Root};
use fbakit::gltf::{parse_glb, GltfDocument, MeshData, NodeData, SceneBuilder};
use glam::Vec3;
use proptest::prelude::*;

use support::gltf_scenes::*;

/// The JSON and binary buffer of GLB bytes, with the container checked.
fn open_glb(glb: &[u8]) -> (Root, Vec<u8>) {
    assert_eq!(u32::from_le_bytes(glb[0..4].try_into().unwrap()), GLB_MAGIC);
    assert_eq!(u32::from_le_bytes(glb[4..8].try_into().unwrap()), 2);
    assert_eq!(
        u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
        glb.len()
    );
    assert_eq!(glb.len() % 4, 0);
    let chunks = parse_glb(glb).unwrap();
    assert_eq!(chunks.json.len() % 4, 0);
    let root: Root = serde_json::from_slice(chunks.json).unwrap();
    let bin = chunks.bin.unwrap_or_default().to_vec();
    if let Some(b) = root.buffers.first() {
        assert_eq!(b.uri, None, "GLB buffer has no uri");
        // The chunk may carry up to 3 padding bytes beyond byteLength.
        assert!(bin.len() >= b.byte_length as usize && bin.len() - (b.byte_length as usize) < 4);
    }
    (root, bin)
}

/// The JSON and decoded embedded buffer of `.gltf` text.
fn open_gltf(text: &str) -> (Root, Vec<u8>) {
    let root: Root = serde_json::from_str(text).unwrap();
    let uri = root.buffers[0].uri.as_deref().unwrap();
    let bin = base64_decode(uri.strip_prefix(DATA_URI_PREFIX).unwrap()).unwrap();
    assert_eq!(bin.len(), root.buffers[0].byte_length as usize);
    (root, bin)
}

fn vec3s(values: &[f64]) -> Vec<Vec3> {
    values
        .chunks(3)
        .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
        .collect()
}

fn attr(attrs: &[(String, u32)], name: &str) -> u32 {
    attrs.iter().find(|(k, _)| k == name).unwrap().1
}

fn check_two_mesh(root: &Root, bin: &[u8]) {
    assert_eq!(root.asset.version, "2.0");
    assert_eq!(root.asset.generator.as_deref(), Some("fbakit"));
    assert_bounds_exact(root, bin);
    // Every buffer view is used by exactly one accessor (or sparse part) and aligned.
    let mut uses = vec![0; root.buffer_views.len()];
    for a in &root.accessors {
        a.buffer_view.iter().for_each(|&v| uses[v as usize] += 1);
        if let Some(s) = &a.sparse {
            uses[s.indices.buffer_view as usize] += 1;
            uses[s.values.buffer_view as usize] += 1;
        }
    }
    assert!(uses.iter().all(|&u| u == 1), "{uses:?}");
    assert!(root.buffer_views.iter().all(|v| v.byte_offset % 4 == 0));

    let skin = &root.meshes[0];
    assert_eq!(skin.name.as_deref(), Some("skin"));
    assert_eq!(
        skin.extras.as_ref().unwrap()["targetNames"],
        serde_json::json!(["jaw_open", "smile"])
    );
    let prim = &skin.primitives[0];
    let pos = read_accessor(root, bin, attr(&prim.attributes, "POSITION"));
    assert_eq!(vec3s(&pos), cube_positions());
    let idx = read_accessor(root, bin, prim.indices.unwrap());
    let tris: Vec<[u32; 3]> = idx
        .chunks(3)
        .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32])
        .collect();
    assert_eq!(tris, cube_triangles());
    for n in vec3s(&read_accessor(root, bin, attr(&prim.attributes, "NORMAL"))) {
        assert!((n.length() - 1.0).abs() < 1e-6);
    }
    assert_eq!(
        read_accessor(root, bin, attr(&prim.attributes, "TEXCOORD_0")).len(),
        16
    );
    let jaw = read_accessor(root, bin, attr(&prim.targets[0], "POSITION"));
    assert_eq!(vec3s(&jaw), jaw_offsets());
    let smile_acc = attr(&prim.targets[1], "POSITION");
    assert!(root.accessors[smile_acc as usize].sparse.is_some());
    let smile = vec3s(&read_accessor(root, bin, smile_acc));
    let mut expected = vec![Vec3::ZERO; 8];
    for (&v, &o) in SMILE_VERTICES.iter().zip(&SMILE_OFFSETS) {
        expected[v as usize] += o;
    }
    assert_eq!(smile, expected);
    // Normal deltas: present for every target (morph_normals), zero where nothing moved.
    assert!(prim
        .targets
        .iter()
        .all(|t| t.len() == 2 && t[1].0 == "NORMAL"));

    let eye = &root.nodes[1];
    assert_eq!(eye.name.as_deref(), Some("eye_left"));
    assert_eq!(root.nodes[0].children, vec![1]);
    assert_eq!(root.scenes[0].nodes, vec![0]);
    assert!(root.materials[1].double_sided);

    let talk = &root.animations[0];
    assert_eq!(talk.name.as_deref(), Some("talk"));
    let weights = &talk.samplers[0];
    let input = &root.accessors[weights.input as usize];
    assert_eq!(input.count, 3);
    assert_eq!(
        (input.min.as_slice(), input.max.as_slice()),
        (&[0.0][..], &[1.0][..])
    );
    let out = &root.accessors[weights.output as usize];
    assert_eq!((out.count, out.kind.as_str()), (3 * 2, "SCALAR"));
    assert_eq!(
        read_accessor(root, bin, weights.output),
        vec![0.0, 0.0, 1.0, 0.5, 0.0, 1.0]
    );
    let rot = &root.accessors[talk.samplers[1].output as usize];
    assert_eq!((rot.count, rot.kind.as_str()), (3, "VEC4"));
    assert_eq!(talk.samplers[1].input, weights.input);
    for q in read_accessor(root, bin, talk.samplers[1].output).chunks(4) {
        let len = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((len - 1.0).abs() < 1e-6);
    }
    for a in &root.animations {
        for s in &a.samplers {
            let views = [s.input, s.output].map(|i| root.accessors[i as usize].buffer_view);
            assert!(views
                .iter()
                .all(|v| root.buffer_views[v.unwrap() as usize].target.is_none()));
        }
    }
    assert_eq!(
        root.animations[1].samplers[0].interpolation.as_deref(),
        Some("STEP")
    );
    // Vertex data views carry their GPU target.
    let pos_view = root.accessors[attr(&prim.attributes, "POSITION") as usize].buffer_view;
    assert_eq!(
        root.buffer_views[pos_view.unwrap() as usize].target,
        Some(json::ARRAY_BUFFER)
    );
}

#[test]
fn two_mesh_glb_reads_back() {
    let doc = two_mesh_scene();
    let (root, bin) = open_glb(&doc.to_glb().unwrap());
    check_two_mesh(&root, &bin);
    assert_eq!(root, doc.root);
}

#[test]
fn two_mesh_gltf_reads_back_and_matches_glb() {
    let doc = two_mesh_scene();
    let (root, bin) = open_gltf(&doc.to_gltf_string().unwrap());
    check_two_mesh(&root, &bin);
    let (glb_root, glb_bin) = open_glb(&doc.to_glb().unwrap());
    assert_eq!(bin, glb_bin);
    let mut without_uri = root.clone();
    without_uri.buffers[0].uri = None;
    assert_eq!(without_uri, glb_root);
}

#[test]
fn files_are_written_atomically_by_extension() {
    let dir = tempfile::tempdir().unwrap();
    let doc = two_mesh_scene();
    doc.write(&dir.path().join("face.glb")).unwrap();
    doc.write(&dir.path().join("face.gltf")).unwrap();
    let glb = std::fs::read(dir.path().join("face.glb")).unwrap();
    assert_eq!(glb, doc.to_glb().unwrap());
    let text = std::fs::read_to_string(dir.path().join("face.gltf")).unwrap();
    assert_eq!(text, doc.to_gltf_string().unwrap());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "no temporary files"
    );
}

#[test]
fn large_mesh_uses_u32_indices() {
    let doc = grid_scene(260);
    let (root, bin) = open_glb(&doc.to_glb().unwrap());
    let prim = &root.meshes[0].primitives[0];
    let indices = &root.accessors[prim.indices.unwrap() as usize];
    assert_eq!(indices.component_type, json::UNSIGNED_INT);
    let lift = &root.accessors[attr(&prim.targets[0], "POSITION") as usize];
    assert_eq!(
        lift.sparse.as_ref().unwrap().indices.component_type,
        json::UNSIGNED_INT
    );
    assert_bounds_exact(&root, &bin);
}

#[test]
fn tiny_gltf_json_snapshot() {
    let text = tiny_scene().to_gltf_string().unwrap();
    insta::assert_snapshot!(text);
}

fn finite() -> impl Strategy<Value = f32> {
    -100.0f32..100.0
}

fn vec3() -> impl Strategy<Value = Vec3> {
    (finite(), finite(), finite()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Vertices, triangles and a sparse target (vertex, offset) list over them.
type MeshInput = (Vec<Vec3>, Vec<[u32; 3]>, Vec<(u32, Vec3)>);

fn mesh_input() -> impl Strategy<Value = MeshInput> {
    prop::collection::vec(vec3(), 1..60).prop_flat_map(|positions| {
        let n = positions.len() as u32;
        (
            Just(positions),
            prop::collection::vec([0..n, 0..n, 0..n], 1..40),
            prop::collection::vec((0..n, vec3()), 0..30),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Mesh data → GLB → data read back: positions, indices and summed sparse offsets are
    /// exactly those given, and every declared bound is exact.
    #[test]
    fn glb_round_trips_mesh_data((positions, triangles, moves) in mesh_input()) {
        let (vertices, offsets): (Vec<u32>, Vec<Vec3>) = moves.iter().copied().unzip();
        let mut s = SceneBuilder::new("p");
        let m = s
            .add_mesh(
                MeshData::new("m", &positions[..], &triangles[..])
                    .with_sparse_target("t", vertices, offsets),
            )
            .unwrap();
        s.add_node(NodeData::new("n").with_mesh(m)).unwrap();
        let doc: GltfDocument = s.build().unwrap();
        let (root, bin) = open_glb(&doc.to_glb().unwrap());
        assert_bounds_exact(&root, &bin);
        let prim = &root.meshes[0].primitives[0];
        prop_assert_eq!(vec3s(&read_accessor(&root, &bin, attr(&prim.attributes, "POSITION"))), positions.clone());
        let idx: Vec<u32> = read_accessor(&root, &bin, prim.indices.unwrap()).iter().map(|&i| i as u32).collect();
        prop_assert_eq!(idx, triangles.iter().flatten().copied().collect::<Vec<_>>());
        let mut expected = vec![Vec3::ZERO; positions.len()];
        let mut sorted = moves.clone();
        sorted.sort_by_key(|m| m.0); // the writer sums repeats in vertex order
        for (v, o) in sorted {
            expected[v as usize] += o;
        }
        let got = vec3s(&read_accessor(&root, &bin, attr(&prim.targets[0], "POSITION")));
        prop_assert_eq!(got, expected);
    }
}
