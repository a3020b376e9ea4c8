//! Face-capture files in and out: the one front door for blend-shape weight curves
//! ([`read_capture_file`], [`parse_capture`]), the Live Link Face layout writer
//! ([`write_live_link_csv`]) and the head and eye rotations ⇄ FAPs table ([`ROTATIONS`]).
//!
//! ## Formats read (detected by content)
//!
//! - **CSV** ([`super::weights_csv`]): Live Link Face (`Timecode,BlendShapeCount,` + 52
//!   shapes + 9 rotations), the bare 52-column form (`Timecode,` + shapes), plain seconds
//!   (`time`), and MediaPipe FaceLandmarker scores written as CSV (`timestamp_ms,_neutral,
//!   browDownLeft,...`: 52 categories, `_neutral` skipped, no `tongueOut`).
//! - **MediaPipe JSON lines**: one object per line,
//!   `{"timestamp_ms": 33, "blendshapes": {"jawOpen": 0.12, ...}}` (the category list form
//!   `"blendshapes": [{"categoryName": "jawOpen", "score": 0.12}, ...]` is read too). The
//!   shapes are those of every line, in the order they first appear (within one object by
//!   name); a shape a line leaves out (writers that drop zero scores) scores 0 there, with
//!   one warning. Errors name the file, the line and column where the JSON breaks, or the
//!   line and the JSON path (`blendshapes.jawOpen`).
//!
//! A text whose first non-blank character is `{` (or `[`) is JSON lines, anything else CSV. Both are
//! bounded like every reader: the text by [`crate::io::DEFAULT_MAX_INPUT_BYTES`], columns by
//! [`super::weights_csv::MAX_COLUMNS`], frames by [`super::weights_csv::MAX_FRAME_NUMBER`].
//!
//! ## Live Link Face layout (what [`write_live_link_csv`] writes)
//!
//! As read from open Live Link Face importers and exporters (the app's CSV export is not
//! specified by Epic in a document we could find): the header
//! `Timecode,BlendShapeCount,EyeBlinkLeft,...,TongueOut,HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,
//! LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll` (the 52 shapes in
//! [`super::arkit_names::ARKIT_SHAPES`] order, capitalised; note `JawRight` before `JawLeft`
//! and `MouthRight` before `MouthLeft`), `BlendShapeCount` 61 on every row, rotations in
//! radians. The timecode is `HH:MM:SS:FF.mmm`: `FF` the frame within the second at the
//! stream's rate, `.mmm` the sub-frame in thousandths (always `.000` for a whole rate, so it
//! reads the same whether a reader takes it as a sub-frame or as milliseconds). It starts at
//! `00:00:00:00` or at a given time of day (the app writes the time of day; reading keeps a
//! capture's first timecode, [`WeightCsv::start`], so it can be written back).
//!
//! ## Rotations ⇄ FAPs
//!
//! The angles are taken as right-handed rotations about the face frame of ARKit's face anchor,
//! which is the MPEG-4 face frame: x towards the face's left, y up, z out of the face. The
//! standard's FAP directions (`specs/fap-table.csv`, the right-handed rule of
//! `../shared/spec/mpeg4-fba.md`) are the same rotations, so every sign is +1 and only the
//! unit changes: FAP value (AU) = radians / 10⁻⁵, rounded to whole AU.
//!
//! | column | FAP | positive means |
//! |---|---|---|
//! | `HeadYaw` | 49 `head_yaw` | the face turns to its left |
//! | `HeadPitch` | 48 `head_pitch` | the face looks down |
//! | `HeadRoll` | 50 `head_roll` | the top of the head tips to the face's right |
//! | `LeftEyeYaw` | 23 `yaw_l_eyeball` | the face's left eye looks to the face's left |
//! | `LeftEyePitch` | 25 `pitch_l_eyeball` | the left eye looks down |
//! | `LeftEyeRoll` | — | no FAP: ignored, written as 0 |
//! | `RightEyeYaw` | 24 `yaw_r_eyeball` | the right eye looks to the face's left |
//! | `RightEyePitch` | 26 `pitch_r_eyeball` | the right eye looks down |
//! | `RightEyeRoll` | — | no FAP: ignored, written as 0 |
//!
//! A rotation column that is 0 on every row (Live Link Face with head rotation off) carries
//! nothing and is not written to the stream.

