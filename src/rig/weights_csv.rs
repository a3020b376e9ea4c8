//! Blend-shape weight curves as CSV, the form iPhone face-capture apps (Live Link Face)
//! export: a header row, a time column, optionally `BlendShapeCount`, then one column per
//! shape, one row per captured frame.
//!
//! ```text
//! Timecode,BlendShapeCount,EyeBlinkLeft,...,JawOpen,...,HeadYaw,...
//! 10:23:45:12.345,61,0.0412,...,0.2231,...,-0.0120,...
//! ```
//!
//! **Time.** `Timecode` is `HH:MM:SS:FF` with an optional sub-frame fraction (`FF.fff`; `;`
//! is accepted for drop-frame). Its frame rate is not written in the file: it is detected as
//! (largest `FF` + 1) once the seconds roll over within the capture, else taken from the
//! caller's `fps`, else the file is refused. A column named `time`, `Time` or `seconds` gives
//! plain seconds instead. Each row becomes frame `round((t − t₀) × fps)`, where `fps` is the
//! caller's or `1 / median(Δt)`; a row landing on the previous row's frame replaces it (and
//! is counted in a warning), time running backwards is an error.
//!
//! A column `timestamp_ms` gives milliseconds (MediaPipe FaceLandmarker's blend-shape scores
//! written as CSV: `timestamp_ms,_neutral,browDownLeft,...`; the `_neutral` score is not a
//! shape and is skipped like `BlendShapeCount`). Millisecond stamps are whole numbers, so the
//! detected rate snaps to a common video rate whose frame period is within 1 ms of the median
//! step (33, 33, 34 ms → 30 fps).
//!
//! **Weights** are finite numbers; values outside 0..1 are clamped, with one warning naming
//! the count and the first place. The nine Live Link Face rotation columns (`HeadYaw`, ...,
//! [`super::capture::ROTATIONS`]) are angles in radians instead: kept as they are, refused
//! beyond ±2π (degrees written by mistake). Other unknown columns are kept by name; the
//! caller decides what they mean (ARKit shapes, rig shapes, or ignored).
//!
//! Errors name the file and `line:column` of the offending field and what was expected; the
//! reader never panics, and allocates in proportion to the text (never from counts inside it).

use std::path::Path;

use serde::Serialize;

use crate::error::{Diagnostic, ParseError, Result};

/// Most weight columns a file may have.
pub const MAX_COLUMNS: usize = 1024;

/// Highest frame number a row may land on (about 46 hours at 60 fps).
pub const MAX_FRAME_NUMBER: u64 = 10_000_000;

/// Largest angle (radians) a rotation column may hold.
pub const MAX_ROTATION: f64 = std::f64::consts::TAU;

/// What the time column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeColumn {
    /// SMPTE-style `HH:MM:SS:FF[.fff]`.
    Timecode,
    /// Plain seconds.
    Seconds,
    /// Milliseconds (`timestamp_ms`, MediaPipe).
    Milliseconds,
}

/// A weight column of the file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeightColumn {
    /// The header as written (`EyeBlinkLeft`).
    pub name: String,
    /// 1-based column in the file.
    pub column: usize,
}

/// One row: its frame number and a value per [`WeightCsv::columns`] entry (a weight, or an
/// angle in radians for the rotation columns).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeightRow {
    /// Frame number at [`WeightCsv::fps`], 0 for the first row.
    pub frame: u64,
    /// 1-based line in the file.
    pub line: usize,
    /// Weights, clamped to 0..1 (rotation columns: radians, as read).
    pub weights: Vec<f32>,
}

