//! Reader of ASCII FAP files (`.fap`).
//!
//! Grammar (one rule per combinator below; lines end in LF or CRLF, blanks are spaces/tabs):
//!
//! ```text
//! file       = { comment | blank } header { comment | blank } { frame }
//! comment    = blanks "#" any-text
//! header     = version name frame_rate frame_count      (name: one token, free text)
//! frame      = mask_line value_line                     (comments/blank lines may sit between)
//! mask_line  = 68 × ("0" | "1")
//! value_line = frame_number { value }                   (one value per masked FAP, FAP order)
//! value      = number                                   (FAPs 3..68)
//!            | select1 select2 blend def                (FAP 1)
//!            | select1 intensity1 select2 intensity2 init_face def   (FAP 2)
//! ```
//!
//! The file is split into lines by hand (a fast byte search), and each line is parsed by the
//! small `nom` combinators at the bottom of this section. Lines are never copied and numbers
//! are parsed from `&str` slices, so reading runs at memory speed and a 1 GB line is linear.
//!
//! [`ReadMode::Strict`] accepts only the format above. [`ReadMode::Lenient`] also reads the
//! deviations met in real files, each reported as a located warning (first occurrence, with a
//! count of further ones): a name containing spaces (Greta), mask lines with more than 68
//! entries (Greta writes 69), a single value for FAP 1 or FAP 2 (Greta, Xface's writer), extra
//! values at the end of a value line, a header frame count that does not match the frames
//! present or is absurdly large (the frames present are read; the declared count is never used
//! for allocation), negative values of unidirectional FAPs, and a version that is not a number.

use std::path::Path;

use nom::branch::alt;
use nom::bytes::complete::take_till1;
use nom::character::complete::{char as ch, digit1, space0};
use nom::combinator::{eof, map_res, rest};
use nom::sequence::preceded;
use nom::{IResult, Parser};

use super::model::{ExpressionParams, FapFrame, FapMask, FapStream, VisemeParams};
use crate::error::{Diagnostic, Error, Location, ParseError, Result, Severity};
use crate::spec::{Expression, FapId, Viseme, NUM_FAPS};

/// Largest frame count a header may declare (strict); larger counts are an error in strict
/// mode and ignored (with a warning) in lenient mode.
pub const MAX_DECLARED_FRAMES: u64 = u32::MAX as u64;

/// Shortest possible frame in bytes (a 68-entry mask line plus a one-token value line): used
/// to cap pre-allocation by what the text can actually hold.
const MIN_FRAME_BYTES: usize = 2 * NUM_FAPS + 2;

/// How tolerant a reader is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ReadMode {
    /// Only the standard layout; any deviation is a located [`ParseError`].
    Strict,
    /// Also real-world deviations, each reported as a located warning.
    #[default]
    Lenient,
}

/// Options of [`parse_fap`] and [`read_fap_file`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadOptions {
    /// Strict or lenient.
    pub mode: ReadMode,
    /// How many located warnings of one kind to keep (further ones are counted in the first
    /// warning's message). Default 1.
    pub max_warnings_per_kind: usize,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            mode: ReadMode::Lenient,
            max_warnings_per_kind: 1,
        }
    }
}

impl ReadOptions {
    /// Strict reading.
    pub fn strict() -> Self {
        ReadOptions {
            mode: ReadMode::Strict,
            ..ReadOptions::default()
        }
    }

    /// Lenient reading (the default).
    pub fn lenient() -> Self {
        ReadOptions::default()
    }
}

/// Reads a `.fap` file (UTF-8, size-bounded) into a stream plus the warnings of lenient mode.
pub fn read_fap_file(path: &Path, opts: &ReadOptions) -> Result<(FapStream, Vec<Diagnostic>)> {
    let text = crate::io::read_text(path)?;
    parse_fap(&text, path, opts)
}

/// Reads a `.fap` stream from `reader` (UTF-8, bounded by
/// [`crate::io::DEFAULT_MAX_INPUT_BYTES`]); `source` names it in locations.
///
/// ```
/// use std::path::Path;
/// let text = std::fs::read("samples/speech.fap").unwrap();
/// let (stream, _warnings) = fbakit::fap::read_fap_from(
///     &text[..],
///     Path::new("speech.fap"),
///     &fbakit::fap::ReadOptions::lenient(),
/// )?;
/// assert!(!stream.frames.is_empty());
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read_fap_from<R: std::io::BufRead>(
    reader: R,
    source: &Path,
    opts: &ReadOptions,
) -> Result<(FapStream, Vec<Diagnostic>)> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_fap(&text, source, opts)
}

/// Reads `.fap` text; `file` names the source in locations.
pub fn parse_fap(
    text: &str,
    file: &Path,
    opts: &ReadOptions,
) -> Result<(FapStream, Vec<Diagnostic>)> {
    let mut r = Reader::new(text, file, opts);
    match r.read() {
        Ok(stream) => Ok((stream, r.finish_warnings())),
        Err(e) => Err(Error::Parse(e)),
    }
}

/// Every problem in `.fap` text as error findings: each deviation that lenient reading
/// tolerates (up to 100 of each kind) and, if reading stops, the error that stopped it.
/// Empty when the text is a valid strict `.fap` file.
pub fn validate_fap_str(text: &str, file: &Path) -> Vec<Diagnostic> {
    let opts = ReadOptions {
        mode: ReadMode::Lenient,
        max_warnings_per_kind: 100,
    };
    let mut r = Reader::new(text, file, &opts);
    let fatal = r.read().err();
    let mut out = r.finish_warnings();
    for d in &mut out {
        d.severity = Severity::Error;
    }
    if let Some(e) = fatal {
        out.push(Diagnostic {
            severity: Severity::Error,
            location: Some(e.location.clone()),
            message: format!("expected {}{}", e.expected, found_text(&e.found)),
        });
    }
    out
}

