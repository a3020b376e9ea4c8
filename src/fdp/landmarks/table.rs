//! The preset tables `specs/landmarks-*.csv`: which landmark (or which derivation rule) gives
//! each MPEG-4 feature point, with the reasoning.
//!
//! The CSV files are the single source: they are compiled into the binary with `include_str!`
//! and parsed once; `tests::presets_parse` keeps them well-formed.

use std::fmt;
use std::str::FromStr;
use std::sync::OnceLock;

use serde::Serialize;

use crate::spec::FeaturePointId;

/// How a preset row places its feature point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rule {
    /// The vertex of one landmark.
    Landmark,
    /// Halfway along the polyline through the row's landmarks, on the nearest skin vertex.
    ArcMidpoint,
    /// The visible upper-lid margin above the pupil (the lowest front-facing lid point).
    UpperLidMargin,
    /// The visible lower-lid margin below the pupil.
    LowerLidMargin,
    /// The front of the eyeball (a sphere-shaped part behind the eye opening), else the
    /// centre of the eye's lid contour.
    Pupil,
    /// The most protruding midline point between the lower lip and the chin bottom.
    ChinBoss,
    /// The skin in front of the cheek, beside the nose-to-mouth span.
    Cheek,
    /// The skin below the outer half of the eye.
    Cheekbone,
    /// The outer edge of the nose wing seen from the front (steepest sideways drop).
    NostrilBorder,
    /// The nose ridge a little below halfway from the eyes to the nose bottom.
    NoseBump,
    /// The highest midline point, when the mesh includes the skull.
    TopOfSkull,
    /// The midline point at the back of the head nearest to eye height, when the mesh
    /// includes the skull.
    BackOfSkull,
}

impl Rule {
    const ALL: [Rule; 12] = [
        Rule::Landmark,
        Rule::ArcMidpoint,
        Rule::UpperLidMargin,
        Rule::LowerLidMargin,
        Rule::Pupil,
        Rule::ChinBoss,
        Rule::Cheek,
        Rule::Cheekbone,
        Rule::NostrilBorder,
        Rule::NoseBump,
        Rule::TopOfSkull,
        Rule::BackOfSkull,
    ];

    /// The word used in the `rule` column.
    pub fn word(self) -> &'static str {
        match self {
            Rule::Landmark => "landmark",
            Rule::ArcMidpoint => "arc-midpoint",
            Rule::UpperLidMargin => "upper-lid-margin",
            Rule::LowerLidMargin => "lower-lid-margin",
            Rule::Pupil => "pupil",
            Rule::ChinBoss => "chin-boss",
            Rule::Cheek => "cheek",
            Rule::Cheekbone => "cheekbone",
            Rule::NostrilBorder => "nostril-border",
            Rule::NoseBump => "nose-bump",
            Rule::TopOfSkull => "top-of-skull",
            Rule::BackOfSkull => "back-of-skull",
        }
    }

    /// How many landmarks the rule takes: `(min, max)`.
    fn landmark_count(self) -> (usize, usize) {
        match self {
            Rule::Landmark => (1, 1),
            Rule::ArcMidpoint => (2, usize::MAX),
            _ => (0, 0),
        }
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.word())
    }
}

impl FromStr for Rule {
    type Err = String;

    fn from_str(s: &str) -> Result<Rule, String> {
        Rule::ALL
            .into_iter()
            .find(|r| r.word() == s)
            .ok_or_else(|| {
                let words: Vec<&str> = Rule::ALL.iter().map(|r| r.word()).collect();
                format!("unknown rule `{s}` (expected one of {})", words.join(", "))
            })
    }
}

/// One row of a preset table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PresetRow {
    /// The feature point the row places.
    pub fp: FeaturePointId,
    /// 0-based landmark indices (positions in the scheme's landmark list).
    pub landmarks: Vec<usize>,
    /// How the point is placed.
    pub rule: Rule,
    /// Why this landmark or rule gives this point.
    pub reasoning: String,
}

pub(super) const IBUG68_CSV: &str = include_str!("../../../specs/landmarks-ibug68.csv");
pub(super) const MEDIAPIPE468_CSV: &str = include_str!("../../../specs/landmarks-mediapipe468.csv");