/// A parsed weight CSV.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeightCsv {
    /// The time column's kind.
    pub time: TimeColumn,
    /// Frame rate of [`WeightRow::frame`] (the caller's, or detected).
    pub fps: f64,
    /// Whether `fps` was detected from the times (false: given by the caller).
    pub fps_detected: bool,
    /// Time of the first row in seconds: since midnight for a `Timecode` column (read at the
    /// timecode's own rate; Live Link Face writes the time of day), else the time column in
    /// seconds.
    pub start: f64,
    /// The weight columns (time, `BlendShapeCount` and `_neutral` excluded).
    pub columns: Vec<WeightColumn>,
    /// The rows, frame numbers increasing.
    pub rows: Vec<WeightRow>,
    /// Clamped values and replaced rows, one line each.
    pub warnings: Vec<Diagnostic>,
}

/// Reads a weight CSV file (bounded read); see [`parse_weights_csv`].
pub fn read_weights_csv(path: &Path, fps: Option<f64>) -> Result<WeightCsv> {
    let text = crate::io::read_text(path)?;
    parse_weights_csv(&text, path, fps)
}

/// Reads a weight CSV from `reader` (UTF-8, bounded by
/// [`crate::io::DEFAULT_MAX_INPUT_BYTES`]); `source` names it in messages; see
/// [`parse_weights_csv`].
///
/// ```
/// use std::path::Path;
/// let csv = "time,jawOpen\n0,0\n0.04,0.5\n0.08,1\n";
/// let w = fbakit::rig::weights_csv::read_weights_csv_from(csv.as_bytes(), Path::new("w.csv"), None)?;
/// assert_eq!(w.fps, 25.0);
/// assert_eq!(w.rows.len(), 3);
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read_weights_csv_from<R: std::io::BufRead>(
    reader: R,
    source: &Path,
    fps: Option<f64>,
) -> Result<WeightCsv> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_weights_csv(&text, source, fps)
}

/// One comma-separated field: its text (trimmed, quotes removed) and byte offset.
struct Field<'a> {
    text: &'a str,
    offset: usize,
}

/// Splits one line (without its line feed) starting at byte `start` of the text.
fn split_line(line: &str, start: usize) -> Vec<Field<'_>> {
    let mut out = Vec::new();
    let mut at = 0;
    for part in line.split(',') {
        let lead = part.len() - part.trim_start().len();
        let t = part.trim();
        let t = t
            .strip_prefix('"')
            .and_then(|x| x.strip_suffix('"'))
            .unwrap_or(t);
        out.push(Field {
            text: t,
            offset: start + at + lead,
        });
        at += part.len() + 1;
    }
    out
}

/// A parsed time: whole seconds and, for timecodes, the frame (with fraction) within it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stamp {
    pub(crate) seconds: f64,
    pub(crate) frames: f64,
}

fn parse_timecode(s: &str) -> Option<Stamp> {
    let parts: Vec<&str> = s.split([':', ';']).collect();
    let [h, m, sec, f] = parts.as_slice() else {
        return None;
    };
    let int = |x: &str, max: u64| -> Option<u64> {
        (!x.is_empty() && x.len() <= 6 && x.bytes().all(|b| b.is_ascii_digit()))
            .then(|| x.parse::<u64>().ok())
            .flatten()
            .filter(|&v| v <= max)
    };
    let (h, m, sec) = (int(h, 999_999)?, int(m, 59)?, int(sec, 59)?);
    let (whole, frac) = f.split_once('.').unwrap_or((f, ""));
    let whole = int(whole, 999)?;
    let frac = if frac.is_empty() {
        0.0
    } else if frac.len() <= 9 && frac.bytes().all(|b| b.is_ascii_digit()) {
        format!("0.{frac}").parse::<f64>().ok()?
    } else {
        return None;
    };
    Some(Stamp {
        seconds: (h * 3600 + m * 60 + sec) as f64,
        frames: whole as f64 + frac,
    })
}