/// [`validate_fap_str`] on a file; `Err` only when the file cannot be read as text.
pub fn validate_fap_file(path: &Path) -> Result<Vec<Diagnostic>> {
    let text = crate::io::read_text(path)?;
    Ok(validate_fap_str(&text, path))
}

fn found_text(found: &Option<String>) -> String {
    match found {
        Some(f) => format!(", found `{f}`"),
        None => ", found end of input".to_string(),
    }
}

// ---------------------------------------------------------------------------------------------
// Grammar combinators (each works on the content of one line, without its line ending)
// ---------------------------------------------------------------------------------------------

type PResult<'a, O> = IResult<&'a str, O>;

/// Spaces and tabs (possibly none). Hand-rolled over bytes: it runs twice per value.
pub(crate) fn blanks(i: &str) -> PResult<'_, &str> {
    let n = i
        .bytes()
        .position(|b| b != b' ' && b != b'\t')
        .unwrap_or(i.len());
    Ok((&i[n..], &i[..n]))
}

/// One whitespace-free token (ASCII whitespace ends it; the split is on an ASCII byte, hence
/// on a character boundary).
pub(crate) fn token(i: &str) -> PResult<'_, &str> {
    let n = i
        .bytes()
        .position(|b| b.is_ascii_whitespace())
        .unwrap_or(i.len());
    if n == 0 {
        return Err(nom::Err::Error(nom::error::Error::new(
            i,
            nom::error::ErrorKind::TakeTill1,
        )));
    }
    Ok((&i[n..], &i[..n]))
}

/// Trailing blanks up to the end of the line.
pub(crate) fn line_end(i: &str) -> PResult<'_, ()> {
    (space0, eof).map(|_| ()).parse(i)
}

/// A comment line: optional blanks, `#`, any text; returns the text after `#`.
pub(crate) fn comment(i: &str) -> PResult<'_, &str> {
    preceded((space0, ch('#')), rest).parse(i)
}

/// A mask entry: `0` or `1` followed by a blank or the end of the line.
pub(crate) fn mask_entry(i: &str) -> PResult<'_, bool> {
    let (i, bit) = alt((ch('0').map(|_| false), ch('1').map(|_| true))).parse(i)?;
    // The entry must end here: `01` or `1.0` is not a mask entry.
    let (_, _) = alt((eof, take_till1(|c: char| c != ' ' && c != '\t'))).parse(i)?;
    Ok((i, bit))
}

/// An unsigned decimal integer token (frame numbers, counts, FAP 1/2 fields).
pub(crate) fn uint(i: &str) -> PResult<'_, u64> {
    let (rest_after, tok) = token(i)?;
    let (_, n) = (map_res(digit1, |d: &str| d.parse::<u64>()), eof)
        .map(|(n, _)| n)
        .parse(tok)?;
    Ok((rest_after, n))
}

/// A number token as `f64` (may be non-finite; callers reject that with a location).
pub(crate) fn number(i: &str) -> PResult<'_, f64> {
    let (after, tok) = token(i)?;
    match parse_f64(tok) {
        Some(v) => Ok((after, v)),
        None => Err(nom::Err::Error(nom::error::Error::new(
            i,
            nom::error::ErrorKind::Float,
        ))),
    }
}

/// Fast path for short integers (the common case), falling back to the standard float parser.
fn parse_f64(tok: &str) -> Option<f64> {
    let b = tok.as_bytes();
    let (neg, digits) = match b.first() {
        Some(b'-') => (true, &b[1..]),
        _ => (false, b),
    };
    if !digits.is_empty() && digits.len() <= 15 && digits.iter().all(u8::is_ascii_digit) {
        let mut n: i64 = 0;
        for d in digits {
            n = n * 10 + i64::from(d - b'0');
        }
        // Exact: |n| < 10^15 < 2^53.
        return Some(if neg { -(n as f64) } else { n as f64 });
    }
    tok.parse::<f64>().ok()
}

/// The next line of `text` from byte `pos`: its content (without `\n` and a trailing `\r`)
/// and the position of the line after it.
pub(crate) fn next_line(text: &str, pos: usize) -> Option<(&str, usize)> {
    if pos >= text.len() {
        return None;
    }
    let tail = &text[pos..];
    let (content, next) = match tail.find('\n') {
        Some(n) => (&tail[..n], pos + n + 1),
        None => (tail, text.len()),
    };
    Some((content.strip_suffix('\r').unwrap_or(content), next))
}

