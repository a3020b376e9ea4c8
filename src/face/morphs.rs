//! Faces from morph sets (a neutral OBJ plus one OBJ per FAP, viseme or expression), and FATs
//! written back out as morph sets.
//!
//! **File names.** A morph file is `NAME.obj` or `NAME@VALUE.obj`, where `NAME` is a table key
//! as [`TableKey::from_name`] reads it: a low-level FAP name (`open_jaw`), `viseme_N` (1..=14)
//! or an expression name (`joy`, `sadness`, `anger`, `fear`, `disgust`, `surprise`). `VALUE`
//! is the FAP value the morph shows (a finite, non-zero number, e.g. `open_jaw@-512.obj`).
//!
//! **Values.** The value a morph represents is, in order: the `@VALUE` of its name; the
//! manifest entry for its file stem (a JSON object `{"open_jaw": 1024, "joy": 63}`); else
//! [`default_value`] (63 for visemes and expressions, 20 000 AU for rotation FAPs, 512 for the
//! other FAPs). A morph without a stored value cannot be converted correctly, so writers always
//! put `@VALUE` into the name when the value is not the default.
//!
//! **Tables.** Each morph must have the neutral's topology (same vertex count, same polygons).
//! Vertices that moved by no more than the tolerance are left out of the table. Morphs of one
//! key at different values make one multi-interval table (borders 0 and every value), see
//! [`fat_from_morph_targets`].
//!
//! **Writing.** [`write_morph_set`] writes `neutral.obj` (all meshes merged in face
//! coordinates, as [`super::write()`] writes OBJ; a face read from an OBJ file that still has
//! its layout gets that file back with only its `v` lines rewritten, in every file of the set), `feature-points.csv` (the feature points
//! bound to the merged mesh's vertices) and one OBJ per table and value: the table's vertex
//! motion plus the effect of the transforms it drives on the meshes under them. Files other
//! than `*.obj` and the file `neutral.obj` are ignored when a set is read, so a written set
//! reads back with `from-morphs DIR/neutral.obj DIR --fp DIR/feature-points.csv`.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use glam::{Affine3A, DVec3, Vec3};
use serde::Serialize;

use super::attach::attach_feature_points;
use super::write::{merged_positions, ObjPose, ObjPoses};
use super::{FaceError, FaceModel};
use crate::error::{Error, Location, Result};
use crate::fat::eval::Activation;
use crate::fat::morph::{default_value, fat_from_morph_targets, MorphMesh, MorphTarget};
use crate::fat::TableKey;
use crate::fdp::csv::{write_csv_file, FeaturePointTable};
use crate::fdp::{FeaturePoint, FeaturePointSet, VertexBinding};
use crate::mesh::obj::read_obj_file;
use crate::mesh::Mesh;

/// Most files a morph folder may hold (a bound against hostile folders).
pub const MAX_MORPH_FOLDER_ENTRIES: usize = 10_000;

/// Default tolerance, relative to the neutral mesh's bounding-box diagonal.
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-6;

/// File name of the neutral face in a written morph set.
pub const NEUTRAL_FILE: &str = "neutral.obj";

/// File name of the feature points in a written morph set.
pub const FEATURE_POINTS_FILE: &str = "feature-points.csv";

/// A morph file name, parsed: `NAME` or `NAME@VALUE`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MorphName {
    /// The table key.
    pub key: TableKey,
    /// The value from the name, if it has one.
    pub value: Option<f64>,
}

/// Parses a morph file stem (`open_jaw`, `viseme_7`, `joy`, `open_jaw@-512`).
pub fn parse_morph_name(stem: &str) -> std::result::Result<MorphName, String> {
    let (name, value) = match stem.split_once('@') {
        Some((n, v)) => (n, Some(v)),
        None => (stem, None),
    };
    let key = TableKey::from_name(name).ok_or_else(|| {
        format!(
            "`{name}` is not a FAP name (e.g. open_jaw), viseme_1..viseme_14 or an expression (joy, sadness, anger, fear, disgust, surprise)"
        )
    })?;
    let value = match value {
        None => None,
        Some(v) => Some(
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x != 0.0)
                .ok_or_else(|| {
                    format!("`@{v}`: the value after @ must be a finite, non-zero number")
                })?,
        ),
    };
    Ok(MorphName { key, value })
}

