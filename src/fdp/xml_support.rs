//! Shared pieces of the two XML readers: a configured quick-xml reader that knows where each
//! event starts, attribute access with exact source offsets, and number parsing with located
//! errors.

use std::borrow::Cow;
use std::path::Path;

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use crate::error::{Error, ParseError, Result};

/// Deepest element nesting either reader accepts; both formats are at most three levels deep,
/// so anything deeper is hostile or not ours (and never recursed into).
pub(crate) const MAX_DEPTH: usize = 16;

/// A quick-xml reader over in-memory text that reports located errors.
pub(crate) struct XmlCursor<'a> {
    pub file: &'a Path,
    pub text: &'a str,
    reader: Reader<&'a [u8]>,
    /// Byte offset where the last returned event starts.
    pub event_start: usize,
    /// Open elements.
    pub depth: usize,
}

impl<'a> XmlCursor<'a> {
    pub fn new(file: &'a Path, text: &'a str) -> XmlCursor<'a> {
        let mut reader = Reader::from_str(text);
        let cfg = reader.config_mut();
        cfg.trim_text(true);
        cfg.check_end_names = true;
        cfg.expand_empty_elements = false;
        XmlCursor {
            file,
            text,
            reader,
            event_start: 0,
            depth: 0,
        }
    }

    /// The next event; XML syntax errors and nesting beyond [`MAX_DEPTH`] are located errors,
    /// and `Eof` with elements still open is "truncated".
    pub fn next(&mut self) -> Result<Event<'a>> {
        let before = self.reader.buffer_position() as usize;
        let skipped = self.text.as_bytes()[before.min(self.text.len())..]
            .iter()
            .take_while(|b| b.is_ascii_whitespace())
            .count();
        self.event_start = before + skipped;
        let ev = self.reader.read_event().map_err(|e| {
            let at = self.reader.error_position() as usize;
            self.error_at(at, format!("well-formed XML ({e})"))
        })?;
        match &ev {
            Event::Start(_) => {
                self.depth += 1;
                if self.depth > MAX_DEPTH {
                    return Err(self.error(format!("element nesting at most {MAX_DEPTH} deep")));
                }
            }
            Event::End(_) => self.depth = self.depth.saturating_sub(1),
            Event::Eof if self.depth > 0 => {
                return Err(self.error_at(
                    self.text.len(),
                    "the closing tags (the document is truncated)",
                ));
            }
            _ => {}
        }
        Ok(ev)
    }

    /// An error at the start of the current event.
    pub fn error(&self, expected: impl Into<String>) -> Error {
        self.error_at(self.event_start, expected)
    }

    /// An error at byte `offset`.
    pub fn error_at(&self, offset: usize, expected: impl Into<String>) -> Error {
        Error::Parse(ParseError::at_offset(
            self.file, self.text, offset, expected,
        ))
    }

    /// Byte offset of `s` inside the source text when `s` borrows from it.
    pub fn offset_of(&self, s: &str) -> Option<usize> {
        let base = self.text.as_ptr() as usize;
        let p = s.as_ptr() as usize;
        (p >= base && p <= base + self.text.len()).then(|| p - base)
    }

    /// Skips the rest of the element just opened (for tolerated unknown elements), bounded by
    /// the nesting limit.
    pub fn skip_element(&mut self) -> Result<()> {
        let target = self.depth - 1;
        while self.depth > target {
            if let Event::Eof = self.next()? {
                break;
            }
        }
        Ok(())
    }
}

/// One attribute: name, unescaped value, and the byte offset of its value.
pub(crate) struct Attr<'a> {
    pub name: String,
    pub value: Cow<'a, str>,
    pub offset: usize,
}

/// The attributes of an element in source order, each located. quick-xml's duplicate check
/// is quadratic, so it is off; callers reject duplicates of the names they know.
pub(crate) fn attributes<'c>(
    cur: &'c XmlCursor<'_>,
    e: &'c BytesStart<'_>,
) -> impl Iterator<Item = Result<Attr<'c>>> + 'c {
    let mut attrs = e.attributes();
    attrs.with_checks(false);
    let start = cur.event_start;
    attrs.map(move |a| {
        let a = a.map_err(|err| cur.error_at(start, format!("well-formed attributes ({err})")))?;
        let offset = match &a.value {
            Cow::Borrowed(b) => cur.offset_of(b).unwrap_or(start),
            Cow::Owned(_) => start,
        };
        let name = a.key.as_ref().to_string();
        let value: Cow<'c, str> = match a.value {
            Cow::Borrowed(raw) => unescape(cur, raw, offset)?,
            Cow::Owned(raw) => Cow::Owned(unescape(cur, &raw, offset)?.into_owned()),
        };
        Ok(Attr {
            name,
            value,
            offset,
        })
    })
}

/// Replaces the five predefined entities and character references; anything else (custom
/// entities) is an error, so no DTD-driven expansion can happen.
fn unescape<'a>(cur: &XmlCursor<'_>, raw: &'a str, offset: usize) -> Result<Cow<'a, str>> {
    if !raw.contains('&') {
        return Ok(Cow::Borrowed(raw));
    }
    quick_xml::escape::unescape(raw)
        .map(|c| Cow::Owned(c.into_owned()))
        .map_err(|e| cur.error_at(offset, format!("only the predefined XML entities ({e})")))
}

/// Element name as text.
pub(crate) fn element_name(e: &BytesStart<'_>) -> String {
    e.name().as_ref().to_string()
}

/// A finite number in an attribute.
pub(crate) fn parse_f64(cur: &XmlCursor<'_>, a: &Attr<'_>) -> Result<f64> {
    let v = a.value.trim();
    match v.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(Error::Parse(ParseError {
            location: crate::error::Location::from_offset(cur.file, cur.text, a.offset),
            expected: format!("a finite number for `{}`", a.name),
            found: Some(truncate(&a.value)),
        })),
    }
}

/// A finite number that also fits an `f32` coordinate.
pub(crate) fn parse_f32(cur: &XmlCursor<'_>, a: &Attr<'_>) -> Result<f32> {
    let x = parse_f64(cur, a)?;
    let y = x as f32;
    if y.is_finite() {
        Ok(y)
    } else {
        Err(Error::Parse(ParseError {
            location: crate::error::Location::from_offset(cur.file, cur.text, a.offset),
            expected: format!("a coordinate within ±3.4e38 for `{}`", a.name),
            found: Some(truncate(&a.value)),
        }))
    }
}

/// Whitespace-separated vertex indices starting at byte `offset`.
pub(crate) fn parse_indices(
    cur: &XmlCursor<'_>,
    text: &str,
    offset: usize,
    what: &str,
) -> Result<Vec<u32>> {
    let mut out = Vec::new();
    let base = text.as_ptr() as usize;
    for tok in text.split_ascii_whitespace() {
        let at = offset + (tok.as_ptr() as usize - base);
        let v: u32 = tok.parse().map_err(|_| {
            Error::Parse(ParseError {
                location: crate::error::Location::from_offset(cur.file, cur.text, at),
                expected: format!("{what}: 0-based vertex indices separated by spaces"),
                found: Some(truncate(tok)),
            })
        })?;
        out.push(v);
    }
    Ok(out)
}

/// At most 40 characters of a value, for messages.
pub(crate) fn truncate(s: &str) -> String {
    let t: String = s.chars().take(40).collect();
    if t.len() < s.len() {
        format!("{t}…")
    } else {
        t
    }
}

/// Escapes text for an attribute value.
pub(crate) fn escape_attr(s: &str) -> Cow<'_, str> {
    quick_xml::escape::escape(s)
}