/// Header fields as slices of the header line, with their byte offsets in the line.
#[derive(Debug, PartialEq)]
pub(crate) struct HeaderFields<'a> {
    pub version: (&'a str, usize),
    /// Everything between the version and the frame rate (trimmed).
    pub name: (&'a str, usize),
    pub frame_rate: (&'a str, usize),
    pub frame_count: (&'a str, usize),
}

/// Splits a header line: the version from the front, frame rate and count from the END (a
/// Greta name contains spaces). `Err` carries the offset and what was expected there.
pub(crate) fn header_fields(
    line: &str,
) -> std::result::Result<HeaderFields<'_>, (usize, &'static str)> {
    const WHAT: &str = "a header `<version> <name> <frame_rate> <frame_count>`";
    let off = |s: &str| s.as_ptr() as usize - line.as_ptr() as usize;
    let (after_version, version) = preceded(blanks, token)
        .parse(line)
        .map_err(|_| (off(line.trim_start()), WHAT))?;
    let body = after_version.trim_end_matches([' ', '\t']);
    if body.trim_start().is_empty() {
        return Err((off(version), WHAT));
    }
    let (before_count, count) = split_last_token(body).ok_or((line.len(), "a frame count"))?;
    let (before_rate, rate) = split_last_token(before_count)
        .ok_or((off(count), "a frame rate before the frame count"))?;
    let name = before_rate.trim_matches([' ', '\t']);
    if name.is_empty() {
        return Err((off(rate), "a name between the version and the frame rate"));
    }
    Ok(HeaderFields {
        version: (version, off(version)),
        name: (name, off(name)),
        frame_rate: (rate, off(rate)),
        frame_count: (count, off(count)),
    })
}

/// The last blank-separated token of `s` (which has no trailing blanks) and what precedes it.
fn split_last_token(s: &str) -> Option<(&str, &str)> {
    if s.is_empty() {
        return None;
    }
    let start = s.rfind([' ', '\t']).map_or(0, |p| p + 1);
    let before = &s[..start];
    // Without a blank before it the token is the whole remaining text; the caller then finds
    // nothing for the next field.
    Some((before.trim_end_matches([' ', '\t']), &s[start..]))
}

// ---------------------------------------------------------------------------------------------
// The reader
// ---------------------------------------------------------------------------------------------

/// The tolerated deviations, one warning (plus a count) each in lenient mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Deviation {
    VersionNotNumber,
    NameWithBlanks,
    CountTooLarge,
    CountMismatch,
    LongMask,
    SingleViseme,
    SingleExpression,
    ExtraValues,
    NegativeUnidirectional,
}

const DEVIATIONS: usize = 9;

struct Line<'a> {
    text: &'a str,
    /// 1-based line number.
    number: usize,
}

struct Warn {
    kind: Deviation,
    diag: Diagnostic,
}

struct Reader<'a> {
    text: &'a str,
    file: &'a Path,
    opts: &'a ReadOptions,
    pos: usize,
    line_no: usize,
    warnings: Vec<Warn>,
    counts: [usize; DEVIATIONS],
}

impl<'a> Reader<'a> {
    fn new(text: &'a str, file: &'a Path, opts: &'a ReadOptions) -> Self {
        Reader {
            text,
            file,
            opts,
            pos: 0,
            line_no: 0,
            warnings: Vec::new(),
            counts: [0; DEVIATIONS],
        }
    }

    fn location(&self, line: &Line<'_>, offset: usize) -> Location {
        let offset = offset.min(line.text.len());
        let before = &line.text.as_bytes()[..offset];
        Location {
            file: self.file.to_path_buf(),
            line: line.number,
            column: before.iter().filter(|&&b| (b & 0xC0) != 0x80).count() + 1,
        }
    }

    fn error(&self, line: &Line<'_>, offset: usize, expected: impl Into<String>) -> ParseError {
        let offset = floor_boundary(line.text, offset.min(line.text.len()));
        let tail = &line.text[offset..];
        let found = if tail.trim().is_empty() {
            Some("end of line".to_string())
        } else {
            let t: String = tail
                .trim_start_matches([' ', '\t'])
                .split([' ', '\t'])
                .next()
                .unwrap_or("")
                .chars()
                .take(40)
                .collect();
            Some(t)
        };
        ParseError {
            location: self.location(line, offset),
            expected: expected.into(),
            found,
        }
    }

    fn end_of_input(&self, expected: impl Into<String>) -> ParseError {
        ParseError {
            location: Location::from_offset(self.file, self.text, self.text.len()),
            expected: expected.into(),
            found: None,
        }
    }

    /// A tolerated deviation: an error in strict mode, a (deduplicated) warning otherwise.
    fn deviate(
        &mut self,
        kind: Deviation,
        line: &Line<'_>,
        offset: usize,
        expected: &str,
        warning: impl FnOnce() -> String,
    ) -> std::result::Result<(), ParseError> {
        if self.opts.mode == ReadMode::Strict {
            return Err(self.error(line, offset, expected));
        }
        let n = &mut self.counts[kind as usize];
        *n += 1;
        if *n <= self.opts.max_warnings_per_kind.max(1) {
            let diag = Diagnostic {
                severity: Severity::Warning,
                location: Some(self.location(line, offset)),
                message: warning(),
            };
            self.warnings.push(Warn { kind, diag });
        }
        Ok(())
    }

    fn finish_warnings(&mut self) -> Vec<Diagnostic> {
        let keep = self.opts.max_warnings_per_kind.max(1);
        let counts = self.counts;
        let mut out: Vec<Diagnostic> = Vec::with_capacity(self.warnings.len());
        let mut seen = [false; DEVIATIONS];
        for w in self.warnings.drain(..) {
            let mut d = w.diag;
            let k = w.kind as usize;
            if !seen[k] && counts[k] > keep {
                d.message
                    .push_str(&format!(" ({} more like this)", counts[k] - keep));
            }
            seen[k] = true;
            out.push(d);
        }
        out
    }

