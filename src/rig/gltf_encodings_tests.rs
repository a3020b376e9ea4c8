//! Hand-built glTF files in each encoding other tools write, read by the rig reader: the same
//! quad must come back whatever the layout, so the code is tested without node.

use std::path::Path;

use glam::{Vec2, Vec3};
use serde_json::{json, Value};

use super::gltf_read::read_gltf_bytes;
use super::Rig;

/// The quad every case encodes: four corners, two counter-clockwise triangles.
const QUAD: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];
const TRIS: [u32; 6] = [0, 1, 2, 0, 2, 3];

/// A `.glb` of `doc` (buffer 0 gets `bin`'s length) and `bin`.
fn glb(mut doc: Value, bin: &[u8]) -> Vec<u8> {
    if !bin.is_empty() {
        doc["buffers"][0]["byteLength"] = json!(bin.len());
    }
    doc["asset"] = json!({"version": "2.0"});
    let mut text = serde_json::to_vec(&doc).unwrap();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    for w in [2u32, total as u32, text.len() as u32, 0x4E4F_534A] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    out.extend_from_slice(&text);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    out
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn read(bytes: &[u8]) -> Rig {
    read_gltf_bytes(bytes, Path::new("case.glb")).unwrap()
}

fn read_err(bytes: &[u8]) -> String {
    read_gltf_bytes(bytes, Path::new("case.glb"))
        .unwrap_err()
        .to_string()
}

fn quad_positions() -> Vec<Vec3> {
    QUAD.iter().map(|&p| Vec3::from(p)).collect()
}

fn triangles(rig: &Rig) -> Vec<Vec<u32>> {
    rig.meshes[0]
        .mesh
        .polygons
        .iter()
        .map(<[u32]>::to_vec)
        .collect()
}

/// One mesh on one node in one scene, primitive `prim`.
fn one_mesh(prim: Value) -> Value {
    json!({
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim]}],
        "buffers": [{"byteLength": 0}],
    })
}

#[test]
fn interleaved_positions_and_normals_with_a_byte_stride() {
    let mut bin = Vec::new();
    for p in QUAD {
        bin.extend(f32s(&p));
        bin.extend(f32s(&[0.0, 0.0, 1.0]));
    }
    let idx_at = bin.len();
    bin.extend(TRIS.iter().flat_map(|&i| (i as u16).to_le_bytes()));
    let mut doc = one_mesh(json!({"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}));
    doc["bufferViews"] = json!([
        {"buffer": 0, "byteLength": idx_at, "byteStride": 24},
        {"buffer": 0, "byteOffset": idx_at, "byteLength": 12},
    ]);
    doc["accessors"] = json!([
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
    ]);
    let rig = read(&glb(doc, &bin));
    let mesh = &rig.meshes[0].mesh;
    assert_eq!(mesh.positions, quad_positions());
    assert_eq!(mesh.normals, vec![Vec3::Z; 4]);
    assert_eq!(triangles(&rig), vec![vec![0, 1, 2], vec![0, 2, 3]]);
}

#[test]
fn indices_of_8_16_and_32_bits_give_the_same_triangles() {
    for (component, size) in [(5121, 1usize), (5123, 2), (5125, 4)] {
        let mut bin = f32s(QUAD.as_flattened());
        let idx_at = bin.len();
        for &i in &TRIS {
            bin.extend_from_slice(&i.to_le_bytes()[..size]);
        }
        let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}, "indices": 1}));
        doc["bufferViews"] = json!([
            {"buffer": 0, "byteLength": idx_at},
            {"buffer": 0, "byteOffset": idx_at, "byteLength": 6 * size},
        ]);
        doc["accessors"] = json!([
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": component, "count": 6, "type": "SCALAR"},
        ]);
        let rig = read(&glb(doc, &bin));
        assert_eq!(
            triangles(&rig),
            vec![vec![0, 1, 2], vec![0, 2, 3]],
            "component type {component}"
        );
    }
}

