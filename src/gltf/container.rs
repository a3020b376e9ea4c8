//! The two glTF containers: binary `.glb` and JSON `.gltf` with an embedded data-URI buffer.
//!
//! GLB layout (glTF 2.0 §4.4): a 12-byte header (`glTF`, version 2, total length), a `JSON`
//! chunk padded with spaces to a multiple of 4 bytes, then a `BIN` chunk padded with zeros.
//! [`parse_glb`] reads that layout back with every length checked, for tests and tools.

use std::path::Path;

use super::json::{Buffer, Root};
use super::GltfError;
use crate::error::{Error, Result};

/// GLB magic `glTF`, little-endian.
pub const GLB_MAGIC: u32 = 0x4654_6C67;
/// GLB container version.
pub const GLB_VERSION: u32 = 2;
/// Chunk type of the JSON chunk (`JSON`).
pub const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk (`BIN\0`).
pub const CHUNK_BIN: u32 = 0x004E_4942;

/// Prefix of the embedded buffer's data URI in `.gltf` output.
pub const DATA_URI_PREFIX: &str = "data:application/octet-stream;base64,";

/// A complete glTF asset: the JSON document and its single binary buffer.
///
/// `root.buffers` is empty when `bin` is, otherwise it holds exactly one buffer whose `uri` is
/// filled in by the container being written.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfDocument {
    /// The JSON part.
    pub root: Root,
    /// Buffer 0 (length a multiple of 4).
    pub bin: Vec<u8>,
}

impl GltfDocument {
    /// The asset as `.glb` bytes.
    pub fn to_glb(&self) -> Result<Vec<u8>> {
        let mut root = self.root.clone();
        if let Some(b) = root.buffers.first_mut() {
            b.uri = None;
        }
        let mut json = serde_json::to_vec(&root).map_err(json_error)?;
        pad_to_4(&mut json, b' ');
        let bin_padded = self.bin.len().next_multiple_of(4);
        let total = 12
            + 8
            + json.len()
            + if self.bin.is_empty() {
                0
            } else {
                8 + bin_padded
            };
        let total = u32::try_from(total).map_err(|_| GltfError::AssetTooLarge)?;
        let mut out = Vec::with_capacity(total as usize);
        for word in [GLB_MAGIC, GLB_VERSION, total, json.len() as u32, CHUNK_JSON] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        out.extend_from_slice(&json);
        if !self.bin.is_empty() {
            out.extend_from_slice(&(bin_padded as u32).to_le_bytes());
            out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
            out.extend_from_slice(&self.bin);
            out.resize(total as usize, 0);
        }
        Ok(out)
    }

    /// The asset as `.gltf` JSON text (pretty-printed) with the buffer embedded as a base64
    /// data URI, so the file is self-contained (about a third larger than the `.glb`).
    pub fn to_gltf_string(&self) -> Result<String> {
        let mut root = self.root.clone();
        if let Some(b) = root.buffers.first_mut() {
            let mut uri = String::with_capacity(DATA_URI_PREFIX.len() + self.bin.len() / 3 * 4 + 4);
            uri.push_str(DATA_URI_PREFIX);
            base64_encode_into(&self.bin, &mut uri);
            *b = Buffer {
                byte_length: b.byte_length,
                uri: Some(uri),
            };
        }
        let mut text = serde_json::to_string_pretty(&root).map_err(json_error)?;
        text.push('\n');
        Ok(text)
    }

    /// Writes `.glb` atomically (not as `.vrm`: a document fbakit builds is no VRM avatar,
    /// [`super::check_vrm_output`]).
    pub fn write_glb(&self, path: &Path) -> Result<()> {
        super::check_vrm_output(path, None, "a new glTF document")?;
        crate::io::write_atomic(path, &self.to_glb()?)
    }

    /// Writes `.gltf` (embedded buffer) atomically.
    pub fn write_gltf(&self, path: &Path) -> Result<()> {
        crate::io::write_atomic(path, self.to_gltf_string()?.as_bytes())
    }