/// Parses a preset table; `landmark_count` bounds the landmark indices. Errors name the
/// 1-based line.
pub(super) fn parse_preset(text: &str, landmark_count: usize) -> Result<Vec<PresetRow>, String> {
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let headers = reader.headers().map_err(|e| e.to_string())?.clone();
    let expected = ["fp", "landmarks", "rule", "reasoning"];
    if headers.iter().collect::<Vec<_>>() != expected {
        return Err(format!("header must be {}", expected.join(",")));
    }
    let mut rows: Vec<PresetRow> = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| e.to_string())?;
        let line = record.position().map_or(0, |p| p.line());
        let at = |msg: String| format!("line {line}: {msg}");
        let fp: FeaturePointId = record[0]
            .parse()
            .map_err(|_| at(format!("`{}` is not a feature point label", &record[0])))?;
        let landmarks = record[1]
            .split(';')
            .filter(|s| !s.trim().is_empty())
            .map(|s| match s.trim().parse::<usize>() {
                Ok(i) if i < landmark_count => Ok(i),
                _ => Err(at(format!(
                    "landmark `{s}` is not an index below {landmark_count}"
                ))),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let rule: Rule = record[2].parse().map_err(at)?;
        let (lo, hi) = rule.landmark_count();
        if landmarks.len() < lo || landmarks.len() > hi {
            return Err(at(format!(
                "rule {rule} takes {lo}..{} landmarks, the row has {}",
                if hi == usize::MAX {
                    "n".to_string()
                } else {
                    hi.to_string()
                },
                landmarks.len()
            )));
        }
        if rows.iter().any(|r| r.fp == fp) {
            return Err(at(format!("feature point {fp} is listed twice")));
        }
        rows.push(PresetRow {
            fp,
            landmarks,
            rule,
            reasoning: record[3].to_string(),
        });
    }
    Ok(rows)
}

/// A preset, parsed once per process.
pub(super) fn preset(
    cell: &'static OnceLock<Vec<PresetRow>>,
    text: &'static str,
    count: usize,
) -> &'static [PresetRow] {
    cell.get_or_init(|| {
        // The tables are compiled in and checked by the tests below, so a failure here is a
        // build defect, not an input error.
        parse_preset(text, count).expect("bundled landmark preset is well-formed")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_parse() {
        let ibug = parse_preset(IBUG68_CSV, 68).unwrap();
        let mp = parse_preset(MEDIAPIPE468_CSV, 468).unwrap();
        assert!(
            ibug.len() >= 50 && mp.len() >= 50,
            "{} {}",
            ibug.len(),
            mp.len()
        );
        for rows in [&ibug, &mp] {
            assert!(rows.iter().all(|r| !r.reasoning.trim().is_empty()));
        }
        // No landmark is used for two different single-landmark points.
        for rows in [&ibug, &mp] {
            let mut seen = std::collections::HashSet::new();
            for r in rows.iter().filter(|r| r.rule == Rule::Landmark) {
                assert!(
                    seen.insert(r.landmarks[0]),
                    "landmark {} reused",
                    r.landmarks[0]
                );
            }
        }
    }

    #[test]
    fn bad_rows_are_located() {
        let head = "fp,landmarks,rule,reasoning\n";
        let e = parse_preset(&format!("{head}2.1,70,landmark,x\n"), 68).unwrap_err();
        assert!(e.contains("line 2") && e.contains("below 68"), "{e}");
        let e = parse_preset(&format!("{head}2.1,,landmark,x\n"), 68).unwrap_err();
        assert!(e.contains("takes 1..1"), "{e}");
        let e = parse_preset(&format!("{head}2.1,,blink,x\n"), 68).unwrap_err();
        assert!(e.contains("unknown rule `blink`"), "{e}");
        let e = parse_preset(&format!("{head}1.1,,cheek,x\n"), 68).unwrap_err();
        assert!(e.contains("not a feature point"), "{e}");
        let e = parse_preset(&format!("{head}2.1,,cheek,x\n2.1,,cheek,y\n"), 68).unwrap_err();
        assert!(e.contains("line 3") && e.contains("twice"), "{e}");
        let e = parse_preset("a,b\n", 68).unwrap_err();
        assert!(e.contains("header"), "{e}");
    }
}
