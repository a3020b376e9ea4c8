//! VRM avatars (`.vrm`): binary glTF documents that carry the VRM extension — `VRM` (VRM
//! 0.x, VRoid Studio's older exports) or `VRMC_vrm` (VRM 1.0). fbakit reads them as any
//! `.glb` and writes one back only as a patch of the avatar it read: the extension's data
//! (humanoid bones, expressions, look-at, first-person, meta) is kept as the user wrote it,
//! and the morph targets fbakit appends leave the indices of the avatar's own targets, which
//! its expressions name, unchanged. A new document (a face not read from a VRM) has no
//! humanoid or meta to give and is refused as `.vrm`.

use std::path::Path;

use serde_json::Value;

use super::GltfError;
use crate::error::Result;
use crate::format::is_vrm_path;

/// The extensions that make a glTF document a VRM avatar.
pub const VRM_EXTENSIONS: [&str; 2] = ["VRM", "VRMC_vrm"];

/// Whether a glTF document's JSON declares a VRM extension in `extensionsUsed`.
pub fn is_vrm_document(json: &Value) -> bool {
    json["extensionsUsed"].as_array().is_some_and(|used| {
        used.iter()
            .any(|e| e.as_str().is_some_and(|e| VRM_EXTENSIONS.contains(&e)))
    })
}

/// Refuses a `.vrm` `path` for a document that is no VRM avatar (`json`: its JSON, `None`
/// for a document fbakit builds anew); `what` names the document in the message. Any other
/// path passes.
pub fn check_vrm_output(path: &Path, json: Option<&Value>, what: &str) -> Result<()> {
    if is_vrm_path(path) && !json.is_some_and(is_vrm_document) {
        return Err(GltfError::NotVrm {
            path: path.to_path_buf(),
            what: what.to_string(),
        }
        .into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn only_a_vrm_document_is_written_as_vrm() {
        let vrm0 = json!({"extensionsUsed": ["KHR_materials_unlit", "VRM"]});
        let vrm1 = json!({"extensionsUsed": ["VRMC_vrm", "VRMC_springBone"]});
        let plain = json!({"extensionsUsed": ["KHR_materials_unlit"]});
        let out = Path::new("out/avatar.VRM");
        assert!(check_vrm_output(out, Some(&vrm0), "x").is_ok());
        assert!(check_vrm_output(out, Some(&vrm1), "x").is_ok());
        for (json, what) in [
            (Some(&plain), "the face's own glTF"),
            (None, "a new glTF document"),
        ] {
            let e = check_vrm_output(out, json, what).unwrap_err();
            assert!(e.is_input_error());
            assert_eq!(
                e.to_string(),
                format!("out/avatar.VRM: a .vrm is a VRM avatar, and {what} has no VRM extension (`VRM` or `VRMC_vrm`); write .glb instead")
            );
        }
        // Any other output is not this check's business.
        assert!(check_vrm_output(Path::new("a.glb"), None, "x").is_ok());
    }
}
