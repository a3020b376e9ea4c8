//! A summary of a face for people and scripts (`fbakit face info`): meshes, feature points,
//! FAPU, FAT coverage and how feature points were matched.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use super::vrml::{FaceFileKind, FaceReadReport, FeaturePointMatch};
use super::FaceModel;
use crate::fat::{TableKey, TransformField};
use crate::spec::{FapId, FapuKind, FeaturePointId};

/// One mesh.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshSummary {
    /// DEF name.
    pub name: String,
    /// Enclosing transforms, outermost first (`head > jaw`), or empty.
    pub transform_path: String,
    /// Vertex count.
    pub vertices: usize,
    /// Polygon count.
    pub polygons: usize,
    /// Triangles after fan triangulation (Σ (corners − 2)).
    pub triangles: usize,
    /// Polygon count per corner count.
    pub arity: BTreeMap<usize, usize>,
}

/// Feature points present and missing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointSummary {
    /// Labels present.
    pub present: Vec<String>,
    /// Labels of the standard the face lacks.
    pub missing: Vec<String>,
    /// Present points bound to mesh vertices.
    pub bound: usize,
    /// Each present point's position in the face frame (the file's world frame and units),
    /// by label: what a feature-point CSV's `fp,x,y,z` rows take.
    pub positions: BTreeMap<String, [f32; 3]>,
}

impl FeaturePointSummary {
    /// The positions as a feature-point CSV (`fp,x,y,z` header, one line per point in the
    /// standard's order), preceded by a blank line.
    pub fn positions_csv(&self) -> String {
        let mut s = String::from("\nfp,x,y,z\n");
        let mut points: Vec<(FeaturePointId, &[f32; 3])> = self
            .positions
            .iter()
            .filter_map(|(k, p)| Some((k.parse::<FeaturePointId>().ok()?, p)))
            .collect();
        points.sort_by_key(|(id, _)| *id);
        for (id, [x, y, z]) in points {
            let _ = writeln!(s, "{id},{x},{y},{z}");
        }
        s
    }
}

/// The FAP units, or why they cannot be measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapuSummary {
    /// Unit per FAPU kind (model length per unit; AU in radians), when measurable.
    pub units: Option<BTreeMap<String, f64>>,
    /// Why not, when not.
    pub error: Option<String>,
}

/// One key's tables.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TableSummary {
    /// The key.
    pub key: TableKey,
    /// Display label (`FAP 3 open_jaw`, `viseme 7 (...)`).
    pub label: String,
    /// Vertex entries over all meshes.
    pub vertices: usize,
    /// Meshes moved.
    pub meshes: usize,
    /// Largest interval count of its meshes.
    pub intervals: usize,
    /// Driven transform fields as `name.field`.
    pub transforms: Vec<String>,
}

/// FAT coverage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FatSummary {
    /// `FaceDefTables` nodes.
    pub table_count: usize,
    /// Per key, in key order (several nodes of one key are merged).
    pub tables: Vec<TableSummary>,
    /// Low-level FAPs (3..=68) without a table.
    pub faps_without_table: Vec<u8>,
    /// Visemes (1..=14) with a table.
    pub visemes: Vec<u8>,
    /// Expressions (1..=6) with a table.
    pub expressions: Vec<u8>,
}

/// Feature points matched to the nearest vertex by the reader.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MatchSummary {
    /// Count.
    pub count: usize,
    /// Largest distance.
    pub max_distance: f32,
    /// Every match.
    pub matches: Vec<FeaturePointMatch>,
}

/// Everything `face info` shows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaceSummary {
    /// Face name.
    pub name: String,
    /// What the file held (VRML files only).
    pub kind: Option<FaceFileKind>,
    /// Meshes.
    pub meshes: Vec<MeshSummary>,
    /// Transform count.
    pub transforms: usize,
    /// Total vertices.
    pub vertices: usize,
    /// Feature points.
    pub feature_points: FeaturePointSummary,
    /// FAPU.
    pub fapu: FapuSummary,
    /// The length unit assumed for the face (glTF export scales it to metres).
    pub units: Option<crate::face::units::UnitGuess>,
    /// FAT coverage.
    pub fat: FatSummary,
    /// Feature points matched to vertices, when the reader matched any.
    pub fp_matches: Option<MatchSummary>,
    /// Reader diagnostics (errors and warnings).
    pub diagnostics: Vec<crate::error::Diagnostic>,
}

fn transform_path(face: &FaceModel, t: Option<usize>) -> String {
    let mut chain = Vec::new();
    let mut cur = t;
    // Parents come first, so following `parent` strictly decreases; the bound guards bad input.
    while let Some(i) = cur.filter(|&i| i < face.transforms.len()) {
        chain.push(face.transforms[i].name.as_str());
        if chain.len() > face.transforms.len() {
            break;
        }
        cur = face.transforms[i].parent.filter(|&p| p < i);
    }
    chain.reverse();
    chain.join(" > ")
}

