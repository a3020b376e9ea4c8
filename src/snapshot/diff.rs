//! Two faces' FATs compared as animation: per table, every vertex's displacement at the
//! values that pin the table down, plus transforms, the neutral, feature points and FAPU.

use std::collections::BTreeSet;
use std::fmt;

use glam::DVec3;
use serde::Serialize;

use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::TableKey;
use crate::fdp::Fapu;
use crate::mesh::spatial::VertexIndex;
use crate::spec::{FapuKind, FeaturePointId};

use super::motion::{rotation_difference_degrees, vec_difference, FaceMotion};
use super::tolerance::{ResolvedTolerance, Tolerance};
use super::{Side, SnapshotError};

/// How the vertices of A are paired with those of B.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexMatch {
    /// Vertex to vertex: the faces must have the same meshes (by name, else in order) with
    /// the same vertex counts.
    #[default]
    Index,
    /// Each vertex of A against the nearest neutral vertex of B (face frames), for faces
    /// whose layouts differ (a re-meshed or merged copy).
    Nearest,
}

/// What [`diff`] compares with.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DiffOptions {
    /// Differences up to this are equal (relative tolerances are of face A's size).
    pub tolerance: Tolerance,
    /// How vertices are paired.
    pub vertex_match: VertexMatch,
}

/// The comparison of one table key.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TableDiff {
    /// `open_jaw`, `viseme_3`, `joy`.
    pub table: String,
    /// FAP number for low-level tables; `null` for visemes and expressions.
    pub fap: Option<u8>,
    /// Within tolerance (and present in both faces).
    pub equal: bool,
    /// `a` or `b` when only one face has the table (it is then compared with no motion).
    pub only_in: Option<Side>,
    /// Largest displacement difference over vertices and values, in face units.
    pub max_difference: f64,
    /// [`TableDiff::max_difference`] in the FAP's unit (FAPU of face A); `null` for visemes,
    /// expressions, angle FAPs and faces without FAP units.
    pub max_difference_fapu: Option<f64>,
    /// Mean difference over the (vertex, value) pairs where either face moves the vertex.
    pub mean_difference: f64,
    /// [`TableDiff::mean_difference`] in the FAP's unit, like `max_difference_fapu`.
    pub mean_difference_fapu: Option<f64>,
    /// Vertices (of A) whose difference exceeds the tolerance at some value.
    pub differing_vertices: usize,
    /// Vertices (of A) that either face moves at some value.
    pub moving_vertices: usize,
    /// The vertex (global index in A: meshes in order) with the largest difference.
    pub worst_vertex: Option<u32>,
    /// The value at which the largest difference occurs.
    pub worst_value: Option<f64>,
    /// The values compared at: every non-zero interval border of either face and the
    /// table's reference value.
    pub values: Vec<f64>,
    /// Largest rotation difference of a driven transform, in degrees.
    pub max_rotation_degrees: f64,
    /// Largest translation difference of a driven transform, in face units.
    pub max_translation: f64,
    /// Largest scale difference of a driven transform.
    pub max_scale: f64,
    /// The key.
    #[serde(skip)]
    pub key: TableKey,
}

/// A neutral transform present in both faces that differs, or one only in one face.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransformDiff {
    /// `DEF` name.
    pub name: String,
    /// `a` or `b` when only one face has it.
    pub only_in: Option<Side>,
    /// Rotation difference in degrees.
    pub rotation_degrees: f64,
    /// Translation difference.
    pub translation: f64,
    /// Scale difference.
    pub scale: f64,
}

/// Neutral geometry compared.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NeutralDiff {
    /// Within tolerance, same meshes, same transforms.
    pub equal: bool,
    /// Vertex counts of A and B.
    pub vertices_a: usize,
    /// Vertex count of B.
    pub vertices_b: usize,
    /// Largest distance between paired neutral vertices (face frame).
    pub max_difference: f64,
    /// Mean distance between paired neutral vertices.
    pub mean_difference: f64,
    /// Paired vertices farther apart than the tolerance.
    pub differing_vertices: usize,
    /// Meshes only in A (by name).
    pub meshes_only_in_a: Vec<String>,
    /// Meshes only in B.
    pub meshes_only_in_b: Vec<String>,
    /// Transforms that differ beyond tolerance or exist in one face only.
    pub transforms: Vec<TransformDiff>,
}

