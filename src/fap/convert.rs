//! Reading and writing a stream by file extension: `.json` is the serde JSON view of
//! [`FapStream`] (frames with named FAP values), anything else is an ASCII `.fap` file.

use std::path::Path;

use super::model::FapStream;
use super::parse::{parse_fap, ReadMode, ReadOptions};
use super::write::write_fap_file;
use super::FapError;
use crate::error::{Diagnostic, EncodeError, Error, Location, ParseError, Result, Severity};

/// Whether `path` names a JSON file (extension `.json`, any case).
pub fn is_json_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// Reads a `.fap` or `.json` stream leniently (what most files in the wild need), the front
/// door beside [`crate::face::read()`]; [`read_with`] chooses the mode and returns the reader's
/// warnings.
///
/// ```
/// let stream = fbakit::fap::read("samples/speech.fap")?;
/// assert!(stream.frame_rate > 0.0);
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read(path: impl AsRef<Path>) -> Result<FapStream> {
    Ok(read_stream_file(path, &ReadOptions::lenient())?.0)
}

/// Reads a `.fap` or `.json` stream with `opts`, with the reader's warnings (the same as
/// [`read_stream_file`]).
pub fn read_with(
    path: impl AsRef<Path>,
    opts: &ReadOptions,
) -> Result<(FapStream, Vec<Diagnostic>)> {
    read_stream_file(path, opts)
}

/// Reads a `.fap` or `.json` stream. JSON input is checked like `.fap` input: frame rate and
/// frame order are errors; negative unidirectional values are errors in strict mode and
/// unlocated warnings in lenient mode.
///
/// ```
/// use fbakit::fap::{read_stream_file, ReadOptions};
/// let (stream, warnings) = read_stream_file("samples/speech.fap", &ReadOptions::lenient())?;
/// assert!(stream.frame_rate > 0.0);
/// for w in &warnings {
///     eprintln!("{w}"); // located: file:line:column: warning: ...
/// }
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read_stream_file(
    path: impl AsRef<Path>,
    opts: &ReadOptions,
) -> Result<(FapStream, Vec<Diagnostic>)> {
    let path = path.as_ref();
    let text = crate::io::read_text(path)?;
    if !is_json_path(path) {
        return parse_fap(&text, path, opts);
    }
    let stream: FapStream = serde_json::from_str(&text).map_err(|e| {
        Error::Parse(ParseError {
            location: Location {
                file: path.to_path_buf(),
                line: e.line().max(1),
                column: e.column().max(1),
            },
            expected: format!("a FAP stream in JSON ({e})"),
            found: None,
        })
    })?;
    let structural = stream.structural_problems();
    if let Some(p) = structural.first() {
        return Err(content(path, p));
    }
    let values = stream.value_problems();
    if opts.mode == ReadMode::Strict {
        if let Some(p) = values.first() {
            return Err(content(path, p));
        }
    }
    let warnings = values
        .into_iter()
        .map(|message| Diagnostic {
            severity: Severity::Warning,
            location: None,
            message,
        })
        .collect();
    Ok((stream, warnings))
}

fn content(path: &Path, problem: &str) -> Error {
    FapError::Content {
        file: path.to_path_buf(),
        problem: problem.to_string(),
    }
    .into()
}

/// Writes `stream` atomically as JSON (pretty) or canonical `.fap`, by the extension of `path`.
pub fn write_stream_file(path: &Path, stream: &FapStream) -> Result<()> {
    use crate::format::OutputFormat;
    let format = OutputFormat::resolve(
        path,
        &[OutputFormat::Fap, OutputFormat::Json],
        "a FAP stream",
    )?;
    if format == OutputFormat::Json {
        let text = serde_json::to_string_pretty(stream).map_err(|e| EncodeError::new("JSON", e))?;
        crate::io::write_atomic(path, format!("{text}\n").as_bytes())
    } else {
        write_fap_file(path, stream)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fap::FapFrame;
    use crate::spec::FapId;

    #[test]
    fn converts_both_ways() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = FapFrame::new(0);
        f.set(FapId::OPEN_JAW, 12.0);
        let s = FapStream {
            frames: vec![f],
            ..FapStream::new("x", 25.0)
        };
        let j = dir.path().join("a.JSON");
        let p = dir.path().join("a.fap");
        write_stream_file(&j, &s).unwrap();
        assert!(std::fs::read_to_string(&j)
            .unwrap()
            .contains("\"open_jaw\": 12"));
        let (back, _) = read_stream_file(&j, &ReadOptions::strict()).unwrap();
        write_stream_file(&p, &back).unwrap();
        let (again, _) = read_stream_file(&p, &ReadOptions::strict()).unwrap();
        assert_eq!(again, s);
    }

    #[test]
    fn json_errors_are_located_or_named() {
        let dir = tempfile::tempdir().unwrap();
        let j = dir.path().join("b.json");
        std::fs::write(&j, "{\n  \"version\": 2\n}").unwrap();
        let e = read_stream_file(&j, &ReadOptions::lenient())
            .unwrap_err()
            .to_string();
        assert!(e.contains("b.json:2:"), "{e}");
        std::fs::write(
            &j,
            r#"{"version":"2.1","name":"n","frame_rate":25,"frames":[{"number":1},{"number":1}]}"#,
        )
        .unwrap();
        let e = read_stream_file(&j, &ReadOptions::lenient())
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not increase"), "{e}");
        std::fs::write(&j, r#"{"version":"2.1","name":"n","frame_rate":25,"frames":[{"number":1,"faps":{"open_jaw":-3}}]}"#).unwrap();
        assert!(read_stream_file(&j, &ReadOptions::strict()).is_err());
        let (_, w) = read_stream_file(&j, &ReadOptions::lenient()).unwrap();
        assert_eq!(w.len(), 1);
    }
}
