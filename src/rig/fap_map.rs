//! Mapping tables: which blend shapes realise which FAP (or viseme / expression), and with
//! which sign.
//!
//! A table is CSV with the columns `fap,positive,negative,reasoning`, one row per key:
//!
//! - `fap`: a low-level FAP name or number (`open_jaw`, `3`), `viseme_N` or an expression
//!   name (`joy`).
//! - `positive` / `negative`: the shapes that realise positive / negative values, as
//!   `|`-separated alternatives (the first whose shapes the rig has is used), each a
//!   `+`-separated sum of `shape` or `shape*weight` terms. Empty: not realised. Unidirectional
//!   FAPs and the high-level keys take no negative shapes.
//! - `reasoning`: free text (why these shapes), kept for reports.
//!
//! Shape names match a rig's names after [`normalise_shape_name`], so the ARKit preset's
//! `eyeBlinkLeft` finds `eyeBlink_L`, `EyeBlinkLeft` or `blendShape1.eyeBlinkLeft`. The
//! built-in ARKit-52 preset is `specs/arkit-fap-map.csv` ([`FapMap::arkit`]).

use std::collections::HashMap;
use std::path::Path;

use serde::Serialize;

use super::Rig;
use crate::error::{Error, Location, ParseError, Result};
use crate::fat::TableKey;
use crate::spec::{Directionality, FapId};

/// The ARKit-52 preset as shipped.
pub const ARKIT_MAP_CSV: &str = include_str!("../../specs/arkit-fap-map.csv");

/// Most rows a mapping table may have.
const MAX_ROWS: usize = 4096;

/// One `shape*weight` term.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShapeTerm {
    /// Shape name as written in the table.
    pub shape: String,
    /// Factor on the shape's weight (1 unless `*w` is given).
    pub weight: f64,
}

/// A sum of shape terms.
pub type ShapeCombo = Vec<ShapeTerm>;

/// One row of a mapping table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapMapRow {
    /// What the row realises.
    pub key: TableKey,
    /// Alternatives for positive values (first available wins).
    pub positive: Vec<ShapeCombo>,
    /// Alternatives for negative values.
    pub negative: Vec<ShapeCombo>,
    /// Why these shapes.
    pub reasoning: String,
    /// 1-based line in the table file.
    pub line: usize,
}

/// A parsed mapping table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapMap {
    /// Where it came from (`arkit` for the preset).
    pub source: String,
    /// Whether shapes missing from a rig are errors (custom tables) or just unmapped (presets).
    pub strict: bool,
    /// Rows in file order.
    pub rows: Vec<FapMapRow>,
}

/// A name reduced for matching: lower case, text up to the last `.` dropped (Maya-style
/// `blendShape1.` prefixes), non-alphanumerics dropped, and a trailing `left` / `right`
/// shortened to `l` / `r` (`eyeBlinkLeft`, `eyeBlink_L`, `eye_blink_left` → `eyeblinkl`).
pub fn normalise_shape_name(name: &str) -> String {
    let base = name.rsplit('.').next().unwrap_or(name);
    let mut s: String = base
        .chars()
        .filter(|c| c.is_alphanumeric())
        .flat_map(char::to_lowercase)
        .collect();
    for (long, short) in [("left", "l"), ("right", "r")] {
        if s.len() > long.len() && s.ends_with(long) {
            s.truncate(s.len() - long.len());
            s.push_str(short);
        }
    }
    s
}

impl FapMap {
    /// The built-in ARKit-52 preset (`specs/arkit-fap-map.csv`).
    pub fn arkit() -> FapMap {
        let mut m = parse_fap_map(ARKIT_MAP_CSV, Path::new("specs/arkit-fap-map.csv"))
            .expect("the bundled ARKit map parses");
        m.source = "arkit".into();
        m.strict = false;
        m
    }

    /// The row for `key`, if any.
    pub fn row(&self, key: TableKey) -> Option<&FapMapRow> {
        self.rows.iter().find(|r| r.key == key)
    }

    /// Checks a custom table against `rig`: every row must have, on each non-empty side, an
    /// alternative whose shapes the rig has. Presets skip this (missing shapes are reported
    /// as unmapped keys instead).
    pub fn check_against(&self, rig: &Rig, file: &Path) -> Result<()> {
        if !self.strict {
            return Ok(());
        }
        let names = ShapeLookup::new(rig);
        for row in &self.rows {
            for side in [&row.positive, &row.negative] {
                if side.is_empty() {
                    continue;
                }
                if names.resolve(side).is_none() {
                    let missing: Vec<&str> = side
                        .iter()
                        .flatten()
                        .map(|t| t.shape.as_str())
                        .filter(|s| names.find(s).is_none())
                        .collect();
                    return Err(super::RigError::UnknownShapes {
                        file: file.to_path_buf(),
                        line: row.line,
                        plural: missing.len() != 1,
                        shapes: missing
                            .iter()
                            .map(|s| format!("`{s}`"))
                            .collect::<Vec<_>>()
                            .join(", "),
                        rig: rig.name.clone(),
                    }
                    .into());
                }
            }
        }
        Ok(())
    }
}