    /// The next line that is neither a comment nor blank.
    fn next_content_line(&mut self) -> Option<Line<'a>> {
        while let Some((content, next)) = next_line(self.text, self.pos) {
            self.pos = next;
            self.line_no += 1;
            if comment(content).is_ok() || line_end(content).is_ok() {
                continue;
            }
            return Some(Line {
                text: content,
                number: self.line_no,
            });
        }
        None
    }

    fn read(&mut self) -> std::result::Result<FapStream, ParseError> {
        let Some(header) = self.next_content_line() else {
            return Err(
                self.end_of_input("a header line `<version> <name> <frame_rate> <frame_count>`")
            );
        };
        let (version, name, frame_rate, declared) = self.read_header(&header)?;
        let cap = declared
            .unwrap_or(0)
            .min((self.text.len() / MIN_FRAME_BYTES) as u64) as usize;
        let mut frames: Vec<FapFrame> = Vec::with_capacity(cap);
        while let Some(mask_line) = self.next_content_line() {
            let mask = self.read_mask(&mask_line)?;
            let Some(value_line) = self.next_content_line() else {
                return Err(self.end_of_input(format!(
                    "the value line of the frame whose mask is on line {}",
                    mask_line.number
                )));
            };
            let previous = frames.last().map(|f| f.number);
            frames.push(self.read_values(&value_line, mask, previous)?);
        }
        if let Some(n) = declared {
            if n != frames.len() as u64 {
                let present = frames.len();
                self.deviate(
                    Deviation::CountMismatch,
                    &header,
                    header_count_offset(header.text),
                    &format!("a frame count equal to the {present} frames present"),
                    || {
                        format!(
                            "header declares {n} frames but {present} are present; \
                             the {present} frames present are used"
                        )
                    },
                )?;
            }
        }
        Ok(FapStream {
            version: version.to_string(),
            name: name.to_string(),
            frame_rate,
            frames,
        })
    }

    /// Returns version, name, frame rate and the declared count (`None` when ignored).
    #[allow(clippy::type_complexity)]
    fn read_header(
        &mut self,
        line: &Line<'a>,
    ) -> std::result::Result<(&'a str, &'a str, f64, Option<u64>), ParseError> {
        let h = header_fields(line.text).map_err(|(off, what)| self.error(line, off, what))?;
        let (version, voff) = h.version;
        if !is_version(version) {
            self.deviate(
                Deviation::VersionNotNumber,
                line,
                voff,
                "a version number such as 2.1",
                || format!("version `{version}` is not a number such as 2.1; kept as written"),
            )?;
        }
        let (name, noff) = h.name;
        if let Some(blank) = name.find([' ', '\t']) {
            let (_, rate_off) = h.frame_rate;
            let at = if self.opts.mode == ReadMode::Strict {
                // What a strict reader sees: the second word of the name where the rate belongs.
                noff + blank + (name[blank..].len() - name[blank..].trim_start().len())
            } else {
                noff
            };
            let _ = rate_off;
            self.deviate(
                Deviation::NameWithBlanks,
                line,
                at,
                "the frame rate (the name must be one token without spaces)",
                || format!("name `{name}` contains spaces; read it up to the frame rate"),
            )?;
        }
        let (rate_tok, roff) = h.frame_rate;
        let frame_rate = match parse_f64(rate_tok) {
            Some(r) if r.is_finite() && r > 0.0 && r <= super::model::MAX_FRAME_RATE => r,
            _ => {
                return Err(self.error(
                    line,
                    roff,
                    format!(
                        "a frame rate (a number > 0 and <= {})",
                        super::model::MAX_FRAME_RATE
                    ),
                ))
            }
        };
        let (count_tok, coff) = h.frame_count;
        let declared = match uint(count_tok) {
            Ok((_, n)) if n <= MAX_DECLARED_FRAMES => Some(n),
            Ok(_) => {
                self.deviate(
                    Deviation::CountTooLarge,
                    line,
                    coff,
                    &format!("a frame count <= {MAX_DECLARED_FRAMES}"),
                    || {
                        format!(
                            "frame count {count_tok} is implausibly large; \
                             ignored, the frames present are read"
                        )
                    },
                )?;
                None
            }
            Err(_) => {
                let what = if count_tok.len() > 19 && count_tok.bytes().all(|b| b.is_ascii_digit())
                {
                    format!("a frame count <= {MAX_DECLARED_FRAMES}")
                } else {
                    "a frame count (a non-negative integer)".to_string()
                };
                if count_tok.bytes().all(|b| b.is_ascii_digit()) {
                    // Digits overflowing u64: same treatment as too large.
                    self.deviate(Deviation::CountTooLarge, line, coff, &what, || {
                        "frame count is implausibly large; ignored, the frames present are read"
                            .to_string()
                    })?;
                    None
                } else {
                    return Err(self.error(line, coff, what));
                }
            }
        };
        Ok((version, name, frame_rate, declared))
    }

    fn read_mask(&mut self, line: &Line<'_>) -> std::result::Result<FapMask, ParseError> {
        if let Some(mask) = canonical_mask(line.text) {
            return Ok(mask);
        }
        let off = |s: &str| line.text.len() - s.len();
        let mut bits: u128 = 0;
        let mut i = line.text;
        for k in 0..NUM_FAPS {
            let (after, _) = blanks(i).unwrap_or((i, ""));
            if after.is_empty() {
                return Err(self.error(
                    line,
                    off(after),
                    format!("{NUM_FAPS} mask entries (0 or 1), only {k} on this line"),
                ));
            }
            match mask_entry(after) {
                Ok((next, bit)) => {
                    bits |= u128::from(bit) << k;
                    i = next;
                }
                Err(_) => return Err(self.error(line, off(after), "a mask entry (0 or 1)")),
            }
        }
        let (after, _) = blanks(i).unwrap_or((i, ""));
        if !after.is_empty() {
            let at = off(after);
            // Lenient: the extra entries must still look like mask entries.
            let mut j = after;
            let mut extra = 0usize;
            loop {
                let (a, _) = blanks(j).unwrap_or((j, ""));
                if a.is_empty() {
                    break;
                }
                match mask_entry(a) {
                    Ok((next, _)) => {
                        extra += 1;
                        j = next;
                    }
                    Err(_) if self.opts.mode == ReadMode::Lenient => {
                        return Err(self.error(line, off(a), "a mask entry (0 or 1)"))
                    }
                    Err(_) => break,
                }
            }
            self.deviate(
                Deviation::LongMask,
                line,
                at,
                &format!("end of line after {NUM_FAPS} mask entries"),
                || {
                    format!(
                        "mask line has {} entries; the {extra} after the {NUM_FAPS}th are ignored",
                        NUM_FAPS + extra
                    )
                },
            )?;
        }
        Ok(FapMask::from_bits(bits))
    }

    fn read_values(
        &mut self,
        line: &Line<'_>,
        mask: FapMask,
        previous: Option<u64>,
    ) -> std::result::Result<FapFrame, ParseError> {
        let off = |s: &str| line.text.len() - s.len();
        let (i, _) = blanks(line.text).unwrap_or((line.text, ""));
        let (mut i, frame_no) = match uint(i) {
            Ok(x) => x,
            Err(_) => {
                return Err(self.error(line, off(i), "a frame number (a non-negative integer)"))
            }
        };
        if let Some(p) = previous {
            if frame_no <= p {
                return Err(self.error(
                    line,
                    off(line.text.trim_start()),
                    format!("a frame number greater than the previous one ({p})"),
                ));
            }
        }
        let want_v = mask.contains(FapId::VISEME);
        let want_e = mask.contains(FapId::EXPRESSION);
        let low = mask.low_level_len();
        // Decide the layout of FAP 1/2 from the token count, only when they are present.
        let (single_v, single_e) = if want_v || want_e {
            let n = i.split_ascii_whitespace().count();
            let v = if want_v { 4 } else { 0 };
            let e = if want_e { 6 } else { 0 };
            if n == v + e + low || self.opts.mode == ReadMode::Strict {
                (false, false)
            } else if want_v && n == 1 + e + low {
                (true, false)
            } else if want_e && n == v + 1 + low {
                (false, true)
            } else if want_v && want_e && n == 2 + low {
                (true, true)
            } else {
                (false, false)
            }
        } else {
            (false, false)
        };

        let mut viseme = None;
        if want_v {
            if single_v {
                let (j, _) = blanks(i).unwrap_or((i, ""));
                self.deviate(
                    Deviation::SingleViseme,
                    line,
                    off(j),
                    "four viseme fields `select1 select2 blend def`",
                    || {
                        "FAP 1 has a single value; read as viseme_select1 with blend 63 \
                         (select2 0, def 0)"
                            .to_string()
                    },
                )?;
                let (j, s1) = self.field(line, i, "viseme_select1 (0..=14)", 14)?;
                i = j;
                viseme = Some(VisemeParams {
                    select1: viseme_of(s1),
                    select2: viseme_of(0),
                    blend: VisemeParams::MAX_BLEND,
                    def: false,
                });
            } else {
                let (j, s1) = self.field(line, i, "viseme_select1 (0..=14)", 14)?;
                let (j, s2) = self.field(line, j, "viseme_select2 (0..=14)", 14)?;
                let (j, blend) = self.field(line, j, "viseme_blend (0..=63)", 63)?;
                let (j, def) = self.field(line, j, "viseme_def (0 or 1)", 1)?;
                i = j;
                viseme = Some(VisemeParams {
                    select1: viseme_of(s1),
                    select2: viseme_of(s2),
                    blend,
                    def: def == 1,
                });
            }
        }
        let mut expression = None;
        if want_e {
            if single_e {
                let (j, _) = blanks(i).unwrap_or((i, ""));
                self.deviate(
                    Deviation::SingleExpression,
                    line,
                    off(j),
                    "six expression fields `select1 intensity1 select2 intensity2 init_face def`",
                    || {
                        "FAP 2 has a single value; read as expression_select1 with intensity 63 \
                         (second expression neutral, bits 0)"
                            .to_string()
                    },
                )?;
                let (j, s1) = self.field(line, i, "expression_select1 (0..=6)", 6)?;
                i = j;
                expression = Some(ExpressionParams {
                    select1: expression_of(s1),
                    intensity1: ExpressionParams::MAX_INTENSITY,
                    ..ExpressionParams::NEUTRAL
                });
            } else {
                let (j, s1) = self.field(line, i, "expression_select1 (0..=6)", 6)?;
                let (j, i1) = self.field(line, j, "expression_intensity1 (0..=63)", 63)?;
                let (j, s2) = self.field(line, j, "expression_select2 (0..=6)", 6)?;
                let (j, i2) = self.field(line, j, "expression_intensity2 (0..=63)", 63)?;
                let (j, init) = self.field(line, j, "init_face (0 or 1)", 1)?;
                let (j, def) = self.field(line, j, "expression_def (0 or 1)", 1)?;
                i = j;
                expression = Some(ExpressionParams {
                    select1: expression_of(s1),
                    intensity1: i1,
                    select2: expression_of(s2),
                    intensity2: i2,
                    init_face: init == 1,
                    def: def == 1,
                });
            }
        }

        let mut values = Vec::with_capacity(low);
        for fap in mask.iter().filter(|f| !f.is_high_level()) {
            let (j, _) = blanks(i).unwrap_or((i, ""));
            let Ok((after, v)) = number(j) else {
                return Err(self.error(
                    line,
                    off(j),
                    format!("a value for FAP {fap} ({})", fap.name()),
                ));
            };
            if !(v.is_finite() && v.abs() <= super::model::MAX_ABS_FAP_VALUE) {
                return Err(self.error(
                    line,
                    off(j),
                    format!(
                        "a finite value within ±{:e} for FAP {fap} ({})",
                        super::model::MAX_ABS_FAP_VALUE,
                        fap.name()
                    ),
                ));
            }
            if !fap.info().accepts(v) {
                self.deviate(
                    Deviation::NegativeUnidirectional,
                    line,
                    off(j),
                    &format!("a value >= 0 for unidirectional FAP {fap} ({})", fap.name()),
                    || {
                        format!(
                            "unidirectional FAP {fap} ({}) has negative value {v}; kept as written",
                            fap.name()
                        )
                    },
                )?;
            }
            values.push(v);
            i = after;
        }
        let (j, _) = blanks(i).unwrap_or((i, ""));
        if !j.is_empty() {
            let count = mask.len();
            self.deviate(
                Deviation::ExtraValues,
                line,
                off(j),
                &format!("end of line after the values of the {count} masked FAPs"),
                || "value line has more values than its mask; the extra ones are ignored".into(),
            )?;
        }
        FapFrame::from_parts(frame_no, mask, values, viseme, expression)
            .ok_or_else(|| self.error(line, 0, "a value line matching its mask"))
    }

    /// One FAP 1/2 field: an integer in `0..=max`.
    fn field<'s>(
        &self,
        line: &Line<'_>,
        i: &'s str,
        what: &str,
        max: u8,
    ) -> std::result::Result<(&'s str, u8), ParseError> {
        let (j, _) = blanks(i).unwrap_or((i, ""));
        match uint(j) {
            Ok((after, n)) if n <= u64::from(max) => Ok((after, n as u8)),
            _ => Err(self.error(line, line.text.len() - j.len(), what)),
        }
    }
}

