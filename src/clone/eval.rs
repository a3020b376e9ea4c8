//! Quality of whole-face cloning, on [`FaceModel`]s.
//!
//! - [`self_clone_error`]: formula (1) of Fratarcangeli & Schaerf 2005 (seed 002) for a face
//!   cloned onto itself, on the skin surface, averaged over all morph targets, in percent
//!   (the paper reports 0.028–0.280 %).
//! - [`compliance`]: for every low-level translation FAP the face has a table for, the
//!   displacement of its feature point at ±512 (full evaluation: meshes and transforms) against
//!   `value × FAPU × direction`. The main figure is the error *along* the FAP's direction
//!   (`|d·dir − v·u| / |v·u|`); the full vector error is reported too (a jaw opening on an arc
//!   also moves 2.1 backwards, which is right but not "along").
//! - [`ground_truth_error`]: a cloned face against the same face with its true FAT: per table
//!   and value, `Σ‖d_true − d_cloned‖ / Σ‖d_true‖` over every vertex of every mesh (posed
//!   with transforms), and over the skin meshes only, averaged per key, in percent; and the
//!   same over every mesh after the best non-negative scale `s` of the cloned motion
//!   (`min over s ≥ 0 of Σ‖d_true − s·d_cloned‖`, per table and value), which judges where
//!   things move apart from how far (FAPU rescaling).
//! - [`clone_against_truth`]: clones a source onto a face whose true FAT is known (the target
//!   is the truth without its FAT) and measures the result with [`ground_truth_error`]:
//!   `fbakit eval ground-truth`.
//!
//! - [`normal_turns`]: smoothness of a clone against its source: per morph target of the
//!   source's FAT, the largest turn of a triangle's normal on each face posed at that table
//!   and value ([`super::quality::max_normal_turn`]), and their ratio
//!   ([`super::quality::normal_turn_ratio`]). A crease, fold or spike the source does not
//!   have shows as a ratio well above 1.
//!
//! Posing composes a FAT rotation after the neutral one (`R₀·ΔR`), as [`super::face`] does.

use std::collections::BTreeMap;

use glam::Vec3;
use serde::Serialize;

use super::face::{
    build_skin_surface, clone_face, clone_surface, identify_parts, CloneOptions, CloneOutcome,
    Method, Similarity,
};
use super::quality::morph_target_error;
use super::{CloneError, SurfaceMotion};
use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::eval::Activation;
use crate::fat::morph::fat_to_morph_targets;
use crate::fat::TableKey;
use crate::spec::Directionality;

/// Formula (1) of seed 002, in percent, for `face` cloned onto itself with `method` (default
/// options otherwise).
pub fn self_clone_error(face: &FaceModel, method: Method) -> Result<f64> {
    let opts = CloneOptions {
        method,
        ..CloneOptions::default()
    };
    self_clone_error_with(face, &opts)
}

/// [`self_clone_error`] with explicit options.
pub fn self_clone_error_with(face: &FaceModel, opts: &CloneOptions) -> Result<f64> {
    let parts = identify_parts(face);
    if parts.skin.is_empty() {
        return Err(CloneError::NoSkin {
            face: format!("face `{}`", face.name),
        }
        .into());
    }
    let skin = build_skin_surface(face, &parts.skin, &Similarity::IDENTITY)?;
    let targets = fat_to_morph_targets(&face.fat);
    let frames = face.frames();
    // Same conversion as cloning: mesh offsets into face-frame motions on the welded surface.
    let slot: BTreeMap<&str, usize> = skin
        .meshes
        .iter()
        .enumerate()
        .map(|(k, &m)| (face.meshes[m].name.as_str(), k))
        .collect();
    let motions: Vec<SurfaceMotion> = targets
        .iter()
        .map(|t| {
            let mut acc: BTreeMap<u32, Vec3> = BTreeMap::new();
            for mm in &t.meshes {
                let Some(&k) = slot.get(mm.mesh.as_str()) else {
                    continue;
                };
                let mi = skin.meshes[k];
                let len = face.meshes[mi].mesh.positions.len();
                for (&v, o) in mm.vertices.iter().zip(&mm.offsets) {
                    if (v as usize) < len {
                        let w = skin.welded[skin.starts[k] + v as usize];
                        acc.insert(w, frames.meshes[mi].transform_vector3(o.as_vec3()));
                    }
                }
            }
            SurfaceMotion {
                key: t.key,
                value: t.value,
                offsets: acc.into_iter().filter(|(_, d)| *d != Vec3::ZERO).collect(),
            }
        })
        .filter(|m| !m.offsets.is_empty())
        .collect();
    let result = clone_surface(opts.method, &skin.surface, &motions, &skin.surface, opts)?;
    Ok(morph_target_error(
        &skin.surface.positions,
        &motions,
        &result.motions,
    ))
}

