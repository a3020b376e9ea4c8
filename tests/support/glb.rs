//! The binary glTF container: a JSON chunk and a BIN chunk behind a 12-byte header (glTF 2.0
//! §4.4), for tests that build their own `.glb` assets.

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