/// Parses a weight CSV; `file` names it in errors, `fps` overrides the detected frame rate
/// (and is the timecode rate when the capture never crosses a second). See the module docs.
pub fn parse_weights_csv(text: &str, file: &Path, fps: Option<f64>) -> Result<WeightCsv> {
    let err = |offset: usize, expected: String| -> crate::error::Error {
        ParseError::at_offset(file, text, offset, expected).into()
    };
    if let Some(f) = fps {
        if !(f.is_finite() && f > 0.0 && f <= 1000.0) {
            return Err(super::RigError::CsvFrameRate {
                file: file.to_path_buf(),
                fps: f,
            }
            .into());
        }
    }
    let body_start = if text.starts_with('\u{feff}') { 3 } else { 0 };
    // Lines with their byte offsets, blank ones dropped.
    let mut lines = Vec::new();
    let mut at = body_start;
    for raw in text[body_start..].split('\n') {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        if !line.trim().is_empty() {
            lines.push((at, line));
        }
        at += raw.len() + 1;
    }
    let Some(&(hstart, hline)) = lines.first() else {
        return Err(err(
            body_start,
            "a header row: `Timecode` (or `time` / `seconds`), then one column per blend shape"
                .into(),
        ));
    };
    let header = split_line(hline, hstart);
    if header.len() > MAX_COLUMNS + 2 {
        return Err(err(
            header[MAX_COLUMNS + 2].offset,
            format!("at most {MAX_COLUMNS} weight columns"),
        ));
    }
    let mut time: Option<(usize, TimeColumn)> = None;
    // Per field: the rotation columns keep their angles (not clamped).
    let mut rotation = vec![false; header.len()];
    let mut skip = vec![false; header.len()];
    let mut columns: Vec<WeightColumn> = Vec::new();
    let mut seen = std::collections::HashMap::new();
    for (i, f) in header.iter().enumerate() {
        let lower = f.text.to_ascii_lowercase();
        if f.text.is_empty() {
            return Err(err(f.offset, "a column name".into()));
        }
        let kind = match lower.as_str() {
            "timecode" => Some(TimeColumn::Timecode),
            "time" | "seconds" => Some(TimeColumn::Seconds),
            "timestamp_ms" => Some(TimeColumn::Milliseconds),
            _ => None,
        };
        if let Some(kind) = kind {
            if time.is_some() {
                return Err(err(f.offset, "one time column".into()));
            }
            time = Some((i, kind));
            skip[i] = true;
            continue;
        }
        if lower == "blendshapecount" || lower == "_neutral" {
            skip[i] = true;
            continue;
        }
        let key = super::fap_map::normalise_shape_name(f.text);
        if let Some(prev) = seen.insert(key, i + 1) {
            return Err(err(
                f.offset,
                format!("one column per shape (`{}` repeats column {prev})", f.text),
            ));
        }
        rotation[i] = super::capture::rotation_index(f.text).is_some();
        columns.push(WeightColumn {
            name: f.text.to_string(),
            column: i + 1,
        });
    }
    let Some((time_col, time_kind)) = time else {
        return Err(err(
            hstart,
            "a `Timecode` column (or `time` / `seconds` / `timestamp_ms`) in the header".into(),
        ));
    };

    // Rows: times and clamped weights.
    let mut stamps: Vec<(Stamp, usize)> = Vec::new();
    let mut weights: Vec<(usize, Vec<f32>)> = Vec::new();
    let mut clamped = 0usize;
    let mut first_clamp: Option<(usize, usize, String)> = None;
    for &(start, line) in &lines[1..] {
        let fields = split_line(line, start);
        let lineno = crate::error::Location::from_offset(file, text, start).line;
        if fields.len() != header.len() {
            let at = if fields.len() > header.len() {
                fields[header.len()].offset
            } else {
                start + line.len()
            };
            return Err(err(
                at,
                format!(
                    "{} fields like the header (this row has {})",
                    header.len(),
                    fields.len()
                ),
            ));
        }
        let tf = &fields[time_col];
        let stamp = match time_kind {
            TimeColumn::Timecode => parse_timecode(tf.text),
            TimeColumn::Seconds | TimeColumn::Milliseconds => tf
                .text
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.abs() < 1e9)
                .map(|s| Stamp {
                    seconds: if time_kind == TimeColumn::Milliseconds {
                        s / 1000.0
                    } else {
                        s
                    },
                    frames: 0.0,
                }),
        };
        let Some(stamp) = stamp else {
            return Err(err(
                tf.offset,
                match time_kind {
                    TimeColumn::Timecode => "a timecode HH:MM:SS:FF or HH:MM:SS:FF.fff".into(),
                    TimeColumn::Seconds => "a time in seconds".into(),
                    TimeColumn::Milliseconds => "a time in milliseconds".into(),
                },
            ));
        };
        let mut row = Vec::with_capacity(columns.len());
        for (i, f) in fields.iter().enumerate() {
            if skip[i] {
                continue;
            }
            let v = f
                .text
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(
                        f.offset,
                        format!(
                            "a finite {} in field {} `{}`",
                            if rotation[i] {
                                "angle (a number, radians)"
                            } else {
                                "weight (a number, 0..1)"
                            },
                            i + 1,
                            header[i].text
                        ),
                    )
                })?;
            if rotation[i] {
                if v.abs() > MAX_ROTATION {
                    return Err(err(
                        f.offset,
                        format!(
                            "an angle in radians (-2π..2π) in field {} `{}`",
                            i + 1,
                            header[i].text
                        ),
                    ));
                }
                row.push(v as f32);
                continue;
            }
            if !(0.0..=1.0).contains(&v) {
                clamped += 1;
                if first_clamp.is_none() {
                    first_clamp = Some((lineno, i + 1, header[i].text.to_string()));
                }
            }
            row.push(v.clamp(0.0, 1.0) as f32);
        }
        stamps.push((stamp, start));
        weights.push((lineno, row));
    }
    if stamps.is_empty() {
        return Err(err(
            text.len(),
            "at least one row of weights after the header".into(),
        ));
    }

    let mut warnings = Vec::new();
    if let Some((line, col, name)) = first_clamp {
        warnings.push(Diagnostic::warning(format!(
            "{}: {clamped} weight{} outside 0..1 clamped (first at line {line}, column {col} `{name}`)",
            file.display(),
            if clamped == 1 { "" } else { "s" }
        )));
    }
    let locate =
        |k: usize, expected: String| err(field_offset(text, stamps[k].1, time_col), expected);
    let rows = stamps
        .iter()
        .zip(weights)
        .map(|(&(stamp, _), (line, weights))| RawRow {
            stamp,
            line,
            weights,
        })
        .collect();
    assemble(file, time_kind, fps, columns, rows, &locate, warnings)
}

