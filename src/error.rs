//! Errors and diagnostics shared by every reader and writer.
//!
//! A [`ParseError`] always names the file, the 1-based line and column, and what was expected,
//! so a user can jump straight to the problem. Lenient readers collect [`Diagnostic`]s (warnings)
//! with the same location information instead of failing.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::Serialize;

/// A place in a text input: file name (or `<input>` for in-memory text), 1-based line and column.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Location {
    /// File the text came from (`<input>` when parsed from memory).
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, counted in characters.
    pub column: usize,
}

impl Location {
    /// Location of byte `offset` inside `text` (clamped to the text's length; an offset inside a
    /// multi-byte character counts as that character).
    pub fn from_offset(file: &Path, text: &str, offset: usize) -> Location {
        let offset = offset.min(text.len());
        let before = &text.as_bytes()[..offset];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1);
        // Count characters, not bytes; a partial UTF-8 sequence counts as one.
        let column = before[line_start..]
            .iter()
            .filter(|&&b| (b & 0xC0) != 0x80)
            .count()
            + 1;
        Location {
            file: file.to_path_buf(),
            line,
            column,
        }
    }

    /// Location of the suffix `rest` of `text` (for parsers that hand back the unparsed rest).
    pub fn from_rest(file: &Path, text: &str, rest: &str) -> Location {
        Location::from_offset(file, text, text.len().saturating_sub(rest.len()))
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file.display(), self.line, self.column)
    }
}

/// A syntax or content error in an input file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, thiserror::Error)]
#[error("{location}: expected {expected}{}", found_suffix(.found))]
pub struct ParseError {
    /// Where the problem is.
    pub location: Location,
    /// What the grammar or the standard expected there, e.g. `a frame count >= 0`.
    pub expected: String,
    /// What was there instead, shortened for display; `None` at end of input.
    pub found: Option<String>,
}

fn found_suffix(found: &Option<String>) -> String {
    match found {
        Some(f) => format!(", found `{f}`"),
        None => ", found end of input".to_string(),
    }
}

impl ParseError {
    /// An error at byte `offset` of `text`; `found` is taken from the text at that point.
    pub fn at_offset(file: &Path, text: &str, offset: usize, expected: impl Into<String>) -> Self {
        let offset = offset.min(text.len());
        ParseError {
            location: Location::from_offset(file, text, offset),
            expected: expected.into(),
            found: snippet(&text[floor_char_boundary(text, offset)..]),
        }
    }

    /// An error at the start of the suffix `rest` of `text`.
    pub fn at_rest(file: &Path, text: &str, rest: &str, expected: impl Into<String>) -> Self {
        Self::at_offset(file, text, text.len().saturating_sub(rest.len()), expected)
    }
}

fn floor_char_boundary(text: &str, mut offset: usize) -> usize {
    while offset > 0 && !text.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}

/// The token at the start of `rest`, at most 40 characters, for "found `...`" messages.
pub fn snippet(rest: &str) -> Option<String> {
    let token: String = rest
        .split(['\n', '\r'])
        .next()
        .unwrap_or("")
        .chars()
        .take(40)
        .collect();
    if rest.is_empty() {
        None
    } else if token.trim().is_empty() {
        Some(if rest.starts_with(['\n', '\r']) {
            "end of line".to_string()
        } else {
            token
        })
    } else {
        Some(token)
    }
}

/// Severity of a [`Diagnostic`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// The input deviates from the standard but was read.
    Warning,
    /// The input violates the standard (reported by validators and strict readers).
    Error,
}

/// A located message about an input: a lenient reader's warning or a validator's finding.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    /// How serious.
    pub severity: Severity,
    /// Where (`None` for whole-file findings).
    pub location: Option<Location>,
    /// What is wrong and, where useful, what to do.
    pub message: String,
}

impl Diagnostic {
    /// A warning about the whole input or operation (no location).
    pub fn warning(message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            location: None,
            message: message.into(),
        }
    }

    /// A warning at `location`.
    pub fn warning_at(location: Location, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            location: Some(location),
            message: message.into(),
        }
    }

    /// The message with its location in front, without the severity: what a list that
    /// names the severity once (`warning: …`) prints per entry.
    pub fn located_message(&self) -> String {
        match &self.location {
            Some(loc) => format!("{loc}: {}", self.message),
            None => self.message.clone(),
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sev = match self.severity {
            Severity::Warning => "warning",
            Severity::Error => "error",
        };
        match &self.location {
            Some(loc) => write!(f, "{loc}: {sev}: {}", self.message),
            None => write!(f, "{sev}: {}", self.message),
        }
    }
}

