//! Feature-point tables as CSV: one row per MPEG-4 point with the mesh vertices it sits on.
//!
//! Columns (header required, order free): `fp` (label such as `3.5`), `vertices` (0-based
//! vertex indices separated by `;`), `combine` (`single` = one vertex, `mean` = the mean of
//! two or more vertices, `absent` = the mesh has no such point; optional, inferred from the
//! vertex count when the column or the cell is missing), `description` (optional free text).
//! This is the layout of the CANDIDE-3 table in `shared/data/candide3/feature-points.csv`.
//! The table has no mesh column: bindings it produces name no mesh.

use std::fmt;
use std::path::Path;

use serde::Serialize;

use crate::error::{EncodeError, Error, Location, ParseError, Result};
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::spec::FeaturePointId;

/// How a row's vertices make the point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Combine {
    /// Exactly one vertex.
    Single,
    /// The mean of two or more vertices (e.g. a pupil centre from the iris corners).
    Mean,
    /// The mesh has no such point; no vertices.
    Absent,
}

impl Combine {
    /// The word used in the `combine` column.
    pub fn word(self) -> &'static str {
        match self {
            Combine::Single => "single",
            Combine::Mean => "mean",
            Combine::Absent => "absent",
        }
    }

    fn for_count(n: usize) -> Combine {
        match n {
            0 => Combine::Absent,
            1 => Combine::Single,
            _ => Combine::Mean,
        }
    }
}

impl fmt::Display for Combine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.word())
    }
}

/// One row of the table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct FeaturePointRow {
    /// The point.
    pub fp: FeaturePointId,
    /// 0-based vertex indices (empty for `absent`).
    pub vertices: Vec<u32>,
    /// How the vertices make the point.
    pub combine: Combine,
    /// Free text (`None` when the file has no description column or the cell is empty).
    pub description: Option<String>,
}

/// A whole table, rows in file order.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct FeaturePointTable {
    /// The rows, including `absent` ones.
    pub rows: Vec<FeaturePointRow>,
}

impl FeaturePointTable {
    /// The bound points (absent rows are left out).
    pub fn to_set(&self) -> FeaturePointSet {
        self.rows
            .iter()
            .filter(|r| !r.vertices.is_empty())
            .map(|r| {
                FeaturePoint::bound(
                    r.fp,
                    VertexBinding {
                        mesh: None,
                        vertices: r.vertices.clone(),
                    },
                )
            })
            .collect()
    }

    /// A table of the points of `set` that have a vertex binding (mesh names are dropped:
    /// the CSV layout has no mesh column).
    pub fn from_set(set: &FeaturePointSet) -> FeaturePointTable {
        let rows = set
            .iter()
            .filter_map(|p| {
                let b = p.binding.as_ref()?;
                Some(FeaturePointRow {
                    fp: p.id,
                    vertices: b.vertices.clone(),
                    combine: Combine::for_count(b.vertices.len()),
                    description: None,
                })
            })
            .collect();
        FeaturePointTable { rows }
    }
}

/// Reads a feature-point CSV file.
pub fn read_csv_file(path: &Path) -> Result<FeaturePointTable> {
    let text = crate::io::read_text(path)?;
    parse_csv(&text, path)
}