/// One row as read: its time, 1-based line and values.
pub(crate) struct RawRow {
    pub(crate) stamp: Stamp,
    pub(crate) line: usize,
    pub(crate) weights: Vec<f32>,
}

/// Rows with their times → frames at the caller's or the detected rate (the rules of the
/// module docs), shared by the CSV and JSON-lines readers; `locate(k, expected)` is the
/// located error at row `k`'s time.
pub(crate) fn assemble(
    file: &Path,
    time_kind: TimeColumn,
    fps: Option<f64>,
    columns: Vec<WeightColumn>,
    raw: Vec<RawRow>,
    locate: &dyn Fn(usize, String) -> crate::error::Error,
    mut warnings: Vec<Diagnostic>,
) -> Result<WeightCsv> {
    // Time must not run backwards (checked on the stamps, before any rate is needed).
    for k in 1..raw.len() {
        let (a, b) = (raw[k - 1].stamp, raw[k].stamp);
        if (b.seconds, b.frames) < (a.seconds, a.frames) {
            return Err(locate(
                k,
                format!(
                    "a time no earlier than the previous row's (line {})",
                    raw[k - 1].line
                ),
            ));
        }
    }

    // Times in seconds from the first row.
    let (times, fps_value, detected) = match time_kind {
        TimeColumn::Seconds | TimeColumn::Milliseconds => {
            let t: Vec<f64> = raw.iter().map(|r| r.stamp.seconds).collect();
            let detect = if time_kind == TimeColumn::Milliseconds {
                rate_from_milliseconds
            } else {
                rate_from_times
            };
            let rate = match fps {
                Some(f) => f,
                None => detect(&t).ok_or_else(|| super::RigError::UndetectableRate {
                    file: file.to_path_buf(),
                })?,
            };
            (t, rate, fps.is_none())
        }
        TimeColumn::Timecode => {
            let rolls = raw
                .windows(2)
                .any(|w| w[1].stamp.seconds > w[0].stamp.seconds);
            let tc_rate = if rolls {
                raw.iter()
                    .map(|r| r.stamp.frames.floor())
                    .fold(0.0, f64::max)
                    + 1.0
            } else {
                fps.ok_or_else(|| super::RigError::UndetectableTimecodeRate {
                    file: file.to_path_buf(),
                })?
            };
            let t: Vec<f64> = raw
                .iter()
                .map(|r| r.stamp.seconds + r.stamp.frames / tc_rate)
                .collect();
            let rate = match fps {
                Some(f) => f,
                None => rate_from_times(&t).unwrap_or(tc_rate),
            };
            (t, rate, fps.is_none())
        }
    };
    let t0 = times[0];
    let mut rows: Vec<WeightRow> = Vec::with_capacity(raw.len());
    let mut replaced = 0usize;
    for (k, (r, t)) in raw.into_iter().zip(&times).enumerate() {
        let n = ((t - t0) * fps_value).round();
        if !(0.0..=MAX_FRAME_NUMBER as f64).contains(&n) {
            return Err(locate(
                k,
                format!("a time within {MAX_FRAME_NUMBER} frames of the first row"),
            ));
        }
        let frame = n as u64;
        if let Some(last) = rows.last_mut().filter(|x| x.frame == frame) {
            replaced += 1;
            last.line = r.line;
            last.weights = r.weights;
            continue;
        }
        rows.push(WeightRow {
            frame,
            line: r.line,
            weights: r.weights,
        });
    }
    if replaced > 0 {
        warnings.push(Diagnostic::warning(format!(
            "{}: {replaced} row{} fell on the previous row's frame at {fps_value} fps and replaced it",
            file.display(),
            if replaced == 1 { "" } else { "s" }
        )));
    }
    Ok(WeightCsv {
        time: time_kind,
        fps: fps_value,
        fps_detected: detected,
        start: t0,
        columns,
        rows,
        warnings,
    })
}

