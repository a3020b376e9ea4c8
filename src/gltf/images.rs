//! Images a patched document references by relative URI, carried to wherever it is written.
//!
//! A `.gltf` (or, rarely, a `.glb`) may name its images as files beside it, also in other
//! folders (`../textures/skin.png`, as Sketchfab downloads are laid out). Written to the
//! input's own folder, the URIs stay and nothing is copied. Written elsewhere, each image
//! found is copied beside the output — under its relative path when that stays below the
//! document's folder, else (a `..` path) flattened into the output folder — and the image's
//! `uri` is rewritten to the written file. A file already at the destination is used only when
//! it is byte-identical to the image; otherwise the copy takes a free name (`skin_2.png`, …),
//! so a user's own file is never overwritten nor mistaken for the texture. Written as `.glb`,
//! the images are embedded instead ([`embed`]): a binary glTF is one file. Data URIs, URLs,
//! absolute paths and images in buffer views are left alone.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};

use serde_json::Value;

use crate::error::{Diagnostic, Error, Result};

/// Largest image copied beside an output: 1 GiB.
pub(super) const MAX_IMAGE_BYTES: u64 = 1 << 30;

/// How many numbered names (`skin_2.png` … ) are tried before giving up.
const MAX_SUFFIX: usize = 10_000;

/// A URI that names a file relative to the document, unescaped; `None` for data URIs, URLs
/// and absolute paths (those mean the same wherever the document is written).
pub(super) fn relative_file(uri: &str) -> Option<String> {
    if uri.is_empty() || uri.starts_with("data:") || uri.contains("://") {
        return None;
    }
    // A scheme such as `file:` or a Windows drive letter (`C:`) is not relative either (an
    // escaped colon, `%3A`, is part of a name).
    let scheme = uri
        .split_once(':')
        .is_some_and(|(s, _)| !s.is_empty() && !s.contains(['/', '\\']));
    let path = uri_unescape(uri);
    let absolute = path.starts_with(['/', '\\']) || Path::new(&path).is_absolute();
    (!scheme && !absolute).then_some(path)
}