/// Parses feature-point CSV text; `file` is used in error locations only.
pub fn parse_csv(text: &str, file: &Path) -> Result<FeaturePointTable> {
    let mut reader = ::csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .trim(::csv::Trim::All)
        .from_reader(text.as_bytes());
    let at = |line: u64, column: usize, expected: &str, found: Option<String>| {
        Error::Parse(ParseError {
            location: Location {
                file: file.to_path_buf(),
                line: line.max(1) as usize,
                column,
            },
            expected: expected.to_string(),
            found,
        })
    };
    let csv_error = |e: ::csv::Error| {
        let line = e.position().map_or(1, |p| p.line());
        at(line, 1, "a CSV record", Some(e.to_string()))
    };
    let headers = reader.headers().map_err(csv_error)?.clone();
    let col = |name: &str| headers.iter().position(|h| h.eq_ignore_ascii_case(name));
    let (Some(c_fp), Some(c_vertices)) = (col("fp"), col("vertices")) else {
        return Err(at(
            1,
            1,
            "a header with columns fp,vertices[,combine][,description]",
            Some(headers.iter().collect::<Vec<_>>().join(",")),
        ));
    };
    let (c_combine, c_description) = (col("combine"), col("description"));

    let mut rows: Vec<FeaturePointRow> = Vec::new();
    let mut seen = std::collections::BTreeMap::new();
    for record in reader.records() {
        let record = record.map_err(csv_error)?;
        let line = record.position().map_or(1, |p| p.line());
        // A blank line parses as one empty field; skip it.
        if record.iter().all(|f| f.is_empty()) {
            continue;
        }
        let field = |c: usize| record.get(c).unwrap_or("");
        let fp: FeaturePointId = field(c_fp).parse().map_err(|msg: String| {
            at(
                line,
                c_fp + 1,
                "a feature point label such as 3.5 (groups 2..11)",
                Some(msg),
            )
        })?;
        if let Some(first) = seen.insert(fp, line) {
            return Err(at(
                line,
                c_fp + 1,
                &format!("each feature point once ({fp} is already on line {first})"),
                Some(fp.to_string()),
            ));
        }
        let mut vertices = Vec::new();
        let vtext = field(c_vertices);
        if !vtext.is_empty() {
            for v in vtext.split(';') {
                let v = v.trim();
                let idx: u32 = v.parse().map_err(|_| {
                    at(
                        line,
                        c_vertices + 1,
                        "0-based vertex indices separated by `;`",
                        Some(v.to_string()),
                    )
                })?;
                vertices.push(idx);
            }
        }
        let combine = match c_combine.map(field).unwrap_or("") {
            "" => Combine::for_count(vertices.len()),
            "single" => Combine::Single,
            "mean" => Combine::Mean,
            "absent" => Combine::Absent,
            other => {
                return Err(at(
                    line,
                    c_combine.unwrap_or(0) + 1,
                    "single, mean or absent",
                    Some(other.to_string()),
                ))
            }
        };
        let count_ok = match combine {
            Combine::Single => vertices.len() == 1,
            Combine::Mean => vertices.len() >= 2,
            Combine::Absent => vertices.is_empty(),
        };
        if !count_ok {
            let need = match combine {
                Combine::Single => "exactly one vertex for `single`",
                Combine::Mean => "two or more vertices for `mean`",
                Combine::Absent => "no vertices for `absent`",
            };
            return Err(at(
                line,
                c_vertices + 1,
                need,
                Some(format!("{} vertices", vertices.len())),
            ));
        }
        let description = c_description
            .map(field)
            .filter(|d| !d.is_empty())
            .map(str::to_string);
        rows.push(FeaturePointRow {
            fp,
            vertices,
            combine,
            description,
        });
    }
    Ok(FeaturePointTable { rows })
}

/// Writes the table as CSV text (always with all four columns).
pub fn to_csv_string(table: &FeaturePointTable) -> Result<String> {
    let mut w = ::csv::WriterBuilder::new().from_writer(Vec::new());
    let enc = |e: ::csv::Error| EncodeError::new("CSV", e);
    w.write_record(["fp", "vertices", "combine", "description"])
        .map_err(enc)?;
    for r in &table.rows {
        let vertices: Vec<String> = r.vertices.iter().map(u32::to_string).collect();
        w.write_record([
            r.fp.to_string().as_str(),
            vertices.join(";").as_str(),
            r.combine.word(),
            r.description.as_deref().unwrap_or(""),
        ])
        .map_err(enc)?;
    }
    let bytes = w.into_inner().map_err(|e| EncodeError::new("CSV", e))?;
    String::from_utf8(bytes).map_err(|e| EncodeError::new("CSV", e).into())
}