/// Byte offset of field `col` of the line starting at `start`.
fn field_offset(text: &str, start: usize, col: usize) -> usize {
    let line = text[start..].split('\n').next().unwrap_or("");
    split_line(line, start).get(col).map_or(start, |f| f.offset)
}

/// The median of the positive steps between successive times (`None` without one).
fn median_step(t: &[f64]) -> Option<f64> {
    let mut d: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 1e-9)
        .collect();
    if d.is_empty() {
        return None;
    }
    d.sort_by(f64::total_cmp);
    Some(d[d.len() / 2])
}

/// `1 / median(Δt)` over the positive steps, snapped to a whole rate within 0.5 %.
fn rate_from_times(t: &[f64]) -> Option<f64> {
    let rate = 1.0 / median_step(t)?;
    if !rate.is_finite() || !(0.001..=1000.0).contains(&rate) {
        return None;
    }
    let whole = rate.round();
    Some(if whole > 0.0 && (rate - whole).abs() <= 0.005 * whole {
        whole
    } else {
        (rate * 1000.0).round() / 1000.0
    })
}

/// Common video and capture rates a millisecond-stamped capture snaps to.
const COMMON_RATES: [f64; 10] = [15.0, 24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 90.0, 120.0, 240.0];

/// The rate of millisecond stamps (as seconds): a [`COMMON_RATES`] entry whose frame period
/// is within 1 ms (the stamps' resolution) of the median step, else [`rate_from_times`].
fn rate_from_milliseconds(t: &[f64]) -> Option<f64> {
    let median = median_step(t)?;
    COMMON_RATES
        .iter()
        .map(|&r| (r, (1.0 / r - median).abs()))
        .filter(|&(_, e)| e <= 0.001)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(r, _)| r)
        .or_else(|| rate_from_times(t))
}

