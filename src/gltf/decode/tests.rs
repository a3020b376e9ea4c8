//! The decode pass on hand-made documents (the rig reader's tests decode whole files).

use std::path::Path;

use serde_json::{json, Value};

use super::*;

fn run(mut doc: Value, buffers: &mut [Vec<u8>]) -> std::result::Result<Value, String> {
    decode_document(&mut doc, buffers, Path::new("in.glb"))
        .map(|_| doc)
        .map_err(|e| e.to_string())
}

#[test]
fn required_extensions_are_sorted_into_read_and_refused() {
    let ok = json!({"extensionsRequired": ["KHR_mesh_quantization", "KHR_materials_clearcoat",
        "KHR_texture_transform"]});
    assert!(run(ok, &mut []).is_ok());
    let draco = json!({"extensionsRequired": ["KHR_draco_mesh_compression"]});
    let e = run(draco, &mut []).unwrap_err();
    assert_eq!(
        e,
        "in.glb: requires the glTF extension `KHR_draco_mesh_compression`, which fbakit cannot \
         decode; decompress it first, e.g. `npx @gltf-transform/cli copy IN.glb OUT.glb`"
    );
    let odd = json!({"extensionsRequired": ["VENDOR_warp"]});
    assert!(run(odd, &mut []).unwrap_err().contains("`VENDOR_warp`"));
    let bad = json!({"extensionsRequired": "KHR_mesh_quantization"});
    assert!(run(bad, &mut [])
        .unwrap_err()
        .contains("extensionsRequired"));
    assert!(run(json!([1, 2]), &mut [])
        .unwrap_err()
        .contains("not a JSON object"));
}

#[test]
fn optional_draco_reads_the_fallback_or_refuses_without_one() {
    let doc = |view: Option<u64>| {
        let mut acc = json!({"componentType": 5126, "count": 3, "type": "VEC3"});
        if let Some(v) = view {
            acc["bufferView"] = json!(v);
        }
        json!({
            "extensionsUsed": ["KHR_draco_mesh_compression"],
            "accessors": [acc],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0},
                "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {}}}}]}],
        })
    };
    let mut doc_with = doc(Some(0));
    let r = decode_document(&mut doc_with, &mut [], Path::new("in.glb")).unwrap();
    assert!(!r.changed);
    let w = r.warnings;
    assert_eq!(w.len(), 1);
    assert!(w[0].message.contains("uncompressed accessors are read"));
    assert!(run(doc(None), &mut [])
        .unwrap_err()
        .contains("gltf-transform/cli copy"));
}

fn meshopt_doc(ext: Value, fallback_len: u64) -> Value {
    json!({
        "extensionsUsed": ["EXT_meshopt_compression"],
        "buffers": [{"byteLength": 64},
            {"byteLength": fallback_len, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}],
        "bufferViews": [{"buffer": 1, "byteLength": fallback_len,
            "extensions": {"EXT_meshopt_compression": ext}}],
    })
}

#[test]
fn meshopt_fields_are_checked_before_decoding() {
    let cases = [
        (
            json!({"buffer": 0, "byteLength": 16, "byteStride": 12, "count": 4, "mode": "LINES"}),
            "mode",
        ),
        (
            json!({"buffer": 0, "byteLength": 16, "byteStride": 3, "count": 4, "mode": "ATTRIBUTES"}),
            "byteStride 3",
        ),
        (
            json!({"buffer": 0, "byteLength": 16, "byteStride": 12, "count": 4, "mode": "ATTRIBUTES",
            "filter": "QUATERNION"}),
            "byteStride 12",
        ),
        (
            json!({"buffer": 0, "byteLength": 16, "byteStride": 2, "count": 4, "mode": "TRIANGLES"}),
            "multiple of 3",
        ),
        (
            json!({"buffer": 0, "byteLength": 99, "byteStride": 4, "count": 4, "mode": "ATTRIBUTES"}),
            "past the end of buffer 0",
        ),
        (
            json!({"buffer": 5, "byteLength": 16, "byteStride": 4, "count": 4, "mode": "ATTRIBUTES"}),
            "no buffer 5",
        ),
        (
            json!({"buffer": 0, "byteLength": 16, "byteStride": 4, "count": -4, "mode": "ATTRIBUTES"}),
            "non-negative",
        ),
        (
            json!({"byteLength": 16, "byteStride": 4, "count": 4, "mode": "ATTRIBUTES"}),
            "buffer: missing",
        ),
        // 4 Gi elements from 16 bytes: refused before anything is allocated.
        (
            json!({"buffer": 0, "byteLength": 16, "byteStride": 256, "count": 1u64 << 32,
            "mode": "ATTRIBUTES"}),
            "more than fbakit expands",
        ),
    ];
    for (ext, want) in cases {
        let e = run(meshopt_doc(ext.clone(), 64), &mut [vec![0; 64], Vec::new()]).unwrap_err();
        assert!(
            e.contains("bufferViews[0]") && e.contains(want),
            "{ext}: `{e}` lacks `{want}`"
        );
    }
    // A fallback buffer far larger than its compressed views could expand to.
    let ext =
        json!({"buffer": 0, "byteLength": 16, "byteStride": 4, "count": 4, "mode": "ATTRIBUTES"});
    let mut doc = meshopt_doc(ext, 1 << 40);
    doc["bufferViews"][0]["byteLength"] = json!(16);
    let e = run(doc, &mut [vec![0; 64], Vec::new()]).unwrap_err();
    assert!(e.contains("buffers[1].byteLength"), "{e}");
}

#[test]
fn dropping_the_last_extension_name_removes_the_lists() {
    let mut doc = json!({"extensionsUsed": ["EXT_meshopt_compression"],
        "extensionsRequired": ["EXT_meshopt_compression", "KHR_mesh_quantization"]});
    drop_extension_name(&mut doc, "EXT_meshopt_compression");
    assert_eq!(
        doc,
        json!({"extensionsRequired": ["KHR_mesh_quantization"]})
    );
}
