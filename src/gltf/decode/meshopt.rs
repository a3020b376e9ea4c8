//! `EXT_meshopt_compression`: buffer views compressed with meshoptimizer's codecs, decoded
//! with the maintained `meshopt` crate (meshoptimizer's C decoder, which is documented as safe
//! on untrusted input), then the spec's filters.
//!
//! Each compressed view names its compressed bytes (`buffer`, `byteOffset`, `byteLength` in
//! the extension) and where the decoded bytes go: the view's own `buffer`/`byteOffset`, usually
//! a *fallback* buffer that has no data in the file. The decoded bytes are written there, so
//! every accessor keeps its view and offset; then the extension is removed from the views,
//! the buffers and the extension lists, and a warning says so.
//!
//! Every number is checked before a byte is allocated or the C decoder is called: modes,
//! strides and filters as the spec allows them (the decoder asserts on others), ranges inside
//! the loaded buffers, and the expanded size bounded both in total
//! ([`super::MAX_DECODED_BYTES`]) and per view by [`MAX_EXPANSION`] times its compressed size.

use std::path::Path;

use serde_json::Value;

use super::{decode_error, drop_extension_name, drop_object_extension, MAX_DECODED_BYTES};
use crate::error::{Diagnostic, Result};

/// The extension's name.
pub const EXTENSION: &str = "EXT_meshopt_compression";

/// Largest ratio of decoded to compressed bytes accepted for one view (plus a small constant).
/// meshoptimizer's codecs spend at least a byte per triangle (index codec: 12 decoded bytes)
/// and two header bits per 16 bytes of a vertex stream (64:1); 1024 leaves room for any real
/// file while a tiny hostile file cannot ask for gigabytes.
pub const MAX_EXPANSION: usize = 1024;

/// What a compressed view holds (the extension's `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

/// The extension's `filter`, applied after decoding `ATTRIBUTES`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
}

/// One compressed view, checked.
#[derive(Debug)]
struct Compressed {
    view: usize,
    source: usize,
    source_offset: usize,
    source_length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
    target: usize,
    target_offset: usize,
}

/// Decodes every compressed view of `json` into `buffers` (see the module docs); no-op when
/// the document has none.
pub fn decode(json: &mut Value, buffers: &mut [Vec<u8>], file: &Path) -> Result<Vec<Diagnostic>> {
    let list = collect(json, buffers, file)?;
    let fallbacks = fallback_buffers(json);
    if list.is_empty() {
        // Nothing compressed. A fallback buffer nothing decodes into stays empty: a plain view
        // over it is refused later as running past its buffer.
        return Ok(Vec::new());
    }
    size_fallbacks(json, buffers, &list, &fallbacks, file)?;
    for c in &list {
        let at = format!("bufferViews[{}].extensions.{EXTENSION}", c.view);
        let src = &buffers[c.source][c.source_offset..c.source_offset + c.source_length];
        let bytes = decode_one(c, src).map_err(|what| decode_error(file, &at, what))?;
        let dst = &mut buffers[c.target];
        dst[c.target_offset..c.target_offset + bytes.len()].copy_from_slice(&bytes);
    }
    // The document now reads as plain glTF: no compressed views, no fallback markers.
    if let Some(Value::Array(views)) = json.get_mut("bufferViews") {
        for c in &list {
            drop_object_extension(&mut views[c.view], EXTENSION);
        }
    }
    if let Some(Value::Array(bufs)) = json.get_mut("buffers") {
        for &b in &fallbacks {
            drop_object_extension(&mut bufs[b], EXTENSION);
        }
    }
    drop_extension_name(json, EXTENSION);
    Ok(vec![Diagnostic::warning(format!(
        "{}: {} buffer view(s) compressed with {EXTENSION} were decoded; the document is \
         handed on without the extension (Blender cannot import it)",
        file.display(),
        list.len()
    ))])
}

/// Indices of the buffers marked as meshopt fallbacks.
fn fallback_buffers(json: &Value) -> Vec<usize> {
    json.get("buffers")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
        .filter(|(_, b)| super::is_meshopt_fallback(b))
        .map(|(i, _)| i)
        .collect()
}

/// A non-negative integer field of `obj`, or `default` when absent.
fn usize_field(
    obj: &Value,
    key: &str,
    default: Option<usize>,
    at: &str,
    file: &Path,
) -> Result<usize> {
    match obj.get(key) {
        None => default.ok_or_else(|| decode_error(file, &format!("{at}.{key}"), "missing")),
        Some(v) => v
            .as_u64()
            .and_then(|n| usize::try_from(n).ok())
            .ok_or_else(|| {
                decode_error(
                    file,
                    &format!("{at}.{key}"),
                    "must be a non-negative integer",
                )
            }),
    }
}