    /// Writes `.glb` or `.gltf` depending on the extension of `path` (case-insensitive).
    pub fn write(&self, path: &Path) -> Result<()> {
        use crate::format::OutputFormat;
        match OutputFormat::resolve(
            path,
            &[OutputFormat::Glb, OutputFormat::Gltf],
            "glTF output",
        )? {
            OutputFormat::Glb => self.write_glb(path),
            _ => self.write_gltf(path),
        }
    }
}

fn json_error(e: serde_json::Error) -> Error {
    GltfError::Serialize(e.to_string()).into()
}

fn pad_to_4(bytes: &mut Vec<u8>, fill: u8) {
    bytes.resize(bytes.len().next_multiple_of(4), fill);
}

/// The chunks of a GLB file, borrowed from its bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GlbChunks<'a> {
    /// JSON chunk data (including its space padding).
    pub json: &'a [u8],
    /// BIN chunk data (including its zero padding), if present.
    pub bin: Option<&'a [u8]>,
}

/// Splits GLB bytes into chunks, checking magic, version, total length, chunk lengths (a
/// multiple of 4, inside the file) and chunk order. Unknown chunks after `BIN` are skipped.
pub fn parse_glb(bytes: &[u8]) -> Result<GlbChunks<'_>> {
    let bad = |what: &str| -> Error {
        GltfError::BadGlb {
            what: what.to_string(),
        }
        .into()
    };
    let word = |at: usize| -> Option<u32> {
        bytes
            .get(at..at.checked_add(4)?)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if word(0) != Some(GLB_MAGIC) {
        return Err(bad("missing `glTF` magic"));
    }
    if word(4) != Some(GLB_VERSION) {
        return Err(bad("container version is not 2"));
    }
    if word(8).map(|n| n as usize) != Some(bytes.len()) {
        return Err(bad("header length differs from the file length"));
    }
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < bytes.len() {
        let (Some(len), Some(kind)) = (word(at), word(at + 4)) else {
            return Err(bad("truncated chunk header"));
        };
        let start = at + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| bad("chunk runs past the end of the file"))?;
        if len % 4 != 0 {
            return Err(bad("chunk length is not a multiple of 4"));
        }
        let data = &bytes[start..end];
        match (kind, json.is_some(), bin.is_some()) {
            (CHUNK_JSON, false, _) => json = Some(data),
            (CHUNK_JSON, true, _) => return Err(bad("more than one JSON chunk")),
            (_, false, _) => return Err(bad("first chunk is not JSON")),
            (CHUNK_BIN, true, false) => bin = Some(data),
            (CHUNK_BIN, true, true) => return Err(bad("more than one BIN chunk")),
            _ => {}
        }
        at = end;
    }
    Ok(GlbChunks {
        json: json.ok_or_else(|| bad("no JSON chunk"))?,
        bin,
    })
}

const BASE64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Appends the standard (RFC 4648, padded) base64 encoding of `data` to `out`.
pub fn base64_encode_into(data: &[u8], out: &mut String) {
    out.reserve(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let n = (u32::from(chunk[0]) << 16)
            | (u32::from(*chunk.get(1).unwrap_or(&0)) << 8)
            | u32::from(*chunk.get(2).unwrap_or(&0));
        let sextet = |shift: u32| BASE64[((n >> shift) & 63) as usize] as char;
        out.push(sextet(18));
        out.push(sextet(12));
        out.push(if chunk.len() > 1 { sextet(6) } else { '=' });
        out.push(if chunk.len() > 2 { sextet(0) } else { '=' });
    }
}

