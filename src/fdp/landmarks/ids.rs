//! Landmark vertex-id files: which mesh vertex is each landmark.
//!
//! Three layouts are read:
//! - JSON object with the ICT-FaceKit key `idx_to_landmark_verts` holding the array;
//! - JSON array of vertex indices;
//! - CSV / plain text: vertex indices separated by commas, whitespace or line breaks, with an
//!   optional header line (a first line that is not a number).
//!
//! Every id keeps its place in the file (JSON path or line:column) so a bad id, a duplicate or
//! an id beyond the mesh's vertices is reported where it is written.

use std::path::Path;

use serde_json::Value;

use crate::error::{Error, Location, ParseError, Result};
use crate::fdp::FdpError;

/// The ICT-FaceKit key holding the 68 iBUG landmark vertex ids.
pub const ICT_LANDMARK_KEY: &str = "idx_to_landmark_verts";

/// Landmark vertex ids read from a file, with where each one is written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LandmarkIds {
    /// 0-based mesh vertex index of each landmark, in landmark order.
    pub ids: Vec<u32>,
    /// Where each id is written (`file: key[3]` or `file:4:7`), for messages.
    pub places: Vec<String>,
}

impl LandmarkIds {
    /// Ids without a file (places are `landmark N`).
    pub fn from_ids(ids: Vec<u32>) -> LandmarkIds {
        let places = (0..ids.len()).map(|i| format!("landmark {i}")).collect();
        LandmarkIds { ids, places }
    }

    /// The identity list `0..count` (a mesh whose vertex order is the landmark order).
    pub fn identity(count: usize) -> LandmarkIds {
        let ids = (0..count as u32).collect();
        let places = (0..count).map(|i| format!("vertex {i}")).collect();
        LandmarkIds { ids, places }
    }

    /// Checks the count, the range against `vertex_count` and duplicates; each problem
    /// names the place of the offending id. `what` names the source in the count message.
    pub fn check(&self, expected: usize, vertex_count: usize, what: &str) -> Result<()> {
        if self.ids.len() != expected {
            return Err(FdpError::LandmarkCount {
                what: what.to_string(),
                expected,
                found: self.ids.len(),
            }
            .into());
        }
        let mut first_at: std::collections::HashMap<u32, usize> = Default::default();
        for (i, &v) in self.ids.iter().enumerate() {
            if v as usize >= vertex_count {
                return Err(FdpError::LandmarkBeyondMesh {
                    place: self.places[i].clone(),
                    landmark: i,
                    vertex: v,
                    vertex_count,
                }
                .into());
            }
            if let Some(&j) = first_at.get(&v) {
                return Err(FdpError::LandmarkRepeated {
                    place: self.places[i].clone(),
                    landmark: i,
                    vertex: v,
                    first: j,
                    first_place: self.places[j].clone(),
                }
                .into());
            }
            first_at.insert(v, i);
        }
        Ok(())
    }
}

/// Reads a landmark id file (layout chosen by content: JSON when it starts with `{` or `[`).
pub fn read_landmark_ids(path: &Path) -> Result<LandmarkIds> {
    let text = crate::io::read_text(path)?;
    parse_landmark_ids(&text, path)
}

/// Reads landmark ids from `reader` (UTF-8, bounded by
/// [`crate::io::DEFAULT_MAX_INPUT_BYTES`]); `source` names it in messages. The layout is
/// chosen by content as in [`read_landmark_ids`].
///
/// ```
/// use std::path::Path;
/// let ids = fbakit::fdp::landmarks::read_landmark_ids_from(&b"[4, 8, 15]"[..], Path::new("ids.json"))?;
/// assert_eq!(ids.ids, vec![4, 8, 15]);
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read_landmark_ids_from<R: std::io::BufRead>(
    reader: R,
    source: &Path,
) -> Result<LandmarkIds> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_landmark_ids(&text, source)
}

/// Parses landmark ids; `file` names the text in messages.
pub fn parse_landmark_ids(text: &str, file: &Path) -> Result<LandmarkIds> {
    let trimmed = text.trim_start_matches('\u{feff}').trim_start();
    if trimmed.starts_with('{') || trimmed.starts_with('[') {
        parse_json(file, text)
    } else {
        parse_list(file, text)
    }
}

fn parse_json(file: &Path, text: &str) -> Result<LandmarkIds> {
    let value: Value = serde_json::from_str(text.trim_start_matches('\u{feff}')).map_err(|e| {
        Error::Parse(ParseError {
            location: Location {
                file: file.to_path_buf(),
                line: e.line().max(1),
                column: e.column().max(1),
            },
            expected: format!("well-formed JSON ({e})"),
            found: None,
        })
    })?;
    let (array, path) = match &value {
        Value::Array(a) => (a, String::new()),
        Value::Object(map) => match map.get(ICT_LANDMARK_KEY) {
            Some(Value::Array(a)) => (a, ICT_LANDMARK_KEY.to_string()),
            Some(_) => {
                return Err(FdpError::LandmarkKeyNotArray {
                    file: file.to_path_buf(),
                }
                .into())
            }
            None => {
                return Err(FdpError::NotLandmarkJson {
                    file: file.to_path_buf(),
                }
                .into())
            }
        },
        _ => {
            return Err(FdpError::NotLandmarkJson {
                file: file.to_path_buf(),
            }
            .into())
        }
    };
    let mut ids = Vec::with_capacity(array.len().min(100_000));
    let mut places = Vec::with_capacity(ids.capacity());
    for (i, v) in array.iter().enumerate() {
        let place = format!("{}: {path}[{i}]", file.display());
        match v.as_u64().and_then(|n| u32::try_from(n).ok()) {
            Some(n) => ids.push(n),
            None => {
                return Err(FdpError::BadVertexIndex {
                    place,
                    found: v.to_string(),
                }
                .into())
            }
        }
        places.push(place);
    }
    Ok(LandmarkIds { ids, places })
}