use std::path::Path;

use serde_json::Value;

use super::fap_map::normalise_shape_name;
use super::weights_csv::{assemble, parse_weights_csv, RawRow, Stamp, TimeColumn, WeightColumn};
use super::weights_csv::{timecode_at, WeightCsv, MAX_COLUMNS, MAX_ROTATION};
use crate::error::{Diagnostic, ParseError, Result};
use crate::fap::FapTimeline;
use crate::spec::FapId;

/// One rotation column of the Live Link Face layout and the FAP it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rotation {
    /// Column name as Live Link Face writes it.
    pub column: &'static str,
    /// The FAP number (`None`: no FAP, eye roll).
    pub fap: Option<u8>,
    /// Sign from radians to the FAP's positive direction (module docs).
    pub sign: i8,
}

/// The nine rotation columns in Live Link Face order (module docs' table).
pub const ROTATIONS: [Rotation; 9] = [
    Rotation {
        column: "HeadYaw",
        fap: Some(49),
        sign: 1,
    },
    Rotation {
        column: "HeadPitch",
        fap: Some(48),
        sign: 1,
    },
    Rotation {
        column: "HeadRoll",
        fap: Some(50),
        sign: 1,
    },
    Rotation {
        column: "LeftEyeYaw",
        fap: Some(23),
        sign: 1,
    },
    Rotation {
        column: "LeftEyePitch",
        fap: Some(25),
        sign: 1,
    },
    Rotation {
        column: "LeftEyeRoll",
        fap: None,
        sign: 1,
    },
    Rotation {
        column: "RightEyeYaw",
        fap: Some(24),
        sign: 1,
    },
    Rotation {
        column: "RightEyePitch",
        fap: Some(26),
        sign: 1,
    },
    Rotation {
        column: "RightEyeRoll",
        fap: None,
        sign: 1,
    },
];

/// Radians per angle unit (AU), the standard's unit of FAPs 23–26 and 48–50.
pub const RADIANS_PER_AU: f64 = 1e-5;

/// Most scores (lines × shapes) a JSON-lines capture may hold once every line has every
/// shape: 2^27 (512 MB as `f32`; an hour at 60 fps with 61 columns is 13 million).
pub const MAX_SCORES: usize = 1 << 27;

/// `BlendShapeCount` of the Live Link Face layout: 52 shapes and 9 rotations.
pub const BLEND_SHAPE_COUNT: usize = 61;

impl Rotation {
    /// The FAP this column is.
    pub fn fap_id(&self) -> Option<FapId> {
        self.fap.and_then(FapId::new)
    }

    /// Radians → FAP value (whole AU, no `-0`).
    pub fn to_fap(&self, radians: f64) -> f64 {
        (f64::from(self.sign) * radians / RADIANS_PER_AU).round() + 0.0
    }

    /// FAP value (AU) → radians.
    pub fn to_radians(&self, value: f64) -> f64 {
        f64::from(self.sign) * value * RADIANS_PER_AU
    }
}

/// The index in [`ROTATIONS`] of a column name in any spelling (`HeadYaw`, `head_yaw`).
pub fn rotation_index(name: &str) -> Option<usize> {
    let n = normalise_shape_name(name);
    ROTATIONS
        .iter()
        .position(|r| normalise_shape_name(r.column) == n)
}

/// The kinds of capture file [`parse_capture`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaptureFormat {
    /// A weight CSV (Live Link Face, bare, seconds, MediaPipe CSV).
    Csv,
    /// MediaPipe JSON lines.
    MediaPipeJsonLines,
}

/// The format of `text` by its content (module docs).
pub fn detect_capture(text: &str) -> CaptureFormat {
    match text
        .trim_start_matches('\u{feff}')
        .trim_start()
        .as_bytes()
        .first()
    {
        Some(b'{' | b'[') => CaptureFormat::MediaPipeJsonLines,
        _ => CaptureFormat::Csv,
    }
}

