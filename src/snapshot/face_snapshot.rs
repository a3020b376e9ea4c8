//! The stable text of a face: what matters about its meshes, feature points, FAP units and
//! tables, every number on the tolerance's grid, the displacements as digests.

use std::fmt::Write;

use glam::DVec3;
use serde::Serialize;

use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::TableKey;
use crate::spec::FapuKind;

use super::motion::{bounding_diagonal, FaceMotion};
use super::quantise::{Digest, Grid};
use super::tolerance::Tolerance;

/// What [`snapshot`](super::snapshot()) prints with.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SnapshotOptions {
    /// Numbers are printed on the grid of this tolerance (relative tolerances are of the
    /// face's size); see the guarantee in [`crate::snapshot`].
    pub tolerance: Tolerance,
}

/// One mesh of a snapshot.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshSnapshot {
    /// `DEF` name.
    pub name: String,
    /// Vertex count.
    pub vertices: usize,
    /// Polygon count.
    pub polygons: usize,
    /// Smallest corner of the neutral's bounds (face frame, on the grid).
    pub min: [f64; 3],
    /// Largest corner.
    pub max: [f64; 3],
    /// Digest of the neutral positions on the grid (face frame) and the polygons.
    pub digest: String,
}

/// One transform of a snapshot (its effect on positions is in the meshes).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransformSnapshot {
    /// `DEF` name.
    pub name: String,
    /// Enclosing transform.
    pub parent: Option<String>,
}

/// One feature point of a snapshot.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointSnapshot {
    /// The label, e.g. `3.5`.
    pub id: String,
    /// Position in the face frame, on the grid.
    pub position: [f64; 3],
}

/// One FAP unit of a snapshot.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapuSnapshot {
    /// `IRISD`, `ES`, `ENS`, `MNS` or `MW`.
    pub unit: String,
    /// The neutral distance behind it (IRISD0, ...), on the grid.
    pub distance: f64,
}

/// One table key of a snapshot.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TableSnapshot {
    /// `open_jaw`, `viseme_3`, `joy`.
    pub table: String,
    /// FAP number for low-level tables, `null` for visemes and expressions.
    pub fap: Option<u8>,
    /// Interval borders of its meshes, merged.
    pub borders: Vec<f64>,
    /// The values it is evaluated at: non-zero borders and the reference value.
    pub values: Vec<f64>,
    /// Vertices whose displacement is off the zero grid point at some value.
    pub vertices: usize,
    /// Largest displacement over vertices and values (face units, on the grid).
    pub max_displacement: f64,
    /// Mean over the (vertex, value) pairs counted in `vertices` (on the grid).
    pub mean_displacement: f64,
    /// Transforms it drives.
    pub transforms: Vec<String>,
    /// Digest of every vertex's displacement at every value, on the grid (face frame, the
    /// motion transforms give included), and of the driven transforms' changes.
    pub digest: String,
}

/// A face's snapshot; [`FaceSnapshot::to_yaml`] is the text.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaceSnapshot {
    /// The tolerance as given.
    pub tolerance: String,
    /// The grid step every number is on.
    pub grid: f64,
    /// Face size: the neutral's bounding-box diagonal (on the grid).
    pub size: f64,
    /// Meshes in order.
    pub meshes: Vec<MeshSnapshot>,
    /// Transforms in order.
    pub transforms: Vec<TransformSnapshot>,
    /// Feature points with a position, in label order (2.1, 2.2, ..., 11.6).
    pub feature_points: Vec<FeaturePointSnapshot>,
    /// The FAP units' neutral distances (IRISD0, ES0, ENS0, MNS0, MW0), `null` when the
    /// face has none.
    pub fapu: Option<Vec<FapuSnapshot>>,
    /// Every table key, FAPs by number, then visemes, then expressions.
    pub tables: Vec<TableSnapshot>,
}