/// One feature point compared.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointDiff {
    /// The label, e.g. `3.5`.
    pub id: String,
    /// `a` or `b` when only one face has a position for it.
    pub only_in: Option<Side>,
    /// Distance between the two positions.
    pub difference: f64,
}

/// Feature points compared.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointsDiff {
    /// Same points, all within tolerance.
    pub equal: bool,
    /// Largest distance between a point's two positions.
    pub max_difference: f64,
    /// Points that differ beyond tolerance or exist in one face only, worst first.
    pub differing: Vec<FeaturePointDiff>,
}

/// One FAP unit compared (the neutral distance behind it, e.g. ES0).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapuUnitDiff {
    /// `IRISD`, `ES`, `ENS`, `MNS`, `MW`.
    pub unit: FapuKind,
    /// A's distance (`null` when A has no FAP units).
    pub a: Option<f64>,
    /// B's distance.
    pub b: Option<f64>,
    /// Absolute difference of the distances.
    pub difference: Option<f64>,
}

/// FAP units compared.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapuDiff {
    /// Both faces measure the same units (distances within tolerance), or neither has any.
    pub equal: bool,
    /// Per unit.
    pub units: Vec<FapuUnitDiff>,
}

/// The typed report of [`diff`]; `Display` renders the text report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaceDiff {
    /// Everything within tolerance.
    pub equal: bool,
    /// Face A's name.
    pub a: String,
    /// Face B's name.
    pub b: String,
    /// The tolerance used.
    pub tolerance: ResolvedTolerance,
    /// Rotations count as different beyond this many degrees: the angle that moves a point
    /// at the face size's half by the tolerance.
    pub rotation_tolerance_degrees: f64,
    /// How vertices were paired.
    pub vertex_match: VertexMatch,
    /// Every table of either face once: differing ones first (worst first), then the equal
    /// ones by key (FAPs by number, visemes, expressions).
    pub tables: Vec<TableDiff>,
    /// Neutral geometry.
    pub neutral: NeutralDiff,
    /// Feature points.
    pub feature_points: FeaturePointsDiff,
    /// FAP units.
    pub fapu: FapuDiff,
    /// Why the faces could not be compared at all (no FAT, different vertex layouts, a bad
    /// tolerance); `None` when they were. Only [`diff`] sets it; [`try_diff`] returns the
    /// error instead. A report with a problem is never equal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problem: Option<String>,
}

impl FaceDiff {
    /// The report of two faces that could not be compared: not equal, `problem` set.
    fn refused(a: &FaceModel, b: &FaceModel, options: &DiffOptions, problem: String) -> Self {
        let given = match options.tolerance {
            Tolerance::Absolute(t) => t.to_string(),
            Tolerance::Relative(r) => format!("{r}x"),
        };
        FaceDiff {
            equal: false,
            a: a.name.clone(),
            b: b.name.clone(),
            tolerance: ResolvedTolerance {
                given,
                absolute: f64::NAN,
                face_size: f64::NAN,
            },
            rotation_tolerance_degrees: f64::NAN,
            vertex_match: options.vertex_match,
            tables: Vec::new(),
            neutral: NeutralDiff {
                equal: false,
                vertices_a: a.meshes.iter().map(|m| m.mesh.vertex_count()).sum(),
                vertices_b: b.meshes.iter().map(|m| m.mesh.vertex_count()).sum(),
                max_difference: f64::NAN,
                mean_difference: f64::NAN,
                differing_vertices: 0,
                meshes_only_in_a: Vec::new(),
                meshes_only_in_b: Vec::new(),
                transforms: Vec::new(),
            },
            feature_points: FeaturePointsDiff {
                equal: false,
                max_difference: f64::NAN,
                differing: Vec::new(),
            },
            fapu: FapuDiff {
                equal: false,
                units: Vec::new(),
            },
            problem: Some(problem),
        }
    }

    /// True when everything is within tolerance.
    pub fn is_equal(&self) -> bool {
        self.equal
    }

    /// The worst differing table, if any.
    pub fn worst_table(&self) -> Option<&TableDiff> {
        self.tables.first().filter(|t| !t.equal)
    }

    /// Tables that differ.
    pub fn differing_tables(&self) -> impl Iterator<Item = &TableDiff> {
        self.tables.iter().filter(|t| !t.equal)
    }
}