/// Reads a capture file (bounded read); see [`parse_capture`].
pub fn read_capture_file(path: &Path, fps: Option<f64>) -> Result<WeightCsv> {
    let text = crate::io::read_text(path)?;
    parse_capture(&text, path, fps)
}

/// Reads a capture from `reader` (UTF-8, bounded by [`crate::io::DEFAULT_MAX_INPUT_BYTES`]);
/// `source` names it in messages; see [`parse_capture`].
pub fn read_capture_from<R: std::io::BufRead>(
    reader: R,
    source: &Path,
    fps: Option<f64>,
) -> Result<WeightCsv> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_capture(&text, source, fps)
}

/// Parses any capture format of the module docs, detected by content; `file` names it in
/// errors, `fps` overrides the detected frame rate.
///
/// ```
/// use std::path::Path;
/// use fbakit::rig::capture::parse_capture;
/// let jsonl = "{\"timestamp_ms\": 0, \"blendshapes\": {\"_neutral\": 1, \"jawOpen\": 0.1}}\n\
///              {\"timestamp_ms\": 33, \"blendshapes\": {\"_neutral\": 1, \"jawOpen\": 0.3}}\n\
///              {\"timestamp_ms\": 67, \"blendshapes\": {\"_neutral\": 1, \"jawOpen\": 0.5}}\n";
/// let w = parse_capture(jsonl, Path::new("mp.jsonl"), None)?;
/// assert_eq!(w.fps, 30.0);
/// assert_eq!(w.columns.len(), 1);
/// assert_eq!(w.rows[2].weights, [0.5]);
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn parse_capture(text: &str, file: &Path, fps: Option<f64>) -> Result<WeightCsv> {
    match detect_capture(text) {
        CaptureFormat::Csv => parse_weights_csv(text, file, fps),
        CaptureFormat::MediaPipeJsonLines => parse_mediapipe_jsonl(text, file, fps),
    }
}