/// Fast path for the common layout: exactly 68 entries separated by single spaces (trailing
/// blanks allowed). Anything else goes through the general combinators.
pub(crate) fn canonical_mask(line: &str) -> Option<FapMask> {
    let b = line.trim_end_matches([' ', '\t']).as_bytes();
    if b.len() != 2 * NUM_FAPS - 1 {
        return None;
    }
    let mut bits: u128 = 0;
    for (k, pair) in b.chunks(2).enumerate() {
        match pair {
            [b'0', b' '] | [b'0'] => {}
            [b'1', b' '] | [b'1'] => bits |= 1u128 << k,
            _ => return None,
        }
    }
    Some(FapMask::from_bits(bits))
}

fn viseme_of(n: u8) -> Viseme {
    // `field` bounded n to 0..=14.
    Viseme::new(n).unwrap_or(VisemeParams::NEUTRAL.select1)
}

fn expression_of(n: u8) -> Expression {
    Expression::new(n).unwrap_or(Expression::Neutral)
}

fn is_version(s: &str) -> bool {
    match s.split_once('.') {
        Some((a, b)) => {
            !a.is_empty()
                && !b.is_empty()
                && a.bytes().all(|c| c.is_ascii_digit())
                && b.bytes().all(|c| c.is_ascii_digit())
        }
        None => false,
    }
}