#[test]
fn non_indexed_strips_and_fans() {
    // Non-indexed triangles: six vertices, two triangles.
    let six: Vec<f32> = TRIS.iter().flat_map(|&i| QUAD[i as usize]).collect();
    let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}}));
    doc["bufferViews"] = json!([{"buffer": 0, "byteLength": 72}]);
    doc["accessors"] = json!([{"bufferView": 0, "componentType": 5126, "count": 6,
        "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]);
    let rig = read(&glb(doc, &f32s(&six)));
    assert_eq!(triangles(&rig), vec![vec![0, 1, 2], vec![3, 4, 5]]);

    // A strip 1-2-0-3 and a fan 0-1-2-3 over the quad's corners, non-indexed.
    for (mode, order, want) in [
        (5, [1u32, 2, 0, 3], vec![vec![0, 1, 2], vec![2, 1, 3]]),
        (6, [0u32, 1, 2, 3], vec![vec![0, 1, 2], vec![0, 2, 3]]),
    ] {
        let pts: Vec<f32> = order.iter().flat_map(|&i| QUAD[i as usize]).collect();
        let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}, "mode": mode}));
        doc["bufferViews"] = json!([{"buffer": 0, "byteLength": 48}]);
        doc["accessors"] = json!([{"bufferView": 0, "componentType": 5126, "count": 4,
            "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]);
        let rig = read(&glb(doc, &f32s(&pts)));
        assert_eq!(triangles(&rig), want, "mode {mode}");
        // Counter-clockwise seen from +z, like the quad.
        let m = &rig.meshes[0].mesh;
        for t in triangles(&rig) {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            assert!(
                (b - a).cross(c - a).z > 0.0,
                "mode {mode}: {t:?} is clockwise"
            );
        }
    }
}

#[test]
fn sparse_accessors_on_a_view_and_on_zeros() {
    let mut bin = f32s(QUAD.as_flattened());
    let idx_at = bin.len();
    bin.extend(TRIS.iter().flat_map(|&i| (i as u16).to_le_bytes()));
    let sparse_idx_at = bin.len();
    bin.extend([1u8, 3, 0, 0]); // u8 indices, padded
    let sparse_val_at = bin.len();
    bin.extend(f32s(&[1.0, 0.0, 0.5, 0.0, 1.0, 0.25]));
    let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}, "indices": 1,
        "targets": [{"POSITION": 2}]}));
    doc["meshes"][0]["extras"] = json!({"targetNames": ["lift"]});
    doc["bufferViews"] = json!([
        {"buffer": 0, "byteLength": idx_at},
        {"buffer": 0, "byteOffset": idx_at, "byteLength": 12},
        {"buffer": 0, "byteOffset": sparse_idx_at, "byteLength": 2},
        {"buffer": 0, "byteOffset": sparse_val_at, "byteLength": 24},
    ]);
    let sparse = json!({"count": 2, "indices": {"bufferView": 2, "componentType": 5121},
        "values": {"bufferView": 3}});
    doc["accessors"] = json!([
        // Base positions with vertex 1 and 3 replaced (z lifted).
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0.5], "sparse": sparse},
        {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        // A morph target of zeros but the same two vertices.
        {"componentType": 5126, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0.5], "sparse": sparse},
    ]);
    let rig = read(&glb(doc, &bin));
    let mut want = quad_positions();
    want[1].z = 0.5;
    want[3].z = 0.25;
    assert_eq!(rig.meshes[0].mesh.positions, want);
    let lift = &rig.shapes[0];
    assert_eq!(lift.name, "lift");
    assert_eq!(lift.deltas[0].vertices, vec![1, 3]);
    assert_eq!(
        lift.deltas[0].offsets,
        vec![Vec3::new(1.0, 0.0, 0.5), Vec3::new(0.0, 1.0, 0.25)]
    );
}

