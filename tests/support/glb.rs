//! The binary glTF container: a JSON chunk and a BIN chunk behind a 12-byte header (glTF 2.0
//! §4.4), for tests that build their own `.glb` assets.
#![allow(dead_code)]

/// `json` and `bin` as `.glb` bytes: the JSON padded with spaces and the buffer with zeros
/// to 4 bytes, as the container requires; `buffers[0].byteLength` is set to the buffer's.
pub fn pack(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut json = json.clone();
    json["buffers"][0]["byteLength"] = serde_json::json!(bin.len());
    let mut text = serde_json::to_vec(&json).unwrap();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    // "glTF", version 2, length; then each chunk's length and type ("JSON", "BIN\0").
    for w in [
        0x4654_6C67u32,
        2,
        total as u32,
        text.len() as u32,
        0x4E4F_534A,
    ] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
    out.extend_from_slice(&bin);
    out
}

/// A `.glb`'s one buffer being filled: its bytes, buffer views and accessors.
#[derive(Default)]
pub struct Buffer {
    pub bin: Vec<u8>,
    pub views: Vec<serde_json::Value>,
    pub accessors: Vec<serde_json::Value>,
}

impl Buffer {
    /// A primitive of `positions` (float VEC3 with min/max) and `triangles` (u32 indices)
    /// appended to the buffer: its JSON, to go into a mesh's `primitives`.
    pub fn primitive(
        &mut self,
        positions: &[glam::Vec3],
        triangles: &[[u32; 3]],
    ) -> serde_json::Value {
        use serde_json::json;
        let lo = positions
            .iter()
            .fold(glam::Vec3::INFINITY, |a, &b| a.min(b));
        let hi = positions
            .iter()
            .fold(glam::Vec3::NEG_INFINITY, |a, &b| a.max(b));
        let start = self.bin.len();
        for c in positions.iter().flat_map(|q| q.to_array()) {
            self.bin.extend_from_slice(&c.to_le_bytes());
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start}));
        self.accessors.push(
            json!({"bufferView": self.views.len() - 1, "componentType": 5126,
            "count": positions.len(), "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()}),
        );
        let start = self.bin.len();
        for i in triangles.iter().flatten() {
            self.bin.extend_from_slice(&i.to_le_bytes());
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start}));
        self.accessors.push(
            json!({"bufferView": self.views.len() - 1, "componentType": 5125,
            "count": triangles.len() * 3, "type": "SCALAR"}),
        );
        json!({"attributes": {"POSITION": self.accessors.len() - 2},
            "indices": self.accessors.len() - 1})
    }
}

/// A `.glb` file's JSON and its BIN chunk (empty when it has none).
pub fn open(path: &std::path::Path) -> (serde_json::Value, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let chunks = fbakit::gltf::parse_glb(&bytes).unwrap();
    let json = serde_json::from_slice(chunks.json).unwrap();
    (json, chunks.bin.unwrap_or_default().to_vec())
}

/// The values of float accessor `a` (tightly packed in its view, no sparse), as fbakit and
/// the test avatars write animation samplers and morph targets.
pub fn floats(json: &serde_json::Value, bin: &[u8], a: usize) -> Vec<f32> {
    let acc = &json["accessors"][a];
    assert_eq!(acc["componentType"], 5126, "accessor {a} is not float");
    let view = &json["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let per = match acc["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        t => panic!("{t}"),
    };
    let n = acc["count"].as_u64().unwrap() as usize * per;
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
        + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    bin[start..start + 4 * n]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The animation `play` added to a document (named `play`).
pub fn play_animation(json: &serde_json::Value) -> serde_json::Value {
    json["animations"]
        .as_array()
        .expect("animations")
        .iter()
        .find(|a| a["name"] == "play")
        .expect("an animation named play")
        .clone()
}
