//! Feature-point tables as CSV: one row per MPEG-4 point with the mesh vertices it sits on.
//!
//! Columns (header required, order free): `fp` (label such as `3.5`), `vertices` (0-based
//! vertex indices separated by `;`), `combine` (`single` = one vertex, `mean` = the mean of
//! two or more vertices, `absent` = the mesh has no such point; optional, inferred from the
//! vertex count when the column or the cell is missing), `description` (optional free text).
//! This is the layout of the CANDIDE-3 table in `shared/data/candide3/feature-points.csv`.
//!
//! Two optional extensions make it fit any target:
//!
//! - **`mesh`**: the mesh the row's vertex ids are on, for multi-mesh files: a mesh (or node)
//!   name as the face names its meshes, `Name/1` for primitive 1 of a glTF mesh or node
//!   `Name`, `#3/1` for primitive 1 of glTF mesh 3 where names are missing or repeated (see
//!   [`crate::face::FaceModel::resolve_mesh_spec`]). An empty cell (or no column) names no
//!   mesh, which only a one-mesh face accepts.
//! - **`x`, `y`, `z`**: a position instead of vertex ids (in the file's world frame and units,
//!   as `fbakit face info` reports them); the point is snapped to the nearest vertex when
//!   attached to a face, and the snap distance reported. A row gives ids or a position,
//!   never both; `combine` is then empty or `single`.

use std::fmt;
use std::path::Path;

use serde::Serialize;

use crate::error::{EncodeError, Error, Location, ParseError, Result};
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::spec::FeaturePointId;
use glam::Vec3;

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
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointRow {
    /// The point.
    pub fp: FeaturePointId,
    /// 0-based vertex indices (empty for `absent` and for a position row).
    pub vertices: Vec<u32>,
    /// The mesh the vertices are on (module docs; `None`: the only mesh).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// A position to snap to the nearest vertex instead of vertex ids.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<Vec3>,
    /// How the vertices make the point.
    pub combine: Combine,
    /// Free text (`None` when the file has no description column or the cell is empty).
    pub description: Option<String>,
}

/// A whole table, rows in file order.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FeaturePointTable {
    /// The rows, including `absent` ones.
    pub rows: Vec<FeaturePointRow>,
}

impl FeaturePointTable {
    /// The bound points and the points given by position (absent rows are left out).
    pub fn to_set(&self) -> FeaturePointSet {
        self.rows
            .iter()
            .filter_map(|r| {
                if let Some(p) = r.position {
                    return Some(FeaturePoint::at(r.fp, p));
                }
                (!r.vertices.is_empty()).then(|| {
                    FeaturePoint::bound(
                        r.fp,
                        VertexBinding {
                            mesh: r.mesh.clone(),
                            vertices: r.vertices.clone(),
                        },
                    )
                })
            })
            .collect()
    }

    /// As [`FeaturePointTable::from_set`], keeping each binding's mesh name in the `mesh`
    /// column (for a face of several meshes, so the table reads back on the same file).
    pub fn from_set_with_meshes(set: &FeaturePointSet) -> FeaturePointTable {
        let mut t = Self::from_set(set);
        for r in &mut t.rows {
            r.mesh = set
                .get(r.fp)
                .and_then(|p| p.binding.as_ref())
                .and_then(|b| b.mesh.clone());
        }
        t
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
                    mesh: None,
                    position: None,
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
    let xyz = match (col("x"), col("y"), col("z")) {
        (Some(x), Some(y), Some(z)) => Some([x, y, z]),
        _ => None,
    };
    let (Some(c_fp), true) = (col("fp"), col("vertices").is_some() || xyz.is_some()) else {
        return Err(at(
            1,
            1,
            "a header with columns fp,vertices[,mesh][,combine][,description] or fp,x,y,z",
            Some(headers.iter().collect::<Vec<_>>().join(",")),
        ));
    };
    let c_vertices = col("vertices");
    let (c_combine, c_description, c_mesh) = (col("combine"), col("description"), col("mesh"));

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
        let c_ids = c_vertices.unwrap_or(c_fp);
        let vtext = c_vertices.map(field).unwrap_or("");
        if !vtext.is_empty() {
            for v in vtext.split(';') {
                let v = v.trim();
                let idx: u32 = v.parse().map_err(|_| {
                    at(
                        line,
                        c_ids + 1,
                        "0-based vertex indices separated by `;`",
                        Some(v.to_string()),
                    )
                })?;
                vertices.push(idx);
            }
        }
        let mesh = c_mesh
            .map(field)
            .filter(|m| !m.is_empty())
            .map(str::to_string);
        let description = c_description
            .map(field)
            .filter(|d| !d.is_empty())
            .map(str::to_string);
        let cells = xyz.map(|c| c.map(field));
        if let Some(cells) = cells.filter(|c| c.iter().any(|t| !t.is_empty())) {
            let cols = xyz.unwrap_or([0; 3]);
            if !vertices.is_empty() {
                return Err(at(
                    line,
                    c_ids + 1,
                    "vertex ids or a position x,y,z, not both",
                    Some(vtext.to_string()),
                ));
            }
            let mut p = [0.0f32; 3];
            for k in 0..3 {
                p[k] = cells[k]
                    .parse::<f32>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        at(
                            line,
                            cols[k] + 1,
                            "a finite coordinate (x, y and z all given)",
                            Some(cells[k].to_string()),
                        )
                    })?;
            }
            match c_combine.map(field).unwrap_or("") {
                "" | "single" => {}
                other => {
                    return Err(at(
                        line,
                        c_combine.unwrap_or(0) + 1,
                        "`single` (or nothing) for a position",
                        Some(other.to_string()),
                    ))
                }
            }
            rows.push(FeaturePointRow {
                fp,
                vertices,
                mesh,
                position: Some(Vec3::from(p)),
                combine: Combine::Single,
                description,
            });
            continue;
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
                c_ids + 1,
                need,
                Some(format!("{} vertices", vertices.len())),
            ));
        }
        rows.push(FeaturePointRow {
            fp,
            vertices,
            mesh,
            position: None,
            combine,
            description,
        });
    }
    Ok(FeaturePointTable { rows })
}