/// The file name of a morph: `NAME.obj` at the key's default value, else `NAME@VALUE.obj`.
pub fn morph_file_name(key: TableKey, value: f64) -> String {
    if value == default_value(key) {
        format!("{}.obj", key.name())
    } else {
        format!("{}@{}.obj", key.name(), value)
    }
}

/// Where a morph's value came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ValueSource {
    /// `@VALUE` in the file name.
    FileName,
    /// The manifest.
    Manifest,
    /// [`default_value`].
    Default,
}

/// One morph file used to build a face.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MorphUsed {
    /// The file.
    pub file: PathBuf,
    /// Its table key.
    pub key: TableKey,
    /// The value it represents.
    pub value: f64,
    /// Where the value came from.
    pub value_source: ValueSource,
    /// Vertices that moved more than the tolerance.
    pub moved_vertices: usize,
}

/// What building a face from a morph set did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MorphSetReport {
    /// Morphs used, in file-name order.
    pub morphs: Vec<MorphUsed>,
    /// Files of the folder that were not read (not `.obj`, or the neutral).
    pub ignored: Vec<PathBuf>,
    /// The absolute tolerance used.
    pub tolerance: f64,
}

/// Reads a manifest: a JSON object mapping morph file stems to FAP values.
pub fn read_manifest(path: &Path) -> Result<BTreeMap<String, f64>> {
    let text = crate::io::read_text(path)?;
    let map: BTreeMap<String, serde_json::Value> =
        serde_json::from_str(&text).map_err(|e| FaceError::ManifestSyntax {
            location: Location {
                file: path.to_path_buf(),
                line: e.line(),
                column: e.column(),
            },
            message: e.to_string(),
        })?;
    map.into_iter()
        .map(|(k, v)| {
            let x = v
                .as_f64()
                .filter(|x| x.is_finite() && *x != 0.0)
                .ok_or_else(|| FaceError::ManifestValue {
                    file: path.to_path_buf(),
                    name: k.clone(),
                    value: v.to_string(),
                })?;
            Ok((k, x))
        })
        .collect()
}

/// Options for [`face_from_morph_set`].
#[derive(Clone, Debug, Default)]
pub struct MorphSetOptions {
    /// Feature-point file for the neutral (any format [`crate::fdp::read_feature_points`] reads).
    pub feature_points: Option<PathBuf>,
    /// Manifest of values (see the module docs).
    pub manifest: Option<PathBuf>,
    /// Absolute tolerance; default [`DEFAULT_RELATIVE_TOLERANCE`] × the neutral's diagonal.
    pub tolerance: Option<f64>,
}