/// A quantized quad as `gltf-transform quantize` writes it: normalised i16 positions placed by
/// the node's scale and translation, i8 normals padded to 4 bytes, u16 texture coordinates,
/// an i16 morph target.
fn quantized_quad() -> Vec<u8> {
    let mut bin = Vec::new();
    // Positions in [-1, 1] as i16 normalised (stride 8: 3 shorts + padding).
    for p in QUAD {
        for c in p {
            let q = ((c * 2.0 - 1.0) * 32767.0).round() as i16;
            bin.extend(q.to_le_bytes());
        }
        bin.extend([0, 0]);
    }
    let normals_at = bin.len();
    for _ in 0..4 {
        bin.extend([0u8, 0, 127, 0]);
    }
    let uv_at = bin.len();
    for p in QUAD {
        for c in [p[0], p[1]] {
            bin.extend(((c * 65535.0) as u16).to_le_bytes());
        }
    }
    let morph_at = bin.len();
    for i in 0..4 {
        let dz: i16 = if i == 2 { 16384 } else { 0 };
        for q in [0i16, 0, dz, 0] {
            bin.extend(q.to_le_bytes());
        }
    }
    let idx_at = bin.len();
    bin.extend(TRIS.iter().map(|&i| i as u8));
    let mut doc = one_mesh(json!({
        "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
        "indices": 4, "targets": [{"POSITION": 3}]}));
    doc["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    doc["meshes"][0]["extras"] = json!({"targetNames": ["bulge"]});
    // Dequantisation: [-1, 1] back to [0, 1] is scale 0.5, translation 0.5.
    doc["nodes"][0]["scale"] = json!([0.5, 0.5, 0.5]);
    doc["nodes"][0]["translation"] = json!([0.5, 0.5, 0.5]);
    doc["bufferViews"] = json!([
        {"buffer": 0, "byteLength": normals_at, "byteStride": 8},
        {"buffer": 0, "byteOffset": normals_at, "byteLength": 16, "byteStride": 4},
        {"buffer": 0, "byteOffset": uv_at, "byteLength": 16},
        {"buffer": 0, "byteOffset": morph_at, "byteLength": 32, "byteStride": 8},
        {"buffer": 0, "byteOffset": idx_at, "byteLength": 6},
    ]);
    doc["accessors"] = json!([
        {"bufferView": 0, "componentType": 5122, "normalized": true, "count": 4,
         "type": "VEC3", "min": [-32767, -32767, -32767], "max": [32767, 32767, -32767]},
        {"bufferView": 1, "componentType": 5120, "normalized": true, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5122, "normalized": true, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [0, 0, 16384]},
        {"bufferView": 4, "componentType": 5121, "count": 6, "type": "SCALAR"},
    ]);
    glb(doc, &bin)
}

#[test]
fn quantized_attributes_are_dequantized_by_the_spec_rules() {
    let rig = read(&quantized_quad());
    let mesh = &rig.meshes[0].mesh;
    // Positions: c / 32767 then the node transform; exact to the 16-bit step.
    for (got, want) in mesh.positions.iter().zip(quad_positions()) {
        assert!(got.distance(want) < 1e-4, "{got} vs {want}");
    }
    assert_eq!(mesh.normals, vec![Vec3::Z; 4]);
    for (got, p) in mesh.uvs.iter().zip(QUAD) {
        assert!(got.distance(Vec2::new(p[0], p[1])) < 1e-4);
    }
    // The morph delta: 16384 / 32767 in quantized space, times the node's 0.5 scale.
    let d = &rig.shapes[0].deltas[0];
    assert_eq!(d.vertices, vec![2]);
    assert!((d.offsets[0].z - 0.5 * 16384.0 / 32767.0).abs() < 1e-6);
    assert!(rig.warnings.is_empty(), "{:?}", rig.warnings);
}

#[test]
fn unsigned_int_vertex_attributes_are_refused() {
    let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}}));
    doc["bufferViews"] = json!([{"buffer": 0, "byteLength": 48}]);
    doc["accessors"] = json!([{"bufferView": 0, "componentType": 5125, "count": 4,
        "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]);
    let e = read_err(&glb(doc, &[0; 48]));
    assert!(
        e.contains("attributes.POSITION") && e.contains("expected VEC3"),
        "{e}"
    );
}

#[test]
fn a_file_without_a_scene_reads_every_root_node_with_a_warning() {
    let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}, "mode": 6}));
    doc.as_object_mut().unwrap().remove("scene");
    doc.as_object_mut().unwrap().remove("scenes");
    doc["nodes"] = json!([{"mesh": 0, "children": [1]}, {"mesh": 0, "translation": [0, 0, 1]}]);
    doc["bufferViews"] = json!([{"buffer": 0, "byteLength": 48}]);
    doc["accessors"] = json!([{"bufferView": 0, "componentType": 5126, "count": 4,
        "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]);
    let rig = read(&glb(doc, &f32s(QUAD.as_flattened())));
    // The root and, through it, its child: two instances.
    assert_eq!(rig.meshes.len(), 2);
    assert_eq!(rig.meshes[1].mesh.positions[0], Vec3::Z);
    assert_eq!(rig.warnings.len(), 1);
    assert!(
        rig.warnings[0].message.contains("no scene"),
        "{:?}",
        rig.warnings
    );

    let empty = json!({"meshes": [{"primitives": []}], "buffers": []});
    assert!(read_err(&glb(empty, &[])).contains("no scene and no nodes"));
}

#[test]
fn required_extensions_fbakit_cannot_decode_are_refused_by_name() {
    let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}}));
    doc["bufferViews"] = json!([{"buffer": 0, "byteLength": 48}]);
    doc["accessors"] = json!([{"bufferView": 0, "componentType": 5126, "count": 4,
        "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]);
    let bin = f32s(QUAD.as_flattened());
    for (ext, hint) in [
        ("KHR_draco_mesh_compression", "gltf-transform/cli copy"),
        ("EXT_mesh_gpu_instancing", "bake or remove it"),
    ] {
        let mut d = doc.clone();
        d["extensionsUsed"] = json!([ext]);
        d["extensionsRequired"] = json!([ext]);
        let e = read_err(&glb(d, &bin));
        assert!(
            e.starts_with("case.glb: ") && e.contains(&format!("`{ext}`")) && e.contains(hint),
            "{e}"
        );
    }
    // Harmless ones are read.
    let mut d = doc.clone();
    d["extensionsUsed"] = json!(["KHR_materials_unlit", "KHR_texture_transform"]);
    d["extensionsRequired"] = json!(["KHR_materials_unlit", "KHR_texture_transform"]);
    assert_eq!(read(&glb(d, &bin)).meshes.len(), 1);
}

/// A quad whose positions and indices are meshopt-compressed (encoded here with the same
/// library), laid out as `gltf-transform meshopt` does: buffer 0 holds the compressed bytes,
/// buffer 1 is the fallback they decode into. `stride` overrides the vertex stream's stride;
/// `corrupt` spoils its header byte.
fn meshopt_quad(stride: Option<usize>, corrupt: bool) -> Vec<u8> {
    let positions: Vec<[f32; 3]> = QUAD.to_vec();
    let mut vertices = ::meshopt::encoding::encode_vertex_buffer(&positions).unwrap();
    if corrupt {
        vertices[0] = 0xFF;
    }
    let indices = ::meshopt::encoding::encode_index_buffer(&TRIS, 4).unwrap();
    let mut bin = vertices.clone();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let idx_at = bin.len();
    bin.extend(&indices);
    let stride = stride.unwrap_or(12);
    let mut doc = one_mesh(json!({"attributes": {"POSITION": 0}, "indices": 1}));
    doc["extensionsUsed"] = json!(["EXT_meshopt_compression"]);
    doc["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    doc["buffers"] = json!([
        {"byteLength": bin.len()},
        {"byteLength": 60, "extensions": {"EXT_meshopt_compression": {"fallback": true}}},
    ]);
    doc["bufferViews"] = json!([
        {"buffer": 1, "byteLength": 48, "byteStride": 12, "extensions": {"EXT_meshopt_compression":
            {"buffer": 0, "byteLength": vertices.len(), "byteStride": stride, "count": 4,
             "mode": "ATTRIBUTES"}}},
        {"buffer": 1, "byteOffset": 48, "byteLength": 12, "extensions": {"EXT_meshopt_compression":
            {"buffer": 0, "byteOffset": idx_at, "byteLength": indices.len(), "byteStride": 2,
             "count": 6, "mode": "TRIANGLES"}}},
    ]);
    doc["accessors"] = json!([
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
    ]);
    glb(doc, &bin)
}

#[test]
fn meshopt_compressed_views_are_decoded_with_a_warning() {
    let rig = read(&meshopt_quad(None, false));
    assert_eq!(rig.meshes[0].mesh.positions, quad_positions());
    assert_eq!(triangles(&rig), vec![vec![0, 1, 2], vec![0, 2, 3]]);
    assert_eq!(rig.warnings.len(), 1);
    assert!(rig.warnings[0].message.contains("EXT_meshopt_compression"));
}

#[test]
fn the_decode_pass_leaves_plain_gltf() {
    let bytes = meshopt_quad(None, false);
    let glb = ::gltf::Glb::from_slice(&bytes).unwrap();
    let mut json: Value = serde_json::from_slice(&glb.json).unwrap();
    let mut buffers = vec![glb.bin.unwrap().into_owned(), Vec::new()];
    let report =
        crate::gltf::decode::decode_document(&mut json, &mut buffers, Path::new("m.glb")).unwrap();
    assert!(report.changed);
    assert_eq!(report.warnings.len(), 1);
    assert!(json.get("extensionsUsed").is_none());
    assert!(json.get("extensionsRequired").is_none());
    assert!(json["bufferViews"][0].get("extensions").is_none());
    assert!(json["buffers"][1].get("extensions").is_none());
    assert_eq!(buffers[1].len(), 60);
    assert_eq!(&buffers[1][..48], f32s(QUAD.as_flattened()).as_slice());
}

#[test]
fn hostile_meshopt_views_are_errors_not_aborts() {
    // A stride the decoder would assert on.
    let e = read_err(&meshopt_quad(Some(6), false));
    assert!(e.contains("byteStride 6 is not allowed"), "{e}");
    // Garbage compressed bytes.
    let e = read_err(&meshopt_quad(None, true));
    assert!(
        e.contains("bufferViews[0].extensions.EXT_meshopt_compression") && e.contains("malformed"),
        "{e}"
    );
}