/// Compliance of one FAP.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapCompliance {
    /// FAP name.
    pub fap: String,
    /// Feature point measured.
    pub feature_point: String,
    /// Worst relative error along the FAP direction over the test values.
    pub along_error: f64,
    /// Worst relative error of the whole displacement vector.
    pub vector_error: f64,
}

/// Result of [`compliance`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ComplianceReport {
    /// Per FAP, in FAP order.
    pub faps: Vec<FapCompliance>,
    /// Worst along-direction error.
    pub worst: f64,
    /// Mean along-direction error.
    pub mean: f64,
    /// FAPs with a table that could not be measured (no feature point on the face).
    pub skipped: Vec<String>,
}

/// FAP compliance of a face's FAT (module docs).
pub fn compliance(face: &FaceModel) -> Result<ComplianceReport> {
    let fapu = face.fapu()?;
    let mut evaluator = face.evaluator()?;
    let mut out = evaluator.output();
    let neutral = face.pose_with(&mut evaluator, &mut out, &[]);
    let mut report = ComplianceReport::default();
    for key in face.fat.keys() {
        let TableKey::LowLevel(fap) = key else {
            continue;
        };
        let info = fap.info();
        let (Some(dir), Some(kind)) = (info.direction(), info.fapu) else {
            continue;
        };
        let Some((id, (mi, v))) = info
            .feature_points
            .iter()
            .find_map(|&id| face.fp_vertex(id).map(|x| (id, x)))
        else {
            report.skipped.push(fap.name().to_string());
            continue;
        };
        let values: &[f64] = if info.directionality == Some(Directionality::Bidirectional) {
            &[512.0, -512.0]
        } else {
            &[512.0]
        };
        let (mut along, mut vector) = (0.0f64, 0.0f64);
        for &value in values {
            let posed = face.pose_with(&mut evaluator, &mut out, &[Activation { key, value }]);
            let d = (posed[mi][v as usize] - neutral[mi][v as usize]).as_dvec3();
            let len = value * fapu.unit(kind);
            let expected = dir.as_dvec3() * len;
            along = along.max((d.dot(dir.as_dvec3()) - len).abs() / len.abs());
            vector = vector.max((d - expected).length() / len.abs());
        }
        report.faps.push(FapCompliance {
            fap: fap.name().to_string(),
            feature_point: id.to_string(),
            along_error: along,
            vector_error: vector,
        });
    }
    if !report.faps.is_empty() {
        report.worst = report
            .faps
            .iter()
            .map(|f| f.along_error)
            .fold(0.0, f64::max);
        report.mean =
            report.faps.iter().map(|f| f.along_error).sum::<f64>() / report.faps.len() as f64;
    }
    Ok(report)
}