/// Builds a face from a neutral OBJ and a folder of morph OBJs (see the module docs).
pub fn face_from_morph_set(
    neutral: &Path,
    dir: &Path,
    options: &MorphSetOptions,
) -> Result<(FaceModel, MorphSetReport)> {
    let (mut face, _) = super::read::read_with(neutral, &Default::default())?;
    if face.meshes.len() != 1
        || super::format::FaceFormat::of_path(neutral)? != super::format::FaceFormat::Obj
    {
        return Err(Error::Unsupported(format!(
            "{}: the neutral face must be an .obj file",
            neutral.display()
        )));
    }
    let neutral_mesh = &face.meshes[0].mesh;
    let mesh_name = face.meshes[0].name.clone();
    let tolerance = match options.tolerance {
        Some(t) if t.is_finite() && t >= 0.0 => t,
        Some(t) => return Err(FaceError::BadTolerance { tolerance: t }.into()),
        None => {
            let diag = neutral_mesh.bounds().map_or(1.0, |b| b.diagonal() as f64);
            DEFAULT_RELATIVE_TOLERANCE * diag
        }
    };
    let manifest = match &options.manifest {
        Some(m) => read_manifest(m)?,
        None => BTreeMap::new(),
    };

    let mut report = MorphSetReport {
        tolerance,
        ..MorphSetReport::default()
    };
    let neutral_canon = std::fs::canonicalize(neutral).ok();
    let mut files = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        if files.len() + report.ignored.len() >= MAX_MORPH_FOLDER_ENTRIES {
            return Err(FaceError::TooManyMorphFiles {
                dir: dir.to_path_buf(),
                limit: MAX_MORPH_FOLDER_ENTRIES,
            }
            .into());
        }
        let path = entry.path();
        if !path.is_file() {
            continue;
        }
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        let is_neutral = std::fs::canonicalize(&path).ok() == neutral_canon
            || path.file_name().is_some_and(|n| n == NEUTRAL_FILE);
        if !is_obj || is_neutral {
            report.ignored.push(path);
        } else {
            files.push(path);
        }
    }
    files.sort();
    report.ignored.sort();

    let mut used_stems = Vec::new();
    let mut targets = Vec::new();
    let mut seen: HashMap<(TableKey, u64), PathBuf> = HashMap::new();
    for path in &files {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let name = parse_morph_name(&stem).map_err(|message| FaceError::BadMorphName {
            file: path.clone(),
            message,
        })?;
        let (value, value_source) = match (name.value, manifest.get(&stem)) {
            (Some(v), _) => (v, ValueSource::FileName),
            (None, Some(&v)) => (v, ValueSource::Manifest),
            (None, None) => (default_value(name.key), ValueSource::Default),
        };
        if manifest.contains_key(&stem) {
            used_stems.push(stem.clone());
        }
        if let Some(other) = seen.insert((name.key, value.to_bits()), path.clone()) {
            return Err(FaceError::DuplicateMorph {
                first: other,
                second: path.clone(),
                key: name.key,
                value,
            }
            .into());
        }
        let (obj, _) = read_obj_file(path)?;
        let target = morph_target(
            name.key,
            value,
            &mesh_name,
            neutral_mesh,
            &obj.mesh,
            tolerance,
        )
        .map_err(|e| FaceError::in_file(path, e))?;
        report.morphs.push(MorphUsed {
            file: path.clone(),
            key: name.key,
            value,
            value_source,
            moved_vertices: target.meshes.first().map_or(0, |m| m.vertices.len()),
        });
        targets.push(target);
    }
    if let Some(unused) = manifest.keys().find(|k| !used_stems.contains(k)) {
        return Err(FaceError::UnusedManifestEntry {
            manifest: options
                .manifest
                .as_deref()
                .map_or_else(String::new, |p| p.display().to_string()),
            name: unused.clone(),
            dir: dir.to_path_buf(),
        }
        .into());
    }
    // Keys in the standard's order (FAPs, visemes, expressions), whatever the file order.
    targets.sort_by(|a, b| a.key.cmp(&b.key).then(a.value.total_cmp(&b.value)));
    face.fat = fat_from_morph_targets(&targets)?;
    if let Some(fp) = &options.feature_points {
        let file = crate::fdp::read_feature_points(fp)?;
        let alias = neutral
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        attach_feature_points(&mut face, file.points, &[&alias])
            .map_err(|e| FaceError::in_file(fp, e))?;
    }
    Ok((face, report))
}