fn field_name(f: TransformField) -> &'static str {
    match f {
        TransformField::Rotation => "rotation",
        TransformField::Scale => "scale",
        TransformField::Translation => "translation",
    }
}

/// Summarises a face and what reading it reported.
pub fn summarize(face: &FaceModel, report: Option<&FaceReadReport>) -> FaceSummary {
    let meshes = face
        .meshes
        .iter()
        .map(|m| {
            let mut arity = BTreeMap::new();
            let mut triangles = 0;
            for p in m.mesh.polygons.iter() {
                *arity.entry(p.len()).or_insert(0) += 1;
                triangles += p.len().saturating_sub(2);
            }
            MeshSummary {
                name: m.name.clone(),
                transform_path: transform_path(face, m.transform),
                vertices: m.mesh.vertex_count(),
                polygons: m.mesh.face_count(),
                triangles,
                arity,
            }
        })
        .collect();
    let feature_points = FeaturePointSummary {
        present: face
            .feature_points
            .iter()
            .map(|p| p.id.to_string())
            .collect(),
        missing: face
            .feature_points
            .missing()
            .iter()
            .map(|id| id.to_string())
            .collect(),
        bound: face
            .feature_points
            .iter()
            .filter(|p| p.binding.is_some())
            .count(),
        positions: face
            .feature_points
            .iter()
            .filter_map(|p| Some((p.id.to_string(), p.position?.to_array())))
            .collect(),
    };
    let fapu = match face.fapu() {
        Ok(f) => FapuSummary {
            units: Some(
                FapuKind::ALL
                    .into_iter()
                    .map(|k| (k.abbreviation().to_string(), f.unit(k)))
                    .collect(),
            ),
            error: None,
        },
        Err(e) => FapuSummary {
            units: None,
            error: Some(e.to_string()),
        },
    };
    let keys = face.fat.keys();
    let tables = keys
        .iter()
        .map(|&key| {
            let ts: Vec<_> = face.fat.tables.iter().filter(|t| t.key == key).collect();
            let mut mesh_names: Vec<&str> = ts
                .iter()
                .flat_map(|t| t.meshes.iter().map(|m| m.mesh.as_str()))
                .collect();
            mesh_names.sort();
            mesh_names.dedup();
            TableSummary {
                key,
                label: key.to_string(),
                vertices: ts.iter().map(|t| t.moved_vertex_count()).sum(),
                meshes: mesh_names.len(),
                intervals: ts
                    .iter()
                    .flat_map(|t| t.meshes.iter().map(|m| m.interval_count()))
                    .max()
                    .unwrap_or(0),
                transforms: ts
                    .iter()
                    .flat_map(|t| t.transforms.iter())
                    .map(|x| format!("{}.{}", x.transform, field_name(x.field)))
                    .collect(),
            }
        })
        .collect();
    let fat = FatSummary {
        table_count: face.fat.tables.len(),
        tables,
        faps_without_table: FapId::low_level()
            .filter(|f| !keys.contains(&TableKey::LowLevel(*f)))
            .map(|f| f.number())
            .collect(),
        visemes: keys
            .iter()
            .filter_map(|k| match k {
                TableKey::Viseme(v) => Some(v.number()),
                _ => None,
            })
            .collect(),
        expressions: keys
            .iter()
            .filter_map(|k| match k {
                TableKey::Expression(e) => Some(e.number()),
                _ => None,
            })
            .collect(),
    };
    let fp_matches = report
        .filter(|r| !r.fp_matches.is_empty())
        .map(|r| MatchSummary {
            count: r.fp_matches.len(),
            max_distance: r.fp_matches.iter().map(|m| m.distance).fold(0.0, f32::max),
            matches: r.fp_matches.clone(),
        });
    FaceSummary {
        name: face.name.clone(),
        kind: report.map(|r| r.kind),
        meshes,
        transforms: face.transforms.len(),
        vertices: face.vertex_count(),
        feature_points,
        fapu,
        units: crate::face::units::detect_unit(face),
        fat,
        fp_matches,
        diagnostics: report.map(|r| r.diagnostics.clone()).unwrap_or_default(),
    }
}