/// A rig's shape names by normalised name.
pub struct ShapeLookup {
    by_name: HashMap<String, usize>,
}

impl ShapeLookup {
    /// The lookup for `rig` by normalised name (when two shapes normalise alike, the first
    /// in the rig wins).
    pub fn new(rig: &Rig) -> Self {
        let mut by_name = HashMap::new();
        for (i, s) in rig.shapes.iter().enumerate() {
            by_name.entry(normalise_shape_name(&s.name)).or_insert(i);
        }
        ShapeLookup { by_name }
    }

    /// The rig shape a table name refers to.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.by_name.get(&normalise_shape_name(name)).copied()
    }

    /// The first alternative all of whose shapes exist, as `(shape index, weight)` terms.
    pub fn resolve(&self, alternatives: &[ShapeCombo]) -> Option<Vec<(usize, f64)>> {
        alternatives.iter().find_map(|combo| {
            combo
                .iter()
                .map(|t| self.find(&t.shape).map(|i| (i, t.weight)))
                .collect()
        })
    }
}

/// Reads a mapping table file (bounded read; strict: unknown shapes are errors).
pub fn read_fap_map(path: &Path) -> Result<FapMap> {
    let text = crate::io::read_text(path)?;
    parse_fap_map(&text, path)
}

/// Reads a mapping table from `reader` (UTF-8, bounded by
/// [`crate::io::DEFAULT_MAX_INPUT_BYTES`]; strict like [`read_fap_map`]); `source` names it
/// in errors.
///
/// ```
/// use std::path::Path;
/// use fbakit::fat::TableKey;
/// use fbakit::spec::FapId;
/// let csv = "fap,positive,negative,reasoning\nopen_jaw,jawOpen,,drops the jaw\n";
/// let map = fbakit::rig::fap_map::read_fap_map_from(csv.as_bytes(), Path::new("map.csv"))?;
/// assert!(map.row(TableKey::LowLevel(FapId::new(3).unwrap())).is_some());
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read_fap_map_from<R: std::io::BufRead>(reader: R, source: &Path) -> Result<FapMap> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_fap_map(&text, source)
}

/// Parses a mapping table; `file` names it in errors (`file:line:column: expected ...`).
pub fn parse_fap_map(text: &str, file: &Path) -> Result<FapMap> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(text.as_bytes());
    let err_at = |offset: usize, expected: String| -> Error {
        ParseError::at_offset(file, text, offset, expected).into()
    };
    let headers = reader
        .headers()
        .map_err(|e| err_at(0, format!("a CSV header ({e})")))?
        .clone();
    let want = ["fap", "positive", "negative", "reasoning"];
    let got: Vec<String> = headers
        .iter()
        .map(|h| h.trim().to_ascii_lowercase())
        .collect();
    if got.len() < 3 || got.iter().zip(want).any(|(g, w)| g != w) {
        return Err(err_at(
            0,
            "the header `fap,positive,negative,reasoning`".into(),
        ));
    }
    let mut rows: Vec<FapMapRow> = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let offset = reader.position().byte() as usize;
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => {
                let at = e.position().map_or(offset, |p| p.byte() as usize);
                return Err(err_at(at, format!("a CSV record ({e})")));
            }
        }
        let line = Location::from_offset(file, text, offset).line;
        if record.iter().all(|f| f.trim().is_empty()) {
            continue;
        }
        if rows.len() >= MAX_ROWS {
            return Err(err_at(offset, format!("at most {MAX_ROWS} rows")));
        }
        // Byte offset of field `i` (for columns in messages): search the record's text.
        let field_at = |i: usize| -> usize {
            let raw = &text[offset.min(text.len())..];
            let mut from = 0;
            for (k, f) in record.iter().enumerate() {
                let pos = raw[from..].find(f).map_or(from, |p| from + p);
                if k == i {
                    return offset + pos;
                }
                from = pos + f.len();
            }
            offset
        };
        let fap_text = record.get(0).unwrap_or("").trim();
        let key = parse_key(fap_text).ok_or_else(|| {
            err_at(
                field_at(0),
                "a low-level FAP name or number, viseme_1..viseme_14 or an expression name".into(),
            )
        })?;
        if let Some(prev) = rows.iter().find(|r| r.key == key) {
            return Err(err_at(
                field_at(0),
                format!("one row per key ({key} is also on line {})", prev.line),
            ));
        }
        let positive =
            parse_side(record.get(1).unwrap_or("")).map_err(|e| err_at(field_at(1), e))?;
        let negative =
            parse_side(record.get(2).unwrap_or("")).map_err(|e| err_at(field_at(2), e))?;
        let one_sided = match key {
            TableKey::LowLevel(f) => {
                f.info().directionality == Some(Directionality::Unidirectional)
            }
            _ => true,
        };
        if one_sided && !negative.is_empty() {
            return Err(err_at(
                field_at(2),
                format!("no negative shapes ({key} takes only positive values)"),
            ));
        }
        rows.push(FapMapRow {
            key,
            positive,
            negative,
            reasoning: record.get(3).unwrap_or("").trim().to_string(),
            line,
        });
    }
    Ok(FapMap {
        source: file.display().to_string(),
        strict: true,
        rows,
    })
}

