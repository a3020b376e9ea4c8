//! The phoneme → viseme table: which of the standard's 14 mouth shapes (FAP 1) shows each
//! espeak-ng phoneme. The data and the reason for every row are in
//! `specs/phoneme-visemes.csv` (compiled in); the standard's own list
//! (`specs/visemes.csv`) names one or three SAMPA phonemes per viseme, and the table extends
//! it to every phoneme the English and German voices of espeak-ng produce.
//!
//! A row's `viseme` is a number (`7`), a glide `A>B` for diphthongs (the first half of the
//! phoneme shows A, the second half B) or `next` for sounds without a mouth shape of their
//! own (`h`), which take the following phoneme's shape.
//!
//! A phoneme missing from the table is looked up again without its trailing modifiers
//! (length `:`, variant digits, `#`, `-`, `/`, `@`), so `e:` falls back to `e` and `r-` to
//! `r`; [`PhonemeVisemeTable::lookup`] returns `None` only when nothing matches.

use std::collections::HashMap;
use std::path::Path;
use std::sync::OnceLock;

use crate::error::{Error, Location, ParseError, Result};
use crate::spec::Viseme;

/// The compiled-in table text.
const TABLE_CSV: &str = include_str!("../../specs/phoneme-visemes.csv");
/// Characters stripped from the end of an unknown phoneme before looking it up again.
const MODIFIERS: &[char] = &[':', '#', '-', '/', '@', '2', '3', ';', '!', '|'];

/// The mouth shape(s) of one phoneme.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisemeTarget {
    /// One viseme for the whole phoneme.
    Single(Viseme),
    /// A diphthong: the first viseme for the first half, the second for the second half.
    Glide(Viseme, Viseme),
    /// No shape of its own: the next phoneme's shape.
    Next,
}

/// One row of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct PhonemeViseme {
    /// espeak-ng mnemonic.
    pub phoneme: String,
    /// Its mouth shape.
    pub target: VisemeTarget,
    /// A word with the sound.
    pub example: String,
    /// Why this viseme.
    pub reasoning: String,
}

/// Phoneme → viseme rows with a lookup index.
#[derive(Clone, Debug)]
pub struct PhonemeVisemeTable {
    rows: Vec<PhonemeViseme>,
    index: HashMap<String, usize>,
}

impl PhonemeVisemeTable {
    /// The table of `specs/phoneme-visemes.csv`.
    pub fn standard() -> &'static PhonemeVisemeTable {
        static T: OnceLock<PhonemeVisemeTable> = OnceLock::new();
        T.get_or_init(|| {
            // The file is part of the crate and checked by a unit test; an empty table
            // would only make every phoneme "unmapped".
            PhonemeVisemeTable::parse(TABLE_CSV, Path::new("specs/phoneme-visemes.csv"))
                .unwrap_or_else(|_| PhonemeVisemeTable {
                    rows: Vec::new(),
                    index: HashMap::new(),
                })
        })
    }

    /// Reads a table in the CSV layout of `specs/phoneme-visemes.csv` (`phoneme, viseme,
    /// example, reasoning`); `file` names the source in errors.
    pub fn parse(text: &str, file: &Path) -> Result<PhonemeVisemeTable> {
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .flexible(false)
            .from_reader(text.as_bytes());
        let at = |line: u64, expected: String, found: Option<String>| {
            Error::Parse(ParseError {
                location: Location {
                    file: file.to_path_buf(),
                    line: line as usize,
                    column: 1,
                },
                expected,
                found,
            })
        };
        let headers = reader
            .headers()
            .map_err(|e| at(1, "a header line".into(), Some(e.to_string())))?
            .clone();
        let wanted = ["phoneme", "viseme", "example", "reasoning"];
        if headers.iter().collect::<Vec<_>>() != wanted {
            return Err(at(
                1,
                format!("the header `{}`", wanted.join(",")),
                Some(headers.iter().collect::<Vec<_>>().join(",")),
            ));
        }
        let mut rows = Vec::new();
        let mut index = HashMap::new();
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line());
                at(line, "a row of 4 fields".into(), Some(e.to_string()))
            })?;
            let line = record.position().map_or(0, |p| p.line());
            let phoneme = record.get(0).unwrap_or("").trim().to_string();
            if phoneme.is_empty() {
                return Err(at(line, "a phoneme".into(), None));
            }
            let field = record.get(1).unwrap_or("").trim();
            let target = parse_target(field).ok_or_else(|| {
                at(
                    line,
                    "a viseme 0..=14, `A>B` or `next`".into(),
                    Some(field.to_string()),
                )
            })?;
            if index.insert(phoneme.clone(), rows.len()).is_some() {
                return Err(at(
                    line,
                    "each phoneme once".into(),
                    Some(format!("`{phoneme}` again")),
                ));
            }
            rows.push(PhonemeViseme {
                phoneme,
                target,
                example: record.get(2).unwrap_or("").to_string(),
                reasoning: record.get(3).unwrap_or("").to_string(),
            });
        }
        Ok(PhonemeVisemeTable { rows, index })
    }

    /// The rows in file order.
    pub fn rows(&self) -> &[PhonemeViseme] {
        &self.rows
    }

    /// The shape of `phoneme`: an exact row, else the row of the phoneme without trailing
    /// modifiers (see the module docs), else `None`.
    pub fn lookup(&self, phoneme: &str) -> Option<VisemeTarget> {
        let mut p = phoneme;
        loop {
            if let Some(&i) = self.index.get(p) {
                return Some(self.rows[i].target);
            }
            let shorter = p.strip_suffix(MODIFIERS)?;
            if shorter.is_empty() {
                return None;
            }
            p = shorter;
        }
    }
}

