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
//!   with transforms), and over the skin meshes only, averaged per key, in percent.
//!
//! Posing composes a FAT rotation after the neutral one (`R₀·ΔR`), as [`super::face`] does.

use std::collections::BTreeMap;

use glam::Vec3;
use serde::Serialize;

use super::face::{
    build_skin_surface, clone_surface, identify_parts, CloneOptions, Method, Similarity,
};
use super::quality::morph_target_error;
use super::SurfaceMotion;
use crate::error::{Error, Result};
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
        return Err(Error::Invalid(format!(
            "face `{}` has no skin mesh",
            face.name
        )));
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

/// Error of one key against the truth, in percent.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyError {
    /// Table name.
    pub key: String,
    /// Over every mesh.
    pub all: f64,
    /// Over the skin meshes.
    pub skin: f64,
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
                        return Err(Error::Invalid("cloned face has no vertices".into()));
                    };
                    if d > 1e-4 * (1.0 + p.length()) {
                        return Err(Error::Invalid(
                            "ground truth comparison needs the same neutral geometry on both faces"
                                .into(),
                        ));
                    }
                    row.push(flat[k as usize]);
                }
            }
        }
        matched.push(row);
    }
    let mut per_key: BTreeMap<TableKey, (f64, f64, usize)> = BTreeMap::new();
    for t in fat_to_morph_targets(&truth.fat) {
        let a = [Activation {
            key: t.key,
            value: t.value,
        }];
        let pc = cloned.pose_with(&mut ec, &mut oc, &a);
        let pt = truth.pose_with(&mut et, &mut ot, &a);
        let (mut num, mut den, mut snum, mut sden) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for mi in 0..pt.len() {
            let is_skin = skin.contains(&mi);
            for v in 0..pt[mi].len() {
                let (cm, cv) = matched[mi][v];
                let dt = pt[mi][v] - nt[mi][v];
                let dc = pc[cm][cv] - nc[cm][cv];
                let e = (dt - dc).length() as f64;
                let l = dt.length() as f64;
                num += e;
                den += l;
                if is_skin {
                    snum += e;
                    sden += l;
                }
            }
        }
        let all = if den > 0.0 { num / den * 100.0 } else { 0.0 };
        let sk = if sden > 0.0 { snum / sden * 100.0 } else { 0.0 };
        let e = per_key.entry(t.key).or_insert((0.0, 0.0, 0));
        e.0 += all;
        e.1 += sk;
        e.2 += 1;
    }
    let mut report = GroundTruthReport::default();
    for (key, (a, s, n)) in per_key {
        report.keys.push(KeyError {
            key: key.name(),
            all: a / n as f64,
            skin: s / n as f64,
        });
    }
    if !report.keys.is_empty() {
        let n = report.keys.len() as f64;
        report.mean_all = report.keys.iter().map(|k| k.all).sum::<f64>() / n;
        report.mean_skin = report.keys.iter().map(|k| k.skin).sum::<f64>() / n;
    }
    Ok(report)
}