/// Builds the snapshot of `face` (a face without a FAT is refused).
pub fn face_snapshot(face: &FaceModel, options: &SnapshotOptions) -> Result<FaceSnapshot> {
    let tolerance = options.tolerance.checked()?;
    let mut motion = FaceMotion::new(face, true)?;
    let size = motion.size();
    let grid = Grid::for_tolerance(tolerance.absolute(size));
    let snap3 = |v: DVec3| [grid.snap(v.x), grid.snap(v.y), grid.snap(v.z)];

    let mut meshes = Vec::with_capacity(face.meshes.len());
    for (i, m) in face.meshes.iter().enumerate() {
        let start = motion.offsets[i];
        let points = &motion.neutral[start..start + m.mesh.vertex_count()];
        let (lo, hi) = bounds(points);
        let mut digest = Digest::default();
        for p in points {
            for c in p.to_array() {
                digest.i64(grid.index(c));
            }
        }
        for poly in m.mesh.polygons.iter() {
            digest.i64(poly.len() as i64);
            for &v in poly {
                digest.i64(i64::from(v));
            }
        }
        meshes.push(MeshSnapshot {
            name: m.name.clone(),
            vertices: m.mesh.vertex_count(),
            polygons: m.mesh.face_count(),
            min: snap3(lo),
            max: snap3(hi),
            digest: digest.hex(),
        });
    }
    let transforms = face
        .transforms
        .iter()
        .map(|t| TransformSnapshot {
            name: t.name.clone(),
            parent: t
                .parent
                .and_then(|p| face.transforms.get(p))
                .map(|p| p.name.clone()),
        })
        .collect();
    let feature_points = face
        .feature_points
        .iter()
        .filter_map(|p| {
            Some(FeaturePointSnapshot {
                id: p.id.to_string(),
                position: snap3(p.position?.as_dvec3()),
            })
        })
        .collect();
    let fapu = face.fapu().ok().map(|f| {
        [
            FapuKind::Irisd,
            FapuKind::Es,
            FapuKind::Ens,
            FapuKind::Mns,
            FapuKind::Mw,
        ]
        .into_iter()
        .filter_map(|k| {
            Some(FapuSnapshot {
                unit: k.abbreviation().to_string(),
                distance: grid.snap(f.distance(k)?),
            })
        })
        .collect()
    });

    let mut tables = Vec::new();
    let mut buf = Vec::new();
    let radius = size / 2.0;
    for key in motion.keys() {
        let values = motion.sample_values(key);
        let names = motion.driven_transforms(key);
        let mut moving = vec![false; motion.vertex_count()];
        let mut digest = Digest::default();
        let (mut max, mut sum, mut count) = (0.0f64, 0.0f64, 0usize);
        for &value in &values {
            digest.f64_bits(value);
            motion.evaluate(key, value, &mut buf);
            for (i, d) in buf.iter().enumerate() {
                if *d == DVec3::ZERO {
                    continue;
                }
                let q = [grid.index(d.x), grid.index(d.y), grid.index(d.z)];
                if q == [0, 0, 0] {
                    continue;
                }
                moving[i] = true;
                digest.i64(i as i64);
                for c in q {
                    digest.i64(c);
                }
                let len = d.length();
                max = max.max(len);
                sum += len;
                count += 1;
            }
            for name in &names {
                let t = motion.transform_delta(name);
                digest.bytes(name.as_bytes());
                // Rotations as the motion of a point at the face's half size.
                let (axis, angle) = t.rotation.to_axis_angle();
                let turn = axis.as_dvec3() * f64::from(angle) * radius;
                for c in [turn, t.translation.as_dvec3(), t.scale.as_dvec3() * radius] {
                    for x in c.to_array() {
                        digest.i64(grid.index(x));
                    }
                }
            }
        }
        tables.push(TableSnapshot {
            table: key.name(),
            fap: match key {
                TableKey::LowLevel(f) => Some(f.number()),
                _ => None,
            },
            borders: motion.borders(key),
            values,
            vertices: moving.iter().filter(|m| **m).count(),
            max_displacement: grid.snap(max),
            mean_displacement: grid.snap(if count == 0 { 0.0 } else { sum / count as f64 }),
            transforms: names.iter().map(|n| n.to_string()).collect(),
            digest: digest.hex(),
        });
    }
    Ok(FaceSnapshot {
        tolerance: tolerance.to_string(),
        grid: grid.snap(grid.step()),
        size: grid.snap(bounding_diagonal(&motion.neutral)),
        meshes,
        transforms,
        feature_points,
        fapu,
        tables,
    })
}

fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    let mut it = points.iter().filter(|p| p.is_finite());
    let Some(first) = it.next() else {
        return (DVec3::ZERO, DVec3::ZERO);
    };
    it.fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

impl FaceSnapshot {
    /// The snapshot as YAML: one fixed layout, keys in a fixed order, strings quoted,
    /// numbers as short decimals, so two snapshots diff line by line.
    pub fn to_yaml(&self) -> String {
        let mut o = String::new();
        let _ = writeln!(
            o,
            "# fbakit face snapshot: numbers on a grid of {} (tolerance {}); digests change \
             when any displacement moves by more than the tolerance",
            num(self.grid),
            self.tolerance
        );
        let _ = writeln!(o, "tolerance: {}", quote(&self.tolerance));
        let _ = writeln!(o, "grid: {}", num(self.grid));
        let _ = writeln!(o, "size: {}", num(self.size));
        o.push_str("meshes:\n");
        for m in &self.meshes {
            let _ = writeln!(o, "  - name: {}", quote(&m.name));
            let _ = writeln!(o, "    vertices: {}", m.vertices);
            let _ = writeln!(o, "    polygons: {}", m.polygons);
            let _ = writeln!(o, "    min: {}", triple(m.min));
            let _ = writeln!(o, "    max: {}", triple(m.max));
            let _ = writeln!(o, "    digest: {}", quote(&m.digest));
        }
        if self.transforms.is_empty() {
            o.push_str("transforms: []\n");
        } else {
            o.push_str("transforms:\n");
            for t in &self.transforms {
                let parent = t.parent.as_deref().map_or("null".to_string(), quote);
                let _ = writeln!(o, "  - {{name: {}, parent: {parent}}}", quote(&t.name));
            }
        }
        if self.feature_points.is_empty() {
            o.push_str("feature_points: {}\n");
        } else {
            o.push_str("feature_points:\n");
            for p in &self.feature_points {
                let _ = writeln!(o, "  {}: {}", quote(&p.id), triple(p.position));
            }
        }
        match &self.fapu {
            None => o.push_str("fapu: null\n"),
            Some(f) => {
                o.push_str("fapu:\n");
                for u in f {
                    let _ = writeln!(o, "  {}: {}", u.unit, num(u.distance));
                }
            }
        }
        o.push_str("tables:\n");
        for t in &self.tables {
            let _ = writeln!(o, "  - table: {}", quote(&t.table));
            let _ = writeln!(
                o,
                "    fap: {}",
                t.fap.map_or("null".to_string(), |f| f.to_string())
            );
            let _ = writeln!(o, "    borders: {}", list(&t.borders));
            let _ = writeln!(o, "    values: {}", list(&t.values));
            let _ = writeln!(o, "    vertices: {}", t.vertices);
            let _ = writeln!(o, "    max_displacement: {}", num(t.max_displacement));
            let _ = writeln!(o, "    mean_displacement: {}", num(t.mean_displacement));
            let names: Vec<String> = t.transforms.iter().map(|n| quote(n)).collect();
            let _ = writeln!(o, "    transforms: [{}]", names.join(", "));
            let _ = writeln!(o, "    digest: {}", quote(&t.digest));
        }
        o
    }
}

/// A YAML (and JSON) double-quoted string: JSON's escaping is valid YAML.
fn quote(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".to_string())
}

/// A number as its shortest decimal (`.nan`, `.inf` for the others, as YAML spells them).
fn num(v: f64) -> String {
    if v.is_nan() {
        ".nan".to_string()
    } else if v.is_infinite() {
        if v > 0.0 { ".inf" } else { "-.inf" }.to_string()
    } else if v == 0.0 {
        // -0 and 0 print alike.
        "0".to_string()
    } else {
        format!("{v}")
    }
}

fn triple(p: [f64; 3]) -> String {
    format!("[{}, {}, {}]", num(p[0]), num(p[1]), num(p[2]))
}

fn list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| num(*x)).collect();
    format!("[{}]", items.join(", "))
}