fn header_count_offset(line: &str) -> usize {
    header_fields(line).map_or(0, |h| h.frame_count.1)
}

fn floor_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: &str = "t.fap";

    fn mask_of(faps: &[u8]) -> String {
        faps.iter()
            .filter_map(|&n| FapId::new(n))
            .collect::<FapMask>()
            .to_string()
    }

    fn strict(text: &str) -> Result<(FapStream, Vec<Diagnostic>)> {
        parse_fap(text, Path::new(P), &ReadOptions::strict())
    }

    fn lenient(text: &str) -> Result<(FapStream, Vec<Diagnostic>)> {
        parse_fap(text, Path::new(P), &ReadOptions::lenient())
    }

    fn err(text: &str) -> String {
        strict(text).unwrap_err().to_string()
    }

    #[test]
    fn combinator_blanks_and_token() {
        assert_eq!(blanks(" \t x"), Ok(("x", " \t ")));
        assert_eq!(token("ab c"), Ok((" c", "ab")));
        assert!(token(" ab").is_err());
        assert!(token("").is_err());
    }

    #[test]
    fn combinator_line_end_and_comment() {
        assert!(line_end("  ").is_ok());
        assert!(line_end("").is_ok());
        assert!(line_end(" x").is_err());
        assert_eq!(comment("  # hi").map(|r| r.1), Ok(" hi"));
        assert!(comment("2.1 # x").is_err());
    }

    #[test]
    fn combinator_mask_entry() {
        assert_eq!(mask_entry("1 0"), Ok((" 0", true)));
        assert_eq!(mask_entry("0"), Ok(("", false)));
        assert!(mask_entry("01").is_err());
        assert!(mask_entry("1.0").is_err());
        assert!(mask_entry("2").is_err());
    }

    #[test]
    fn combinator_uint_and_number() {
        assert_eq!(uint("42 x"), Ok((" x", 42)));
        assert!(uint("4a").is_err());
        assert!(uint("-4").is_err());
        assert!(uint("99999999999999999999999").is_err());
        assert_eq!(number("-43 1"), Ok((" 1", -43.0)));
        assert_eq!(number("1.5"), Ok(("", 1.5)));
        assert_eq!(number("1e3"), Ok(("", 1000.0)));
        assert!(number("NaN").unwrap().1.is_nan());
        assert!(number("abc").is_err());
        assert_eq!(parse_f64("-0"), Some(-0.0));
        assert_eq!(parse_f64("123456789012345"), Some(123456789012345.0));
        assert_eq!(
            parse_f64("1234567890123456789"),
            Some(1234567890123456789.0)
        );
    }

    #[test]
    fn canonical_mask_fast_path() {
        let m = mask_of(&[1, 68]);
        assert_eq!(canonical_mask(&m), Some(FapMask::from_bits(1 | 1 << 67)));
        assert_eq!(canonical_mask(&format!("{m}  ")).map(|m| m.len()), Some(2));
        assert_eq!(canonical_mask(&m.replacen(' ', "\t", 1)), None);
        assert_eq!(canonical_mask(&m.replacen('0', "2", 1)), None);
        assert_eq!(canonical_mask(&format!("{m} 0")), None);
    }

    #[test]
    fn combinator_next_line() {
        let t = "a\r\nb\nc";
        assert_eq!(next_line(t, 0), Some(("a", 3)));
        assert_eq!(next_line(t, 3), Some(("b", 5)));
        assert_eq!(next_line(t, 5), Some(("c", 6)));
        assert_eq!(next_line(t, 6), None);
    }

    #[test]
    fn combinator_header_fields() {
        let h = header_fields("2.1 AU Interpolation_2.fap 25 1 ").unwrap();
        assert_eq!(h.version, ("2.1", 0));
        assert_eq!(h.name, ("AU Interpolation_2.fap", 4));
        assert_eq!(h.frame_rate, ("25", 27));
        assert_eq!(h.frame_count, ("1", 30));
        let h = header_fields(r"2.1 C:\a\b 12.5 3").unwrap();
        assert_eq!(h.name.0, r"C:\a\b");
        assert_eq!(
            header_fields("2.1 25 3").unwrap_err().1,
            "a name between the version and the frame rate"
        );
        assert!(header_fields("2.1").is_err());
        assert!(header_fields("").is_err());
    }

    fn demo() -> String {
        format!(
            "# demo\n2.1 demo 25 3\n{}\n0 200 300 300\n{}\n1 3 10 42 0 150\n{}\n2 1 40 6 20 0 0 -8000\n",
            mask_of(&[3, 19, 20]),
            mask_of(&[1, 3]),
            mask_of(&[2, 48])
        )
    }

    #[test]
    fn reads_the_spec_example() {
        let (s, w) = strict(&demo()).unwrap();
        assert!(w.is_empty());
        assert_eq!(s.version, "2.1");
        assert_eq!(s.frame_rate, 25.0);
        assert_eq!(s.frames.len(), 3);
        let f1 = &s.frames[1];
        let v = f1.viseme().unwrap();
        assert_eq!(
            (v.select1.number(), v.select2.number(), v.blend, v.def),
            (3, 10, 42, false)
        );
        assert_eq!(f1.value(FapId::OPEN_JAW), Some(150.0));
        let e = s.frames[2].expression().unwrap();
        assert_eq!(
            (e.select1, e.intensity1, e.select2, e.intensity2),
            (Expression::Joy, 40, Expression::Surprise, 20)
        );
        assert_eq!(s.frames[2].value(FapId::new(48).unwrap()), Some(-8000.0));
    }

    #[test]
    fn crlf_trailing_spaces_comments_and_skipped_frames() {
        let m = mask_of(&[3]);
        let t = format!("2.1 x 25 2 \r\n# c\r\n{m} \r\n0 5 \r\n\r\n  # again\r\n{m}\r\n7 6\r\n");
        let (s, w) = strict(&t).unwrap();
        assert!(w.is_empty());
        assert_eq!(
            s.frames.iter().map(|f| f.number).collect::<Vec<_>>(),
            [0, 7]
        );
    }

    #[test]
    fn located_errors() {
        let m = mask_of(&[3]);
        assert_eq!(err(""), "t.fap:1:1: expected a header line `<version> <name> <frame_rate> <frame_count>`, found end of input");
        assert_eq!(
            err("2.1 x 0 1\n"),
            "t.fap:1:7: expected a frame rate (a number > 0 and <= 1000), found `0`"
        );
        assert_eq!(
            err("2.1 x -25 1\n"),
            "t.fap:1:7: expected a frame rate (a number > 0 and <= 1000), found `-25`"
        );
        assert_eq!(
            err("2.1 x NaN 1\n"),
            "t.fap:1:7: expected a frame rate (a number > 0 and <= 1000), found `NaN`"
        );
        assert_eq!(
            err("2.1 x 25 1.5\n"),
            "t.fap:1:10: expected a frame count (a non-negative integer), found `1.5`"
        );
        assert_eq!(
            err("2.1 x 25 1000000000000\n"),
            "t.fap:1:10: expected a frame count <= 4294967295, found `1000000000000`"
        );
        assert_eq!(err(&format!("2.1 x 25 1\n{m}\n")), "t.fap:3:1: expected the value line of the frame whose mask is on line 2, found end of input");
        assert_eq!(
            err(&format!("2.1 x 25 1\n{m}\n0 inf\n")),
            "t.fap:3:3: expected a finite value within ±1e9 for FAP 3 (open_jaw), found `inf`"
        );
        assert_eq!(
            err(&format!("2.1 x 25 1\n{m}\n0\n")),
            "t.fap:3:2: expected a value for FAP 3 (open_jaw), found `end of line`"
        );
        assert_eq!(
            err(&format!("2.1 x 25 2\n{m}\n3 1\n{m}\n3 1\n")),
            "t.fap:5:1: expected a frame number greater than the previous one (3), found `3`"
        );
        assert_eq!(
            err(&format!("2.1 x 25 1\n{m}\n0 -1\n")),
            "t.fap:3:3: expected a value >= 0 for unidirectional FAP 3 (open_jaw), found `-1`"
        );
        assert_eq!(
            err("2.1 x 25 1\n0 1 2\n"),
            "t.fap:2:5: expected a mask entry (0 or 1), found `2`"
        );
        assert_eq!(err("2.1 x 25 1\n0 1\n"), "t.fap:2:4: expected 68 mask entries (0 or 1), only 2 on this line, found `end of line`");
        assert_eq!(
            err(&format!("2.1 x 25 2\n{m}\n0 1\n")),
            "t.fap:1:10: expected a frame count equal to the 1 frames present, found `2`"
        );
        assert_eq!(
            err(&format!("2.1 x 25 1\n{m}\n0 1 2\n")),
            "t.fap:3:5: expected end of line after the values of the 1 masked FAPs, found `2`"
        );
        let v = mask_of(&[1]);
        assert_eq!(
            err(&format!("2.1 x 25 1\n{v}\n0 15 0 0 0\n")),
            "t.fap:3:3: expected viseme_select1 (0..=14), found `15`"
        );
        assert_eq!(
            err(&format!("2.1 x 25 1\n{v}\n0 1 0 64 0\n")),
            "t.fap:3:7: expected viseme_blend (0..=63), found `64`"
        );
        let e = mask_of(&[2]);
        assert_eq!(
            err(&format!("2.1 x 25 1\n{e}\n0 7 0 0 0 0 0\n")),
            "t.fap:3:3: expected expression_select1 (0..=6), found `7`"
        );
        assert_eq!(
            err(&format!("2.1 x 25 1\n{e}\n0 1 0 0 0 2 0\n")),
            "t.fap:3:11: expected init_face (0 or 1), found `2`"
        );
        assert_eq!(err("\u{0}\u{1}garbage\u{7f}"), "t.fap:1:1: expected a header `<version> <name> <frame_rate> <frame_count>`, found `\u{0}\u{1}garbage\u{7f}`");
    }

    #[test]
    fn lenient_reads_deviations_with_one_warning_each() {
        let m69 = format!("{} 0", mask_of(&[1, 3]));
        let t = format!("2.1 my name 25 5\n{m69}\n0 4 7\n{m69}\n1 5 0 63 0 8 9\n");
        let (s, w) = lenient(&t).unwrap();
        assert_eq!(s.name, "my name");
        assert_eq!(s.frames.len(), 2);
        assert_eq!(s.frames[0].viseme().unwrap().select1.number(), 4);
        assert_eq!(s.frames[0].viseme().unwrap().blend, 63);
        assert_eq!(s.frames[1].value(FapId::OPEN_JAW), Some(8.0));
        let msgs: Vec<String> = w.iter().map(|d| d.to_string()).collect();
        assert_eq!(msgs, [
            "t.fap:1:5: warning: name `my name` contains spaces; read it up to the frame rate",
            "t.fap:2:137: warning: mask line has 69 entries; the 1 after the 68th are ignored (1 more like this)",
            "t.fap:3:3: warning: FAP 1 has a single value; read as viseme_select1 with blend 63 (select2 0, def 0)",
            "t.fap:5:14: warning: value line has more values than its mask; the extra ones are ignored",
            "t.fap:1:16: warning: header declares 5 frames but 2 are present; the 2 frames present are used",
        ], "{msgs:#?}");
        // The same text is rejected in strict mode at the first deviation.
        assert_eq!(err(&t), "t.fap:1:8: expected the frame rate (the name must be one token without spaces), found `name`");
        // Validation lists them all as errors.
        let all = validate_fap_str(&t, Path::new(P));
        assert_eq!(all.len(), 6, "both long masks are listed");
        assert!(all.iter().all(|d| d.severity == Severity::Error));
    }

    #[test]
    fn lenient_huge_count_reads_what_is_there() {
        let m = mask_of(&[3]);
        let (s, w) = lenient(&format!("2.1 x 25 1000000000000\n{m}\n0 1\n")).unwrap();
        assert_eq!(s.frames.len(), 1);
        assert_eq!(w.len(), 1, "{w:?}");
        let (s, _) = lenient("2.1 x 25 99999999999999999999999999\n").unwrap();
        assert!(s.frames.is_empty());
    }

    #[test]
    fn backslash_name_is_strict_valid() {
        let (s, w) = strict("2.1 C:\\Users\\x\\TempFile 25 0\n").unwrap();
        assert_eq!(s.name, "C:\\Users\\x\\TempFile");
        assert!(w.is_empty());
    }

    #[test]
    fn validate_reports_fatal_error_after_warnings() {
        let t = format!("2.1 a b 25 1\n{}\n0 x\n", mask_of(&[3]));
        let all = validate_fap_str(&t, Path::new(P));
        let msgs: Vec<String> = all.iter().map(|d| d.to_string()).collect();
        assert_eq!(
            msgs,
            [
                "t.fap:1:5: error: name `a b` contains spaces; read it up to the frame rate",
                "t.fap:3:3: error: expected a value for FAP 3 (open_jaw), found `x`",
            ]
        );
    }
}