/// The document's images named by relative file URI: (image index, URI, unescaped path).
fn relative_images(json: &Value) -> Vec<(usize, String, String)> {
    json["images"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
        .filter_map(|(i, img)| {
            let uri = img["uri"].as_str()?;
            relative_file(uri).map(|rel| (i, uri.to_string(), rel))
        })
        .collect()
}

/// The image files the document at `source_dir` references (whether they exist or not).
pub(super) fn files(json: &Value, source_dir: &Path) -> Vec<PathBuf> {
    relative_images(json)
        .into_iter()
        .map(|(_, _, rel)| source_dir.join(rel))
        .collect()
}

/// A warning per image whose file is missing: its URI is kept, so the output names a file
/// that is not there, as the input did.
pub(super) fn missing(json: &Value, source_dir: &Path, file: &str) -> Vec<Diagnostic> {
    relative_images(json)
        .into_iter()
        .filter(|(_, _, rel)| !source_dir.join(rel).is_file())
        .map(|(i, uri, rel)| {
            Diagnostic::warning(format!(
                "{file}: images[{i}] names {}, which does not exist; its URI `{uri}` was kept \
                 as it is (put the image there and write again to carry it over)",
                source_dir.join(rel).display()
            ))
        })
        .collect()
}

/// Where the images go for one output: the copies to make and the rewritten URIs.
#[derive(Debug, Default)]
pub(super) struct Placement {
    /// (source file, destination) pairs still to write.
    copies: Vec<(PathBuf, PathBuf)>,
    /// New `uri` per image index (only those that changed).
    uris: Vec<(usize, String)>,
}

/// Plans the images of `json` (read from `source_dir`) for a document written into `out_dir`;
/// `reserved` are the files the write itself makes (never taken by an image).
pub(super) fn place(
    json: &Value,
    source_dir: &Path,
    out_dir: &Path,
    reserved: &[PathBuf],
) -> Result<Placement> {
    let mut plan = Placement::default();
    let same = match (out_dir.canonicalize(), source_dir.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if same {
        return Ok(plan);
    }
    let mut taken: BTreeSet<PathBuf> = reserved.iter().cloned().collect();
    // One destination per source file, however many images name it.
    let mut placed: BTreeMap<PathBuf, String> = BTreeMap::new();
    for (i, uri, rel) in relative_images(json) {
        let from = source_dir.join(&rel);
        if !from.is_file() {
            // Warned about when the patch was made; the URI stays.
            continue;
        }
        let new_uri = match placed.get(&from) {
            Some(u) => u.clone(),
            None => {
                let wanted = destination(&rel);
                let (dest, write) = free_destination(&from, out_dir, &wanted, &taken)?;
                taken.insert(out_dir.join(&dest));
                if write {
                    plan.copies.push((from.clone(), out_dir.join(&dest)));
                }
                let u = if dest == Path::new(&rel) {
                    uri.clone()
                } else {
                    path_uri(&dest)
                };
                placed.insert(from, u.clone());
                u
            }
        };
        if new_uri != uri {
            plan.uris.push((i, new_uri));
        }
    }
    Ok(plan)
}

/// The image's path below the output folder: its own relative path, or its file name alone
/// when the path climbs out of the document's folder (`..`) or is otherwise odd.
fn destination(rel: &str) -> PathBuf {
    let path = Path::new(rel);
    let plain = path.components().all(|c| matches!(c, Component::Normal(_))) && !rel.contains('\\');
    if plain {
        return path.to_path_buf();
    }
    let name = rel
        .rsplit(['/', '\\'])
        .find(|c| !c.is_empty() && *c != "." && *c != "..")
        .unwrap_or("image");
    PathBuf::from(name)
}

/// The first of `wanted`, `stem_2.ext`, `stem_3.ext`, … (relative to `out_dir`) that is free
/// or already holds exactly `from`'s bytes, and whether it still has to be written.
fn free_destination(
    from: &Path,
    out_dir: &Path,
    wanted: &Path,
    taken: &BTreeSet<PathBuf>,
) -> Result<(PathBuf, bool)> {
    let stem = wanted
        .file_stem()
        .map_or_else(|| "image".into(), |s| s.to_string_lossy().into_owned());
    let ext = wanted
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    for k in 1..=MAX_SUFFIX {
        let candidate = if k == 1 {
            wanted.to_path_buf()
        } else {
            wanted.with_file_name(format!("{stem}_{k}{ext}"))
        };
        let full = out_dir.join(&candidate);
        if taken.contains(&full) {
            continue;
        }
        match std::fs::symlink_metadata(&full) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((candidate, true)),
            Err(e) => return Err(Error::io(&full, e)),
            Ok(_) if same_bytes(from, &full)? => return Ok((candidate, false)),
            Ok(_) => continue,
        }
    }
    Err(Error::Usage(format!(
        "{}: no free name for the image {} in {MAX_SUFFIX} tries; write the output to another \
         folder",
        out_dir.join(wanted).display(),
        from.display()
    )))
}

/// Whether `existing` is a file holding exactly `from`'s bytes (sizes compared first, so a
/// differing file of another size is never read).
fn same_bytes(from: &Path, existing: &Path) -> Result<bool> {
    let (Ok(a), Ok(b)) = (std::fs::metadata(from), std::fs::metadata(existing)) else {
        return Ok(false);
    };
    if !b.is_file() || a.len() != b.len() {
        return Ok(false);
    }
    Ok(crate::io::read_bounded(from, MAX_IMAGE_BYTES)?
        == crate::io::read_bounded(existing, MAX_IMAGE_BYTES)?)
}

impl Placement {
    /// Rewrites the `uri` of each moved image in `json`.
    pub(super) fn set_uris(&self, json: &mut Value) {
        for (i, uri) in &self.uris {
            if let Some(img) = json["images"].get_mut(*i) {
                img["uri"] = Value::from(uri.as_str());
            }
        }
    }

    /// Copies the images (each atomically; folders made as needed).
    pub(super) fn copy(&self) -> Result<()> {
        for (from, to) in &self.copies {
            if let Some(dir) = to.parent() {
                std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
            }
            let bytes = crate::io::read_bounded(from, MAX_IMAGE_BYTES)?;
            crate::io::write_atomic(to, &bytes)?;
        }
        Ok(())
    }
}

/// The media type of an image file, from its first bytes (a file's name can lie), else from
/// its extension; `None` for a type glTF does not name.
fn media_type(bytes: &[u8], path: &Path) -> Option<&'static str> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        return Some("image/png");
    }
    if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        return Some("image/jpeg");
    }
    if bytes.len() >= 12 && &bytes[..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
        return Some("image/webp");
    }
    if bytes.starts_with(b"\xABKTX 20\xBB\r\n\x1a\n") {
        return Some("image/ktx2");
    }
    let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
    match ext.as_str() {
        "png" => Some("image/png"),
        "jpg" | "jpeg" => Some("image/jpeg"),
        "webp" => Some("image/webp"),
        "ktx2" => Some("image/ktx2"),
        _ => None,
    }
}