/// The compressed views of the document, every field checked against the spec and the
/// loaded buffers (fallback buffers are checked against their declared `byteLength`).
fn collect(json: &Value, buffers: &[Vec<u8>], file: &Path) -> Result<Vec<Compressed>> {
    let views = match json.get("bufferViews") {
        None => return Ok(Vec::new()),
        Some(Value::Array(v)) => v,
        Some(_) => return Err(decode_error(file, "bufferViews", "must be an array")),
    };
    let declared: Vec<Option<u64>> = json
        .get("buffers")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .map(|b| b.get("byteLength").and_then(Value::as_u64))
        .collect();
    let mut out = Vec::new();
    for (i, view) in views.iter().enumerate() {
        let Some(ext) = view.pointer(&format!("/extensions/{EXTENSION}")) else {
            continue;
        };
        let at = format!("bufferViews[{i}].extensions.{EXTENSION}");
        let vat = format!("bufferViews[{i}]");
        if !ext.is_object() {
            return Err(decode_error(file, &at, "must be an object"));
        }
        let source = usize_field(ext, "buffer", None, &at, file)?;
        let source_offset = usize_field(ext, "byteOffset", Some(0), &at, file)?;
        let source_length = usize_field(ext, "byteLength", None, &at, file)?;
        let stride = usize_field(ext, "byteStride", None, &at, file)?;
        let count = usize_field(ext, "count", None, &at, file)?;
        let mode = match ext.get("mode").and_then(Value::as_str) {
            Some("ATTRIBUTES") => Mode::Attributes,
            Some("TRIANGLES") => Mode::Triangles,
            Some("INDICES") => Mode::Indices,
            _ => {
                return Err(decode_error(
                    file,
                    &format!("{at}.mode"),
                    "must be ATTRIBUTES, TRIANGLES or INDICES",
                ))
            }
        };
        let filter = match ext.get("filter").map(Value::as_str) {
            None | Some(Some("NONE")) => Filter::None,
            Some(Some("OCTAHEDRAL")) => Filter::Octahedral,
            Some(Some("QUATERNION")) => Filter::Quaternion,
            Some(Some("EXPONENTIAL")) => Filter::Exponential,
            _ => {
                return Err(decode_error(
                    file,
                    &format!("{at}.filter"),
                    "must be NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL",
                ))
            }
        };
        // The decoder asserts on these (an abort, not an error), so they are checked here.
        let stride_ok = match (mode, filter) {
            (Mode::Attributes, Filter::None) => stride % 4 == 0 && (4..=256).contains(&stride),
            (Mode::Attributes, Filter::Octahedral) => stride == 4 || stride == 8,
            (Mode::Attributes, Filter::Quaternion) => stride == 8,
            (Mode::Attributes, Filter::Exponential) => {
                stride % 4 == 0 && (4..=256).contains(&stride)
            }
            (_, Filter::None) => stride == 2 || stride == 4,
            _ => false,
        };
        if !stride_ok {
            return Err(decode_error(
                file,
                &at,
                format!(
                    "byteStride {stride} is not allowed for mode {mode:?} with filter {filter:?}"
                ),
            ));
        }
        if count == 0 || (mode == Mode::Triangles && count % 3 != 0) {
            return Err(decode_error(
                file,
                &format!("{at}.count"),
                format!("count {count} must be positive (and a multiple of 3 for TRIANGLES)"),
            ));
        }
        let src_len = buffers.get(source).map(Vec::len).ok_or_else(|| {
            decode_error(file, &format!("{at}.buffer"), format!("no buffer {source}"))
        })?;
        if source_offset
            .checked_add(source_length)
            .is_none_or(|end| end > src_len)
        {
            return Err(decode_error(
                file,
                &at,
                format!("compressed bytes run past the end of buffer {source}"),
            ));
        }
        let decoded = count.checked_mul(stride).filter(|&d| {
            d <= MAX_DECODED_BYTES && d <= source_length.saturating_mul(MAX_EXPANSION) + 4096
        });
        let Some(decoded) = decoded else {
            return Err(decode_error(
                file,
                &at,
                format!(
                    "{count} elements of {stride} bytes from {source_length} compressed bytes \
                     is more than fbakit expands"
                ),
            ));
        };
        let target = usize_field(view, "buffer", None, &vat, file)?;
        let target_offset = usize_field(view, "byteOffset", Some(0), &vat, file)?;
        let view_length = usize_field(view, "byteLength", None, &vat, file)?;
        if decoded > view_length {
            return Err(decode_error(
                file,
                &vat,
                format!("byteLength {view_length} is less than the {decoded} decoded bytes"),
            ));
        }
        let target_len = match declared.get(target) {
            Some(Some(n)) => usize::try_from(*n).unwrap_or(usize::MAX),
            _ => {
                return Err(decode_error(
                    file,
                    &format!("{vat}.buffer"),
                    format!("no buffer {target} with a byteLength"),
                ))
            }
        };
        if target == source {
            return Err(decode_error(
                file,
                &vat,
                "decodes into the buffer that holds its compressed bytes",
            ));
        }
        if target_offset
            .checked_add(decoded)
            .is_none_or(|end| end > target_len)
        {
            return Err(decode_error(
                file,
                &vat,
                format!("decoded bytes run past the end of buffer {target}"),
            ));
        }
        out.push(Compressed {
            view: i,
            source,
            source_offset,
            source_length,
            stride,
            count,
            mode,
            filter,
            target,
            target_offset,
        });
    }
    Ok(out)
}

