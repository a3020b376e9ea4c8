//! Writing a user's glTF document back with fbakit's additions, everything else kept.
//!
//! A [`GltfPatch`] lists what fbakit adds to a [`GltfSource`]: morph targets appended to
//! meshes (named in `mesh.extras.targetNames`, with default `weights`), extras on meshes and
//! scenes, and one animation. [`GltfPatch::apply`] makes a [`PatchedGltf`]: a copy of the JSON
//! with the additions, and one binary buffer holding the document's buffers (each at a
//! 4-byte-aligned offset, so every accessor keeps its alignment) followed by the new data.
//! Nodes, meshes, primitives, materials, textures, images, samplers, skins, animations,
//! cameras, scenes, extensions and extras are carried over as they were; only `buffers` and
//! the `buffer` / `byteOffset` of buffer views change (the buffers are merged), and weight
//! channels of the user's animations on patched meshes get zero weights for the new targets
//! (glTF requires one weight per target). Writing over a document fbakit patched before
//! replaces fbakit's own targets in their slots and drops their old accessors, views and bytes
//! (`reclaim`), so a file does not grow with each write.
//!
//! glTF rules the patch follows: every primitive of a mesh has the same number of targets, so
//! a primitive a new target does not move gets a zero target (a sparse accessor with one zero
//! entry: sparse accessors need at least one); `POSITION` target accessors carry exact
//! `min`/`max`; new buffer views carry no `target`.
//!
//! [`PatchedGltf::write`] writes `.glb` (one `BIN` chunk), or `.gltf` with the buffer as
//! `<stem>.bin` beside it; images the document references by relative URI are carried to the
//! output's folder when it is another, their URIs rewritten (`images`). A `<stem>.bin` that
//! would replace one of the input's own files is refused before anything is written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use serde_json::{json, Map, Value};

use super::images::{self, uri_escape};
use super::source::GltfSource;
use super::GltfError;
use crate::error::{Diagnostic, Result};

/// `componentType` FLOAT.
const FLOAT: u32 = 5126;
/// `componentType` UNSIGNED_INT.
const UNSIGNED_INT: u32 = 5125;

/// The morph targets added to one glTF mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshPatch {
    /// Names of the new targets (appended after the mesh's own, in order, except those
    /// that replace a target).
    pub names: Vec<String>,
    /// Per new target, the index of an existing target it overwrites (fbakit's own from an
    /// earlier write: same table piece), keeping that target's name; `None` appends.
    pub replaces: Vec<Option<usize>>,
    /// Existing targets to overwrite with zeros (fbakit's own that no longer have a table).
    pub zeroed: Vec<usize>,
    /// Per primitive index, per new target, the moved vertices and their offsets in the
    /// primitive's own space. Primitives or targets absent here get zero targets.
    pub primitives: BTreeMap<usize, Vec<SparseOffsets>>,
    /// Extras merged into `mesh.extras` (besides `targetNames`), e.g. fbakit's FAT record.
    pub extras: Map<String, Value>,
}

/// Moved vertices of one primitive under one target.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SparseOffsets {
    /// Vertex indices, increasing.
    pub vertices: Vec<u32>,
    /// Offset of each listed vertex.
    pub offsets: Vec<Vec3>,
}

/// One animation added by the patch; every channel shares `times`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PatchAnimation {
    /// Animation name.
    pub name: String,
    /// Key times in seconds, increasing.
    pub times: Vec<f32>,
    /// Morph weights per node: the node index and, per key, one weight per target of its
    /// mesh after the patch (the user's targets first).
    pub weights: Vec<(usize, Vec<f32>)>,
    /// Rotations per node: the node index and one rotation per key.
    pub rotations: Vec<(usize, Vec<Quat>)>,
    /// Translations per node: the node index and one translation per key.
    pub translations: Vec<(usize, Vec<Vec3>)>,
    /// Scales per node: the node index and one scale per key.
    pub scales: Vec<(usize, Vec<Vec3>)>,
}

/// What fbakit adds to a document.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfPatch {
    /// Additions per glTF mesh index.
    pub meshes: BTreeMap<usize, MeshPatch>,
    /// Extras merged into the shown scene's `extras` (fbakit's feature points and FAPU).
    pub scene_extras: Map<String, Value>,
    /// The animation to add, if any.
    pub animation: Option<PatchAnimation>,
}