fn parse_list(file: &Path, text: &str) -> Result<LandmarkIds> {
    let mut ids = Vec::new();
    let mut places = Vec::new();
    let mut offset = 0usize;
    let mut first_line = true;
    for line in text.split_inclusive('\n') {
        let line_start = offset;
        offset += line.len();
        let content = line.trim_end_matches(['\n', '\r']);
        if content.trim().is_empty() {
            continue;
        }
        // An optional header: a first non-empty line that does not start with a digit.
        let skip_header = first_line
            && !content
                .trim_start_matches('\u{feff}')
                .trim_start()
                .starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+');
        first_line = false;
        if skip_header {
            continue;
        }
        let mut pos = 0usize;
        for token in content.split(|c: char| c == ',' || c == ';' || c.is_whitespace()) {
            let token_offset = line_start + pos;
            pos += token.len() + 1;
            if token.is_empty() {
                continue;
            }
            match token.parse::<u32>() {
                Ok(n) => {
                    ids.push(n);
                    places.push(Location::from_offset(file, text, token_offset).to_string());
                }
                Err(_) => {
                    return Err(Error::Parse(ParseError::at_offset(
                        file,
                        text,
                        token_offset,
                        format!("a vertex index (an integer from 0 to {})", u32::MAX),
                    )))
                }
            }
        }
    }
    Ok(LandmarkIds { ids, places })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(name: &str, text: &str) -> Result<LandmarkIds> {
        parse_landmark_ids(text, Path::new(name))
    }

    #[test]
    fn reader_matches_text_and_names_its_source() {
        let text = "vertex\n4\n5, 6\n";
        let from = read_landmark_ids_from(text.as_bytes(), Path::new("r.csv")).unwrap();
        assert_eq!(from.ids, parse("r.csv", text).unwrap().ids);
        assert_eq!(from.places[1], "r.csv:3:1");
        let e = read_landmark_ids_from(&b"\xff"[..], Path::new("bad.csv")).unwrap_err();
        assert!(e.to_string().contains("bad.csv"), "{e}");
    }

    #[test]
    fn reads_the_three_layouts() {
        let ict = parse(
            "v.json",
            r#"{"expressions": [], "idx_to_landmark_verts": [5, 7, 9]}"#,
        )
        .unwrap();
        assert_eq!(ict.ids, vec![5, 7, 9]);
        assert_eq!(ict.places[1], "v.json: idx_to_landmark_verts[1]");
        assert_eq!(parse("a.json", "[1,2,3]").unwrap().ids, vec![1, 2, 3]);
        let csv = parse("a.csv", "vertex\n4\n5, 6\n\n7;8 9\n").unwrap();
        assert_eq!(csv.ids, vec![4, 5, 6, 7, 8, 9]);
        assert_eq!(csv.places[2], "a.csv:3:4");
    }

    #[test]
    fn bad_ids_are_located() {
        let e = parse("v.json", r#"{"idx_to_landmark_verts": [1, -2]}"#).unwrap_err();
        assert!(
            e.to_string()
                .contains("v.json: idx_to_landmark_verts[1]: expected a vertex index"),
            "{e}"
        );
        let e = parse("v.json", "[1, 2.5]").unwrap_err();
        assert!(e.to_string().contains("v.json: [1]"), "{e}");
        let e = parse("v.json", r#"{"other": [1]}"#).unwrap_err();
        assert!(e.to_string().contains("idx_to_landmark_verts"), "{e}");
        let e = parse("v.json", "[1, 2").unwrap_err();
        assert!(e.to_string().starts_with("v.json:1:"), "{e}");
        let e = parse("a.csv", "1\n2\nx3\n").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("a.csv:3:1: expected a vertex index"),
            "{e}"
        );
        let e = parse("a.csv", "1, 99999999999\n").unwrap_err();
        assert!(e.to_string().starts_with("a.csv:1:4"), "{e}");
    }

    #[test]
    fn check_names_count_range_and_duplicates() {
        let ids = parse("a.csv", "0\n1\n2\n1\n").unwrap();
        let e = ids.check(3, 10, "a.csv").unwrap_err();
        assert!(
            e.to_string()
                .contains("expected 3 landmark vertex ids, found 4"),
            "{e}"
        );
        let e = ids.check(4, 10, "a.csv").unwrap_err();
        assert!(
            e.to_string()
                .contains("a.csv:4:1: landmark 3 repeats vertex 1 of landmark 1 (a.csv:2:1)"),
            "{e}"
        );
        let e = ids.check(4, 2, "a.csv").unwrap_err();
        assert!(
            e.to_string()
                .contains("a.csv:3:1: landmark 2 is vertex 2, beyond the mesh's 2 vertices"),
            "{e}"
        );
        assert!(LandmarkIds::identity(4).check(4, 4, "x").is_ok());
    }
}