/// `7`, `10>12` or `next`.
fn parse_target(s: &str) -> Option<VisemeTarget> {
    if s == "next" {
        return Some(VisemeTarget::Next);
    }
    let v = |t: &str| t.trim().parse::<u8>().ok().and_then(Viseme::new);
    match s.split_once('>') {
        Some((a, b)) => Some(VisemeTarget::Glide(v(a)?, v(b)?)),
        None => Some(VisemeTarget::Single(v(s)?)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vis(n: u8) -> Viseme {
        Viseme::new(n).unwrap()
    }

    #[test]
    fn the_bundled_table_parses_and_covers_the_standard_list() {
        let t = PhonemeVisemeTable::parse(TABLE_CSV, Path::new("t.csv")).unwrap();
        assert!(t.rows().len() > 70);
        assert!(t.rows().iter().all(|r| !r.reasoning.is_empty()));
        // Every SAMPA phoneme the standard lists maps to its own viseme; espeak-ng writes
        // the standard's `Q` (hot) as `0` and its `e` (bet) as `E`.
        for v in Viseme::shapes() {
            for &p in v.phonemes() {
                let p = match p {
                    "Q" => "0",
                    other => other,
                };
                assert_eq!(t.lookup(p), Some(VisemeTarget::Single(v)), "{p}");
            }
        }
        assert_eq!(PhonemeVisemeTable::standard().rows().len(), t.rows().len());
    }

    #[test]
    fn diphthongs_pauses_and_h() {
        let t = PhonemeVisemeTable::standard();
        assert_eq!(t.lookup("oU"), Some(VisemeTarget::Glide(vis(13), vis(14))));
        assert_eq!(t.lookup("aI"), Some(VisemeTarget::Glide(vis(10), vis(12))));
        assert_eq!(t.lookup("_:"), Some(VisemeTarget::Single(vis(0))));
        assert_eq!(t.lookup("h"), Some(VisemeTarget::Next));
        assert_eq!(t.lookup("w"), Some(VisemeTarget::Single(vis(14))));
    }

    #[test]
    fn unknown_phonemes_fall_back_by_dropping_modifiers() {
        let t = PhonemeVisemeTable::standard();
        assert_eq!(t.lookup("s:"), Some(VisemeTarget::Single(vis(7))));
        assert_eq!(t.lookup("l#"), Some(VisemeTarget::Single(vis(8))));
        assert_eq!(t.lookup("Q"), None);
        assert_eq!(t.lookup(":"), None);
        assert_eq!(t.lookup(""), None);
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = "phoneme,viseme,example,reasoning\np,1,pan,x\nb,15,bin,y\n";
        let e = PhonemeVisemeTable::parse(bad, Path::new("v.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("v.csv:3:1: expected a viseme"), "{e}");
        let dup = "phoneme,viseme,example,reasoning\np,1,pan,x\np,1,pan,x\n";
        assert!(PhonemeVisemeTable::parse(dup, Path::new("v.csv")).is_err());
        let header = "phon,viseme\np,1\n";
        assert!(PhonemeVisemeTable::parse(header, Path::new("v.csv")).is_err());
        assert!(parse_target("3>").is_none());
        assert_eq!(
            parse_target("3>4"),
            Some(VisemeTarget::Glide(vis(3), vis(4)))
        );
    }
}
