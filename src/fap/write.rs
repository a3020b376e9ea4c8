//! Canonical writer of ASCII FAP files.
//!
//! Output: one header line `<version> <name> <frame_rate> <frame_count>`, then a 68-entry mask
//! line and a value line per frame; LF line endings, single spaces, no trailing blanks.
//! Integral values are written without a decimal point, other values in the shortest form
//! that reads back to the same `f64`.

use std::fmt::Write as _;
use std::path::Path;

use super::model::{FapFrame, FapStream, DEFAULT_VERSION};
use crate::error::Result;

/// The canonical text of a stream.
pub fn write_fap_string(stream: &FapStream) -> String {
    // About 180 bytes per frame for a typical 30-FAP frame.
    let mut out = String::with_capacity(64 + stream.frames.len().saturating_mul(180));
    write_header(&mut out, stream);
    for f in &stream.frames {
        write_frame(&mut out, f);
    }
    out
}

/// Writes the canonical text atomically to `path`.
pub fn write_fap_file(path: &Path, stream: &FapStream) -> Result<()> {
    crate::io::write_atomic_with(path, |w| {
        let mut buf = String::with_capacity(64 * 1024);
        write_header(&mut buf, stream);
        for f in &stream.frames {
            write_frame(&mut buf, f);
            if buf.len() >= 60 * 1024 {
                w.write_all(buf.as_bytes())?;
                buf.clear();
            }
        }
        w.write_all(buf.as_bytes())
    })
}

/// The version as written: the stream's own if it is one clean token, else `2.1`.
fn version_token(stream: &FapStream) -> &str {
    let v = stream.version.as_str();
    if v.is_empty() || v.starts_with('#') || v.bytes().any(|c| c.is_ascii_whitespace()) {
        DEFAULT_VERSION
    } else {
        v
    }
}

/// The name as written: line feeds (which would split the header) become spaces, spaces and
/// tabs at the ends are dropped (as the reader does), and an empty name becomes `-` so the
/// header keeps four fields.
fn name_text(stream: &FapStream) -> String {
    let n = stream.name.replace('\n', " ");
    let n = n.trim_matches([' ', '\t']);
    if n.is_empty() {
        "-".to_string()
    } else {
        n.to_string()
    }
}

fn write_header(out: &mut String, stream: &FapStream) {
    out.push_str(version_token(stream));
    out.push(' ');
    out.push_str(&name_text(stream));
    out.push(' ');
    push_number(out, stream.frame_rate);
    let _ = writeln!(out, " {}", stream.frames.len());
}

fn write_frame(out: &mut String, f: &FapFrame) {
    let _ = writeln!(out, "{}", f.mask());
    let _ = write!(out, "{}", f.number);
    if let Some(v) = f.viseme() {
        let _ = write!(
            out,
            " {} {} {} {}",
            v.select1.number(),
            v.select2.number(),
            v.blend,
            u8::from(v.def)
        );
    }
    if let Some(e) = f.expression() {
        let _ = write!(
            out,
            " {} {} {} {} {} {}",
            e.select1.number(),
            e.intensity1,
            e.select2.number(),
            e.intensity2,
            u8::from(e.init_face),
            u8::from(e.def)
        );
    }
    for &v in f.values() {
        out.push(' ');
        push_number(out, v);
    }
    out.push('\n');
}

/// Integers without a decimal point; other values in shortest round-trip form.
pub(crate) fn push_number(out: &mut String, v: f64) {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        let _ = write!(out, "{}", v as i64);
    } else {
        // `Debug` is the shortest representation that parses back to the same value.
        let _ = write!(out, "{v:?}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::FapId;

    #[test]
    fn numbers_are_canonical() {
        let mut s = String::new();
        for v in [120.0, -0.0, -43.0, 0.5, 1e-7, 1e20, 0.1 + 0.2] {
            push_number(&mut s, v);
            s.push(' ');
        }
        assert_eq!(s, "120 0 -43 0.5 1e-7 1e20 0.30000000000000004 ");
    }

    #[test]
    fn writes_header_and_frames() {
        let mut f = FapFrame::new(0);
        f.set(FapId::OPEN_JAW, 200.0);
        let st = FapStream {
            frames: vec![f],
            ..FapStream::new("", 12.5)
        };
        let t = write_fap_string(&st);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[0], "2.1 - 12.5 1");
        assert!(lines[1].starts_with("0 0 1 0"));
        assert_eq!(lines[2], "0 200");
        assert!(!t.contains(" \n"));
    }
}