/// A patched document ready to write.
#[derive(Clone, Debug)]
pub struct PatchedGltf {
    /// The JSON (its single buffer's `uri` is set by the writer).
    pub json: Value,
    /// Buffer 0.
    pub bin: Vec<u8>,
    /// The folder relative image URIs were resolved against.
    pub source_dir: PathBuf,
    /// The input's own files: the document, its external buffers and images (none of them
    /// may be replaced by the output's `.bin`).
    pub inputs: Vec<PathBuf>,
    /// What could not be kept exactly.
    pub warnings: Vec<Diagnostic>,
}

fn content(at: impl Into<String>, what: impl Into<String>) -> crate::error::Error {
    GltfError::Scene(format!("{}: {}", at.into(), what.into())).into()
}

/// Growing JSON arrays and buffer of a document under patch.
struct Builder {
    json: Value,
    bin: Vec<u8>,
    /// Accessors of fbakit's own targets that new ones replaced (dropped at the end when
    /// nothing else uses them).
    released: Vec<usize>,
}

impl Builder {
    fn array(&mut self, key: &str) -> &mut Vec<Value> {
        let root = self.json.as_object_mut().expect("checked to be an object");
        let v = root.entry(key).or_insert_with(|| Value::Array(Vec::new()));
        if !v.is_array() {
            *v = Value::Array(Vec::new());
        }
        v.as_array_mut().expect("just made an array")
    }

    /// Appends `bytes` as a new buffer view (4-byte aligned); returns its index.
    fn view(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let views = self.array("bufferViews");
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}));
        views.len() - 1
    }

    fn accessor(&mut self, value: Value) -> usize {
        let list = self.array("accessors");
        list.push(value);
        list.len() - 1
    }

    fn floats(&mut self, values: &[f32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.view(&bytes)
    }

    /// A VEC3 target accessor of `count` vertices (zeros but the listed ones): sparse, or dense
    /// when that is smaller.
    fn sparse_target(&mut self, count: usize, s: &SparseOffsets) -> usize {
        let zero = SparseOffsets {
            vertices: vec![0],
            offsets: vec![Vec3::ZERO],
        };
        let s = if s.vertices.is_empty() { &zero } else { s };
        let mut min = Vec3::splat(f32::INFINITY);
        let mut max = Vec3::splat(f32::NEG_INFINITY);
        for o in &s.offsets {
            min = min.min(*o);
            max = max.max(*o);
        }
        if s.vertices.len() < count {
            // The unlisted vertices are zeros.
            min = min.min(Vec3::ZERO);
            max = max.max(Vec3::ZERO);
        }
        // A sparse entry costs 16 bytes (index + VEC3), a dense one 12: a target that moves
        // more than three quarters of its vertices is smaller (and faster to write) dense.
        if s.vertices.len() * 16 > count * 12 && s.vertices.iter().all(|&v| (v as usize) < count) {
            let mut dense = vec![0.0f32; count * 3];
            for (&v, o) in s.vertices.iter().zip(&s.offsets) {
                dense[v as usize * 3..v as usize * 3 + 3].copy_from_slice(&o.to_array());
            }
            let dv = self.floats(&dense);
            return self.accessor(json!({
                "bufferView": dv,
                "componentType": FLOAT,
                "count": count,
                "type": "VEC3",
                "min": [min.x, min.y, min.z],
                "max": [max.x, max.y, max.z],
            }));
        }
        let idx: Vec<u8> = s.vertices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let vals: Vec<f32> = s.offsets.iter().flat_map(|o| o.to_array()).collect();
        let iv = self.view(&idx);
        let vv = self.floats(&vals);
        self.accessor(json!({
            "componentType": FLOAT,
            "count": count,
            "type": "VEC3",
            "min": [min.x, min.y, min.z],
            "max": [max.x, max.y, max.z],
            "sparse": {
                "count": s.vertices.len(),
                "indices": {"bufferView": iv, "componentType": UNSIGNED_INT},
                "values": {"bufferView": vv}
            }
        }))
    }
}

/// Number of elements of accessor `a` (0 when absent or malformed).
fn accessor_count(json: &Value, a: Option<u64>) -> usize {
    a.and_then(|a| json["accessors"].get(a as usize))
        .and_then(|acc| acc["count"].as_u64())
        .unwrap_or(0) as usize
}