/// Normal turns of one morph target on the source and on the clone.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyNormalTurn {
    /// Table name.
    pub key: String,
    /// The table value posed (an interval border of the source's table).
    pub value: f64,
    /// Largest normal turn on the source, degrees.
    pub source_degrees: f64,
    /// Largest normal turn on the clone, degrees.
    pub target_degrees: f64,
    /// [`super::quality::normal_turn_ratio`] of the two.
    pub ratio: f64,
    /// Neutral centroid (face frame) of the clone's triangle turning most.
    pub target_at: Option<[f32; 3]>,
}

/// Result of [`normal_turns`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct NormalTurnReport {
    /// Per morph target of the source's FAT.
    pub keys: Vec<KeyNormalTurn>,
    /// The largest ratio, or 0 without keys.
    pub worst_ratio: f64,
}

impl NormalTurnReport {
    /// The entry with the largest ratio.
    pub fn worst(&self) -> Option<&KeyNormalTurn> {
        self.keys.iter().max_by(|a, b| a.ratio.total_cmp(&b.ratio))
    }
}

/// Every mesh's triangles (polygons triangulated) as indices into the meshes' concatenated
/// vertices.
fn face_triangles(face: &FaceModel) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    let mut start = 0u32;
    for m in &face.meshes {
        let (tris, _) = crate::mesh::geometry::triangulate(&m.mesh.positions, &m.mesh.polygons);
        out.extend(tris.iter().map(|t| t.map(|v| v + start)));
        start += m.mesh.positions.len() as u32;
    }
    out
}

/// Normal turns of `cloned` against `source` (module docs): for every morph target of the
/// source's FAT (each table at each non-zero interval border), both faces posed at it with
/// every mesh and transform, the largest turn of a triangle's normal on each.
pub fn normal_turns(source: &FaceModel, cloned: &FaceModel) -> Result<NormalTurnReport> {
    use super::quality::{max_normal_turn, normal_turn_ratio};
    let (ts, tc) = (face_triangles(source), face_triangles(cloned));
    let (mut es, mut ec) = (source.evaluator()?, cloned.evaluator()?);
    let (mut os, mut oc) = (es.output(), ec.output());
    let flat = |p: Vec<Vec<Vec3>>| p.into_iter().flatten().collect::<Vec<Vec3>>();
    let ns = flat(source.pose_with(&mut es, &mut os, &[]));
    let nc = flat(cloned.pose_with(&mut ec, &mut oc, &[]));
    let mut report = NormalTurnReport::default();
    for t in fat_to_morph_targets(&source.fat) {
        let a = [Activation {
            key: t.key,
            value: t.value,
        }];
        let ps = flat(source.pose_with(&mut es, &mut os, &a));
        let pc = flat(cloned.pose_with(&mut ec, &mut oc, &a));
        let s = max_normal_turn(&ns, &ps, &ts);
        let c = max_normal_turn(&nc, &pc, &tc);
        report.keys.push(KeyNormalTurn {
            key: t.key.name(),
            value: t.value,
            source_degrees: s.angle.to_degrees(),
            target_degrees: c.angle.to_degrees(),
            ratio: normal_turn_ratio(s.angle, c.angle),
            target_at: c
                .triangle
                .map(|i| (tc[i].iter().map(|&v| nc[v as usize]).sum::<Vec3>() / 3.0).to_array()),
        });
    }
    report.worst_ratio = report.keys.iter().map(|k| k.ratio).fold(0.0, f64::max);
    Ok(report)
}

/// Error of one key against the truth, in percent.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyError {
    /// Table name.
    pub key: String,
    /// Over every mesh.
    pub all: f64,
    /// Over the skin meshes.
    pub skin: f64,
    /// Over every mesh, after the best non-negative scale of the cloned motion.
    pub scaled: f64,
}

/// Result of [`ground_truth_error`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GroundTruthReport {
    /// Per key of the truth's FAT.
    pub keys: Vec<KeyError>,
    /// Mean over keys, every mesh.
    pub mean_all: f64,
    /// Mean over keys, skin meshes.
    pub mean_skin: f64,
    /// Median over keys, every mesh.
    pub median_all: f64,
    /// Median over keys, every mesh, after the best scale per key and value.
    pub median_scaled: f64,
    /// The key with the largest error over every mesh, and that error.
    pub worst: Option<(String, f64)>,
}

