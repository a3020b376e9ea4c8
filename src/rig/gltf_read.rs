//! glTF 2.0 rigs: `.glb`, and `.gltf` with external or `data:` URI buffers, read with the
//! maintained `gltf` crate.
//!
//! Every mesh instance of the default scene (or the first scene) becomes one [`RigMesh`] per
//! triangle primitive, in world space (node transforms applied to positions, normals and
//! morph deltas). Morph targets are named by `mesh.extras.targetNames` (the convention
//! Blender and three.js write; a primitive's own `extras.targetNames` is accepted too);
//! targets of the same name on several meshes are one [`BlendShape`]. Default weights come
//! from `node.weights`, else `mesh.weights`. A file with meshes but no scene is read whole
//! (every root node), with a warning.
//!
//! Files as other tools write them: compressed data (`EXT_meshopt_compression`) is decoded
//! first by [`crate::gltf::decode::decode_document`], which also refuses required extensions
//! fbakit cannot decode (`KHR_draco_mesh_compression`); accessors are read by `gltf_accessor`
//! (interleaved views, sparse accessors, `KHR_mesh_quantization` integer attributes, 8/16/32-bit
//! indices).
//!
//! The reader is bounded and never trusts counts: before the crate touches an accessor, its
//! type, count and byte ranges are checked against the buffers actually loaded, so a hostile
//! file is an error naming the file and the JSON path (`meshes[0].primitives[1].targets[3]`),
//! never a panic or a huge allocation. Points and lines are skipped with a warning; strips and
//! fans are turned into triangles.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use ::gltf::mesh::{Mode, Semantic};
use ::gltf::Document;
use glam::{Mat3, Mat4, Vec3};
use serde_json::Value;

use super::gltf_accessor::{AccessorData, Want};
use super::{BlendShape, Rig, RigError, RigMesh, ShapeDelta, MAX_RIG_SHAPES, MAX_RIG_VERTICES};
use crate::error::{Diagnostic, Error, Result};
use crate::gltf::source::{GltfSource, RestPose, SourcePart};
use crate::mesh::{FaceGroup, Mesh, Polygons};

/// Largest glTF file (and each external buffer) read: 1 GiB.
pub const MAX_GLTF_BYTES: u64 = 1 << 30;

/// Most elements one accessor may declare.
pub const MAX_ACCESSOR_COUNT: usize = 16 << 20;

/// Deepest node hierarchy followed.
const MAX_NODE_DEPTH: usize = 256;

/// Reads a glTF rig from `path` (`.glb` or `.gltf`). A file without morph targets reads as a
/// rig without shapes (use [`super::read_rig`] to require them).
pub fn read_gltf(path: &Path) -> Result<Rig> {
    let bytes = crate::io::read_bounded(path, MAX_GLTF_BYTES)?;
    read_gltf_bytes(&bytes, path)
}