/// Parses MediaPipe JSON lines (module docs).
pub fn parse_mediapipe_jsonl(text: &str, file: &Path, fps: Option<f64>) -> Result<WeightCsv> {
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
    let mut columns: Vec<WeightColumn> = Vec::new();
    let mut index: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    let mut raw: Vec<RawRow> = Vec::new();
    let mut starts: Vec<usize> = Vec::new();
    let mut clamped = 0usize;
    let mut first_clamp: Option<(usize, String)> = None;
    let mut at = body_start;
    let mut lineno = 0usize;
    for rawline in text[body_start..].split('\n') {
        let start = at;
        at += rawline.len() + 1;
        lineno += 1;
        let line = rawline.strip_suffix('\r').unwrap_or(rawline);
        if line.trim().is_empty() {
            continue;
        }
        let lead = line.len() - line.trim_start().len();
        let value: Value = serde_json::from_str(line).map_err(|e| {
            // serde_json counts columns from 1 within this one-line text.
            let col = e.column().saturating_sub(1).min(line.len());
            let what = e.to_string();
            let what = what.split(" at line ").next().unwrap_or(&what).to_string();
            err(
                start + col,
                format!(
                    "one JSON object per line, {{\"timestamp_ms\": ..., \"blendshapes\": {{...}}}} ({what})"
                ),
            )
        })?;
        let key_at = |key: &str| -> usize {
            line.find(&format!("\"{key}\""))
                .map_or(start + lead, |i| start + i)
        };
        let Some(obj) = value.as_object() else {
            return Err(err(
                start + lead,
                "a JSON object {\"timestamp_ms\": ..., \"blendshapes\": {...}}".into(),
            ));
        };
        let ms = obj
            .get("timestamp_ms")
            .and_then(Value::as_f64)
            .filter(|v| v.is_finite() && v.abs() < 1e12);
        let Some(ms) = ms else {
            return Err(err(
                key_at("timestamp_ms"),
                "`timestamp_ms`: a time in milliseconds (a number)".into(),
            ));
        };
        let scores: Vec<(&str, Option<f64>)> = match obj.get("blendshapes") {
            Some(Value::Object(m)) => m.iter().map(|(k, v)| (k.as_str(), v.as_f64())).collect(),
            Some(Value::Array(list)) => {
                let mut out = Vec::with_capacity(list.len().min(MAX_COLUMNS + 1));
                for (i, c) in list.iter().enumerate() {
                    let name = c
                        .get("categoryName")
                        .or_else(|| c.get("category_name"))
                        .and_then(Value::as_str);
                    let Some(name) = name else {
                        return Err(err(
                            key_at("blendshapes"),
                            format!("`blendshapes[{i}].categoryName`: a shape name"),
                        ));
                    };
                    out.push((name, c.get("score").and_then(Value::as_f64)));
                    if out.len() > MAX_COLUMNS + 1 {
                        break;
                    }
                }
                out
            }
            _ => {
                return Err(err(
                    key_at("blendshapes"),
                    "`blendshapes`: an object of scores by shape name".into(),
                ))
            }
        };
        // Columns are the shapes of every line, in the order they first appear: a writer
        // that leaves out zero scores, or adds a shape later on, is read (module docs).
        let mut row = vec![f32::NAN; columns.len()];
        for (name, v) in &scores {
            if name.eq_ignore_ascii_case("_neutral") {
                continue;
            }
            let key = normalise_shape_name(name);
            let c = match index.get(&key) {
                Some(&c) => c,
                None => {
                    if name.is_empty() {
                        return Err(err(
                            key_at("blendshapes"),
                            "a shape name in `blendshapes`".into(),
                        ));
                    }
                    if columns.len() == MAX_COLUMNS {
                        return Err(err(key_at(name), format!("at most {MAX_COLUMNS} shapes")));
                    }
                    index.insert(key, columns.len());
                    columns.push(WeightColumn {
                        name: (*name).to_string(),
                        column: columns.len() + 1,
                    });
                    row.push(f32::NAN);
                    columns.len() - 1
                }
            };
            let Some(v) = v.filter(|v| v.is_finite()) else {
                return Err(err(
                    key_at(name),
                    format!("`blendshapes.{name}`: a finite score (a number, 0..1)"),
                ));
            };
            if !row[c].is_nan() {
                return Err(err(
                    key_at(name),
                    format!("one score per shape (`{name}` repeats)"),
                ));
            }
            let rotation = rotation_index(name).is_some();
            row[c] = if rotation {
                if v.abs() > MAX_ROTATION {
                    return Err(err(
                        key_at(name),
                        format!("`blendshapes.{name}`: an angle in radians (-2π..2π)"),
                    ));
                }
                v as f32
            } else {
                if !(0.0..=1.0).contains(&v) {
                    clamped += 1;
                    if first_clamp.is_none() {
                        first_clamp = Some((lineno, (*name).to_string()));
                    }
                }
                v.clamp(0.0, 1.0) as f32
            };
        }
        // Every line is padded to every shape at the end: bounded, as a line naming few
        // shapes after one that named many would otherwise cost far more than its bytes.
        if (raw.len() + 1).saturating_mul(columns.len()) > MAX_SCORES {
            return Err(err(
                start + lead,
                format!("at most {MAX_SCORES} scores in all (lines × shapes); split the file"),
            ));
        }
        starts.push(key_at("timestamp_ms"));
        raw.push(RawRow {
            stamp: Stamp {
                seconds: ms / 1000.0,
                frames: 0.0,
            },
            line: lineno,
            weights: row,
        });
    }
    if raw.is_empty() {
        return Err(err(
            text.len(),
            "a JSON object per line: {\"timestamp_ms\": ..., \"blendshapes\": {...}}".into(),
        ));
    }
    if columns.is_empty() {
        return Err(err(
            starts[0],
            "`blendshapes`: at least one shape score on some line".into(),
        ));
    }
    let mut warnings = Vec::new();
    // A shape a line leaves out scores 0 there (a rotation: straight ahead), as when the
    // writer drops zero scores; said once, with the first place.
    let mut missing = 0usize;
    let mut first_missing: Option<(usize, String)> = None;
    for r in &mut raw {
        r.weights.resize(columns.len(), f32::NAN);
        for (c, w) in r.weights.iter_mut().enumerate() {
            if w.is_nan() {
                *w = 0.0;
                missing += 1;
                if first_missing.is_none() {
                    first_missing = Some((r.line, columns[c].name.clone()));
                }
            }
        }
    }
    if let Some((line, name)) = first_missing {
        warnings.push(Diagnostic::warning(format!(
            "{}: {missing} score{} left out read as 0 (first at line {line}, `blendshapes.{name}`)",
            file.display(),
            if missing == 1 { "" } else { "s" }
        )));
    }
    if let Some((line, name)) = first_clamp {
        warnings.push(Diagnostic::warning(format!(
            "{}: {clamped} score{} outside 0..1 clamped (first at line {line}, `blendshapes.{name}`)",
            file.display(),
            if clamped == 1 { "" } else { "s" }
        )));
    }
    let locate = |k: usize, expected: String| err(starts[k], format!("`timestamp_ms`: {expected}"));
    assemble(
        file,
        TimeColumn::Milliseconds,
        fps,
        columns,
        raw,
        &locate,
        warnings,
    )
}