impl fmt::Display for FaceDiff {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&super::report::face_diff_text(self))
    }
}

/// Compares the FATs (and neutrals, feature points, FAP units) of two faces as animation,
/// for a test's `assert!`: a pair that cannot be compared at all (a face without a FAT or
/// without vertices, different vertex layouts under [`VertexMatch::Index`], a tolerance that
/// is not a positive finite number) gives a report that is not equal and names the problem
/// ([`FaceDiff::problem`]); [`try_diff`] returns it as an error instead.
///
/// ```
/// use fbakit::snapshot::{diff, DiffOptions};
///
/// let a = fbakit::face::read("alma")?;
/// let mut b = a.clone();
/// b.fat.tables[0].meshes[0].displacements[0].x += 0.01; // one vertex of one table
/// let report = diff(&a, &b, &DiffOptions::default());
/// assert!(!report.is_equal(), "{report}");
/// assert_eq!(report.worst_table().unwrap().key, a.fat.tables[0].key);
/// let opts = DiffOptions::default();
/// let report = diff(&a, &a, &opts);
/// assert!(report.is_equal(), "{report}");
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn diff(a: &FaceModel, b: &FaceModel, options: &DiffOptions) -> FaceDiff {
    try_diff(a, b, options).unwrap_or_else(|e| FaceDiff::refused(a, b, options, e.to_string()))
}