/// Reads a glTF rig from memory; `path` names the file in errors and locates external buffers.
pub fn read_gltf_bytes(bytes: &[u8], path: &Path) -> Result<Rig> {
    check_glb_header(bytes, path)?;
    let (gltf, buffers, json, warnings) = open_decoded(bytes, path)?;
    check_attribute_indices(&gltf, path)?;
    validate(&gltf, path)?;
    let mut reader = Reader {
        file: path,
        doc: &gltf,
        buffers: &buffers,
        data: AccessorData {
            file: path,
            buffers: &buffers,
        },
        rig: Rig {
            name: super::rig_name(path),
            meshes: Vec::new(),
            shapes: Vec::new(),
            warnings,
            source: None,
        },
        shape_by_name: HashMap::new(),
        vertices: 0,
        mesh_names: HashMap::new(),
        parts: Vec::new(),
        node_world: Vec::new(),
    };
    reader.check_views()?;
    reader.node_world = rest::node_world_matrices(&gltf);
    let roots = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => sceneless_roots(&gltf, path, &mut reader.rig.warnings)?,
    };
    let mut stack: Vec<(::gltf::Node, Mat4, usize)> =
        roots.into_iter().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    stack.reverse();
    let mut seen = vec![false; gltf.nodes().len()];
    let mut instanced = vec![false; gltf.meshes().len()];
    while let Some((node, parent, depth)) = stack.pop() {
        let at = format!("nodes[{}]", node.index());
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(located(path, &at, "appears twice in the scene's node tree"));
        }
        if depth > MAX_NODE_DEPTH {
            return Err(located(path, &at, "node tree deeper than 256 levels"));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(located(path, &at, "non-finite transform"));
        }
        if let Some(mesh) = node.mesh() {
            instanced[mesh.index()] = true;
            // A skinned mesh ignores its node's transform (glTF 2.0, 3.7.3): its vertices are
            // placed by its joints at rest.
            let placed = match node.skin() {
                Some(skin) => reader.skin_rest(&skin)?,
                None => rest::Placement::Matrix(world),
            };
            reader.mesh_instance(Some(&node), &mesh, placed)?;
        }
        let children: Vec<_> = node.children().collect();
        for c in children.into_iter().rev() {
            stack.push((c, world, depth + 1));
        }
    }
    if gltf.scenes().len() == 0 {
        // A file without scenes (nor nodes for some meshes): those meshes as they are.
        for mesh in gltf.meshes().filter(|m| !instanced[m.index()]) {
            reader.mesh_instance(None, &mesh, rest::Placement::Matrix(Mat4::IDENTITY))?;
        }
    }
    reader.rig.check()?;
    let parts = std::mem::take(&mut reader.parts);
    let mut rig = reader.rig;
    rig.source = Some(std::sync::Arc::new(GltfSource {
        path: path.to_path_buf(),
        json,
        buffers,
        parts,
    }));
    Ok(rig)
}

/// The roots of a document without a scene: every node that is no other's child, with a
/// warning (viewers show nothing, but the meshes are the user's).
fn sceneless_roots<'a>(
    doc: &'a Document,
    file: &Path,
    warnings: &mut Vec<Diagnostic>,
) -> Result<Vec<::gltf::Node<'a>>> {
    let mut child = vec![false; doc.nodes().len()];
    for n in doc.nodes() {
        for c in n.children() {
            child[c.index()] = true;
        }
    }
    let roots: Vec<_> = doc.nodes().filter(|n| !child[n.index()]).collect();
    if doc.meshes().len() == 0 || roots.is_empty() {
        return Err(located(file, "scenes", "no scene and no nodes to read"));
    }
    warnings.push(Diagnostic::warning(format!(
        "{}: the file has no scene; reading the meshes of all {} root node(s)",
        file.display(),
        roots.len()
    )));
    Ok(roots)
}

/// The document of `bytes` (`.glb` or `.gltf` JSON) with its buffers loaded and compressed
/// data decoded ([`crate::gltf::decode::decode_document`]), and the decoder's warnings.
/// The JSON returned is the decoded document's (what a patch writes back: decoded, the
/// compression extensions dropped).
#[allow(clippy::type_complexity)]
fn open_decoded(
    bytes: &[u8],
    file: &Path,
) -> Result<(Document, Vec<Vec<u8>>, Value, Vec<Diagnostic>)> {
    let (json_bytes, bin) = if bytes.starts_with(b"glTF") {
        let glb = ::gltf::Glb::from_slice(bytes).map_err(|e| gltf_error(file, e))?;
        (glb.json, glb.bin.map(|b| b.into_owned()))
    } else {
        (std::borrow::Cow::Borrowed(bytes), None)
    };
    let unreadable = |e: serde_json::Error| RigError::UnreadableGltf {
        file: file.to_path_buf(),
        message: format!("JSON: {e}"),
    };
    let mut json: Value = serde_json::from_slice(&json_bytes).map_err(unreadable)?;
    let mut buffers = load_buffers(&json, bin, file)?;
    let report = crate::gltf::decode::decode_document(&mut json, &mut buffers, file)?;
    // The crate parses text (it keeps `extras` as raw JSON, which only its text parser makes):
    // the original, or the decoded document written out.
    let root = if report.changed {
        let text = serde_json::to_vec(&json).map_err(unreadable)?;
        ::gltf::json::deserialize::from_slice(&text)
    } else {
        ::gltf::json::deserialize::from_slice(&json_bytes)
    }
    .map_err(|e| gltf_error(file, ::gltf::Error::Deserialize(e)))?;
    Ok((
        Document::from_json_without_validation(root),
        buffers,
        json,
        report.warnings,
    ))
}

