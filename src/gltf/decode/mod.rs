//! Decoding a read glTF document's compressed and extended data before anything reads its
//! accessors: what other tools write (`gltf-transform`, `gltfpack`, three.js exporters) becomes
//! plain glTF 2.0 that the `gltf` crate and fbakit's accessor reader understand.
//!
//! [`decode_document`] works on the document's JSON and its loaded buffers, in place, so a
//! writer that hands the user's document back writes it decoded:
//! - `EXT_meshopt_compression` (`meshopt.rs`): compressed buffer views are decoded into their
//!   fallback buffer, the extension is removed from the views and buffers and from
//!   `extensionsUsed`/`extensionsRequired`, with a warning (Blender cannot import meshopt).
//! - `KHR_draco_mesh_compression` (`draco.rs`): no maintained Rust decoder exists, so a file that
//!   requires it is refused (exit 2) with the command that decompresses it.
//! - `KHR_mesh_quantization` needs no pass: the accessor reader dequantises integer
//!   attributes (glTF 2.0 §3.11: normalised values by the spec's rules).
//!
//! Any other required extension that fbakit does not know to leave geometry alone is refused,
//! naming it: reading on would give wrong positions silently.

mod draco;
mod meshopt;

use std::path::Path;

use serde_json::Value;

use super::GltfError;
use crate::error::{Diagnostic, Result};

/// Most decoded bytes one document may expand to (all compressed views together): 1 GiB.
pub const MAX_DECODED_BYTES: usize = 1 << 30;

/// How `gltf-transform` rewrites a file without compression (`copy` decodes and writes plain
/// buffers); quoted in refusals.
pub const DECOMPRESS_HINT: &str =
    "decompress it first, e.g. `npx @gltf-transform/cli copy IN.glb OUT.glb`";

/// Required extensions that leave positions, topology and morph targets alone (materials,
/// textures, lights, metadata), plus the two fbakit decodes. Entries ending in `_` are prefixes.
const HARMLESS_REQUIRED: &[&str] = &[
    "KHR_mesh_quantization",
    meshopt::EXTENSION,
    "KHR_materials_",
    "KHR_texture_transform",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "MSFT_texture_dds",
    "KHR_lights_punctual",
    "EXT_lights_image_based",
    "KHR_xmp_json_ld",
];

/// What [`decode_document`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DecodeReport {
    /// One warning per decoded (or ignored optional) extension.
    pub warnings: Vec<Diagnostic>,
    /// Whether the JSON or the buffers were changed (a reader may parse the original text
    /// when not).
    pub changed: bool,
}

/// Decodes the compressed data of the document `json` (whose buffers, in order, are `buffers`;
/// placeholders may be empty for meshopt fallback buffers, see [`is_meshopt_fallback`]) in
/// place, and refuses documents that require an extension fbakit cannot decode. `file` names
/// the document in errors and warnings.
pub fn decode_document(
    json: &mut Value,
    buffers: &mut [Vec<u8>],
    file: &Path,
) -> Result<DecodeReport> {
    if !json.is_object() {
        return Err(decode_error(file, "", "the document is not a JSON object"));
    }
    check_required(json, file)?;
    let mut report = DecodeReport {
        warnings: draco::check(json, file)?,
        changed: false,
    };
    let decoded = meshopt::decode(json, buffers, file)?;
    report.changed |= !decoded.is_empty();
    report.warnings.extend(decoded);
    Ok(report)
}

/// True when buffer `b` (a `buffers[i]` JSON object) is an `EXT_meshopt_compression` fallback:
/// its bytes are not in the file but made by decoding, so a loader leaves it empty.
pub fn is_meshopt_fallback(buffer: &Value) -> bool {
    buffer
        .pointer(&format!("/extensions/{}/fallback", meshopt::EXTENSION))
        .and_then(Value::as_bool)
        == Some(true)
}

/// The names in `extensionsRequired`, checked against what fbakit can read.
fn check_required(json: &Value, file: &Path) -> Result<()> {
    let Some(list) = json.get("extensionsRequired") else {
        return Ok(());
    };
    let list = list
        .as_array()
        .ok_or_else(|| decode_error(file, "extensionsRequired", "must be an array of names"))?;
    for (i, name) in list.iter().enumerate() {
        let name = name.as_str().ok_or_else(|| {
            decode_error(
                file,
                &format!("extensionsRequired[{i}]"),
                "must be a string",
            )
        })?;
        if name == draco::EXTENSION {
            return Err(unsupported(file, name, DECOMPRESS_HINT.to_string()));
        }
        let known = HARMLESS_REQUIRED.iter().any(|h| {
            if h.ends_with('_') {
                name.starts_with(h)
            } else {
                name == *h
            }
        });
        if !known {
            return Err(unsupported(
                file,
                name,
                "fbakit reads files that require only KHR_mesh_quantization, \
                 EXT_meshopt_compression and material, texture or light extensions; \
                 bake or remove it in the tool that wrote the file"
                    .to_string(),
            ));
        }
    }
    Ok(())
}

/// Removes `name` from `extensionsUsed` and `extensionsRequired` (dropping lists left empty,
/// which glTF does not allow).
fn drop_extension_name(json: &mut Value, name: &str) {
    let Some(root) = json.as_object_mut() else {
        return;
    };
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(Value::Array(list)) = root.get_mut(key) {
            list.retain(|v| v.as_str() != Some(name));
            if list.is_empty() {
                root.remove(key);
            }
        }
    }
}

/// Removes extension `name` from the `extensions` object of `object`, and the object when
/// left empty.
fn drop_object_extension(object: &mut Value, name: &str) {
    let Some(obj) = object.as_object_mut() else {
        return;
    };
    if let Some(Value::Object(ext)) = obj.get_mut("extensions") {
        ext.remove(name);
        if ext.is_empty() {
            obj.remove("extensions");
        }
    }
}

fn unsupported(file: &Path, extension: &str, how: String) -> crate::error::Error {
    GltfError::UnsupportedExtension {
        file: file.to_path_buf(),
        extension: extension.to_string(),
        how,
    }
    .into()
}

fn decode_error(file: &Path, at: &str, what: impl std::fmt::Display) -> crate::error::Error {
    GltfError::Decode {
        file: file.to_path_buf(),
        at: if at.is_empty() {
            "(root)".into()
        } else {
            at.to_string()
        },
        what: what.to_string(),
    }
    .into()
}

#[cfg(test)]
mod tests;