/// The morph target of `morph` against `neutral` (same topology required): every vertex
/// that moved by more than `tolerance`.
pub fn morph_target(
    key: TableKey,
    value: f64,
    mesh_name: &str,
    neutral: &Mesh,
    morph: &Mesh,
    tolerance: f64,
) -> Result<MorphTarget> {
    if morph.vertex_count() != neutral.vertex_count() {
        return Err(FaceError::MorphVertexCount {
            morph: morph.vertex_count(),
            neutral: neutral.vertex_count(),
        }
        .into());
    }
    if morph.polygons != neutral.polygons {
        let at = morph
            .polygons
            .iter()
            .zip(neutral.polygons.iter())
            .position(|(a, b)| a != b)
            .unwrap_or(morph.polygons.len().min(neutral.polygons.len()));
        return Err(FaceError::MorphPolygons {
            at: at + 1,
            morph: morph.polygons.len(),
            neutral: neutral.polygons.len(),
        }
        .into());
    }
    if let Some(i) = morph.positions.iter().position(|p| !p.is_finite()) {
        return Err(FaceError::MorphNonFinite { vertex: i + 1 }.into());
    }
    let mut vertices = Vec::new();
    let mut offsets = Vec::new();
    for (i, (m, n)) in morph.positions.iter().zip(&neutral.positions).enumerate() {
        let d = m.as_dvec3() - n.as_dvec3();
        if d.length() > tolerance && d != DVec3::ZERO {
            vertices.push(i as u32);
            offsets.push(d);
        }
    }
    Ok(MorphTarget {
        key,
        value,
        meshes: vec![MorphMesh {
            mesh: mesh_name.to_string(),
            vertices,
            offsets,
        }],
        transforms: Vec::new(),
    })
}

/// One file written by [`write_morph_set`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WrittenMorph {
    /// The file.
    pub file: PathBuf,
    /// Its table key.
    pub key: TableKey,
    /// The value it shows.
    pub value: f64,
}

/// The values each key of the face's FAT is written at: `value` if given, else every non-zero
/// interval border of the key's meshes (or [`default_value`] for transform-only tables).
pub fn morph_values(face: &FaceModel, value: Option<f64>) -> Vec<(TableKey, Vec<f64>)> {
    let mut out: Vec<(TableKey, Vec<f64>)> = Vec::new();
    for t in &face.fat.tables {
        if out.iter().any(|(k, _)| *k == t.key) {
            continue;
        }
        let values = match value {
            Some(v) => vec![v],
            None => {
                let mut v: Vec<f64> = face
                    .fat
                    .tables
                    .iter()
                    .filter(|x| x.key == t.key)
                    .flat_map(|x| x.meshes.iter().flat_map(|m| m.interval_borders.iter()))
                    .copied()
                    .filter(|b| *b != 0.0 && b.is_finite())
                    .collect();
                v.sort_by(f64::total_cmp);
                v.dedup();
                if v.is_empty() {
                    v.push(default_value(t.key));
                }
                v
            }
        };
        out.push((t.key, values));
    }
    // Keys in order whatever the tables' order, so equal FATs write the same set.
    out.sort_by_key(|(k, _)| *k);
    out
}