/// A GLB header whose total length is below the header's own 12 bytes: the `gltf` crate
/// subtracts without checking (a panic under overflow checks; found by fuzzing).
fn check_glb_header(bytes: &[u8], file: &Path) -> Result<()> {
    if let Some(len) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
    {
        if len < 12 {
            return Err(RigError::GlbTooShort {
                file: file.to_path_buf(),
                length: len,
            }
            .into());
        }
    }
    Ok(())
}

/// Vertex attributes (and morph target attributes) that name an accessor past the end: the
/// `gltf` crate's validation indexes `accessors` with them unchecked (a panic; found by
/// fuzzing), so they are refused first.
fn check_attribute_indices(doc: &Document, file: &Path) -> Result<()> {
    let json = doc.as_json();
    let count = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let targets = prim.targets.iter().flatten().flat_map(|t| {
                [t.positions, t.normals, t.tangents]
                    .into_iter()
                    .flatten()
                    .map(|i| i.value())
            });
            let mut all = prim.attributes.values().map(|i| i.value()).chain(targets);
            if let Some(i) = all.find(|&i| i >= count) {
                return Err(located(
                    file,
                    &format!("meshes[{m}].primitives[{p}]"),
                    format!("an attribute names accessor {i}, but there are {count}"),
                ));
            }
        }
    }
    Ok(())
}

/// An error at JSON path `at` of `file`.
fn located(file: &Path, at: &str, what: impl std::fmt::Display) -> Error {
    RigError::GltfContent {
        file: file.to_path_buf(),
        at: at.to_string(),
        what: what.to_string(),
    }
    .into()
}

/// The `gltf` crate's validation, less three findings that valid files trigger: accessors
/// without `min`/`max` (only required for positions, unused here) and accessors without a
/// `bufferView` (allowed by the glTF spec: they read as zeros, see `AccessorData::check`).
fn validate(doc: &Document, file: &Path) -> Result<()> {
    use ::gltf::json::validation::{Error as V, Validate};
    let mut errors = Vec::new();
    doc.as_json().validate(
        doc.as_json(),
        ::gltf::json::Path::new,
        &mut |path, error| {
            let p = path();
            let s = p.as_str();
            let benign = (error == V::Missing
                && (s.ends_with(".min")
                    || s.ends_with(".max")
                    || (s.starts_with("accessors[") && s.ends_with("].bufferView"))))
                // Required extensions were vetted by the decode pass (the crate knows none).
                || (error == V::Unsupported && s.starts_with("extensionsRequired["));
            if !benign {
                errors.push((p, error));
            }
        },
    );
    if errors.is_empty() {
        Ok(())
    } else {
        Err(gltf_error(file, ::gltf::Error::Validation(errors)))
    }
}

fn gltf_error(file: &Path, e: ::gltf::Error) -> Error {
    match e {
        ::gltf::Error::Validation(list) => {
            let shown: Vec<String> = list
                .iter()
                .take(5)
                .map(|(p, e)| format!("{p}: {e}"))
                .collect();
            let more = list.len().saturating_sub(5);
            RigError::InvalidGltf {
                file: file.to_path_buf(),
                findings: format!(
                    "{}{}",
                    shown.join("; "),
                    if more > 0 {
                        format!(" (and {more} more)")
                    } else {
                        String::new()
                    }
                ),
            }
            .into()
        }
        ::gltf::Error::Io(io) => Error::io(file, io),
        other => RigError::UnreadableGltf {
            file: file.to_path_buf(),
            message: other.to_string(),
        }
        .into(),
    }
}