impl GltfPatch {
    /// The source document with this patch applied (see the module docs).
    pub fn apply(&self, source: &GltfSource) -> Result<PatchedGltf> {
        let file = source.path.display().to_string();
        if !source.json.is_object() {
            return Err(content(file, "the document is not a JSON object"));
        }
        let mut warnings = Vec::new();
        let mut b = Builder {
            json: source.json.clone(),
            bin: Vec::new(),
            released: Vec::new(),
        };
        merge_buffers(&mut b, source)?;
        for (&m, patch) in &self.meshes {
            patch_mesh(&mut b, &file, m, patch, &mut warnings)?;
        }
        if !self.scene_extras.is_empty() {
            let s = b.json["scene"].as_u64().unwrap_or(0) as usize;
            if let Some(scene) = b.json["scenes"].get_mut(s) {
                merge_extras(scene, &self.scene_extras, &format!("{file}: scenes[{s}]"))?;
            } else {
                // A file without scenes: fbakit's record goes on the asset instead.
                merge_extras(
                    &mut b.json["asset"],
                    &self.scene_extras,
                    &format!("{file}: asset"),
                )?;
            }
        }
        if let Some(anim) = &self.animation {
            add_animation(&mut b, anim);
        }
        super::reclaim::drop_released(&mut b.json, &mut b.bin, &b.released, &file, &mut warnings);
        if let Some(buffers) = b.json.get_mut("buffers") {
            if let Some(first) = buffers.get_mut(0) {
                first["byteLength"] = json!(b.bin.len());
            }
        }
        let source_dir = source
            .path
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        warnings.extend(images::missing(&b.json, &source_dir, &file));
        let mut inputs = vec![source.path.clone()];
        inputs.extend(
            source.json["buffers"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|buf| images::relative_file(buf["uri"].as_str()?))
                .map(|rel| source_dir.join(rel)),
        );
        inputs.extend(images::files(&b.json, &source_dir));
        Ok(PatchedGltf {
            json: b.json,
            bin: b.bin,
            source_dir,
            inputs,
            warnings,
        })
    }
}

/// One buffer from all the document's buffers; buffer views re-pointed into it.
fn merge_buffers(b: &mut Builder, source: &GltfSource) -> Result<()> {
    let mut base = Vec::with_capacity(source.buffers.len());
    for data in &source.buffers {
        b.bin.resize(b.bin.len().next_multiple_of(4), 0);
        base.push(b.bin.len());
        b.bin.extend_from_slice(data);
    }
    if let Some(views) = b.json.get_mut("bufferViews").and_then(Value::as_array_mut) {
        for (i, v) in views.iter_mut().enumerate() {
            let buf = v["buffer"].as_u64().unwrap_or(0) as usize;
            let Some(&start) = base.get(buf) else {
                return Err(content(
                    format!("{}: bufferViews[{i}]", source.path.display()),
                    format!("names buffer {buf}, but there are {}", base.len()),
                ));
            };
            let offset = v["byteOffset"].as_u64().unwrap_or(0) as usize;
            v["buffer"] = json!(0);
            if offset + start > 0 {
                v["byteOffset"] = json!(offset + start);
            }
        }
    }
    // The first buffer's own fields (name, extras) stay; its data is the merged buffer.
    let mut first = b
        .json
        .get("buffers")
        .and_then(|l| l.get(0))
        .cloned()
        .unwrap_or_else(|| json!({}));
    if let Some(o) = first.as_object_mut() {
        o.remove("uri");
    }
    b.json["buffers"] = json!([first]);
    Ok(())
}

/// Merges `extras` into `node.extras` (an object, created when absent).
fn merge_extras(node: &mut Value, extras: &Map<String, Value>, at: &str) -> Result<()> {
    if !node.is_object() {
        return Err(content(at, "is not a JSON object"));
    }
    let slot = node
        .as_object_mut()
        .expect("checked")
        .entry("extras")
        .or_insert_with(|| json!({}));
    let Some(obj) = slot.as_object_mut() else {
        return Err(content(
            format!("{at}.extras"),
            "is not an object, so fbakit's record cannot be added",
        ));
    };
    for (k, v) in extras {
        obj.insert(k.clone(), v.clone());
    }
    Ok(())
}

