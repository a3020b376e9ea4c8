//! Face file formats: named by extension, or recognised by content when the extension says
//! nothing (a file called `head` or `face.txt`).

use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Result};

/// The face file formats [`crate::face::read()`] understands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FaceFormat {
    /// VRML97 text (`.wrl`, `.vrml`): a `Face` node, a bare `FDP` or a plain scene.
    Vrml,
    /// Gzip-compressed VRML97 (`.wrl.gz`, `.vrml.gz`, `.wrz`).
    VrmlGz,
    /// Wavefront OBJ (`.obj`): geometry only; feature points come from a separate file.
    Obj,
    /// The CANDIDE-3 model (`.wfm`); needs its feature-point table.
    Wfm,
    /// A glTF 2.0 blendshape rig (`.glb`, `.gltf`): meshes and morph targets; with feature
    /// points its shapes become a FAT ([`crate::face::read()`]).
    Gltf,
}

impl FaceFormat {
    /// The format `path`'s extension names (case-insensitive), if any.
    pub fn of_extension(path: &Path) -> Option<FaceFormat> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        let ends = |ext: &str| name.len() > ext.len() && name.ends_with(ext);
        if ends(".wrl.gz") || ends(".vrml.gz") || ends(".wrz") {
            Some(FaceFormat::VrmlGz)
        } else if ends(".wrl") || ends(".vrml") {
            Some(FaceFormat::Vrml)
        } else if ends(".obj") {
            Some(FaceFormat::Obj)
        } else if ends(".wfm") {
            Some(FaceFormat::Wfm)
        } else if ends(".glb") || ends(".gltf") {
            Some(FaceFormat::Gltf)
        } else {
            None
        }
    }

    /// The format of `path` from its extension; an unknown extension is an input error.
    pub fn of_path(path: &Path) -> Result<FaceFormat> {
        FaceFormat::of_extension(path).ok_or_else(|| {
            Error::Unsupported(format!(
                "{}: unknown face file type (expected .wrl, .vrml, .wrl.gz, .vrml.gz, .wrz, \
                 .obj, .wfm, .glb or .gltf, or a folder of rig shape OBJs)",
                path.display()
            ))
        })
    }

    /// Recognises a face file by its first bytes: the gzip magic, the GLB magic or a glTF
    /// JSON `asset`, the VRML header, the CANDIDE-3 section headers or OBJ statements.
    /// `None` when nothing matches.
    pub fn sniff(bytes: &[u8]) -> Option<FaceFormat> {
        if bytes.starts_with(&[0x1f, 0x8b]) {
            return Some(FaceFormat::VrmlGz);
        }
        if bytes.starts_with(b"glTF") {
            return Some(FaceFormat::Gltf);
        }
        let head = &bytes[..bytes.len().min(64 * 1024)];
        let text = String::from_utf8_lossy(head);
        let text = text.trim_start_matches('\u{feff}');
        if text.starts_with("#VRML") {
            return Some(FaceFormat::Vrml);
        }
        if text.trim_start().starts_with('{') && text.contains("\"asset\"") {
            return Some(FaceFormat::Gltf);
        }
        if text.contains("# VERTEX LIST:") && text.contains("# FACE LIST:") {
            return Some(FaceFormat::Wfm);
        }
        let mut obj_statements = 0;
        for line in text.lines().map(str::trim_start) {
            let word = line.split_whitespace().next().unwrap_or("");
            match word {
                "v" | "vt" | "vn" | "f" | "o" | "g" | "usemtl" | "mtllib" | "s" => {
                    obj_statements += 1
                }
                "" => {}
                w if w.starts_with('#') => {}
                _ => return None,
            }
            if obj_statements >= 3 {
                return Some(FaceFormat::Obj);
            }
        }
        (obj_statements > 0).then_some(FaceFormat::Obj)
    }
}

/// The name a face read from `path` gets: the file name without its face extension.
pub fn face_name(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "face".into());
    let lower = name.to_ascii_lowercase();
    for ext in [
        ".wrl.gz", ".vrml.gz", ".wrz", ".wrl", ".vrml", ".obj", ".wfm", ".glb", ".gltf",
    ] {
        if lower.ends_with(ext) && name.len() > ext.len() {
            return name[..name.len() - ext.len()].to_string();
        }
    }
    name
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_by_extension() {
        let f = |p: &str| FaceFormat::of_path(Path::new(p)).ok();
        assert_eq!(f("a.wrl"), Some(FaceFormat::Vrml));
        assert_eq!(f("a.VRML"), Some(FaceFormat::Vrml));
        assert_eq!(f("a.wrl.gz"), Some(FaceFormat::VrmlGz));
        assert_eq!(f("a.vrml.gz"), Some(FaceFormat::VrmlGz));
        assert_eq!(f("a.wrz"), Some(FaceFormat::VrmlGz));
        assert_eq!(f("a.obj"), Some(FaceFormat::Obj));
        assert_eq!(f("c.wfm"), Some(FaceFormat::Wfm));
        assert_eq!(f("a.gz"), None);
        assert_eq!(f("rig.glb"), Some(FaceFormat::Gltf));
        assert_eq!(f("rig.GLTF"), Some(FaceFormat::Gltf));
        assert_eq!(face_name(Path::new("x/avatar.glb")), "avatar");
        assert_eq!(face_name(Path::new("x/alma.wrl.gz")), "alma");
        assert_eq!(face_name(Path::new("x/head.obj")), "head");
    }

    #[test]
    fn formats_by_content() {
        assert_eq!(
            FaceFormat::sniff(b"#VRML V2.0 utf8\nGroup {}"),
            Some(FaceFormat::Vrml)
        );
        assert_eq!(
            FaceFormat::sniff(&[0x1f, 0x8b, 8, 0]),
            Some(FaceFormat::VrmlGz)
        );
        assert_eq!(FaceFormat::sniff(b"glTF\x02\0\0\0"), Some(FaceFormat::Gltf));
        assert_eq!(
            FaceFormat::sniff(b"{\n  \"asset\": {\"version\": \"2.0\"}}"),
            Some(FaceFormat::Gltf)
        );
        assert_eq!(
            FaceFormat::sniff(b"# a mesh\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            Some(FaceFormat::Obj)
        );
        assert_eq!(
            FaceFormat::sniff(b"# CANDIDE\n# VERTEX LIST:\n1\n0 0 0\n# FACE LIST:\n"),
            Some(FaceFormat::Wfm)
        );
        assert_eq!(FaceFormat::sniff(b"hello world"), None);
        assert_eq!(FaceFormat::sniff(b""), None);
        assert_eq!(FaceFormat::sniff(b"\xff\xfe\x00garbage"), None);
    }
}