/// [`diff`], with the problems that stop a comparison as errors (all of them bad input):
/// both faces need a FAT; faces with different vertex layouts are refused unless
/// `options.vertex_match` is [`VertexMatch::Nearest`].
pub fn try_diff(a: &FaceModel, b: &FaceModel, options: &DiffOptions) -> Result<FaceDiff> {
    let tolerance = options.tolerance.checked()?;
    let mut ma = FaceMotion::new(a, true)?;
    let mut mb = FaceMotion::new(b, true)?;
    if ma.vertex_count() == 0 {
        return Err(SnapshotError::EmptyFace {
            face: a.name.clone(),
        }
        .into());
    }
    if mb.vertex_count() == 0 {
        return Err(SnapshotError::EmptyFace {
            face: b.name.clone(),
        }
        .into());
    }
    let pairing = match options.vertex_match {
        VertexMatch::Index => index_pairing(&ma, &mb)?,
        VertexMatch::Nearest => nearest_pairing(&ma, &mb),
    };
    let size = ma.size();
    let resolved = ResolvedTolerance::new(tolerance, size);
    let tol = resolved.absolute;
    let radius = (size / 2.0).max(f64::MIN_POSITIVE);
    let rot_tol_deg = (tol / radius).min(std::f64::consts::PI).to_degrees();
    let fapu_a = a.fapu().ok();

    let keys: BTreeSet<TableKey> = ma.keys().into_iter().chain(mb.keys()).collect();
    let mut tables = Vec::with_capacity(keys.len());
    let mut buf_a = Vec::new();
    let mut buf_b = Vec::new();
    let zero_a = vec![DVec3::ZERO; ma.vertex_count()];
    let zero_b = vec![DVec3::ZERO; mb.vertex_count()];
    for key in keys {
        let in_a = a.fat.table(key).is_some();
        let in_b = b.fat.table(key).is_some();
        let mut values = Vec::new();
        if in_a {
            values.extend(ma.sample_values(key));
        }
        if in_b {
            values.extend(mb.sample_values(key));
        }
        values.sort_by(f64::total_cmp);
        values.dedup();
        // Driven transforms both faces have; where one face has no such node (an OBJ
        // morph set bakes it), its effect is judged by the vertex motion it causes.
        let mut names: Vec<&str> = ma.driven_transforms(key);
        names.extend(mb.driven_transforms(key));
        names.retain(|n| a.transform_index(n).is_some() && b.transform_index(n).is_some());
        names.sort_unstable();
        names.dedup();

        let n = ma.vertex_count();
        let mut vertex_differs = vec![false; n];
        let mut vertex_moves = vec![false; n];
        let (mut max, mut worst_vertex, mut worst_value) = (0.0f64, None, None);
        let (mut sum, mut count) = (0.0f64, 0usize);
        let (mut max_rot, mut max_tr, mut max_sc) = (0.0f64, 0.0f64, 0.0f64);
        for &value in &values {
            if in_a {
                ma.evaluate(key, value, &mut buf_a);
            }
            if in_b {
                mb.evaluate(key, value, &mut buf_b);
            }
            let da = if in_a { &buf_a } else { &zero_a };
            let db = if in_b { &buf_b } else { &zero_b };
            for (i, &j) in pairing.iter().enumerate() {
                let (pa, pb) = (da[i], db[j as usize]);
                if pa == DVec3::ZERO && pb == DVec3::ZERO {
                    continue;
                }
                vertex_moves[i] = true;
                let d = (pa - pb).length();
                sum += d;
                count += 1;
                if d > tol {
                    vertex_differs[i] = true;
                }
                if d > max {
                    max = d;
                    worst_vertex = Some(i as u32);
                    worst_value = Some(value);
                }
            }
            for name in &names {
                let ta = if in_a {
                    ma.transform_delta(name)
                } else {
                    crate::fat::eval::TransformDelta::IDENTITY
                };
                let tb = if in_b {
                    mb.transform_delta(name)
                } else {
                    crate::fat::eval::TransformDelta::IDENTITY
                };
                max_rot = max_rot.max(rotation_difference_degrees(ta.rotation, tb.rotation));
                max_tr = max_tr.max(vec_difference(ta.translation, tb.translation));
                max_sc = max_sc.max(vec_difference(ta.scale, tb.scale));
            }
        }
        let mean = if count == 0 { 0.0 } else { sum / count as f64 };
        let unit = fapu_unit(fapu_a.as_ref(), key);
        let only_in = match (in_a, in_b) {
            (true, false) => Some(Side::A),
            (false, true) => Some(Side::B),
            _ => None,
        };
        let equal = only_in.is_none()
            && max <= tol
            && max_rot <= rot_tol_deg
            && max_tr <= tol
            && max_sc * radius <= tol;
        tables.push(TableDiff {
            table: key.name(),
            fap: match key {
                TableKey::LowLevel(f) => Some(f.number()),
                _ => None,
            },
            equal,
            only_in,
            max_difference: max,
            max_difference_fapu: unit.map(|u| max / u),
            mean_difference: mean,
            mean_difference_fapu: unit.map(|u| mean / u),
            differing_vertices: vertex_differs.iter().filter(|d| **d).count(),
            moving_vertices: vertex_moves.iter().filter(|d| **d).count(),
            worst_vertex,
            worst_value,
            values,
            max_rotation_degrees: max_rot,
            max_translation: max_tr,
            max_scale: max_sc,
            key,
        });
    }
    // Differing first, worst first; equal ones keep key order. Ties by key: a stable order.
    tables.sort_by(|x, y| {
        x.equal.cmp(&y.equal).then_with(|| {
            if x.equal {
                x.key.cmp(&y.key)
            } else {
                table_badness(y)
                    .total_cmp(&table_badness(x))
                    .then_with(|| x.key.cmp(&y.key))
            }
        })
    });

    let neutral = neutral_diff(&ma, &mb, &pairing, tol, rot_tol_deg, radius);
    let feature_points = feature_points_diff(a, b, tol);
    let fapu = fapu_diff(fapu_a.as_ref(), b.fapu().ok().as_ref(), tol);
    let equal =
        tables.iter().all(|t| t.equal) && neutral.equal && feature_points.equal && fapu.equal;
    Ok(FaceDiff {
        equal,
        a: a.name.clone(),
        b: b.name.clone(),
        tolerance: resolved,
        rotation_tolerance_degrees: rot_tol_deg,
        vertex_match: options.vertex_match,
        tables,
        neutral,
        feature_points,
        fapu,
        problem: None,
    })
}

/// How bad a differing table is, for ordering: its largest vertex difference (a table only
/// in one face or differing only in transforms still sorts among the differing ones).
fn table_badness(t: &TableDiff) -> f64 {
    t.max_difference.max(t.max_translation)
}

/// The size of one unit of `key`'s FAP on a face with `fapu`, for lengths only.
fn fapu_unit(fapu: Option<&Fapu>, key: TableKey) -> Option<f64> {
    let TableKey::LowLevel(fap) = key else {
        return None;
    };
    let kind = fap.info().fapu?;
    if kind == FapuKind::Au {
        return None;
    }
    let u = fapu?.unit(kind);
    (u.is_finite() && u > 0.0).then_some(u)
}