/// Writes the table to `path` atomically.
pub fn write_csv_file(path: &Path, table: &FeaturePointTable) -> Result<()> {
    crate::io::write_atomic(path, to_csv_string(table)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse(text: &str) -> Result<FeaturePointTable> {
        parse_csv(text, Path::new("t.csv"))
    }

    #[test]
    fn reads_candide_layout() {
        let t = parse(
            "fp,vertices,combine,description\n\
             2.1,10,single,Bottom of the chin\n\
             3.5,67;68;71;72,mean,\"Center of the pupil, left\"\n\
             6.1,,absent,Tongue\n",
        )
        .unwrap();
        assert_eq!(t.rows.len(), 3);
        assert_eq!(t.rows[1].vertices, [67, 68, 71, 72]);
        assert_eq!(
            t.rows[1].description.as_deref(),
            Some("Center of the pupil, left")
        );
        let set = t.to_set();
        assert_eq!(set.len(), 2);
        assert!(!set.contains("6.1".parse().unwrap()));
    }

    #[test]
    fn description_and_combine_columns_are_optional() {
        let t = parse("fp,vertices\n2.1,10\n3.5,1;2\n7.1,\n").unwrap();
        let c: Vec<Combine> = t.rows.iter().map(|r| r.combine).collect();
        assert_eq!(c, [Combine::Single, Combine::Mean, Combine::Absent]);
        assert!(t.rows.iter().all(|r| r.description.is_none()));
        // Columns in another order, blank lines skipped.
        let t = parse("vertices,fp\n\n5,2.2\n").unwrap();
        assert_eq!(t.rows[0].fp.to_string(), "2.2");
    }

    #[test]
    fn located_errors() {
        let cases = [
            (
                "fp,vertices\n1.1,3\n",
                "t.csv:2:1: expected a feature point label",
            ),
            (
                "fp,vertices\n2.1,x\n",
                "t.csv:2:2: expected 0-based vertex indices",
            ),
            (
                "fp,vertices\n2.1,-1\n",
                "t.csv:2:2: expected 0-based vertex indices",
            ),
            (
                "fp,vertices\n2.1,99999999999\n",
                "t.csv:2:2: expected 0-based",
            ),
            (
                "fp,vertices,combine\n2.1,1;2,single\n",
                "t.csv:2:2: expected exactly one vertex",
            ),
            (
                "fp,vertices,combine\n2.1,1,mean\n",
                "t.csv:2:2: expected two or more",
            ),
            (
                "fp,vertices,combine\n2.1,1,absent\n",
                "t.csv:2:2: expected no vertices",
            ),
            (
                "fp,vertices,combine\n2.1,1,avg\n",
                "t.csv:2:3: expected single, mean or absent",
            ),
            (
                "fp,vertices\n2.1,1\n2.1,2\n",
                "t.csv:3:1: expected each feature point once (2.1 is already on line 2)",
            ),
            (
                "a,b\n",
                "t.csv:1:1: expected a header with columns fp,vertices",
            ),
            ("", "t.csv:1:1: expected a header"),
        ];
        for (text, want) in cases {
            let e = parse(text).unwrap_err().to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn writer_round_trips_quotes_and_commas() {
        let t =
            parse("fp,vertices,combine,description\n3.5,1;2,mean,\"a, \"\"b\"\"\"\n9.1,,absent,\n")
                .unwrap();
        let text = to_csv_string(&t).unwrap();
        assert_eq!(parse(&text).unwrap(), t);
    }

    fn arb_row() -> impl Strategy<Value = FeaturePointRow> {
        (
            0usize..84,
            proptest::collection::vec(any::<u32>(), 0..5),
            proptest::option::of("[ -~]{1,20}"),
        )
            .prop_map(|(o, vertices, description)| FeaturePointRow {
                fp: FeaturePointId::from_ordinal(o).unwrap(),
                combine: Combine::for_count(vertices.len()),
                vertices,
                // Cells are trimmed when read, so only trimmed non-empty text survives.
                description: description
                    .map(|d| d.trim().to_string())
                    .filter(|d| !d.is_empty()),
            })
    }

    proptest! {
        #[test]
        fn round_trip(rows in proptest::collection::vec(arb_row(), 0..30)) {
            let mut seen = std::collections::BTreeSet::new();
            let rows: Vec<_> = rows.into_iter().filter(|r| seen.insert(r.fp)).collect();
            let t = FeaturePointTable { rows };
            let text = to_csv_string(&t).unwrap();
            prop_assert_eq!(parse(&text).unwrap(), t);
        }
    }
}