/// The timecode of frame `n` at `fps`: `HH:MM:SS:FF.fff` (frames within the second, with
/// the sub-frame fraction for rates that are not whole).
pub fn timecode(n: u64, fps: f64) -> String {
    timecode_at(n as f64 / fps, fps)
}

/// The timecode of time `t` (seconds since midnight, or since the capture's start) at `fps`,
/// as [`timecode`] writes it.
pub fn timecode_at(t: f64, fps: f64) -> String {
    let mut secs = t.max(0.0).floor();
    let mut within = (t.max(0.0) - secs) * fps;
    // Snap rounding noise (59.99999 frames) to the whole frame, and a whole second's worth
    // into the next second.
    if (within - within.round()).abs() < 1e-6 {
        within = within.round();
    }
    if within >= fps {
        secs += 1.0;
        within = (within - fps).max(0.0);
    }
    let s = secs as u64;
    format!(
        "{:02}:{:02}:{:02}:{:06.3}",
        s / 3600,
        (s / 60) % 60,
        s % 60,
        within
    )
}

/// Seconds since midnight of a timecode `HH:MM:SS:FF[.fff]` at `fps` (`;` accepted for
/// drop-frame); `None` when it is not one, or its frame is not below `fps`.
pub fn timecode_seconds(text: &str, fps: f64) -> Option<f64> {
    let stamp = parse_timecode(text.trim())?;
    (stamp.frames < fps).then(|| stamp.seconds + stamp.frames / fps)
}

/// A weight CSV: `Timecode`, then `names` as columns, one row per frame (`frames[i]` holds
/// the weights of frame `i` in `names` order) at `fps`.
pub fn write_weights_csv(names: &[String], fps: f64, frames: &[Vec<f32>]) -> String {
    use std::fmt::Write as _;
    let mut out = String::with_capacity(32 + frames.len() * (16 + names.len() * 8));
    out.push_str("Timecode");
    for n in names {
        out.push(',');
        out.push_str(n);
    }
    out.push('\n');
    for (i, w) in frames.iter().enumerate() {
        out.push_str(&timecode(i as u64, fps));
        for v in w {
            let _ = write!(out, ",{}", format_weight(*v));
        }
        out.push('\n');
    }
    out
}