/// Writes the face's FAT as a morph set into `dir` (created, or replaced whole when it holds
/// an earlier set; written atomically): see the module docs.
/// `value` evaluates every table at that value instead of its reference values.
pub fn write_morph_set(
    face: &FaceModel,
    dir: &Path,
    value: Option<f64>,
) -> Result<Vec<WrittenMorph>> {
    if let Some(v) = value {
        if !v.is_finite() || v == 0.0 {
            return Err(FaceError::BadMorphValue { value: v }.into());
        }
    }
    face.check_structure()?;
    let mut eval = face.evaluator()?;
    let mut out = eval.output();
    // Written into a temporary sibling renamed into place at the end: a failure half-way
    // leaves no partial set. An existing set (OBJs and the CSV) is replaced whole; a folder
    // holding anything else is refused.
    let out_dir =
        crate::io::open_frame_dir(dir, |n| n.ends_with(".obj") || n == FEATURE_POINTS_FILE)?;

    let poses = ObjPoses::new(face)?;
    let neutral = ObjPose {
        file: NEUTRAL_FILE.to_string(),
        mesh_name: None,
        positions: merged_positions(face, &face.frames().meshes, None),
    };
    poses.write(&out_dir, std::slice::from_ref(&neutral))?;
    let points = FeaturePointTable::from_set(&merged_feature_points(face));
    out_dir.write_file(FEATURE_POINTS_FILE, |p| write_csv_file(p, &points))?;

    // Poses are evaluated one by one and written a batch at a time on rayon's threads.
    let batch_len = ObjPoses::batch_len();
    let mut batch = Vec::with_capacity(batch_len);
    let mut written = Vec::new();
    for (key, values) in morph_values(face, value) {
        for v in values {
            eval.evaluate(&[Activation { key, value: v }], &mut out);
            let locals: Vec<Affine3A> = face
                .transforms
                .iter()
                .zip(&out.transforms)
                .map(|(t, d)| t.animated_matrix(d))
                .collect();
            let frames = face.frames_with(&locals);
            let name = morph_file_name(key, v);
            batch.push(ObjPose {
                file: name.clone(),
                mesh_name: Some(key.name()),
                positions: merged_positions(face, &frames.meshes, Some(&out.displacements)),
            });
            if batch.len() == batch_len {
                poses.write(&out_dir, &batch)?;
                batch.clear();
            }
            written.push(WrittenMorph {
                file: dir.join(name),
                key,
                value: v,
            });
        }
    }
    poses.write(&out_dir, &batch)?;
    out_dir.commit()?;
    Ok(written)
}

/// The face's feature points re-bound to the vertices of its merged mesh (see
/// [`super::write::merged_mesh`]), with no mesh name.
pub fn merged_feature_points(face: &FaceModel) -> FeaturePointSet {
    let mut base = HashMap::new();
    let mut n = 0u32;
    for m in &face.meshes {
        base.insert(m.name.as_str(), n);
        n += m.mesh.vertex_count() as u32;
    }
    let single = (face.meshes.len() == 1).then(|| face.meshes[0].name.as_str());
    let mut out = FeaturePointSet::new();
    for p in face.feature_points.iter() {
        let binding = p.binding.as_ref().and_then(|b| {
            let mesh = b.mesh.as_deref().or(single)?;
            let off = *base.get(mesh)?;
            Some(VertexBinding {
                mesh: None,
                vertices: b.vertices.iter().map(|v| v + off).collect(),
            })
        });
        out.insert(FeaturePoint {
            id: p.id,
            position: p.position,
            binding,
        });
    }
    out
}

/// Builds a single-mesh face from a neutral mesh and in-memory morphs (for tests and tools
/// that already hold meshes): `(key, value, morph mesh)`.
pub fn face_from_morph_meshes(
    name: &str,
    neutral: Mesh,
    morphs: &[(TableKey, f64, Mesh)],
    tolerance: f64,
) -> Result<FaceModel> {
    let mut targets = Vec::with_capacity(morphs.len());
    for (key, value, m) in morphs {
        targets.push(
            morph_target(*key, *value, name, &neutral, m, tolerance).map_err(|e| {
                FaceError::Morph {
                    key: *key,
                    value: *value,
                    source: Box::new(e),
                }
            })?,
        );
    }
    let mut face = FaceModel::single_mesh(name, neutral);
    face.fat = fat_from_morph_targets(&targets)?;
    Ok(face)
}