/// The Live Link Face header: `Timecode,BlendShapeCount`, the 52 shapes, the 9 rotations.
pub fn live_link_header() -> String {
    let mut h = String::from("Timecode,BlendShapeCount");
    for n in super::arkit_names::ARKIT_SHAPES {
        h.push(',');
        h.push_str(&super::arkit_names::capture_name(n));
    }
    for r in ROTATIONS {
        h.push(',');
        h.push_str(r.column);
    }
    h
}

/// A Live Link Face CSV (module docs): frame `i` has the 52 weights `shapes[i]`
/// ([`super::arkit_names::ARKIT_SHAPES`] order) and the 9 angles `rotations[i]` (radians,
/// [`ROTATIONS`] order; missing rows are 0), at `fps`, its timecodes from `start` (seconds
/// since midnight: 0 writes `00:00:00:00.000` first; a capture's own start, as
/// [`super::weights_csv::WeightCsv::start`] reads it, writes its time of day back).
pub fn write_live_link_csv(
    fps: f64,
    start: f64,
    shapes: &[Vec<f32>],
    rotations: &[[f64; 9]],
) -> String {
    use std::fmt::Write as _;
    let mut out = String::with_capacity(700 + shapes.len() * (24 + 61 * 8));
    out.push_str(&live_link_header());
    out.push('\n');
    for (i, w) in shapes.iter().enumerate() {
        out.push_str(&timecode_at(start + i as f64 / fps, fps));
        let _ = write!(out, ",{BLEND_SHAPE_COUNT}");
        for k in 0..super::arkit_names::ARKIT_SHAPES.len() {
            let v = w.get(k).copied().unwrap_or(0.0);
            let _ = write!(out, ",{}", format_decimals(f64::from(v.clamp(0.0, 1.0))));
        }
        let r = rotations.get(i).copied().unwrap_or([0.0; 9]);
        for a in r {
            let _ = write!(out, ",{}", format_decimals(a));
        }
        out.push('\n');
    }
    out
}

/// A number with at most 5 decimals (1 AU for angles), trailing zeros dropped, no `-0`.
fn format_decimals(v: f64) -> String {
    let s = format!("{:.5}", if v.is_finite() { v } else { 0.0 });
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "" | "-0" | "-" => "0".into(),
        _ => s.to_string(),
    }
}

/// The 9 rotation angles (radians, [`ROTATIONS`] order) of frames `0..frames` of a stream
/// played by the hold rule: each FAP of the table converted, eye roll 0.
pub fn stream_rotations(timeline: &FapTimeline, frames: u64) -> Vec<[f64; 9]> {
    (0..frames)
        .map(|n| {
            let state = timeline.at_frame(n);
            let mut out = [0.0; 9];
            for (o, r) in out.iter_mut().zip(&ROTATIONS) {
                if let Some(fap) = r.fap_id() {
                    *o = r.to_radians(state.value(fap));
                }
            }
            out
        })
        .collect()
}

/// Whether a FAP is one of the table's rotations (head or eyeball), which travel as angle
/// columns rather than as blend-shape weights.
pub fn is_rotation_fap(fap: FapId) -> bool {
    ROTATIONS.iter().any(|r| r.fap_id() == Some(fap))
}