fn patch_mesh(
    b: &mut Builder,
    file: &str,
    m: usize,
    patch: &MeshPatch,
    warnings: &mut Vec<Diagnostic>,
) -> Result<()> {
    let at = format!("{file}: meshes[{m}]");
    let total = patch.names.len();
    let slot_of = |t: usize| patch.replaces.get(t).copied().flatten();
    let new = (0..total).filter(|&t| slot_of(t).is_none()).count();
    let Some(mesh) = b.json["meshes"].get(m).cloned() else {
        return Err(content(at, "no such mesh"));
    };
    let prims = mesh["primitives"].as_array().cloned().unwrap_or_default();
    let old = prims
        .first()
        .and_then(|p| p["targets"].as_array())
        .map_or(0, Vec::len);
    // Names of the user's targets: mesh extras, else primitive 0's (both conventions exist).
    let mut names: Vec<Value> = super::source::target_names_value(&mesh)
        .cloned()
        .unwrap_or_default();
    if names.len() != old {
        return Err(content(
            format!("{at}.extras.targetNames"),
            format!(
                "{} names for {old} morph targets (the counts must match)",
                names.len()
            ),
        ));
    }
    let mut new_prims = Vec::with_capacity(prims.len());
    let mut released = Vec::new();
    for (p, prim) in prims.iter().enumerate() {
        let mut prim = prim.clone();
        let count = accessor_count(&b.json, prim["attributes"]["POSITION"].as_u64());
        if count == 0 {
            return Err(content(
                format!("{at}.primitives[{p}]"),
                "no POSITION to add morph targets to",
            ));
        }
        let have = prim["targets"].as_array().map_or(0, Vec::len);
        if have != old {
            return Err(content(
                format!("{at}.primitives[{p}].targets"),
                format!("{have} morph targets, but primitive 0 has {old}"),
            ));
        }
        let given = patch.primitives.get(&p);
        let mut added = Vec::with_capacity(new);
        let mut replaced = Vec::new();
        for t in 0..total {
            let s = given.and_then(|g| g.get(t)).cloned().unwrap_or_default();
            if s.vertices.len() != s.offsets.len()
                || s.vertices.iter().any(|&v| v as usize >= count)
                || s.vertices.windows(2).any(|w| w[0] >= w[1])
            {
                return Err(content(
                    format!("{at}.primitives[{p}]"),
                    format!("target `{}` lists bad vertices", patch.names[t]),
                ));
            }
            let a = b.sparse_target(count, &s);
            match slot_of(t) {
                Some(i) if i < old => replaced.push((i, json!({"POSITION": a}))),
                Some(i) => {
                    return Err(content(
                        format!("{at}.primitives[{p}].targets"),
                        format!("no target {i} to replace"),
                    ))
                }
                None => added.push(json!({"POSITION": a})),
            }
        }
        for &i in patch.zeroed.iter().filter(|&&i| i < old) {
            let a = b.sparse_target(count, &SparseOffsets::default());
            replaced.push((i, json!({"POSITION": a})));
        }
        let targets = prim
            .as_object_mut()
            .expect("a primitive is an object")
            .entry("targets")
            .or_insert_with(|| json!([]));
        if let Some(list) = targets.as_array_mut() {
            for (i, t) in replaced {
                let old = std::mem::replace(&mut list[i], t);
                released.extend(
                    old.as_object()
                        .into_iter()
                        .flat_map(|o| o.values())
                        .filter_map(Value::as_u64)
                        .map(|a| a as usize),
                );
            }
            list.extend(added);
        }
        new_prims.push(prim);
    }
    names.extend(
        (0..total)
            .filter(|&t| slot_of(t).is_none())
            .map(|t| json!(patch.names[t])),
    );
    b.released.extend(released);
    let mesh_json = &mut b.json["meshes"][m];
    mesh_json["primitives"] = Value::Array(new_prims);
    let mut extras = patch.extras.clone();
    extras.insert("targetNames".into(), Value::Array(names));
    merge_extras(mesh_json, &extras, &at)?;
    let mut weights: Vec<Value> = mesh_json["weights"]
        .as_array()
        .cloned()
        .unwrap_or_else(|| vec![json!(0.0); old]);
    weights.resize(old + new, json!(0.0));
    mesh_json["weights"] = Value::Array(weights);
    // Nodes that instance the mesh with their own weights get zeros for the new targets.
    let mut nodes_of_mesh = Vec::new();
    if let Some(nodes) = b.json.get_mut("nodes").and_then(Value::as_array_mut) {
        for (i, n) in nodes.iter_mut().enumerate() {
            if n["mesh"].as_u64() != Some(m as u64) {
                continue;
            }
            nodes_of_mesh.push(i);
            if let Some(w) = n.get_mut("weights").and_then(Value::as_array_mut) {
                w.resize(old + new, json!(0.0));
            }
        }
    }
    widen_weight_channels(b, file, &nodes_of_mesh, old, new, warnings)
}