/// `v` with `digits` significant digits in plain decimal notation.
fn significant(v: f64, digits: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    let decimals = (digits - 1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// Compresses sorted numbers into ranges: `3-5, 7, 9-12`.
fn ranges(v: &[u8]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < v.len() {
        let mut j = i;
        while j + 1 < v.len() && v[j + 1] == v[j] + 1 {
            j += 1;
        }
        out.push(if j > i {
            format!("{}-{}", v[i], v[j])
        } else {
            v[i].to_string()
        });
        i = j + 1;
    }
    if out.is_empty() {
        "none".into()
    } else {
        out.join(", ")
    }
}

impl FaceSummary {
    /// The human-readable text `face info` prints.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let kind = match self.kind {
            Some(FaceFileKind::Face) => " (Face node)",
            Some(FaceFileKind::BareFdp) => " (bare FDP)",
            Some(FaceFileKind::PlainScene) => " (plain scene)",
            None => "",
        };
        let _ = writeln!(
            s,
            "face {}{kind}: {} mesh(es), {} vertices, {} transform(s)",
            self.name,
            self.meshes.len(),
            self.vertices,
            self.transforms
        );
        let _ = writeln!(s, "\nmeshes:");
        for m in &self.meshes {
            let arity: Vec<String> = m.arity.iter().map(|(k, v)| format!("{k}:{v}")).collect();
            let under = if m.transform_path.is_empty() {
                String::new()
            } else {
                format!(" under {}", m.transform_path)
            };
            let _ = writeln!(
                s,
                "  {}{under}: {} vertices, {} polygons ({} triangles; corners:count {})",
                m.name,
                m.vertices,
                m.polygons,
                m.triangles,
                arity.join(" ")
            );
        }
        let fp = &self.feature_points;
        let _ = writeln!(
            s,
            "\nfeature points: {} present ({} bound to vertices), {} missing",
            fp.present.len(),
            fp.bound,
            fp.missing.len()
        );
        if !fp.missing.is_empty() {
            let _ = writeln!(s, "  missing: {}", fp.missing.join(" "));
        }
        if let Some(m) = &self.fp_matches {
            let _ = writeln!(
                s,
                "  {} matched to the nearest vertex, largest distance {}",
                m.count, m.max_distance
            );
            let mut worst: Vec<&FeaturePointMatch> = m.matches.iter().collect();
            worst.sort_by(|a, b| b.distance.total_cmp(&a.distance));
            for w in worst.iter().take(5) {
                let _ = writeln!(
                    s,
                    "    {} -> {} vertex {} (distance {})",
                    w.id, w.mesh, w.vertex, w.distance
                );
            }
        }
        match (&self.fapu.units, &self.fapu.error) {
            (Some(u), _) => {
                let list: Vec<String> = FapuKind::ALL
                    .iter()
                    .filter_map(|k| {
                        let a = k.abbreviation();
                        u.get(a).map(|v| match k {
                            FapuKind::Au => format!("{a} {v:e} rad"),
                            _ => format!("{a} {}", significant(*v, 6)),
                        })
                    })
                    .collect();
                let _ = writeln!(s, "\nFAPU: {}", list.join(", "));
            }
            (None, Some(e)) => {
                let _ = writeln!(s, "\nFAPU: not measurable: {e}");
            }
            _ => {}
        }
        if let Some(u) = &self.units {
            let _ = writeln!(s, "Units: {u}");
        }
        let f = &self.fat;
        let low = f
            .tables
            .iter()
            .filter(|t| matches!(t.key, TableKey::LowLevel(_)))
            .count();
        let _ = writeln!(
            s,
            "\nFAT: {} table(s): {low} low-level FAPs, visemes {}, expressions {}",
            f.table_count,
            ranges(&f.visemes),
            ranges(&f.expressions)
        );
        if f.table_count > 0 {
            let _ = writeln!(
                s,
                "  low-level FAPs without a table: {}",
                ranges(&f.faps_without_table)
            );
            for t in &f.tables {
                let tr = if t.transforms.is_empty() {
                    String::new()
                } else {
                    format!("; drives {}", t.transforms.join(", "))
                };
                if t.meshes == 0 {
                    let _ = writeln!(s, "  {}: drives {}", t.label, t.transforms.join(", "));
                } else {
                    let _ = writeln!(
                        s,
                        "  {}: {} vertices in {} mesh(es), {} interval(s){tr}",
                        t.label, t.vertices, t.meshes, t.intervals
                    );
                }
            }
        }
        if !self.diagnostics.is_empty() {
            let _ = writeln!(s, "\nreader diagnostics:");
            for d in &self.diagnostics {
                let _ = writeln!(s, "  {d}");
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_compress() {
        assert_eq!(ranges(&[3, 4, 5, 7, 9, 10]), "3-5, 7, 9-10");
        assert_eq!(ranges(&[]), "none");
        assert_eq!(significant(0.012345012, 6), "0.0123450");
        assert_eq!(significant(0.00001, 6), "0.0000100000");
        assert_eq!(significant(512.25, 6), "512.250");
    }

    #[test]
    fn synthetic_face_summary() {
        let face = crate::synth::alma().to_face_model();
        let s = summarize(&face, None);
        assert_eq!(s.meshes.len(), face.meshes.len());
        assert_eq!(s.fat.visemes, (1..=14).collect::<Vec<_>>());
        assert_eq!(s.fat.expressions, (1..=6).collect::<Vec<_>>());
        assert!(s.fapu.units.is_some());
        assert_eq!(s.meshes[0].vertices, face.meshes[0].mesh.vertex_count());
        assert!(s.to_text().contains("FAT: "));
    }
}
