//! `KHR_draco_mesh_compression`: no maintained Rust decoder exists, so a document that
//! requires it is refused (see [`super::check_required`]). A document that only *uses* it
//! carries uncompressed fallback accessors beside the Draco data; those are read, with a
//! warning, unless a compressed primitive's `POSITION` has no data of its own.

use std::path::Path;

use serde_json::Value;

use super::{decode_error, unsupported, DECOMPRESS_HINT};
use crate::error::{Diagnostic, Result};

/// The extension's name.
pub const EXTENSION: &str = "KHR_draco_mesh_compression";

/// Warnings for a document whose primitives carry optional Draco data; an error when one of
/// them has nothing else to read.
pub fn check(json: &Value, file: &Path) -> Result<Vec<Diagnostic>> {
    let accessors = json.get("accessors").and_then(Value::as_array);
    let mut compressed = 0usize;
    let meshes = json.get("meshes").and_then(Value::as_array);
    for (m, mesh) in meshes.into_iter().flatten().enumerate() {
        let prims = mesh.get("primitives").and_then(Value::as_array);
        for (p, prim) in prims.into_iter().flatten().enumerate() {
            if prim.pointer(&format!("/extensions/{EXTENSION}")).is_none() {
                continue;
            }
            compressed += 1;
            let position = prim
                .pointer("/attributes/POSITION")
                .and_then(Value::as_u64)
                .and_then(|i| accessors.and_then(|a| a.get(i as usize)));
            let has_data = position
                .is_some_and(|a| a.get("bufferView").is_some() || a.get("sparse").is_some());
            if !has_data {
                return Err(match position {
                    Some(_) => unsupported(file, EXTENSION, DECOMPRESS_HINT.to_string()),
                    None => decode_error(
                        file,
                        &format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                        "missing or names no accessor",
                    ),
                });
            }
        }
    }
    if compressed == 0 {
        return Ok(Vec::new());
    }
    Ok(vec![Diagnostic::warning(format!(
        "{}: {compressed} primitive(s) carry optional {EXTENSION} data, which fbakit cannot \
         decode; their uncompressed accessors are read instead",
        file.display()
    ))])
}