/// Whether a FAP is a head rotation (48–50): rigid motion of the whole head, never a blend
/// shape.
pub fn is_head_rotation_fap(fap: FapId) -> bool {
    matches!(fap.number(), 48..=50)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn jsonl(text: &str) -> Result<WeightCsv> {
        parse_capture(text, Path::new("mp.jsonl"), None)
    }

    fn message(text: &str) -> String {
        jsonl(text).unwrap_err().to_string()
    }

    #[test]
    fn rotation_table_follows_the_standard() {
        let faps: Vec<Option<&str>> = ROTATIONS
            .iter()
            .map(|r| r.fap_id().map(|f| f.name()))
            .collect();
        assert_eq!(
            faps,
            [
                Some("head_yaw"),
                Some("head_pitch"),
                Some("head_roll"),
                Some("yaw_l_eyeball"),
                Some("pitch_l_eyeball"),
                None,
                Some("yaw_r_eyeball"),
                Some("pitch_r_eyeball"),
                None
            ]
        );
        // 0.15708 rad is 15708 AU (the standard's example, about 9 degrees).
        assert_eq!(ROTATIONS[0].to_fap(0.15708), 15708.0);
        assert_eq!(ROTATIONS[0].to_fap(-0.0), 0.0);
        assert!((ROTATIONS[1].to_radians(-15708.0) + 0.15708).abs() < 1e-12);
        assert_eq!(rotation_index("head_yaw"), Some(0));
        assert_eq!(rotation_index("RightEyeRoll"), Some(8));
        assert_eq!(rotation_index("JawOpen"), None);
        assert!(is_rotation_fap(FapId::new(23).unwrap()));
        assert!(!is_rotation_fap(FapId::new(3).unwrap()));
        assert!(is_head_rotation_fap(FapId::new(50).unwrap()));
        assert!(!is_head_rotation_fap(FapId::new(26).unwrap()));
    }

    #[test]
    fn detection_by_content() {
        assert_eq!(
            detect_capture("\u{feff} \n{\"a\":1}"),
            CaptureFormat::MediaPipeJsonLines
        );
        assert_eq!(detect_capture("Timecode,JawOpen\n"), CaptureFormat::Csv);
        assert_eq!(detect_capture(""), CaptureFormat::Csv);
    }

    #[test]
    fn mediapipe_json_lines_and_category_lists() {
        let text = "{\"timestamp_ms\": 0, \"blendshapes\": {\"_neutral\": 0.9, \"jawOpen\": 0.1, \"eyeBlinkLeft\": 0.0}}\n\
                    \n\
                    {\"timestamp_ms\": 17, \"blendshapes\": {\"_neutral\": 0.9, \"jawOpen\": 1.2, \"eyeBlinkLeft\": 0.5}}\n\
                    {\"timestamp_ms\": 33, \"blendshapes\": [{\"categoryName\": \"_neutral\", \"score\": 1}, {\"categoryName\": \"jawOpen\", \"score\": 0.2}, {\"category_name\": \"eyeBlinkLeft\", \"score\": 0.25}]}\n";
        let w = jsonl(text).unwrap();
        assert_eq!(w.time, TimeColumn::Milliseconds);
        assert_eq!(w.fps, 60.0);
        let names: Vec<&str> = w.columns.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names.len(), 2);
        let jaw = names.iter().position(|n| *n == "jawOpen").unwrap();
        let blink = 1 - jaw;
        assert_eq!(
            w.rows.iter().map(|r| r.frame).collect::<Vec<_>>(),
            [0, 1, 2]
        );
        assert_eq!(w.rows[1].weights[jaw], 1.0);
        assert_eq!(w.rows[1].line, 3);
        assert_eq!(w.rows[2].weights[blink], 0.25);
        assert_eq!(w.warnings.len(), 1);
        assert!(
            w.warnings[0].message.contains(
                "mp.jsonl: 1 score outside 0..1 clamped (first at line 3, `blendshapes.jawOpen`)"
            ),
            "{}",
            w.warnings[0]
        );
    }

    #[test]
    fn mediapipe_csv_skips_neutral_and_reads_milliseconds() {
        let text = "timestamp_ms,_neutral,browDownLeft,jawOpen\n0,1,0,0.1\n33,1,0,0.2\n67,1,0.1,0.3\n100,1,0.2,0.4\n";
        let w = parse_capture(text, Path::new("mp.csv"), None).unwrap();
        assert_eq!(w.time, TimeColumn::Milliseconds);
        assert_eq!(w.fps, 30.0);
        assert_eq!(w.columns.len(), 2);
        assert_eq!(w.columns[0].name, "browDownLeft");
        assert_eq!(w.columns[0].column, 3);
        assert_eq!(
            w.rows.iter().map(|r| r.frame).collect::<Vec<_>>(),
            [0, 1, 2, 3]
        );
    }

    #[test]
    fn json_lines_that_leave_out_shapes_score_them_0() {
        // A writer that drops zero scores: line 1 has jawOpen only, line 2 adds a blink and
        // a head turn, line 3 gives nothing but `_neutral`.
        let text = "{\"timestamp_ms\": 0, \"blendshapes\": {\"jawOpen\": 0.4}}\n\
                    {\"timestamp_ms\": 33, \"blendshapes\": {\"eyeBlinkLeft\": 0.5, \"HeadYaw\": 0.1}}\n\
                    {\"timestamp_ms\": 67, \"blendshapes\": {\"_neutral\": 1}}\n";
        let w = jsonl(text).unwrap();
        let names: Vec<&str> = w.columns.iter().map(|c| c.name.as_str()).collect();
        // Within one object serde_json keeps keys by name.
        assert_eq!(names, ["jawOpen", "HeadYaw", "eyeBlinkLeft"]);
        let rows: Vec<&[f32]> = w.rows.iter().map(|r| r.weights.as_slice()).collect();
        assert_eq!(
            rows,
            [&[0.4, 0.0, 0.0][..], &[0.0, 0.1, 0.5], &[0.0, 0.0, 0.0]]
        );
        assert_eq!(w.warnings.len(), 1, "{:?}", w.warnings);
        assert_eq!(
            w.warnings[0].message,
            "mp.jsonl: 6 scores left out read as 0 (first at line 1, `blendshapes.HeadYaw`)"
        );
        // A full file says nothing.
        let full = "{\"timestamp_ms\": 0, \"blendshapes\": {\"jawOpen\": 0.4}}\n\
                    {\"timestamp_ms\": 33, \"blendshapes\": {\"jawOpen\": 0.5}}\n";
        assert!(jsonl(full).unwrap().warnings.is_empty());
    }

    #[test]
    fn hostile_json_lines_are_located_errors() {
        let ok = "{\"timestamp_ms\": 0, \"blendshapes\": {\"jawOpen\": 0.1}}\n";
        let broken = message(&format!(
            "{ok}{{\"timestamp_ms\": 5, \"blendshapes\": {{\"jawOpen\": }}}}\n"
        ));
        assert!(broken.starts_with("mp.jsonl:2:"), "{broken}");
        assert!(broken.contains("one JSON object per line"), "{broken}");
        let none = message("{\"timestamp_ms\": 0, \"blendshapes\": {}}\n{\"timestamp_ms\": 5, \"blendshapes\": {\"_neutral\": 1}}\n");
        assert!(
            none.contains("mp.jsonl:1:2: expected `blendshapes`: at least one shape score"),
            "{none}"
        );
        let nan = message("{\"timestamp_ms\": 0, \"blendshapes\": {\"jawOpen\": \"x\"}}\n");
        assert!(
            nan.contains("mp.jsonl:1:37: expected `blendshapes.jawOpen`: a finite score"),
            "{nan}"
        );
        let time = message("{\"timestamp\": 0, \"blendshapes\": {\"jawOpen\": 0}}\n");
        assert!(
            time.contains("mp.jsonl:1:1: expected `timestamp_ms`"),
            "{time}"
        );
        let back = message(&format!(
            "{{\"timestamp_ms\": 50, \"blendshapes\": {{\"jawOpen\": 0.1}}}}\n{ok}"
        ));
        assert!(
            back.contains("mp.jsonl:2:2: expected `timestamp_ms`: a time no earlier"),
            "{back}"
        );
        assert!(message("[1, 2]\n").contains("mp.jsonl:1:1: expected a JSON object"));
        assert!(message("{\"timestamp_ms\": 0, \"blendshapes\": 3}")
            .contains("`blendshapes`: an object"));
        // Few shapes a line after one naming many: refused before the padding is paid.
        let wide: String = (0..MAX_COLUMNS)
            .map(|k| format!("\"s{k}\": 0"))
            .collect::<Vec<_>>()
            .join(", ");
        let mut many = format!("{{\"timestamp_ms\": 0, \"blendshapes\": {{{wide}}}}}\n");
        for i in 1..=MAX_SCORES / MAX_COLUMNS {
            many += &format!("{{\"timestamp_ms\": {i}, \"blendshapes\": {{}}}}\n");
        }
        let last = MAX_SCORES / MAX_COLUMNS + 1;
        assert!(
            message(&many).contains(&format!(
                "mp.jsonl:{last}:1: expected at most 134217728 scores"
            )),
            "{}",
            message(&many)
        );
        let deep = format!("{{\"a\": {}{}}}", "[".repeat(10_000), "]".repeat(10_000));
        assert!(jsonl(&deep).is_err());
        for junk in [
            "{",
            "{}",
            "{\"timestamp_ms\": 1e400}",
            "\u{feff}{\n",
            "{\"blendshapes\": []}",
        ] {
            assert!(jsonl(junk).is_err(), "{junk}");
        }
    }

    #[test]
    fn live_link_layout_is_written_and_reads_back() {
        let shapes: Vec<Vec<f32>> = (0..70)
            .map(|i| {
                let mut w = vec![0.0; 52];
                w[17] = i as f32 / 70.0;
                w
            })
            .collect();
        let rotations: Vec<[f64; 9]> = (0..70)
            .map(|i| [0.01 * i as f64, -0.2, 0.0, 0.1, -0.1, 0.3, 0.0, 0.0, 0.0])
            .collect();
        let text = write_live_link_csv(60.0, 0.0, &shapes, &rotations);
        let header = text.lines().next().unwrap();
        assert!(header.starts_with("Timecode,BlendShapeCount,EyeBlinkLeft,"));
        assert!(header.contains(",JawForward,JawRight,JawLeft,JawOpen,"));
        assert!(header.ends_with(",TongueOut,HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll"));
        assert_eq!(header.split(',').count(), 63);
        assert!(text.contains("\n00:00:00:01.000,61,"));
        assert!(text.contains("\n00:00:01:00.000,61,"));
        let w = parse_capture(&text, Path::new("llf.csv"), None).unwrap();
        assert_eq!(w.fps, 60.0);
        assert_eq!(w.rows.len(), 70);
        assert_eq!(w.columns.len(), 61);
        // Rotations keep their sign (not clamped to 0..1).
        assert!((w.rows[3].weights[53] + 0.2).abs() < 1e-6);
        assert!((w.rows[69].weights[52] - 0.69).abs() < 1e-6);
        assert!((w.rows[35].weights[17] - 0.5).abs() < 1e-5);
        // Degrees by mistake are refused.
        let degrees = text.replacen(",-0.2,", ",-20,", 1);
        let e = parse_capture(&degrees, Path::new("llf.csv"), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected an angle in radians"), "{e}");
        assert_eq!(format_decimals(-0.000001), "0");
        assert_eq!(format_decimals(-0.25), "-0.25");
    }

    #[test]
    fn random_lines_never_panic() {
        let alphabet: Vec<char> =
            "{}[]\":,0123456789.-e timestamp_msblendshapescategoryNamescore\n"
                .chars()
                .collect();
        let mut seed = 11u64;
        for len in 0..2000usize {
            let mut t =
                String::from("{\"timestamp_ms\": 0, \"blendshapes\": {\"jawOpen\": 0.5}}\n");
            for _ in 0..(len % 89) {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                t.push(alphabet[(seed >> 33) as usize % alphabet.len()]);
            }
            let _ = jsonl(&t);
            let _ = parse_capture(&t, Path::new("x"), Some(30.0));
        }
    }
}