/// Gives every fallback buffer that compressed views decode into its declared size (zeros),
/// within the expansion bounds; a loaded target buffer must already be large enough.
fn size_fallbacks(
    json: &Value,
    buffers: &mut [Vec<u8>],
    list: &[Compressed],
    fallbacks: &[usize],
    file: &Path,
) -> Result<()> {
    let mut total = 0usize;
    for &b in fallbacks {
        let into: Vec<&Compressed> = list.iter().filter(|c| c.target == b).collect();
        if into.is_empty() {
            continue;
        }
        let declared = json
            .pointer(&format!("/buffers/{b}/byteLength"))
            .and_then(Value::as_u64)
            .and_then(|n| usize::try_from(n).ok())
            .unwrap_or(0);
        let compressed: usize = into.iter().map(|c| c.source_length).sum();
        let allowed = compressed
            .saturating_mul(MAX_EXPANSION)
            .saturating_add(4096);
        total = total.saturating_add(declared);
        if declared > allowed || total > MAX_DECODED_BYTES {
            return Err(decode_error(
                file,
                &format!("buffers[{b}].byteLength"),
                format!(
                    "a fallback buffer of {declared} bytes for {compressed} compressed bytes is \
                     more than fbakit expands"
                ),
            ));
        }
        if buffers[b].len() < declared {
            buffers[b] = vec![0; declared];
        }
    }
    for c in list {
        if buffers[c.target].len() < c.target_offset + c.count * c.stride {
            return Err(decode_error(
                file,
                &format!("bufferViews[{}]", c.view),
                format!(
                    "decoded bytes run past the loaded data of buffer {}",
                    c.target
                ),
            ));
        }
    }
    Ok(())
}

/// Decodes one view's compressed bytes (`count * stride` bytes out) and applies its filter.
fn decode_one(c: &Compressed, src: &[u8]) -> std::result::Result<Vec<u8>, String> {
    let mut out = vec![0u8; c.count * c.stride];
    // SAFETY: `out` holds exactly `count * stride` bytes, what each decoder writes; `src` is
    // a valid slice; mode, stride, count and filter were checked against the decoder's
    // preconditions in `collect` (it asserts on those, and returns an error code for
    // malformed data).
    let code = unsafe {
        match c.mode {
            Mode::Attributes => ::meshopt::ffi::meshopt_decodeVertexBuffer(
                out.as_mut_ptr().cast(),
                c.count,
                c.stride,
                src.as_ptr(),
                src.len(),
            ),
            Mode::Triangles => ::meshopt::ffi::meshopt_decodeIndexBuffer(
                out.as_mut_ptr().cast(),
                c.count,
                c.stride,
                src.as_ptr(),
                src.len(),
            ),
            Mode::Indices => ::meshopt::ffi::meshopt_decodeIndexSequence(
                out.as_mut_ptr().cast(),
                c.count,
                c.stride,
                src.as_ptr(),
                src.len(),
            ),
        }
    };
    if code != 0 {
        return Err(format!(
            "the compressed {:?} data is malformed (meshopt error {code})",
            c.mode
        ));
    }
    // SAFETY: as above; the filters rewrite `count` elements of `stride` bytes in place, and
    // the stride suits the filter (checked in `collect`).
    unsafe {
        let p = out.as_mut_ptr().cast();
        match c.filter {
            Filter::None => {}
            Filter::Octahedral => ::meshopt::ffi::meshopt_decodeFilterOct(p, c.count, c.stride),
            Filter::Quaternion => ::meshopt::ffi::meshopt_decodeFilterQuat(p, c.count, c.stride),
            Filter::Exponential => ::meshopt::ffi::meshopt_decodeFilterExp(p, c.count, c.stride),
        }
    }
    Ok(out)
}