/// Moves the images `json` names by relative file URI (read from `source_dir`) into `bin`, for
/// a `.glb`: a binary glTF is one self-contained file, as users converting a `.gltf` expect.
/// Each file becomes one buffer view (4-byte aligned, in buffer 0, whose `byteLength` follows)
/// and each image naming it gets `bufferView` and `mimeType` instead of its `uri`. A missing
/// file, or one of a type glTF does not name, keeps its URI (and is carried beside the output
/// by [`place`] as before). Returns how many images were embedded.
pub(super) fn embed(json: &mut Value, bin: &mut Vec<u8>, source_dir: &Path) -> Result<usize> {
    let mut views: BTreeMap<PathBuf, (usize, &'static str)> = BTreeMap::new();
    let mut embedded = 0;
    for (i, _, rel) in relative_images(json) {
        let from = source_dir.join(&rel);
        if !from.is_file() {
            continue;
        }
        let (view, mime) = match views.get(&from) {
            Some(&v) => v,
            None => {
                let bytes = crate::io::read_bounded(&from, MAX_IMAGE_BYTES)?;
                let Some(mime) = media_type(&bytes, &from) else {
                    continue;
                };
                bin.resize(bin.len().next_multiple_of(4), 0);
                let offset = bin.len();
                bin.extend_from_slice(&bytes);
                if !json["bufferViews"].is_array() {
                    json["bufferViews"] = Value::Array(Vec::new());
                }
                let list = json["bufferViews"].as_array_mut().expect("made an array");
                list.push(serde_json::json!({
                    "buffer": 0, "byteOffset": offset, "byteLength": bytes.len()
                }));
                let v = (list.len() - 1, mime);
                views.insert(from, v);
                v
            }
        };
        if let Some(img) = json["images"].get_mut(i).and_then(Value::as_object_mut) {
            img.remove("uri");
            img.insert("bufferView".into(), view.into());
            img.insert("mimeType".into(), mime.into());
            embedded += 1;
        }
    }
    if embedded > 0 {
        if !json["buffers"].is_array() || json["buffers"].as_array().is_some_and(Vec::is_empty) {
            json["buffers"] = serde_json::json!([{}]);
        }
        json["buffers"][0]["byteLength"] = bin.len().into();
    }
    Ok(embedded)
}

/// A relative path as a URI: each component escaped, joined by `/`.
fn path_uri(path: &Path) -> String {
    path.components()
        .map(|c| uri_escape(&c.as_os_str().to_string_lossy()))
        .collect::<Vec<_>>()
        .join("/")
}

/// A file name as a relative URI (`%`, spaces and other reserved bytes escaped).
pub(super) fn uri_escape(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for b in name.bytes() {
        if b.is_ascii_alphanumeric() || b"-_.~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// `%XX` decoding (malformed escapes kept as they are).
pub(super) fn uri_unescape(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = (b[i] == b'%')
            .then(|| b.get(i + 1..i + 3))
            .flatten()
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match hex {
            Some(v) => {
                out.push(v);
                i += 3;
            }
            None => {
                out.push(b[i]);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn doc(uris: &[&str]) -> Value {
        json!({"images": uris.iter().map(|u| json!({"uri": u})).collect::<Vec<_>>()})
    }

    #[test]
    fn relative_uris_are_told_from_the_rest() {
        assert_eq!(relative_file("a%20b.png").as_deref(), Some("a b.png"));
        assert_eq!(
            relative_file("../textures/skin.png").as_deref(),
            Some("../textures/skin.png")
        );
        for u in [
            "data:image/png;base64,AAAA",
            "https://x.org/a.png",
            "/abs/a.png",
            "file:a.png",
            "C:/a.png",
            "",
        ] {
            assert_eq!(relative_file(u), None, "{u}");
        }
        assert_eq!(
            destination("textures/skin.png"),
            Path::new("textures/skin.png")
        );
        assert_eq!(destination("../textures/skin.png"), Path::new("skin.png"));
        assert_eq!(destination("./a/../b.png"), Path::new("b.png"));
        assert_eq!(path_uri(Path::new("my tex/a b.png")), "my%20tex/a%20b.png");
    }

    #[test]
    fn images_go_beside_the_output_under_free_names_and_their_uris_follow() {
        let dir = tempfile::tempdir().unwrap();
        let src = dir.path().join("models");
        let out = dir.path().join("out");
        std::fs::create_dir_all(src.join("sub")).unwrap();
        std::fs::create_dir_all(dir.path().join("textures")).unwrap();
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(dir.path().join("textures/skin.png"), b"skin").unwrap();
        std::fs::write(src.join("sub/eye one.png"), b"eye").unwrap();
        std::fs::write(src.join("same.png"), b"same").unwrap();
        // Foreign same-named file beside the output; an identical one is used as it is.
        std::fs::write(out.join("skin.png"), b"not the skin").unwrap();
        std::fs::write(out.join("same.png"), b"same").unwrap();
        let json = doc(&[
            "../textures/skin.png",
            "sub/eye%20one.png",
            "same.png",
            "../textures/skin.png",
            "missing.png",
            "data:image/png;base64,AAAA",
        ]);
        let reserved = [out.join("skin_2.png")];
        let plan = place(&json, &src, &out, &reserved).unwrap();
        let mut y = json.clone();
        plan.set_uris(&mut y);
        plan.copy().unwrap();
        assert_eq!(y["images"][0]["uri"], "skin_3.png");
        assert_eq!(y["images"][3]["uri"], "skin_3.png");
        assert_eq!(y["images"][1]["uri"], "sub/eye%20one.png");
        assert_eq!(y["images"][2]["uri"], "same.png");
        assert_eq!(y["images"][4]["uri"], "missing.png");
        assert_eq!(y["images"][5]["uri"], json["images"][5]["uri"]);
        assert_eq!(std::fs::read(out.join("skin_3.png")).unwrap(), b"skin");
        assert_eq!(
            std::fs::read(out.join("skin.png")).unwrap(),
            b"not the skin"
        );
        assert!(!out.join("skin_2.png").exists());
        assert_eq!(std::fs::read(out.join("sub/eye one.png")).unwrap(), b"eye");
        assert_eq!(plan.copies.len(), 2, "{:?}", plan.copies);
        let warned = missing(&json, &src, "m.gltf");
        assert_eq!(warned.len(), 1);
        assert!(warned[0].message.contains("missing.png"));
        // Into the input's own folder: nothing moves.
        let plan = place(&json, &src, &src, &[]).unwrap();
        assert!(plan.copies.is_empty() && plan.uris.is_empty());
    }

    #[test]
    fn a_glb_embeds_the_images_it_can_and_keeps_the_uris_of_the_rest() {
        let dir = tempfile::tempdir().unwrap();
        let png = b"\x89PNG\r\n\x1a\n-png-bytes";
        std::fs::create_dir_all(dir.path().join("tex")).unwrap();
        std::fs::write(dir.path().join("tex/skin a.png"), png).unwrap();
        // A JPEG named `.png`: the bytes decide.
        std::fs::write(dir.path().join("eye.png"), [0xFF, 0xD8, 0xFF, 0xE0, 1]).unwrap();
        std::fs::write(dir.path().join("notes.txt"), b"not an image").unwrap();
        let mut json = doc(&[
            "tex/skin%20a.png",
            "eye.png",
            "tex/skin%20a.png",
            "gone.png",
            "notes.txt",
            "data:image/png;base64,AAAA",
        ]);
        json["buffers"] = json!([{"byteLength": 3}]);
        json["bufferViews"] = json!([{"buffer": 0, "byteLength": 3}]);
        let mut bin = vec![1, 2, 3];
        let n = embed(&mut json, &mut bin, dir.path()).unwrap();
        assert_eq!(n, 3);
        let img = &json["images"];
        assert_eq!(img[0], json!({"bufferView": 1, "mimeType": "image/png"}));
        assert_eq!(img[1], json!({"bufferView": 2, "mimeType": "image/jpeg"}));
        // The same file twice: one view.
        assert_eq!(img[2], img[0]);
        for (k, uri) in [
            (3, "gone.png"),
            (4, "notes.txt"),
            (5, "data:image/png;base64,AAAA"),
        ] {
            assert_eq!(img[k], json!({ "uri": uri }), "image {k}");
        }
        let view = |k: usize| {
            let v = &json["bufferViews"][k];
            let at = v["byteOffset"].as_u64().unwrap() as usize;
            assert_eq!(at % 4, 0, "view {k} unaligned");
            bin[at..at + v["byteLength"].as_u64().unwrap() as usize].to_vec()
        };
        assert_eq!(view(1), png);
        assert_eq!(view(2), [0xFF, 0xD8, 0xFF, 0xE0, 1]);
        assert_eq!(bin[..3], [1, 2, 3]);
        assert_eq!(json["buffers"][0]["byteLength"], bin.len());
        // No buffer yet: one is made for the images.
        let mut bare = doc(&["eye.png"]);
        let mut bin = Vec::new();
        assert_eq!(embed(&mut bare, &mut bin, dir.path()).unwrap(), 1);
        assert_eq!(bare["buffers"], json!([{"byteLength": 5}]));
    }
}
