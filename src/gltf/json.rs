//! The glTF 2.0 JSON data model: the subset of the schema fbakit writes.
//!
//! Plain serde structs mirroring the schema's property names. Optional properties are omitted
//! when unset and arrays when empty, because glTF forbids empty arrays and the validator reports
//! properties set to their defaults. This model knows nothing about meshes or faces: the
//! the builder fills it, the container serialises it ([`super::GltfDocument`]).

use serde::{Deserialize, Serialize};
use serde_json::Value;

/// `componentType` of 8-bit unsigned integers.
pub const UNSIGNED_BYTE: u32 = 5121;
/// `componentType` of 16-bit unsigned integers.
pub const UNSIGNED_SHORT: u32 = 5123;
/// `componentType` of 32-bit unsigned integers.
pub const UNSIGNED_INT: u32 = 5125;
/// `componentType` of 32-bit floats.
pub const FLOAT: u32 = 5126;
/// `bufferView.target` for vertex attributes.
pub const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` for vertex indices.
pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The root object of a glTF asset.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Root {
    /// Metadata: version and generator.
    pub asset: Asset,
    /// Index of the scene shown by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene: Option<u32>,
    /// Scenes (root-node lists).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scenes: Vec<Scene>,
    /// All nodes, referenced by index.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nodes: Vec<Node>,
    /// Meshes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub meshes: Vec<Mesh>,
    /// Materials.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<Material>,
    /// Animations.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub animations: Vec<Animation>,
    /// Typed views into buffer views.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub accessors: Vec<Accessor>,
    /// Byte ranges of buffers.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub buffer_views: Vec<BufferView>,
    /// Binary buffers.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub buffers: Vec<Buffer>,
}

/// `asset`: glTF version and the tool that wrote the file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Asset {
    /// Always `"2.0"`.
    pub version: String,
    /// Writing tool (`"fbakit"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub generator: Option<String>,
}

/// A scene: the root nodes to show.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// Scene name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Root node indices.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nodes: Vec<u32>,
    /// Application data (fbakit's feature-point record, `specs/gltf-fat.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extras: Option<Value>,
}

/// A node of the scene hierarchy.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Node {
    /// Node name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Child node indices.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub children: Vec<u32>,
    /// Mesh instantiated at this node.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh: Option<u32>,
    /// Translation (omitted when zero).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub translation: Option<[f32; 3]>,
    /// Unit quaternion `[x, y, z, w]` (omitted when identity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[f32; 4]>,
    /// Scale (omitted when one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale: Option<[f32; 3]>,
}

/// A mesh: one or more primitives plus default morph weights.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Mesh {
    /// Mesh name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Primitives (fbakit writes one triangle list per mesh).
    pub primitives: Vec<Primitive>,
    /// Default morph-target weights, one per target.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub weights: Vec<f32>,
    /// Application data; fbakit stores `{"targetNames": [...]}` here, the de-facto convention
    /// three.js and Blender read morph-target names from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub extras: Option<Value>,
}

/// Attribute semantic → accessor index, in a fixed order (a map would reorder the snapshot).
pub type Attributes = Vec<(String, u32)>;

/// A drawable piece of a mesh.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Primitive {
    /// Vertex attributes (`POSITION`, `NORMAL`, `TEXCOORD_0`).
    #[serde(with = "ordered_map")]
    pub attributes: Attributes,
    /// Index accessor.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub indices: Option<u32>,
    /// Material index.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material: Option<u32>,
    /// Topology; omitted means 4 = triangles, the only mode fbakit writes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<u32>,
    /// Morph targets: attribute displacements (`POSITION`, optionally `NORMAL`).
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        with = "ordered_map_vec"
    )]
    pub targets: Vec<Attributes>,
}

/// A metallic-roughness material.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Material {
    /// Material name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// PBR parameters.
    pub pbr_metallic_roughness: PbrMetallicRoughness,
    /// `"BLEND"` for translucent colours; omitted (opaque) otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha_mode: Option<String>,
    /// Render both faces (omitted when false).
    #[serde(default, skip_serializing_if = "is_false")]
    pub double_sided: bool,
}

/// `pbrMetallicRoughness` factors (no textures).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct PbrMetallicRoughness {
    /// Linear RGBA base colour.
    pub base_color_factor: [f32; 4],
    /// Metalness 0..=1.
    pub metallic_factor: f32,
    /// Roughness 0..=1.
    pub roughness_factor: f32,
}