/// `neutral` with `offsets` added (for building morph meshes in tests and tools).
pub fn displaced_mesh(neutral: &Mesh, offsets: &[(u32, Vec3)]) -> Mesh {
    let mut m = neutral.clone();
    for &(v, d) in offsets {
        if let Some(p) = m.positions.get_mut(v as usize) {
            *p += d;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{Expression, FapId, Viseme};

    #[test]
    fn morph_names() {
        let f = |s: &str| parse_morph_name(s);
        let jaw = TableKey::LowLevel(FapId::from_name("open_jaw").unwrap());
        assert_eq!(
            f("open_jaw").unwrap(),
            MorphName {
                key: jaw,
                value: None
            }
        );
        assert_eq!(
            f("open_jaw@-512").unwrap(),
            MorphName {
                key: jaw,
                value: Some(-512.0)
            }
        );
        assert_eq!(
            f("viseme_7").unwrap().key,
            TableKey::Viseme(Viseme::new(7).unwrap())
        );
        assert_eq!(
            f("joy").unwrap().key,
            TableKey::Expression(Expression::from_name("joy").unwrap())
        );
        for bad in [
            "open_jaws",
            "viseme_0",
            "viseme_15",
            "neutral",
            "open_jaw@",
            "open_jaw@0",
            "open_jaw@nan",
            "open_jaw@inf",
            "open_jaw@1@2",
            "viseme",
        ] {
            assert!(f(bad).is_err(), "{bad}");
        }
        assert_eq!(morph_file_name(jaw, 512.0), "open_jaw.obj");
        assert_eq!(morph_file_name(jaw, 1024.0), "open_jaw@1024.obj");
        assert_eq!(morph_file_name(jaw, -512.0), "open_jaw@-512.obj");
        assert_eq!(f("open_jaw@1024").unwrap().value, Some(1024.0));
    }

    fn grid() -> Mesh {
        let mut p = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                p.push(Vec3::new(x as f32, y as f32, 0.0));
            }
        }
        let mut t = Vec::new();
        for y in 0..3u32 {
            for x in 0..3u32 {
                let i = y * 4 + x;
                t.push([i, i + 1, i + 5]);
                t.push([i, i + 5, i + 4]);
            }
        }
        Mesh::from_triangles("grid", p, &t)
    }

    #[test]
    fn topology_and_value_checks() {
        let n = grid();
        let jaw = TableKey::LowLevel(FapId::from_name("open_jaw").unwrap());
        let mut fewer = n.clone();
        fewer.positions.pop();
        let e = morph_target(jaw, 1.0, "g", &n, &fewer, 0.0).unwrap_err();
        assert!(
            e.to_string().contains("15 vertices, the neutral has 16"),
            "{e}"
        );
        let mut flipped = n.clone();
        flipped.polygons = crate::mesh::Polygons::from_triangles(&[[0, 5, 1]]);
        assert!(morph_target(jaw, 1.0, "g", &n, &flipped, 0.0).is_err());
        let mut nan = n.clone();
        nan.positions[3].x = f32::NAN;
        let e = morph_target(jaw, 1.0, "g", &n, &nan, 0.0).unwrap_err();
        assert!(e.to_string().contains("vertex 4"), "{e}");
        // Tolerance drops tiny motion.
        let m = displaced_mesh(
            &n,
            &[(1, Vec3::new(0.0, -1.0, 0.0)), (2, Vec3::splat(1e-7))],
        );
        let t = morph_target(jaw, 512.0, "g", &n, &m, 1e-5).unwrap();
        assert_eq!(t.meshes[0].vertices, vec![1]);
    }

    #[test]
    fn several_values_make_a_multi_interval_table() {
        let n = grid();
        let jaw = TableKey::LowLevel(FapId::from_name("open_jaw").unwrap());
        let down = Vec3::new(0.0, -1.0, 0.0);
        let morphs = vec![
            (jaw, 512.0, displaced_mesh(&n, &[(1, down)])),
            (jaw, 1024.0, displaced_mesh(&n, &[(1, down * 3.0)])),
            (jaw, -256.0, displaced_mesh(&n, &[(1, -down)])),
        ];
        let face = face_from_morph_meshes("g", n, &morphs, 0.0).unwrap();
        let t = &face.fat.tables[0];
        assert_eq!(
            t.meshes[0].interval_borders,
            vec![-256.0, 0.0, 512.0, 1024.0]
        );
        let d = |p: f64| t.meshes[0].displacement(0, p);
        assert!((d(512.0) - down).length() < 1e-6);
        assert!((d(1024.0) - down * 3.0).length() < 1e-6);
        assert!((d(-256.0) + down).length() < 1e-6);
    }
}