/// The user's weight channels on `nodes` get `new` zero weights after their `old` per key.
fn widen_weight_channels(
    b: &mut Builder,
    file: &str,
    nodes: &[usize],
    old: usize,
    new: usize,
    warnings: &mut Vec<Diagnostic>,
) -> Result<()> {
    if new == 0 || old == 0 {
        // Without targets before, the user cannot have animated their weights.
        return Ok(());
    }
    let mut outputs = Vec::new();
    let anims = b.json["animations"].as_array().cloned().unwrap_or_default();
    for (ai, anim) in anims.iter().enumerate() {
        for ch in anim["channels"].as_array().into_iter().flatten() {
            let node = ch["target"]["node"].as_u64().map(|n| n as usize);
            if ch["target"]["path"] != "weights" || !node.is_some_and(|n| nodes.contains(&n)) {
                continue;
            }
            if let Some(s) = ch["sampler"].as_u64() {
                outputs.push((ai, s as usize));
            }
        }
    }
    outputs.sort_unstable();
    outputs.dedup();
    for (ai, s) in outputs {
        let at = format!("{file}: animations[{ai}].samplers[{s}].output");
        let Some(acc) = b.json["animations"][ai]["samplers"][s]["output"].as_u64() else {
            continue;
        };
        let Some(values) = read_floats(b, acc as usize) else {
            warnings.push(Diagnostic::warning(format!(
                "{at}: weights not stored as plain floats; the channel was left as it is and \
                 does not fit the mesh's new target count"
            )));
            continue;
        };
        let mut widened = Vec::with_capacity(values.len() / old * (old + new));
        for key in values.chunks(old) {
            widened.extend_from_slice(key);
            widened.resize(widened.len() + new, 0.0);
        }
        let view = b.floats(&widened);
        let a = b.accessor(json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": widened.len(),
            "type": "SCALAR"
        }));
        b.json["animations"][ai]["samplers"][s]["output"] = json!(a);
    }
    Ok(())
}