/// A typed view of binary data.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Accessor {
    /// Buffer view; absent for all-zero (possibly sparse) data.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub buffer_view: Option<u32>,
    /// Element type code ([`FLOAT`], [`UNSIGNED_SHORT`], ...).
    pub component_type: u32,
    /// Number of elements.
    pub count: u32,
    /// `"SCALAR"`, `"VEC2"`, `"VEC3"` or `"VEC4"`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Per-component maximum (required for `POSITION` and animation input).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub max: Vec<f32>,
    /// Per-component minimum.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub min: Vec<f32>,
    /// Sparse substitution over the (zero or viewed) base data.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sparse: Option<Sparse>,
}

/// `accessor.sparse`: element indices and replacement values.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Sparse {
    /// Number of replaced elements (>= 1).
    pub count: u32,
    /// Strictly increasing element indices.
    pub indices: SparseIndices,
    /// Replacement values.
    pub values: SparseValues,
}

/// `accessor.sparse.indices`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SparseIndices {
    /// Buffer view (without target or stride).
    pub buffer_view: u32,
    /// [`UNSIGNED_BYTE`], [`UNSIGNED_SHORT`] or [`UNSIGNED_INT`].
    pub component_type: u32,
}

/// `accessor.sparse.values`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SparseValues {
    /// Buffer view (without target or stride).
    pub buffer_view: u32,
}

/// A byte range of a buffer.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct BufferView {
    /// Buffer index.
    pub buffer: u32,
    /// Start (omitted when 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub byte_offset: u32,
    /// Length in bytes.
    pub byte_length: u32,
    /// [`ARRAY_BUFFER`] or [`ELEMENT_ARRAY_BUFFER`] for GPU data; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target: Option<u32>,
}

/// A binary buffer: the GLB `BIN` chunk (no `uri`) or an embedded data URI.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Buffer {
    /// Length in bytes.
    pub byte_length: u32,
    /// Data URI for `.gltf`; absent in `.glb`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uri: Option<String>,
}

/// An animation: samplers (keyframes) and the channels they drive.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Animation {
    /// Animation name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Channels.
    pub channels: Vec<Channel>,
    /// Samplers.
    pub samplers: Vec<AnimationSampler>,
}

/// `animation.channels[]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Channel {
    /// Sampler index within the animation.
    pub sampler: u32,
    /// Animated node property.
    pub target: ChannelTarget,
}

/// `animation.channels[].target`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ChannelTarget {
    /// Node index.
    pub node: u32,
    /// `"weights"`, `"rotation"`, `"translation"` or `"scale"`.
    pub path: String,
}

/// `animation.samplers[]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AnimationSampler {
    /// Keyframe times accessor (seconds, with min/max).
    pub input: u32,
    /// `"STEP"`; omitted for the default `"LINEAR"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interpolation: Option<String>,
    /// Keyframe values accessor.
    pub output: u32,
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

/// Serialises attribute lists as JSON objects, keeping insertion order.
mod ordered_map {
    use serde::de::{Deserializer, MapAccess, Visitor};
    use serde::ser::{SerializeMap, Serializer};

    pub fn serialize<S: Serializer>(attrs: &[(String, u32)], s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(attrs.len()))?;
        for (k, v) in attrs {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }

    /// Reads a JSON object keeping its key order (so a written file reads back equal).
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<(String, u32)>, D::Error> {
        d.deserialize_map(InOrder)
    }

    struct InOrder;

    impl<'de> Visitor<'de> for InOrder {
        type Value = Vec<(String, u32)>;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object of accessor indices")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut out = Vec::new();
            while let Some(entry) = map.next_entry::<String, u32>()? {
                out.push(entry);
            }
            Ok(out)
        }
    }
}

/// [`ordered_map`] for a list of attribute lists (`primitive.targets`).
mod ordered_map_vec {
    use serde::de::Deserializer;
    use serde::ser::{SerializeSeq, Serializer};
    use serde::{Deserialize, Serialize};

    struct Ordered<'a>(&'a [(String, u32)]);

    impl Serialize for Ordered<'_> {
        fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            super::ordered_map::serialize(self.0, s)
        }
    }

    pub fn serialize<S: Serializer>(list: &[Vec<(String, u32)>], s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(list.len()))?;
        for attrs in list {
            seq.serialize_element(&Ordered(attrs))?;
        }
        seq.end()
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Vec<Vec<(String, u32)>>, D::Error> {
        #[derive(Deserialize)]
        struct Attrs(#[serde(with = "super::ordered_map")] Vec<(String, u32)>);
        let maps = Vec::<Attrs>::deserialize(d)?;
        Ok(maps.into_iter().map(|m| m.0).collect())
    }
}