impl GroundTruthReport {
    /// The error of one key by name.
    pub fn key(&self, name: &str) -> Option<&KeyError> {
        self.keys.iter().find(|k| k.key == name)
    }
}

/// Displacement error of `cloned` against `truth`: the same neutral geometry with a
/// different FAT (module docs). The meshes may be cut differently (a one-mesh target has its
/// parts split out by cloning): truth vertices are then matched to cloned vertices by neutral
/// world position.
pub fn ground_truth_error(cloned: &FaceModel, truth: &FaceModel) -> Result<GroundTruthReport> {
    let skin = identify_parts(truth).skin;
    let mut ec = cloned.evaluator()?;
    let mut et = truth.evaluator()?;
    let (mut oc, mut ot) = (ec.output(), et.output());
    let nc = cloned.pose_with(&mut ec, &mut oc, &[]);
    let nt = truth.pose_with(&mut et, &mut ot, &[]);
    let same = cloned.mesh_sizes() == truth.mesh_sizes();
    // Truth (mesh, vertex) → cloned (mesh, vertex).
    let flat: Vec<(usize, usize)> = nc
        .iter()
        .enumerate()
        .flat_map(|(m, l)| (0..l.len()).map(move |v| (m, v)))
        .collect();
    let index = (!same).then(|| {
        crate::mesh::VertexIndex::new(&nc.iter().flatten().copied().collect::<Vec<Vec3>>())
    });
    let mut matched: Vec<Vec<(usize, usize)>> = Vec::with_capacity(nt.len());
    for (mi, l) in nt.iter().enumerate() {
        let mut row = Vec::with_capacity(l.len());
        for (v, &p) in l.iter().enumerate() {
            match &index {
                None => row.push((mi, v)),
                Some(ix) => {
                    let Some((k, d)) = ix.nearest_vertex(p) else {
                        return Err(CloneError::EmptyClone.into());
                    };
                    if d > 1e-4 * (1.0 + p.length()) {
                        return Err(CloneError::TruthGeometryDiffers.into());
                    }
                    row.push(flat[k as usize]);
                }
            }
        }
        matched.push(row);
    }
    let mut per_key: BTreeMap<TableKey, [f64; 4]> = BTreeMap::new();
    for t in fat_to_morph_targets(&truth.fat) {
        let a = [Activation {
            key: t.key,
            value: t.value,
        }];
        let pc = cloned.pose_with(&mut ec, &mut oc, &a);
        let pt = truth.pose_with(&mut et, &mut ot, &a);
        let (mut num, mut den, mut snum, mut sden) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let (mut tc, mut cc) = (0.0f64, 0.0f64);
        let mut pairs = Vec::with_capacity(matched.iter().map(Vec::len).sum());
        for mi in 0..pt.len() {
            let is_skin = skin.contains(&mi);
            for v in 0..pt[mi].len() {
                let (cm, cv) = matched[mi][v];
                let dt = (pt[mi][v] - nt[mi][v]).as_dvec3();
                let dc = (pc[cm][cv] - nc[cm][cv]).as_dvec3();
                let e = (dt - dc).length();
                let l = dt.length();
                num += e;
                den += l;
                if is_skin {
                    snum += e;
                    sden += l;
                }
                tc += dt.dot(dc);
                cc += dc.length_squared();
                pairs.push((dt, dc));
            }
        }
        let scaled_num = best_scale_error(&pairs, if cc > 0.0 { tc / cc } else { 0.0 });
        let pct = |n: f64, d: f64| if d > 0.0 { n / d * 100.0 } else { 0.0 };
        let e = per_key.entry(t.key).or_insert([0.0; 4]);
        e[0] += pct(num, den);
        e[1] += pct(snum, sden);
        e[2] += pct(scaled_num, den);
        e[3] += 1.0;
    }
    let mut report = GroundTruthReport::default();
    for (key, [a, s, sc, n]) in per_key {
        report.keys.push(KeyError {
            key: key.name(),
            all: a / n,
            skin: s / n,
            scaled: sc / n,
        });
    }
    if !report.keys.is_empty() {
        let n = report.keys.len() as f64;
        report.mean_all = report.keys.iter().map(|k| k.all).sum::<f64>() / n;
        report.mean_skin = report.keys.iter().map(|k| k.skin).sum::<f64>() / n;
        report.median_all = median(report.keys.iter().map(|k| k.all).collect());
        report.median_scaled = median(report.keys.iter().map(|k| k.scaled).collect());
        report.worst = report
            .keys
            .iter()
            .max_by(|a, b| a.all.total_cmp(&b.all))
            .map(|k| (k.key.clone(), k.all));
    }
    Ok(report)
}