/// A key from its table text: FAP name or number (3..=68), `viseme_N`, expression name.
fn parse_key(s: &str) -> Option<TableKey> {
    if let Ok(n) = s.parse::<u8>() {
        return FapId::new(n)
            .filter(|f| !f.is_high_level())
            .map(TableKey::LowLevel);
    }
    TableKey::from_name(s)
}

/// `a+b*0.5|c` → alternatives of weighted sums.
fn parse_side(s: &str) -> std::result::Result<Vec<ShapeCombo>, String> {
    let s = s.trim();
    if s.is_empty() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    for alt in s.split('|') {
        let mut combo = Vec::new();
        for term in alt.split('+') {
            let term = term.trim();
            let (name, weight) = match term.split_once('*') {
                Some((n, w)) => {
                    let w: f64 = w
                        .trim()
                        .parse()
                        .map_err(|_| format!("a number after `*` in `{term}`"))?;
                    if !w.is_finite() || w == 0.0 {
                        return Err(format!("a finite non-zero weight in `{term}`"));
                    }
                    (n.trim(), w)
                }
                None => (term, 1.0),
            };
            if name.is_empty() || name.chars().any(|c| c.is_whitespace() || c == ',') {
                return Err(format!("a shape name, found `{term}`"));
            }
            combo.push(ShapeTerm {
                shape: name.to_string(),
                weight,
            });
        }
        out.push(combo);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arkit_preset_has_one_row_per_key() {
        let m = FapMap::arkit();
        assert_eq!(m.rows.len(), 66 + 14 + 6);
        for f in FapId::low_level().filter(|f| !f.is_high_level()) {
            assert!(
                m.row(TableKey::LowLevel(f)).is_some(),
                "no row for {}",
                f.name()
            );
        }
        let jaw = m.row(TableKey::from_name("open_jaw").unwrap()).unwrap();
        assert_eq!(jaw.positive[0][0].shape, "jawOpen");
        assert!(jaw.negative.is_empty());
        let smile = m
            .row(TableKey::from_name("raise_l_cornerlip").unwrap())
            .unwrap();
        assert_eq!(smile.negative[0][0].shape, "mouthFrownLeft");
        assert!(m.rows.iter().all(|r| !r.reasoning.is_empty()));
    }

    #[test]
    fn reader_matches_text_and_names_its_source() {
        let from = read_fap_map_from(ARKIT_MAP_CSV.as_bytes(), Path::new("m.csv")).unwrap();
        let text = parse_fap_map(ARKIT_MAP_CSV, Path::new("m.csv")).unwrap();
        assert_eq!(from.rows, text.rows);
        let e = read_fap_map_from(&b"fap,positive\n\xff\n"[..], Path::new("bad.csv")).unwrap_err();
        assert!(e.to_string().contains("bad.csv"), "{e}");
    }

    #[test]
    fn names_normalise_across_conventions() {
        for n in [
            "eyeBlinkLeft",
            "eyeBlink_L",
            "EyeBlinkLeft",
            "blendShape1.eyeBlinkLeft",
        ] {
            assert_eq!(normalise_shape_name(n), "eyeblinkl", "{n}");
        }
        assert_eq!(normalise_shape_name("mouthLeft"), "mouthl");
        assert_eq!(normalise_shape_name("jawOpen"), "jawopen");
    }

    #[test]
    fn sides_parse_alternatives_and_weights() {
        let s = parse_side("a+b*0.5|c").unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0][1].weight, 0.5);
        assert_eq!(s[1][0].shape, "c");
        assert!(parse_side("a*x").is_err());
        assert!(parse_side("a+").is_err());
    }

    #[test]
    fn bad_tables_are_located() {
        let p = Path::new("m.csv");
        let e = parse_fap_map(
            "fap,positive,negative,reasoning\nopen_jaw,jawOpen,,ok\nwink,x,,\n",
            p,
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("m.csv:3:1: expected a low-level FAP"), "{e}");
        let e = parse_fap_map(
            "fap,positive,negative,reasoning\nopen_jaw,jawOpen,jawClose,no\n",
            p,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("m.csv:2:18: expected no negative shapes"),
            "{e}"
        );
        let e = parse_fap_map("fap,positive,negative,reasoning\n3,a,,\nopen_jaw,b,,\n", p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.csv:3:1") && e.contains("line 2"), "{e}");
        let e = parse_fap_map("name,shape\n", p).unwrap_err().to_string();
        assert!(e.contains("m.csv:1:1: expected the header"), "{e}");
    }
}