/// The values of a dense (non-sparse) FLOAT SCALAR accessor in the merged buffer.
fn read_floats(b: &Builder, acc: usize) -> Option<Vec<f32>> {
    let a = b.json["accessors"].get(acc)?;
    if a["componentType"].as_u64()? != u64::from(FLOAT)
        || a["type"] != "SCALAR"
        || a.get("sparse").is_some()
    {
        return None;
    }
    let count = a["count"].as_u64()? as usize;
    let view = b.json["bufferViews"].get(a["bufferView"].as_u64()? as usize)?;
    let stride = view["byteStride"].as_u64().unwrap_or(4) as usize;
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    (0..count)
        .map(|i| {
            let at = start.checked_add(i.checked_mul(stride)?)?;
            let w = b.bin.get(at..at + 4)?;
            Some(f32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        })
        .collect()
}

fn add_animation(b: &mut Builder, anim: &PatchAnimation) {
    if anim.times.is_empty()
        || (anim.weights.is_empty()
            && anim.rotations.is_empty()
            && anim.translations.is_empty()
            && anim.scales.is_empty())
    {
        return;
    }
    let tv = b.floats(&anim.times);
    let (lo, hi) = (anim.times[0], anim.times[anim.times.len() - 1]);
    let times = b.accessor(json!({
        "bufferView": tv, "componentType": FLOAT, "count": anim.times.len(),
        "type": "SCALAR", "min": [lo], "max": [hi]
    }));
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for (node, values) in &anim.weights {
        let v = b.floats(values);
        let out = b.accessor(json!({
            "bufferView": v, "componentType": FLOAT, "count": values.len(), "type": "SCALAR"
        }));
        channels
            .push(json!({"sampler": samplers.len(), "target": {"node": node, "path": "weights"}}));
        samplers.push(json!({"input": times, "output": out, "interpolation": "LINEAR"}));
    }
    for (node, values) in &anim.rotations {
        let flat: Vec<f32> = values.iter().flat_map(|q| q.to_array()).collect();
        let v = b.floats(&flat);
        let out = b.accessor(json!({
            "bufferView": v, "componentType": FLOAT, "count": values.len(), "type": "VEC4"
        }));
        channels
            .push(json!({"sampler": samplers.len(), "target": {"node": node, "path": "rotation"}}));
        samplers.push(json!({"input": times, "output": out, "interpolation": "LINEAR"}));
    }
    for (path, list) in [("translation", &anim.translations), ("scale", &anim.scales)] {
        for (node, values) in list {
            let flat: Vec<f32> = values.iter().flat_map(|v| v.to_array()).collect();
            let v = b.floats(&flat);
            let out = b.accessor(json!({
                "bufferView": v, "componentType": FLOAT, "count": values.len(), "type": "VEC3"
            }));
            channels
                .push(json!({"sampler": samplers.len(), "target": {"node": node, "path": path}}));
            samplers.push(json!({"input": times, "output": out, "interpolation": "LINEAR"}));
        }
    }
    b.array("animations").push(json!({
        "name": anim.name, "samplers": samplers, "channels": channels
    }));
}

impl PatchedGltf {
    /// Writes `.glb` or `.gltf` (+ `<stem>.bin`) as `path`'s extension says, atomically per
    /// file, with the images the document names by relative URI embedded in a `.glb`, carried
    /// beside a `.gltf` (see `images`). Refused before anything is written (exit code 2) when the `.bin`, or the
    /// output itself, would replace one of the input's buffers or images: the input is read
    /// whole, but a `.gltf` and its `.bin` are two files, and a write stopped between them
    /// would leave the input's `.gltf` pointing into a rewritten buffer. The output may
    /// replace the input document itself (it is replaced last, atomically). `.vrm` is a
    /// `.glb` of a VRM avatar ([`super::vrm`]).
    pub fn write(&self, path: &Path) -> Result<()> {
        use crate::format::OutputFormat;
        let format = OutputFormat::resolve(
            path,
            &[OutputFormat::Glb, OutputFormat::Gltf],
            "glTF output",
        )?;
        super::check_vrm_output(path, Some(&self.json), "the face's own glTF")?;
        let out_dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let file_name = path.file_name().map_or_else(
            || std::ffi::OsString::from("model"),
            std::ffi::OsStr::to_os_string,
        );
        let bin_name = (format == OutputFormat::Gltf).then(|| {
            let stem = path
                .file_stem()
                .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
            format!("{stem}.bin")
        });
        let document = self.inputs.first();
        let own_files = self.inputs.iter().skip(1);
        if let Some(input) = own_files.clone().find(|i| same_file(path, i)) {
            return Err(crate::error::Error::Usage(format!(
                "{}: is {}, a file {} reads; choose another output name",
                path.display(),
                input.display(),
                document.map_or_else(String::new, |d| d.display().to_string())
            )));
        }
        if let Some(bin) = &bin_name {
            let bin_path = out_dir.join(bin);
            if let Some(input) = own_files.clone().find(|i| same_file(&bin_path, i)) {
                return Err(crate::error::Error::Usage(format!(
                    "{}: writing {} there would replace {}, which {} reads; choose another \
                     output name",
                    bin_path.display(),
                    path.display(),
                    input.display(),
                    document.map_or_else(String::new, |d| d.display().to_string())
                )));
            }
        }
        let mut reserved = vec![out_dir.join(&file_name)];
        reserved.extend(bin_name.iter().map(|b| out_dir.join(b)));
        let mut json = self.json.clone();
        let mut glb_bin = Vec::new();
        if bin_name.is_none() {
            glb_bin.clone_from(&self.bin);
            images::embed(&mut json, &mut glb_bin, &self.source_dir)?;
        }
        let placement = images::place(&json, &self.source_dir, out_dir, &reserved)?;
        placement.set_uris(&mut json);
        placement.copy()?;
        match bin_name {
            None => crate::io::write_atomic(path, &glb_bytes(&json, &glb_bin)?),
            Some(bin_name) => {
                if let Some(first) = json["buffers"].get_mut(0) {
                    first["uri"] = json!(uri_escape(&bin_name));
                }
                crate::io::write_atomic(&out_dir.join(&bin_name), &self.bin)?;
                let mut text = serde_json::to_string_pretty(&json)
                    .map_err(|e| GltfError::Serialize(e.to_string()))?;
                text.push('\n');
                crate::io::write_atomic(path, text.as_bytes())
            }
        }
    }

    /// The document as `.glb` bytes, one self-contained file: the images it names by
    /// relative URI (found beside the input) embedded.
    pub fn to_glb(&self) -> Result<Vec<u8>> {
        let (mut json, mut bin) = (self.json.clone(), self.bin.clone());
        images::embed(&mut json, &mut bin, &self.source_dir)?;
        glb_bytes(&json, &bin)
    }
}

/// Whether `a` and `b` are one existing file (after resolving links).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// `json` and `bin` as `.glb` bytes.
fn glb_bytes(json: &Value, bin: &[u8]) -> Result<Vec<u8>> {
    let mut json = serde_json::to_vec(json).map_err(|e| GltfError::Serialize(e.to_string()))?;
    json.resize(json.len().next_multiple_of(4), b' ');
    let bin_len = bin.len().next_multiple_of(4);
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin_len };
    let total = u32::try_from(total).map_err(|_| GltfError::AssetTooLarge)?;
    let mut out = Vec::with_capacity(total as usize);
    for w in [
        super::container::GLB_MAGIC,
        super::container::GLB_VERSION,
        total,
        json.len() as u32,
        super::container::CHUNK_JSON,
    ] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    out.extend_from_slice(&json);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin_len as u32).to_le_bytes());
        out.extend_from_slice(&super::container::CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(bin);
        out.resize(total as usize, 0);
    }
    Ok(out)
}