/// A weight with at most 5 decimals, trailing zeros dropped (`0`, `0.5`, `0.12346`).
fn format_weight(v: f32) -> String {
    let s = format!("{:.5}", v.clamp(0.0, 1.0));
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() {
        "0".into()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str, fps: Option<f64>) -> Result<WeightCsv> {
        parse_weights_csv(text, Path::new("w.csv"), fps)
    }

    fn message(text: &str) -> String {
        parse(text, None).unwrap_err().to_string()
    }

    #[test]
    fn live_link_face_layout_with_a_second_roll_over() {
        let text = "Timecode,BlendShapeCount,EyeBlinkLeft,JawOpen,HeadYaw\n\
                    10:23:45:58.000,61,0.1,0.2,0.01\n\
                    10:23:45:59.000,61,0.2,0.3,0.01\n\
                    10:23:46:00.000,61,0.3,0.4,0.01\n\
                    10:23:46:01.000,61,1.5,0.5,0.01\n";
        let w = parse(text, None).unwrap();
        assert_eq!(w.time, TimeColumn::Timecode);
        assert_eq!(w.fps, 60.0);
        assert!(w.fps_detected);
        let names: Vec<&str> = w.columns.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["EyeBlinkLeft", "JawOpen", "HeadYaw"]);
        let frames: Vec<u64> = w.rows.iter().map(|r| r.frame).collect();
        assert_eq!(frames, [0, 1, 2, 3]);
        assert_eq!(w.rows[3].weights[0], 1.0);
        assert_eq!(w.warnings.len(), 1, "{:?}", w.warnings);
        assert!(
            w.warnings[0].message.contains(
                "w.csv: 1 weight outside 0..1 clamped (first at line 5, column 3 `EyeBlinkLeft`)"
            ),
            "{}",
            w.warnings[0]
        );
    }

    #[test]
    fn reader_matches_text_and_names_its_source() {
        let text = "time,jawOpen\n0,0\n0.04,0.5\n0.08,1\n";
        let from = read_weights_csv_from(text.as_bytes(), Path::new("w.csv"), None).unwrap();
        assert_eq!(from.rows.len(), parse(text, None).unwrap().rows.len());
        assert_eq!(from.fps, 25.0);
        let e = read_weights_csv_from(&b"time,\xff\n"[..], Path::new("bad.csv"), None).unwrap_err();
        assert!(e.to_string().contains("bad.csv"), "{e}");
    }

    #[test]
    fn seconds_column_and_explicit_rate() {
        let text = "time,jawOpen\n0,0\n0.04,0.5\n0.08,1\n";
        let w = parse(text, None).unwrap();
        assert_eq!(w.fps, 25.0);
        assert_eq!(w.rows.len(), 3);
        let w = parse(text, Some(50.0)).unwrap();
        assert_eq!(
            w.rows.iter().map(|r| r.frame).collect::<Vec<_>>(),
            [0, 2, 4]
        );
        // Timecodes within one second need --fps.
        let tc = "Timecode,JawOpen\n00:00:01:00,0\n00:00:01:02,1\n";
        assert!(message(tc).contains("give --fps"), "{}", message(tc));
        let w = parse(tc, Some(30.0)).unwrap();
        assert_eq!(w.rows[1].frame, 2);
    }

    #[test]
    fn hostile_inputs_are_located_errors() {
        assert!(message("").contains("w.csv:1:1: expected a header row"));
        assert!(message("EyeBlinkLeft,JawOpen\n0.1,0.2\n")
            .contains("w.csv:1:1: expected a `Timecode` column"),);
        let ragged = message("time,JawOpen\n0,0.1\n0.1\n");
        assert!(
            ragged.contains("w.csv:3:4: expected 2 fields like the header (this row has 1)"),
            "{ragged}"
        );
        let long = message("time,JawOpen\n0,0.1,7\n");
        assert!(long.contains("w.csv:2:7: expected 2 fields"), "{long}");
        let nan = message("time,JawOpen\n0,NaN\n");
        assert!(nan.contains("w.csv:2:3: expected a finite weight"), "{nan}");
        let inf = message("time,JawOpen\n0,inf\n");
        assert!(inf.contains("w.csv:2:3: expected a finite weight"), "{inf}");
        let tc = message("Timecode,JawOpen\n12:00:61:00,0\n");
        assert!(tc.contains("w.csv:2:1: expected a timecode"), "{tc}");
        let back = message("time,JawOpen\n1,0\n0.5,0\n");
        assert!(
            back.contains("w.csv:3:1: expected a time no earlier"),
            "{back}"
        );
        let dup = message("time,JawOpen,jaw_open\n0,0,0\n");
        assert!(
            dup.contains("w.csv:1:14: expected one column per shape"),
            "{dup}"
        );
        assert!(message("time,JawOpen\n").contains("at least one row"));
        let far = message("time,JawOpen\n0,0\n0.01,0\n0.02,0\n1e6,0\n");
        assert!(far.contains("within 10000000 frames"), "{far}");
        let empty_name = message("time,,JawOpen\n0,0,0\n");
        assert!(
            empty_name.contains("w.csv:1:6: expected a column name"),
            "{empty_name}"
        );
        // A huge BlendShapeCount is just a number: nothing is sized from it.
        let w = parse(
            "Timecode,BlendShapeCount,JawOpen\n00:00:00:59,99999999999999999999,0.5\n00:00:01:00,1e300,0.5\n",
            None,
        )
        .unwrap();
        assert_eq!(w.rows.len(), 2);
        // Too many columns are refused before any row is read.
        let wide = format!("time{}\n", ",x".repeat(MAX_COLUMNS + 5));
        assert!(parse(&wide, None).is_err());
        // Arbitrary bytes never panic.
        for junk in [
            "\u{feff}",
            "\u{feff}Timecode\n",
            ",,,\n,,,",
            "time\n\n\n0\n",
            "Timecode,a\n::::,1",
        ] {
            let _ = parse(junk, None);
        }
    }

    #[test]
    fn random_text_never_panics() {
        // Deterministic pseudo-random texts over the characters that matter to the grammar.
        let alphabet: Vec<char> = "Timecode,time:;.0123456789-e+NaInf\"\r\n \u{feff}é"
            .chars()
            .collect();
        let mut seed = 7u64;
        for len in 0..3000usize {
            let mut t = String::from(if len % 2 == 0 {
                "Timecode,A,B\n"
            } else {
                "time,A\n"
            });
            for _ in 0..(len % 97) {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                t.push(alphabet[(seed >> 33) as usize % alphabet.len()]);
            }
            let _ = parse(&t, None);
            let _ = parse(&t, Some(30.0));
        }
    }

    #[test]
    fn timecodes_of_a_time_of_day() {
        let start = timecode_seconds("14:03:22:15", 25.0).unwrap();
        assert_eq!(start, 50_602.6);
        assert_eq!(timecode_at(start, 25.0), "14:03:22:15.000");
        assert_eq!(timecode_at(start + 10.0 / 25.0, 25.0), "14:03:23:00.000");
        // Just under a whole second reads as the next second's frame 0, not frame 25.
        assert_eq!(timecode_at(50_602.999_999_999_9, 25.0), "14:03:23:00.000");
        assert_eq!(
            timecode_seconds("10:00:00:29.500", 30.0),
            Some(36_000.0 + 29.5 / 30.0)
        );
        assert_eq!(timecode_seconds("10:00:00:25", 25.0), None);
        assert_eq!(timecode_seconds("10:00:00", 25.0), None);
        assert_eq!(timecode_seconds("10:60:00:00", 25.0), None);
        // A capture's first row is its start, at the timecode's own rate.
        let w = parse(
            "Timecode,A\n14:03:22:58.000,0.1\n14:03:22:59.000,0.2\n14:03:23:00.000,0.3\n",
            None,
        )
        .unwrap();
        assert_eq!(w.fps, 60.0);
        assert!((w.start - (50_602.0 + 58.0 / 60.0)).abs() < 1e-9);
        assert_eq!(timecode_at(w.start, w.fps), "14:03:22:58.000");
    }

    #[test]
    fn written_csv_reads_back() {
        let names = vec!["EyeBlinkLeft".to_string(), "JawOpen".to_string()];
        let frames: Vec<Vec<f32>> = (0..70).map(|i| vec![i as f32 / 70.0, 0.25]).collect();
        let text = write_weights_csv(&names, 60.0, &frames);
        assert!(text.starts_with("Timecode,EyeBlinkLeft,JawOpen\n00:00:00:00.000,0,0.25\n"));
        assert!(text.contains("\n00:00:01:00.000,"));
        let w = parse(&text, None).unwrap();
        assert_eq!(w.fps, 60.0);
        assert_eq!(w.rows.len(), 70);
        assert!((w.rows[35].weights[0] - 0.5).abs() < 1e-5);
        assert_eq!(timecode(3, 12.5), "00:00:00:03.000");
        assert_eq!(timecode(13, 12.5), "00:00:01:00.500");
    }
}