/// `min over s ≥ 0 of Σ‖t − s·c‖` for `(t, c)` pairs. The sum is convex in `s`, so a golden
/// section search over a bracket that holds both 1 and the least-squares scale `ls` finds it
/// (never worse than `s = 1`).
fn best_scale_error(pairs: &[(glam::DVec3, glam::DVec3)], ls: f64) -> f64 {
    let f = |s: f64| -> f64 { pairs.iter().map(|(t, c)| (*t - *c * s).length()).sum() };
    let (mut lo, mut hi) = (0.0f64, 2.0f64.max(2.0 * ls));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..60 {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    f1.min(f2).min(f(1.0))
}

/// Median of `v` (mean of the two middle values for an even count; 0 when empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => v[n / 2],
        _ => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// `face` as a cloning target: its meshes and feature points without the FAT (and without
/// the scene it was read from, which carried that FAT).
pub fn without_fat(face: &FaceModel) -> FaceModel {
    let mut f = face.clone();
    f.fat = crate::fat::Fat::default();
    f.scene = None;
    f
}

/// One clone measured against the truth: [`clone_against_truth`]'s result.
#[derive(Clone, Debug)]
pub struct TruthRun {
    /// The clone (face and report).
    pub outcome: CloneOutcome,
    /// Its error against the truth.
    pub report: GroundTruthReport,
}

/// Clones `source`'s FAT onto `truth` without its FAT and measures the result against
/// `truth`'s own FAT ([`ground_truth_error`]). `truth` must have a FAT.
pub fn clone_against_truth(
    source: &FaceModel,
    truth: &FaceModel,
    opts: &CloneOptions,
) -> Result<TruthRun> {
    if truth.fat.tables.is_empty() {
        return Err(CloneError::NoTruthFat {
            face: truth.name.clone(),
        }
        .into());
    }
    let outcome = clone_face(source, &without_fat(truth), opts)?;
    let report = ground_truth_error(&outcome.face, truth)?;
    Ok(TruthRun { outcome, report })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn best_scale_removes_a_uniform_scale_only() {
        let t = [
            DVec3::X,
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(1.0, 1.0, 1.0),
        ];
        let half: Vec<_> = t.iter().map(|&d| (d, d * 0.5)).collect();
        let sum: f64 = t.iter().map(|d| d.length()).sum();
        assert!(best_scale_error(&half, 2.0) < 1e-9 * sum);
        // A wrong direction is not repaired by scaling: the best is s = 0 here (error = Σ‖t‖).
        let wrong: Vec<_> = t.iter().map(|&d| (d, -d)).collect();
        assert!((best_scale_error(&wrong, -1.0) - sum).abs() < 1e-9 * sum);
        assert_eq!(median(vec![3.0, 1.0, 2.0, 10.0]), 2.5);
        assert_eq!(median(vec![]), 0.0);
    }
}