/// A value could not be serialised (JSON, CSV, WAV, ...) for an output: `cannot encode {what}:
/// {message}`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cannot encode {what}: {message}")]
pub struct EncodeError {
    /// What was being encoded, e.g. `JSON` or `frames.json`.
    pub what: String,
    /// The encoder's message.
    pub message: String,
}

impl EncodeError {
    /// An encoding failure of `what` with the encoder's error `e`.
    pub fn new(what: impl Into<String>, e: impl fmt::Display) -> Self {
        EncodeError {
            what: what.into(),
            message: e.to_string(),
        }
    }
}

/// Every error the library returns.
///
/// Each layer has its own error enum ([`crate::fap::FapError`], [`crate::fdp::FdpError`],
/// [`crate::face::FaceError`], ...) whose variants name the domain problem; this enum wraps
/// them transparently, so `?` converts and the message is the layer's own. Callers that care
/// about the kind `match` on the wrapped enum, e.g.
/// `Error::Face(FaceError::NoFat { .. })`. Located syntax errors are [`Error::Parse`].
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The input is not well-formed.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// The requested operation or format is not supported.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// A program or library the operation needs is not installed (e.g. `ffmpeg`,
    /// `espeak-ng`); the message says what to install. An environment problem, not bad
    /// input: exit code 1.
    #[error("{0}")]
    MissingTool(String),
    /// Writing an output failed (the input was fine): exit code 1 whatever the OS said.
    #[error("cannot write {}: {source}", path.display())]
    Output {
        /// The output the user named (never a temporary file).
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// An output path that cannot be used (unknown extension, an input, an occupied folder).
    #[error(transparent)]
    OutputPath(#[from] crate::format::OutputPathError),
    /// A value could not be serialised.
    #[error(transparent)]
    Encode(#[from] EncodeError),
    /// Bad command-line usage the argument parser cannot see (options that need each other
    /// or name the same file).
    #[error("{0}")]
    Usage(String),
    /// FAP streams.
    #[error(transparent)]
    Fap(#[from] crate::fap::FapError),
    /// Feature points, FAP units and landmarks.
    #[error(transparent)]
    Fdp(#[from] crate::fdp::FdpError),
    /// Meshes and OBJ.
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    /// The CANDIDE-3 model.
    #[error(transparent)]
    Candide(#[from] crate::candide::CandideError),
    /// glTF containers and scenes.
    #[error(transparent)]
    Gltf(#[from] crate::gltf::GltfError),
    /// Facial Animation Tables.
    #[error(transparent)]
    Fat(#[from] crate::fat::FatError),
    /// Face models.
    #[error(transparent)]
    Face(#[from] crate::face::FaceError),
    /// Blendshape rigs and the ARKit bridge.
    #[error(transparent)]
    Rig(#[from] crate::rig::RigError),
    /// Speech synthesis.
    #[error(transparent)]
    Speech(#[from] crate::speech::SpeechError),
    /// Cloning (whole-face alignment and assembly).
    #[error(transparent)]
    Clone(#[from] crate::clone::CloneError),
    /// Playing a stream on a face.
    #[error(transparent)]
    Player(#[from] crate::player::PlayerError),
    /// Outputs: glTF, viewer, pictures, videos.
    #[error(transparent)]
    Export(#[from] crate::export::ExportError),
    /// Rendering.
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    /// The demo application.
    #[error(transparent)]
    Demo(#[from] crate::demo::DemoError),
    /// Comparisons and snapshots.
    #[error(transparent)]
    Snapshot(#[from] crate::snapshot::SnapshotError),
    /// An error of a step that works on named files, with the file (or option) it concerns:
    /// a layer's error that cannot know the file (a player limit, a degenerate feature-point
    /// set, a face without skin) reads `playing speech.fap on alma.wrl: …`.
    #[error("{context}: {source}")]
    Context {
        /// What was being done, naming the file or option (`reading stream x.fap`).
        context: String,
        /// The error itself; its exit code is kept.
        source: Box<Error>,
    },
}

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// This error with `context` (naming the file or option it concerns) in front. An error
    /// whose message already names the file (located parse errors, I/O errors) is returned
    /// as it is, so messages never name a file twice.
    pub fn context(self, context: impl Into<String>) -> Self {
        match self {
            Error::Io { .. } | Error::Parse(_) | Error::Output { .. } | Error::Context { .. } => {
                self
            }
            e => Error::Context {
                context: context.into(),
                source: Box::new(e),
            },
        }
    }

    /// A failure writing the output `path`.
    pub fn output(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Output {
            path: path.into(),
            source,
        }
    }

    /// True for errors caused by the input (bad usage/input, exit code 2), false for failures
    /// of the operation itself (exit code 1).
    pub fn is_input_error(&self) -> bool {
        match self {
            Error::Io { source, .. } => matches!(
                source.kind(),
                std::io::ErrorKind::NotFound
                    | std::io::ErrorKind::IsADirectory
                    | std::io::ErrorKind::PermissionDenied
                    | std::io::ErrorKind::InvalidData
                    | std::io::ErrorKind::FileTooLarge
            ),
            Error::Parse(_) | Error::Unsupported(_) => true,
            Error::MissingTool(_) | Error::Output { .. } => false,
            // Content and usage problems: bad input, exit code 2.
            Error::OutputPath(_) | Error::Encode(_) | Error::Usage(_) => true,
            Error::Fap(e) => e.is_input_error(),
            Error::Fdp(e) => e.is_input_error(),
            Error::Mesh(e) => e.is_input_error(),
            Error::Candide(e) => e.is_input_error(),
            Error::Gltf(e) => e.is_input_error(),
            Error::Fat(e) => e.is_input_error(),
            Error::Face(e) => e.is_input_error(),
            Error::Rig(e) => e.is_input_error(),
            Error::Speech(e) => e.is_input_error(),
            Error::Clone(e) => e.is_input_error(),
            Error::Player(e) => e.is_input_error(),
            Error::Export(e) => e.is_input_error(),
            Error::Render(e) => e.is_input_error(),
            Error::Demo(e) => e.is_input_error(),
            Error::Snapshot(e) => e.is_input_error(),
            Error::Context { source, .. } => source.is_input_error(),
        }
    }
}

/// [`Error::context`] on results: `player.map_err(..)` without the closure noise.
pub trait ResultExt<T> {
    /// On error, puts the context `f()` (naming the file or option) in front of it.
    fn with_context(self, f: impl FnOnce() -> String) -> Result<T>;
}

impl<T, E: Into<Error>> ResultExt<T> for std::result::Result<T, E> {
    fn with_context(self, f: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| e.into().context(f()))
    }
}

/// Untrusted text made safe for a terminal: control characters (C0, DEL and C1, which
/// terminals read as escape sequences) become visible escapes such as `\x1b`, `\x07` and
/// `\0`; line feeds and tabs are kept so multi-line reports stay readable. Text without
/// control characters is returned as is, without copying.
pub fn escape_control(text: &str) -> std::borrow::Cow<'_, str> {
    let unsafe_char = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !text.chars().any(unsafe_char) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\0' => out.push_str("\\0"),
            '\r' => out.push_str("\\r"),
            // Every `char::is_control` character is below U+0100.
            c if unsafe_char(c) => out.push_str(&format!("\\x{:02x}", c as u32)),
            c => out.push(c),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// Result with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_errors_convert_keep_their_message_and_classify_as_input() {
        let e: Error = crate::face::FaceError::DuplicateMesh {
            name: "skin".into(),
        }
        .into();
        assert_eq!(e.to_string(), "two meshes are named `skin`");
        assert!(e.is_input_error());
        assert!(matches!(
            e,
            Error::Face(crate::face::FaceError::DuplicateMesh { ref name }) if name == "skin"
        ));
        let e: Error = crate::format::OutputPathError::WouldOverwriteInput {
            path: "a.wrl".into(),
        }
        .into();
        assert_eq!(
            e.to_string(),
            "a.wrl: refusing to write over the input file; choose another output path"
        );
        assert!(e.is_input_error());
        // A wrapped error keeps the file prefix of the file at fault.
        let inner: Error = crate::fdp::FdpError::FapuNotPositive {
            details: "ES0 = 0".into(),
        }
        .into();
        let e: Error = crate::face::FaceError::in_file("fp.csv", inner).into();
        assert!(e
            .to_string()
            .starts_with("fp.csv: cannot compute the FAPUs: ES0 = 0"));
        assert!(!Error::MissingTool("ffmpeg".into()).is_input_error());
    }

    #[test]
    fn clone_errors_are_input_errors_naming_what_is_at_fault() {
        use crate::clone::{CloneError, FitSystemError, RbfFitError};
        let fp = |s: &str| s.parse::<crate::spec::FeaturePointId>().unwrap();
        let cases: Vec<(Error, &str)> = vec![
            (
                CloneError::FeaturePointOutOfRange {
                    side: "target".into(),
                    id: fp("2.1"),
                    vertex: 9,
                    vertices: 4,
                }
                .into(),
                "the target surface: feature point 2.1 names vertex 9 beyond the 4 vertices",
            ),
            (
                CloneError::BadOption {
                    method: "rbf",
                    option: "ray_length_factor",
                    value: -1.0,
                }
                .into(),
                "rbf option ray_length_factor must be a finite non-negative number, got -1",
            ),
            (
                CloneError::RbfFeaturePointFit {
                    correspondences: 3,
                    source: RbfFitError::TooFew { found: 3 },
                }
                .into(),
                "RBF fit from 3 distinct feature-point correspondences failed: RBF fit needs at \
                 least 4 distinct correspondences, got 3",
            ),
            (
                CloneError::FitSystem(FitSystemError::NonFinite).into(),
                "fit: non-finite solution",
            ),
            (
                crate::face::FaceError::TooManySubdivided {
                    face: "alma".into(),
                    rounds: 9,
                    vertices: 100,
                    max: 1000,
                }
                .into(),
                "face `alma`: 9 rounds of subdivision would make over 1000 vertices from 100; \
                 use fewer rounds",
            ),
        ];
        for (e, message) in cases {
            assert_eq!(e.to_string(), message);
            // Bad input: the CLI exits with 2.
            assert!(e.is_input_error(), "{e}");
        }
    }

    #[test]
    fn control_characters_are_escaped() {
        assert!(matches!(
            escape_control("plain\ttext\n"),
            std::borrow::Cow::Borrowed(_)
        ));
        assert_eq!(
            escape_control("a\x1b]0;x\x07\x1b[2J\0\r\u{9b}\x7fz\n"),
            "a\\x1b]0;x\\x07\\x1b[2J\\0\\r\\x9b\\x7fz\n"
        );
    }

    #[test]
    fn location_counts_lines_and_characters() {
        let text = "ab\ncdé\nfg";
        let p = Path::new("x.fap");
        assert_eq!(Location::from_offset(p, text, 0).to_string(), "x.fap:1:1");
        assert_eq!(Location::from_offset(p, text, 3).to_string(), "x.fap:2:1");
        // 'é' is two bytes; 'g' after "\nf" on line 3.
        let g = text.find('g').unwrap();
        assert_eq!(Location::from_offset(p, text, g).to_string(), "x.fap:3:2");
        let after_e = text.find('\n').unwrap() + 1 + "cdé".len();
        assert_eq!(Location::from_offset(p, text, after_e).column, 4);
        // Past the end clamps.
        assert_eq!(Location::from_offset(p, text, 999).line, 3);
    }

    #[test]
    fn parse_error_message_names_everything() {
        let text = "2.1 name 25 x\n";
        let e = ParseError::at_offset(Path::new("a.fap"), text, 12, "a frame count");
        assert_eq!(
            e.to_string(),
            "a.fap:1:13: expected a frame count, found `x`"
        );
        let e = ParseError::at_offset(Path::new("a.fap"), text, text.len(), "a mask line");
        assert_eq!(
            e.to_string(),
            "a.fap:2:1: expected a mask line, found end of input"
        );
        // Offsets inside a multi-byte character do not panic.
        let e = ParseError::at_offset(Path::new("u"), "é", 1, "x");
        assert_eq!(e.location.column, 2);
    }
}