/// A's global vertex → B's, vertex to vertex: meshes paired by name when both faces have the
/// same names, else in order; every pair needs the same vertex count.
fn index_pairing(ma: &FaceMotion, mb: &FaceMotion) -> Result<Vec<u32>> {
    let (a, b) = (ma.face, mb.face);
    let mismatch = |detail: String| SnapshotError::LayoutMismatch {
        a: a.name.clone(),
        b: b.name.clone(),
        detail,
    };
    if a.meshes.len() != b.meshes.len() {
        return Err(mismatch(format!(
            "{} meshes against {}",
            a.meshes.len(),
            b.meshes.len()
        ))
        .into());
    }
    let mut names_a: Vec<&str> = a.meshes.iter().map(|m| m.name.as_str()).collect();
    let mut names_b: Vec<&str> = b.meshes.iter().map(|m| m.name.as_str()).collect();
    names_a.sort_unstable();
    names_b.sort_unstable();
    let by_name = names_a == names_b;
    let mut pairing = Vec::with_capacity(ma.vertex_count());
    for (i, m) in a.meshes.iter().enumerate() {
        let j = if by_name {
            b.mesh_index(&m.name).unwrap_or(i)
        } else {
            i
        };
        let (na, nb) = (m.mesh.vertex_count(), b.meshes[j].mesh.vertex_count());
        if na != nb {
            return Err(mismatch(format!(
                "mesh `{}` has {na} vertices, `{}` {nb}",
                m.name, b.meshes[j].name
            ))
            .into());
        }
        let off = mb.offsets[j] as u32;
        pairing.extend((0..na as u32).map(|v| off + v));
    }
    Ok(pairing)
}

/// A's global vertex → the nearest neutral vertex of B (face frames). Within a mesh B also
/// has (by name) the search stays in that mesh; ties (coincident vertices, such as split
/// lips) go to the same vertex number, then to the lowest, so the pairing is deterministic.
fn nearest_pairing(ma: &FaceMotion, mb: &FaceMotion) -> Vec<u32> {
    let (a, b) = (ma.face, mb.face);
    let index_of = |range: std::ops::Range<usize>| {
        let points: Vec<glam::Vec3> = mb.neutral[range].iter().map(|p| p.as_vec3()).collect();
        VertexIndex::new(&points)
    };
    let whole = index_of(0..mb.vertex_count());
    // Coincident vertices (seam twins, a lid over an eyeball) written through f32 by one
    // format and not another land a hair apart: count as ties what float noise separates.
    let noise = ma.size() as f32 * 1e-6;
    let mut pairing = Vec::with_capacity(ma.vertex_count());
    for (i, m) in a.meshes.iter().enumerate() {
        let own = b.mesh_index(&m.name).map(|j| {
            let start = mb.offsets[j];
            (
                start,
                index_of(start..start + b.meshes[j].mesh.vertex_count()),
            )
        });
        let first = ma.offsets[i];
        // Ties prefer the vertex of the same number: within the mesh, or over the face.
        let (start, index, same_base) = match &own {
            Some((s, idx)) if !idx.is_empty() => (*s, idx, *s),
            _ => (0, &whole, first),
        };
        for (k, p) in ma.neutral[first..first + m.mesh.vertex_count()]
            .iter()
            .enumerate()
        {
            let p = p.as_vec3();
            let Some((_, d)) = index.nearest_vertex(p) else {
                pairing.push(0);
                continue;
            };
            let ties = index.within(p, d + noise);
            let same = (same_base + k) as u32;
            let pick = ties
                .iter()
                .map(|(v, _)| start as u32 + v)
                .min_by_key(|v| (*v != same, *v))
                .unwrap_or(start as u32);
            pairing.push(pick);
        }
    }
    pairing
}