/// The bytes of every buffer of the document `json`, checked against the declared
/// `byteLength`; a buffer without a URI is the GLB's binary chunk `bin`. Meshopt fallback
/// buffers are left empty: their bytes come from decoding.
fn load_buffers(json: &Value, mut bin: Option<Vec<u8>>, file: &Path) -> Result<Vec<Vec<u8>>> {
    let list = match json.get("buffers") {
        None => return Ok(Vec::new()),
        Some(Value::Array(list)) => list,
        Some(_) => return Err(located(file, "buffers", "must be an array")),
    };
    let mut out = Vec::with_capacity(list.len().min(1024));
    let mut bin_users = list
        .iter()
        .filter(|b| b.get("uri").is_none() && !crate::gltf::decode::is_meshopt_fallback(b))
        .count();
    for (i, b) in list.iter().enumerate() {
        let at = format!("buffers[{i}]");
        let length = b
            .get("byteLength")
            .and_then(Value::as_u64)
            .ok_or_else(|| located(file, &at, "byteLength must be a non-negative integer"))?;
        if crate::gltf::decode::is_meshopt_fallback(b) {
            out.push(Vec::new());
            continue;
        }
        let data = match b.get("uri") {
            None => {
                // Only buffer 0 should lack a URI; more are given the chunk too (as the crate
                // did), the last of them taking it.
                bin_users -= 1;
                let chunk = if bin_users == 0 {
                    bin.take()
                } else {
                    bin.clone()
                };
                chunk.ok_or_else(|| {
                    located(file, &at, "refers to a GLB binary chunk the file lacks")
                })?
            }
            Some(Value::String(uri)) => buffer_from_uri(file, &at, uri)?,
            Some(_) => return Err(located(file, &format!("{at}.uri"), "must be a string")),
        };
        if (data.len() as u64) < length {
            return Err(located(
                file,
                &at,
                format!(
                    "byteLength is {length} but the data has {} bytes",
                    data.len()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

fn buffer_from_uri(file: &Path, at: &str, uri: &str) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or_else(|| located(file, at, "a data URI must be base64 (`;base64,`)"))?;
        return crate::gltf::container::base64_decode(payload)
            .ok_or_else(|| located(file, at, "the data URI is not valid base64"));
    }
    if uri.contains("://") || uri.starts_with('/') || uri.starts_with('\\') {
        return Err(located(
            file,
            at,
            format!("buffer `{uri}` is not a relative file reference (only local files and data URIs are read)"),
        ));
    }
    let rel = percent_decode(uri)
        .ok_or_else(|| located(file, at, format!("`{uri}` is not a valid URI")))?;
    let dir = file.parent().unwrap_or(Path::new("."));
    let target: PathBuf = dir.join(rel);
    crate::io::read_bounded(&target, MAX_GLTF_BYTES)
}

/// `%XX` decoding of a relative URI (UTF-8); `None` for malformed escapes.
fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = std::str::from_utf8(b.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

mod rest;

struct Reader<'a> {
    file: &'a Path,
    doc: &'a Document,
    buffers: &'a [Vec<u8>],
    data: AccessorData<'a>,
    rig: Rig,
    shape_by_name: HashMap<String, usize>,
    vertices: usize,
    mesh_names: HashMap<String, usize>,
    /// Where each rig mesh came from, for writing the document back.
    parts: Vec<SourcePart>,
    /// World matrix of every node at rest (joints need them whether in the scene or not).
    node_world: Vec<Mat4>,
}

impl Reader<'_> {
    fn err(&self, at: &str, what: impl std::fmt::Display) -> Error {
        located(self.file, at, what)
    }

    /// Every buffer view lies inside its buffer's loaded data.
    fn check_views(&self) -> Result<()> {
        for v in self.doc.views() {
            let end = v.offset().checked_add(v.length());
            let len = self.buffers[v.buffer().index()].len();
            if end.is_none_or(|e| e > len) {
                return Err(self.err(
                    &format!("bufferViews[{}]", v.index()),
                    format!("byte range past the end of buffer {}", v.buffer().index()),
                ));
            }
            if v.stride().is_some_and(|s| !(4..=252).contains(&s)) {
                return Err(self.err(
                    &format!("bufferViews[{}]", v.index()),
                    "byteStride must lie in 4..=252",
                ));
            }
        }
        Ok(())
    }

    fn unique_mesh_name(&mut self, base: String) -> String {
        let n = self.mesh_names.entry(base.clone()).or_insert(0);
        *n += 1;
        if *n == 1 {
            base
        } else {
            format!("{base}_{n}")
        }
    }

    /// Target names of `mesh`: `mesh.extras.targetNames`, else the first primitive's.
    fn target_names(&self, mesh: &::gltf::Mesh, targets: usize) -> Result<Option<Vec<String>>> {
        let m = mesh.index();
        let mut sources = vec![(format!("meshes[{m}].extras.targetNames"), mesh.extras())];
        if let Some(p) = mesh.primitives().next() {
            sources.push((
                format!("meshes[{m}].primitives[0].extras.targetNames"),
                p.extras(),
            ));
        }
        for (at, extras) in sources {
            let Some(raw) = extras else { continue };
            let value: serde_json::Value = serde_json::from_str(raw.get())
                .map_err(|e| self.err(&at, format!("extras are not JSON: {e}")))?;
            let Some(names) = value.get("targetNames") else {
                continue;
            };
            let arr = names
                .as_array()
                .ok_or_else(|| self.err(&at, "must be an array of strings"))?;
            let mut out = Vec::with_capacity(arr.len().min(MAX_RIG_SHAPES));
            for (i, n) in arr.iter().enumerate() {
                match n.as_str() {
                    Some(s) if !s.trim().is_empty() => out.push(s.to_string()),
                    _ => {
                        return Err(self.err(
                            &format!("{at}[{i}]"),
                            "a morph target needs a non-empty name",
                        ))
                    }
                }
            }
            if out.len() != targets {
                return Err(self.err(
                    &at,
                    format!(
                        "{} names for {targets} morph targets (the counts must match)",
                        out.len()
                    ),
                ));
            }
            return Ok(Some(out));
        }
        Ok(None)
    }

    fn mesh_instance(
        &mut self,
        node: Option<&::gltf::Node>,
        mesh: &::gltf::Mesh,
        placed: rest::Placement,
    ) -> Result<()> {
        let m = mesh.index();
        let prims: Vec<_> = mesh.primitives().collect();
        let targets = prims.first().map_or(0, |p| p.morph_targets().len());
        for (p, prim) in prims.iter().enumerate() {
            if prim.morph_targets().len() != targets {
                return Err(self.err(
                    &format!("meshes[{m}].primitives[{p}].targets"),
                    format!(
                        "{} morph targets, but primitive 0 has {targets} (all primitives of a mesh must have the same)",
                        prim.morph_targets().len()
                    ),
                ));
            }
        }
        let names = if targets > 0 {
            match self.target_names(mesh, targets)? {
                Some(n) => n,
                None => {
                    return Err(self.err(
                        &format!("meshes[{m}].extras.targetNames"),
                        format!(
                            "{targets} morph targets but no names (a rig's shapes must be named)"
                        ),
                    ))
                }
            }
        } else {
            Vec::new()
        };
        let mut seen = HashMap::new();
        for (i, n) in names.iter().enumerate() {
            if let Some(j) = seen.insert(n.as_str(), i) {
                return Err(self.err(
                    &format!("meshes[{m}].extras.targetNames[{i}]"),
                    format!("`{n}` also names target {j}"),
                ));
            }
        }
        let node_weights = node.and_then(|n| n.weights());
        let weights = match node_weights.or(mesh.weights()) {
            Some(w) if w.len() != targets => {
                let at = if let (Some(n), Some(_)) = (node, node_weights) {
                    format!("nodes[{}].weights", n.index())
                } else {
                    format!("meshes[{m}].weights")
                };
                return Err(self.err(
                    &at,
                    format!("{} weights for {targets} morph targets", w.len()),
                ));
            }
            Some(w) => w.to_vec(),
            None => vec![0.0; targets],
        };
        if let Some(i) = weights.iter().position(|w| !w.is_finite()) {
            return Err(self.err(&format!("meshes[{m}].weights[{i}]"), "non-finite weight"));
        }
        // Shape indices for this mesh's targets, creating shapes on first sight.
        let mut shape_ids = Vec::with_capacity(targets);
        for (t, name) in names.iter().enumerate() {
            let id = match self.shape_by_name.get(name) {
                Some(&id) => id,
                None => {
                    if self.rig.shapes.len() >= MAX_RIG_SHAPES {
                        return Err(self.err(
                            &format!("meshes[{m}]"),
                            format!("more than {MAX_RIG_SHAPES} blend shapes"),
                        ));
                    }
                    self.rig.shapes.push(BlendShape {
                        name: name.clone(),
                        default_weight: weights[t],
                        deltas: Vec::new(),
                    });
                    self.shape_by_name
                        .insert(name.clone(), self.rig.shapes.len() - 1);
                    self.rig.shapes.len() - 1
                }
            };
            shape_ids.push(id);
        }
        let base = node
            .and_then(|n| n.name())
            .or(mesh.name())
            .map_or_else(|| format!("mesh{m}"), str::to_string);
        for (p, prim) in prims.iter().enumerate() {
            let at = format!("meshes[{m}].primitives[{p}]");
            let name = if prims.len() > 1 {
                format!("{base}.{p}")
            } else {
                base.clone()
            };
            let before = self.rig.meshes.len();
            let vertex_count = prim.get(&Semantic::Positions).map_or(0, |a| a.count());
            let (world, per_vertex) = placed.for_primitive(self, prim, &at, vertex_count)?;
            self.primitive(prim, &at, name, world, &shape_ids)?;
            if self.rig.meshes.len() == before {
                continue;
            }
            let rest = match per_vertex {
                Some(list) => {
                    self.place_per_vertex(before, &list);
                    RestPose::PerVertex(list)
                }
                None => RestPose::Matrix(world),
            };
            self.parts.push(SourcePart {
                face_mesh: self.rig.meshes[before].name.clone(),
                node: node.map(|n| n.index()),
                mesh: m,
                primitive: p,
                vertex_count,
                rest,
            });
        }
        Ok(())
    }

    fn primitive(
        &mut self,
        prim: &::gltf::Primitive,
        at: &str,
        name: String,
        world: Mat4,
        shape_ids: &[usize],
    ) -> Result<()> {
        match prim.mode() {
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => {}
            other => {
                self.rig.warnings.push(Diagnostic::warning(format!(
                    "{}: {at}: {other:?} primitive skipped (only triangles are faces)",
                    self.file.display()
                )));
                return Ok(());
            }
        }
        let pos_acc = prim
            .get(&Semantic::Positions)
            .ok_or_else(|| self.err(&format!("{at}.attributes"), "no POSITION"))?;
        self.data.check(
            &pos_acc,
            &format!("{at}.attributes.POSITION"),
            Want::Vec3,
            None,
        )?;
        let n = pos_acc.count();
        if self.vertices + n > MAX_RIG_VERTICES {
            return Err(self.err(at, format!("the rig exceeds {MAX_RIG_VERTICES} vertices")));
        }
        self.vertices += n;
        let normal_acc = prim.get(&Semantic::Normals);
        if let Some(a) = &normal_acc {
            self.data
                .check(a, &format!("{at}.attributes.NORMAL"), Want::Vec3, Some(n))?;
        }
        let uv_acc = prim.get(&Semantic::TexCoords(0));
        if let Some(a) = &uv_acc {
            self.data.check(
                a,
                &format!("{at}.attributes.TEXCOORD_0"),
                Want::Vec2,
                Some(n),
            )?;
        }
        if let Some(a) = prim.indices() {
            self.data
                .check(&a, &format!("{at}.indices"), Want::Index, None)?;
        }
        let targets: Vec<_> = prim.morph_targets().collect();
        for (t, target) in targets.iter().enumerate() {
            if let Some(a) = target.positions() {
                self.data.check(
                    &a,
                    &format!("{at}.targets[{t}].POSITION"),
                    Want::Vec3,
                    Some(n),
                )?;
            }
        }

        let linear = Mat3::from_mat4(world);
        let normal_m = linear.inverse().transpose();
        // No bufferView and no sparse values: all zeros (glTF 2.0, 3.6.2.3).
        let local = self.data.vec3(&pos_acc);
        if let Some(i) = local.iter().position(|p| !p.is_finite()) {
            return Err(self.err(
                &format!("{at}.attributes.POSITION"),
                format!("vertex {i} has a non-finite coordinate"),
            ));
        }
        let positions: Vec<Vec3> = local.iter().map(|&p| world.transform_point3(p)).collect();
        let indices: Vec<u32> = match prim.indices() {
            Some(a) => self.data.indices(&a),
            None => (0..n as u32).collect(),
        };
        if let Some(i) = indices.iter().position(|&i| i as usize >= n) {
            return Err(self.err(
                &format!("{at}.indices"),
                format!("index {} at {i} is past the {n} vertices", indices[i]),
            ));
        }
        let triangles = triangles(prim.mode(), &indices);
        if prim.mode() == Mode::Triangles && indices.len() % 3 != 0 {
            self.rig.warnings.push(Diagnostic::warning(format!(
                "{}: {at}: {} indices is not a multiple of 3; the last {} ignored",
                self.file.display(),
                indices.len(),
                indices.len() % 3
            )));
        }
        // glTF winding is counter-clockwise; a mirroring transform flips it.
        let flip = linear.determinant() < 0.0;
        let polygons =
            Polygons::from_lists(triangles.iter().map(
                |t| {
                    if flip {
                        [t[0], t[2], t[1]]
                    } else {
                        *t
                    }
                },
            ));
        let mut mesh = Mesh {
            name: name.clone(),
            positions,
            polygons: polygons.clone(),
            ..Mesh::default()
        };
        if let Some(a) = &normal_acc {
            let normals: Vec<Vec3> = self
                .data
                .vec3(a)
                .into_iter()
                .map(|v| (normal_m * v).normalize_or_zero())
                .collect();
            if normals.iter().all(|v| v.is_finite()) {
                mesh.normals = normals;
                mesh.normal_polygons = Some(polygons.clone());
            }
        }
        if let Some(a) = &uv_acc {
            let uvs = self.data.vec2(a);
            if uvs.iter().all(|v| v.is_finite()) {
                mesh.uvs = uvs;
                mesh.uv_polygons = Some(polygons.clone());
            }
        }
        if let Some(material) = prim.material().name() {
            mesh.groups.push(FaceGroup {
                material: Some(material.to_string()),
                ..FaceGroup::default()
            });
        }
        let mesh_index = self.rig.meshes.len();
        let unique = self.unique_mesh_name(name);
        mesh.name = unique.clone();

        for (t, target) in targets.iter().enumerate() {
            let Some(acc) = target.positions() else {
                continue;
            };
            let deltas = self.data.vec3(&acc);
            if let Some(i) = deltas.iter().position(|p| !p.is_finite()) {
                return Err(self.err(
                    &format!("{at}.targets[{t}].POSITION"),
                    format!("vertex {i} has a non-finite offset"),
                ));
            }
            let mut delta = ShapeDelta {
                mesh: mesh_index,
                vertices: Vec::new(),
                offsets: Vec::new(),
            };
            for (v, &d) in deltas.iter().enumerate() {
                if d != Vec3::ZERO {
                    delta.vertices.push(v as u32);
                    delta.offsets.push(linear * d);
                }
            }
            if !delta.vertices.is_empty() {
                self.rig.shapes[shape_ids[t]].deltas.push(delta);
            }
        }
        self.rig.meshes.push(RigMesh { name: unique, mesh });
        Ok(())
    }
}

/// Triangles of an index list drawn in `mode` (strips alternate winding; fans share corner 0).
fn triangles(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    match mode {
        Mode::TriangleStrip => {
            for i in 2..idx.len() {
                let t = if i % 2 == 0 {
                    [idx[i - 2], idx[i - 1], idx[i]]
                } else {
                    [idx[i - 1], idx[i - 2], idx[i]]
                };
                out.push(t);
            }
        }
        Mode::TriangleFan => {
            for i in 2..idx.len() {
                out.push([idx[0], idx[i - 1], idx[i]]);
            }
        }
        _ => {
            for c in idx.chunks_exact(3) {
                out.push([c[0], c[1], c[2]]);
            }
        }
    }
    // Degenerate triangles (repeated corners) are common in strips and carry no surface.
    out.retain(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin").as_deref(), Some("a b.bin"));
        assert_eq!(percent_decode("plain.bin").as_deref(), Some("plain.bin"));
        assert_eq!(percent_decode("bad%2"), None);
        assert_eq!(percent_decode("bad%zz"), None);
    }

    #[test]
    fn strips_and_fans_become_triangles() {
        assert_eq!(
            triangles(Mode::TriangleStrip, &[0, 1, 2, 3]),
            vec![[0, 1, 2], [2, 1, 3]]
        );
        assert_eq!(
            triangles(Mode::TriangleFan, &[0, 1, 2, 3]),
            vec![[0, 1, 2], [0, 2, 3]]
        );
        assert_eq!(
            triangles(Mode::Triangles, &[0, 1, 2, 2, 2, 3, 4]),
            vec![[0, 1, 2]]
        );
    }
}