/// Decodes standard padded base64 (the inverse of [`base64_encode_into`]); `None` on any
/// malformed input.
pub fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let bytes = text.as_bytes();
    if bytes.len() % 4 != 0 {
        return None;
    }
    let value = |c: u8| BASE64.iter().position(|&b| b == c).map(|p| p as u32);
    let mut out = Vec::with_capacity(bytes.len() / 4 * 3);
    let quads = bytes.len() / 4;
    for (i, q) in bytes.chunks(4).enumerate() {
        let pad = q.iter().rev().take_while(|&&c| c == b'=').count();
        if pad > 2 || (pad > 0 && i + 1 != quads) {
            return None;
        }
        let mut n = 0u32;
        for &c in &q[..4 - pad] {
            n = (n << 6) | value(c)?;
        }
        n <<= 6 * pad as u32;
        let three = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&three[..3 - pad]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors_and_round_trips() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            let mut s = String::new();
            base64_encode_into(plain.as_bytes(), &mut s);
            assert_eq!(s, coded);
            assert_eq!(base64_decode(coded).unwrap(), plain.as_bytes());
        }
        let all: Vec<u8> = (0..=255).collect();
        let mut s = String::new();
        base64_encode_into(&all, &mut s);
        assert_eq!(base64_decode(&s).unwrap(), all);
        assert_eq!(base64_decode("Zg="), None);
        assert_eq!(base64_decode("Z==="), None);
        assert_eq!(base64_decode("Zg==Zg=="), None);
        assert_eq!(base64_decode("Zm9*"), None);
    }

    fn doc(bin: Vec<u8>) -> GltfDocument {
        let mut root = Root::default();
        root.asset.version = "2.0".into();
        if !bin.is_empty() {
            root.buffers.push(Buffer {
                byte_length: bin.len() as u32,
                uri: None,
            });
        }
        GltfDocument { root, bin }
    }

    #[test]
    fn glb_layout_is_aligned_and_parses_back() {
        let d = doc(vec![1, 2, 3, 4, 5, 6, 7, 8]);
        let glb = d.to_glb().unwrap();
        assert_eq!(glb.len() % 4, 0);
        let chunks = parse_glb(&glb).unwrap();
        assert_eq!(chunks.json.len() % 4, 0);
        let root: Root = serde_json::from_slice(chunks.json).unwrap();
        assert_eq!(root, d.root);
        assert_eq!(chunks.bin, Some(&[1, 2, 3, 4, 5, 6, 7, 8][..]));
        // No buffer: no BIN chunk at all.
        let glb = doc(Vec::new()).to_glb().unwrap();
        assert_eq!(parse_glb(&glb).unwrap().bin, None);
    }

    #[test]
    fn glb_parser_rejects_broken_files_without_panicking() {
        let good = doc(vec![9; 8]).to_glb().unwrap();
        // Every truncation and a few corruptions are errors, never panics.
        for n in 0..good.len() {
            assert!(parse_glb(&good[..n]).is_err(), "truncated at {n}");
        }
        let mut bad_len = good.clone();
        bad_len[12] = 0xFF; // JSON chunk length beyond the file
        bad_len[13] = 0xFF;
        assert!(parse_glb(&bad_len).is_err());
        let mut bad_magic = good.clone();
        bad_magic[0] = b'x';
        assert!(parse_glb(&bad_magic).is_err());
        let mut huge = good.clone();
        huge[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse_glb(&huge).is_err());
    }

    #[test]
    fn gltf_text_embeds_buffer_as_data_uri() {
        let d = doc(vec![0, 1, 2, 3]);
        let text = d.to_gltf_string().unwrap();
        let root: Root = serde_json::from_str(&text).unwrap();
        let uri = root.buffers[0].uri.as_deref().unwrap();
        let data = base64_decode(uri.strip_prefix(DATA_URI_PREFIX).unwrap()).unwrap();
        assert_eq!(data, d.bin);
    }

    #[test]
    fn write_picks_container_by_extension() {
        let dir = tempfile::tempdir().unwrap();
        let d = doc(vec![7; 4]);
        d.write(&dir.path().join("a.GLB")).unwrap();
        assert!(parse_glb(&std::fs::read(dir.path().join("a.GLB")).unwrap()).is_ok());
        d.write(&dir.path().join("a.gltf")).unwrap();
        let e = d.write(&dir.path().join("a.obj")).unwrap_err();
        assert!(e.to_string().contains("must be .glb, .gltf"), "{e}");
    }
}