/// Writes the table as CSV text (always `fp,vertices,combine,description`; `mesh` and
/// `x,y,z` when a row needs them).
pub fn to_csv_string(table: &FeaturePointTable) -> Result<String> {
    let mut w = ::csv::WriterBuilder::new().from_writer(Vec::new());
    let enc = |e: ::csv::Error| EncodeError::new("CSV", e);
    let with_mesh = table.rows.iter().any(|r| r.mesh.is_some());
    let with_xyz = table.rows.iter().any(|r| r.position.is_some());
    let mut header = vec!["fp", "vertices"];
    if with_mesh {
        header.push("mesh");
    }
    if with_xyz {
        header.extend(["x", "y", "z"]);
    }
    header.extend(["combine", "description"]);
    w.write_record(&header).map_err(enc)?;
    for r in &table.rows {
        let vertices: Vec<String> = r.vertices.iter().map(u32::to_string).collect();
        let mut rec = vec![r.fp.to_string(), vertices.join(";")];
        if with_mesh {
            rec.push(r.mesh.clone().unwrap_or_default());
        }
        if with_xyz {
            match r.position {
                Some(p) => rec.extend([p.x, p.y, p.z].map(|v| v.to_string())),
                None => rec.extend([String::new(), String::new(), String::new()]),
            }
        }
        let combine = if r.position.is_some() {
            ""
        } else {
            r.combine.word()
        };
        rec.push(combine.to_string());
        rec.push(r.description.clone().unwrap_or_default());
        w.write_record(&rec).map_err(enc)?;
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
    fn positions_and_mesh_names() {
        let t = parse(
            "fp,vertices,mesh,x,y,z,combine\n\
             2.1,10,Body/1,,,,\n\
             3.5,,,1.5,-2,3e1,single\n\
             9.3,4;5,#3/0,,,,mean\n",
        )
        .unwrap();
        assert_eq!(t.rows[0].mesh.as_deref(), Some("Body/1"));
        assert_eq!(t.rows[1].position, Some(Vec3::new(1.5, -2.0, 30.0)));
        assert!(t.rows[1].vertices.is_empty());
        let set = t.to_set();
        let p = set.get("3.5".parse().unwrap()).unwrap();
        assert!(p.binding.is_none() && p.position.is_some());
        let b = set
            .get("9.3".parse().unwrap())
            .unwrap()
            .binding
            .clone()
            .unwrap();
        assert_eq!(b.mesh.as_deref(), Some("#3/0"));
        // Written and read back the same.
        assert_eq!(parse(&to_csv_string(&t).unwrap()).unwrap(), t);
        // Positions alone, no vertices column.
        let t = parse("fp,x,y,z\n2.1,0,1,2\n").unwrap();
        assert_eq!(t.rows[0].position, Some(Vec3::new(0.0, 1.0, 2.0)));
        for (text, want) in [
            (
                "fp,x,y,z\n2.1,0,,2\n",
                "t.csv:2:3: expected a finite coordinate",
            ),
            (
                "fp,x,y,z\n2.1,0,NaN,2\n",
                "t.csv:2:3: expected a finite coordinate",
            ),
            (
                "fp,vertices,x,y,z\n2.1,3,0,1,2\n",
                "t.csv:2:2: expected vertex ids or a position",
            ),
            (
                "fp,x,y,z,combine\n2.1,0,1,2,mean\n",
                "t.csv:2:5: expected `single`",
            ),
            (
                "fp,x,y\n2.1,0,1\n",
                "t.csv:1:1: expected a header with columns",
            ),
        ] {
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
                mesh: None,
                position: None,
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