#[cfg(test)]
mod target_tests {
    use super::*;

    fn builder() -> Builder {
        Builder {
            json: json!({}),
            bin: Vec::new(),
            released: Vec::new(),
        }
    }

    fn floats_of(b: &Builder, view: &Value) -> Vec<f32> {
        let v = &b.json["bufferViews"][view.as_u64().unwrap() as usize];
        let (o, n) = (
            v["byteOffset"].as_u64().unwrap() as usize,
            v["byteLength"].as_u64().unwrap() as usize,
        );
        b.bin[o..o + n]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    #[test]
    fn few_moving_vertices_stay_sparse_and_most_go_dense() {
        let mut b = builder();
        let few = SparseOffsets {
            vertices: vec![1, 3],
            offsets: vec![Vec3::X, Vec3::new(0.0, -2.0, 0.5)],
        };
        let a = b.sparse_target(10, &few);
        let acc = b.json["accessors"][a].clone();
        assert_eq!(acc["sparse"]["count"], 2);
        assert!(acc.get("bufferView").is_none());
        assert_eq!(acc["min"], json!([0.0, -2.0, 0.0]));
        assert_eq!(acc["max"], json!([1.0, 0.0, 0.5]));

        // 9 of 10 move: dense, the unlisted vertex a zero.
        let most = SparseOffsets {
            vertices: (0..10).filter(|&v| v != 4).collect(),
            offsets: (0..9).map(|i| Vec3::splat(i as f32 + 1.0)).collect(),
        };
        let a = b.sparse_target(10, &most);
        let acc = b.json["accessors"][a].clone();
        assert!(acc.get("sparse").is_none());
        assert_eq!(acc["count"], 10);
        let values = floats_of(&b, &acc["bufferView"]);
        assert_eq!(values.len(), 30);
        assert_eq!(&values[12..15], &[0.0, 0.0, 0.0]);
        assert_eq!(&values[15..18], &[5.0, 5.0, 5.0]);
        assert_eq!(acc["min"], json!([0.0, 0.0, 0.0]));
        assert_eq!(acc["max"], json!([9.0, 9.0, 9.0]));
    }
}