fn neutral_diff(
    ma: &FaceMotion,
    mb: &FaceMotion,
    pairing: &[u32],
    tol: f64,
    rot_tol_deg: f64,
    radius: f64,
) -> NeutralDiff {
    let (mut max, mut sum, mut differing) = (0.0f64, 0.0f64, 0usize);
    for (i, &j) in pairing.iter().enumerate() {
        let d = (ma.neutral[i] - mb.neutral[j as usize]).length();
        if d.is_nan() || d > tol {
            differing += 1;
        }
        if d.is_finite() {
            sum += d;
            max = max.max(d);
        }
    }
    let (a, b) = (ma.face, mb.face);
    let only = |x: &FaceModel, y: &FaceModel| -> Vec<String> {
        x.meshes
            .iter()
            .filter(|m| y.mesh_index(&m.name).is_none())
            .map(|m| m.name.clone())
            .collect()
    };
    let mut transforms = Vec::new();
    for t in &a.transforms {
        match b.transform_index(&t.name) {
            None => transforms.push(TransformDiff {
                name: t.name.clone(),
                only_in: Some(Side::A),
                rotation_degrees: 0.0,
                translation: 0.0,
                scale: 0.0,
            }),
            Some(j) => {
                let u = &b.transforms[j];
                let d = TransformDiff {
                    name: t.name.clone(),
                    only_in: None,
                    rotation_degrees: rotation_difference_degrees(t.rotation, u.rotation).max(
                        rotation_difference_degrees(t.scale_orientation, u.scale_orientation),
                    ),
                    translation: vec_difference(t.translation, u.translation)
                        .max(vec_difference(t.center, u.center)),
                    scale: vec_difference(t.scale, u.scale),
                };
                if d.rotation_degrees > rot_tol_deg || d.translation > tol || d.scale * radius > tol
                {
                    transforms.push(d);
                }
            }
        }
    }
    for t in &b.transforms {
        if a.transform_index(&t.name).is_none() {
            transforms.push(TransformDiff {
                name: t.name.clone(),
                only_in: Some(Side::B),
                rotation_degrees: 0.0,
                translation: 0.0,
                scale: 0.0,
            });
        }
    }
    let meshes_only_in_a = only(a, b);
    let meshes_only_in_b = only(b, a);
    NeutralDiff {
        equal: differing == 0
            && transforms.is_empty()
            && (pairing.len() == mb.vertex_count())
            && meshes_only_in_a.is_empty()
            && meshes_only_in_b.is_empty(),
        vertices_a: ma.vertex_count(),
        vertices_b: mb.vertex_count(),
        max_difference: max,
        mean_difference: if pairing.is_empty() {
            0.0
        } else {
            sum / pairing.len() as f64
        },
        differing_vertices: differing,
        meshes_only_in_a,
        meshes_only_in_b,
        transforms,
    }
}

fn feature_points_diff(a: &FaceModel, b: &FaceModel, tol: f64) -> FeaturePointsDiff {
    let pos = |f: &FaceModel, id: FeaturePointId| {
        f.feature_points
            .get(id)
            .and_then(|p| p.position)
            .filter(|p| p.is_finite())
    };
    let ids: BTreeSet<FeaturePointId> = a
        .feature_points
        .iter()
        .chain(b.feature_points.iter())
        .map(|p| p.id)
        .collect();
    let mut differing = Vec::new();
    let mut max = 0.0f64;
    for id in ids {
        let (pa, pb) = (pos(a, id), pos(b, id));
        let (only_in, difference) = match (pa, pb) {
            (Some(x), Some(y)) => (None, vec_difference(x, y)),
            (Some(_), None) => (Some(Side::A), 0.0),
            (None, Some(_)) => (Some(Side::B), 0.0),
            (None, None) => continue,
        };
        max = max.max(difference);
        if only_in.is_some() || difference > tol {
            differing.push(FeaturePointDiff {
                id: id.to_string(),
                only_in,
                difference,
            });
        }
    }
    differing.sort_by(|x, y| y.difference.total_cmp(&x.difference));
    FeaturePointsDiff {
        equal: differing.is_empty(),
        max_difference: max,
        differing,
    }
}

fn fapu_diff(a: Option<&Fapu>, b: Option<&Fapu>, tol: f64) -> FapuDiff {
    let kinds = [
        FapuKind::Irisd,
        FapuKind::Es,
        FapuKind::Ens,
        FapuKind::Mns,
        FapuKind::Mw,
    ];
    let mut equal = a.is_some() == b.is_some();
    let units = kinds
        .into_iter()
        .map(|unit| {
            let da = a.and_then(|f| f.distance(unit));
            let db = b.and_then(|f| f.distance(unit));
            let difference = da.zip(db).map(|(x, y)| (x - y).abs());
            if difference.is_some_and(|d| d.is_nan() || d > tol) {
                equal = false;
            }
            FapuUnitDiff {
                unit,
                a: da,
                b: db,
                difference,
            }
        })
        .collect();
    FapuDiff { equal, units }
}
