//! Rig → FAT: a FAP-compliant Facial Animation Table built from a rig's blend shapes.
//!
//! For every low-level FAP a [`FapMap`] realises, each side (positive / negative values) is a
//! weighted sum of blend shapes. **Calibration** measures on the rig itself how far the FAP's
//! feature point moves at shape weight 1, along the FAP's direction, in the face's FAP unit:
//! that is the FAP value `V` the shape shows, and the table stores `shape / V` per FAP unit
//! (`open_jaw` from how far 2.1 drops under `jawOpen`, in MNS). A FAP with both sides gets a
//! two-interval `FaceDefMesh` (`[V−, 0, V+]`), so `fbakit eval compliance` is exact by
//! construction along the direction.
//!
//! **Shared shapes.** One shape may realise several FAPs (`mouthSmileLeft` lifts both the inner
//! and the outer lip corner, 2.4 and 8.3). Each vertex's motion is split between those FAPs by
//! inverse-square distance to their feature points (a partition of unity, exact 1 at each
//! feature point), so driving all of them at their calibrated values shows the shape once,
//! and each feature point follows only its own FAP.
//!
//! **Eyes.** ARKit's `eyeLook*` shapes move the eyeball vertices; the eyeball FAPs 23–26 are
//! angles. They are realised as mesh tables from the shapes (rigs such as the ICT-FaceKit have
//! no eyeball transforms to drive): the shape's eyeball rotation is measured by a least-squares
//! rigid fit (Kabsch) on the moved vertices of the mesh piece holding the pupil feature point,
//! and `V` is that angle about the FAP's axis in AU. Linear vertex motion approximates the
//! rotation well for the shapes' own range (a few tens of degrees).
//!
//! **Eye and head turns the shapes lack.** Eyeball (23–26) and head (48–50) FAPs no shape
//! realises get the standard's rotation tables about the face's own eyeball centres and neck
//! pivot ([`crate::clone::face::standard`]), so a rig without `eyeLook*` shapes or head joints
//! (the bundled `ict`) still turns its eyes and head.
//!
//! **Visemes and expressions** come from named rig shapes when the map finds them (VRM `aa`,
//! Oculus `viseme_aa`, `happy`), at full strength 63; otherwise from the low-level FAT just built,
//! evaluated at the FAP vectors of [`crate::synth::viseme_faps`] / [`crate::synth::expression_faps`].
//!
//! Nothing is silently lost: every key the map cannot realise, every side that fails
//! calibration and every rig shape left unused is in the [`RigFatReport`].

use std::collections::{BTreeMap, HashMap};

use glam::{DQuat, DVec3, Vec3};
use serde::Serialize;

use super::fap_map::{FapMap, ShapeLookup};
use super::Rig;
use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::eval::Activation;
use crate::fat::morph::{fat_from_morph_targets, MorphMesh, MorphTarget};
use crate::fat::{FaceDefMesh, FaceDefTable, TableKey, HIGH_LEVEL_FULL};
use crate::fdp::{Fapu, FeaturePointSet};
use crate::mesh::rotation_fit::fit_rotation;
use crate::spec::{Expression, FapId, FeaturePointId, Viseme};

/// Smallest |FAP value| a shape at weight 1 must show to be calibrated: below it the shape
/// barely moves the feature point and the table would amplify it beyond recognition.
pub const MIN_CALIBRATED_VALUE: f64 = 64.0;

/// Largest rigid-fit residual (RMS, relative to the RMS motion) for an eyeball rotation.
const MAX_ROTATION_RESIDUAL: f64 = 0.25;

/// One calibrated side of a FAP.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibratedSide {
    /// FAP name.
    pub fap: String,
    /// `+` or `-`.
    pub sign: char,
    /// The shapes (`name*weight`).
    pub shapes: Vec<String>,
    /// Feature point measured.
    pub feature_point: String,
    /// FAP value the shapes show at weight 1 (in the FAP's unit).
    pub value: f64,
    /// The FAP unit.
    pub unit: String,
}

/// A viseme or expression table and where it came from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HighLevelSource {
    /// `viseme_N` or the expression name.
    pub key: String,
    /// `shape NAME` or `low-level FAPs (k of n realised)`.
    pub source: String,
}

/// A key (or one side of it) without a table, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Unmapped {
    /// Key name, with ` (+)` / ` (-)` for one side of a FAP.
    pub key: String,
    /// Why.
    pub reason: String,
}

/// What [`face_from_rig`] did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RigFatReport {
    /// The mapping table used.
    pub map: String,
    /// FAPU distances the calibration used (`None` without feature points).
    pub fapu: Option<crate::fdp::FapuDistances>,
    /// Calibrated FAP sides.
    pub calibrated: Vec<CalibratedSide>,
    /// Viseme and expression tables.
    pub high_level: Vec<HighLevelSource>,
    /// Keys and sides without tables.
    pub unmapped: Vec<Unmapped>,
    /// Rig shapes no table uses.
    pub unused_shapes: Vec<String>,
    /// The standard's eyeball and head rotation tables added where the shapes gave none
    /// ([`crate::clone::face::standard`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standard_rotations: Option<crate::clone::face::standard::StandardRotations>,
    /// Feature points given by position, snapped to their nearest vertex.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub fp_matches: Vec<crate::face::vrml::FeaturePointMatch>,
}

/// Motion of `(mesh, vertex)` pairs.
type SparseMotion = BTreeMap<(usize, u32), Vec3>;

/// Vertex motions below this fraction of a table's largest motion are left out of the table:
/// a shape split between FAPs by distance weights leaves every far vertex a sliver of motion
/// (down to 1e-15), invisible but a dozen digits each in a VRML file (the ICT-FaceKit FAT
/// drops from 19 MB to a few MB gzipped).
const NEGLIGIBLE_MOTION: f32 = 1e-3;

/// The length under which a motion of `delta` is negligible ([`NEGLIGIBLE_MOTION`]).
fn negligible(delta: &SparseMotion) -> f32 {
    delta.values().map(|o| o.length()).fold(0.0, f32::max) * NEGLIGIBLE_MOTION
}

/// One side of one FAP waiting for calibration.
struct Use {
    fap: FapId,
    sign: f64,
    terms: Vec<(usize, f64)>,
    fp: FeaturePointId,
    fp_mesh: usize,
    fp_vertex: u32,
    fp_pos: Vec3,
}

/// Builds `rig`'s face with a FAT realised through `map`, calibrated on `feature_points`
/// (without them only named visemes / expressions get tables). See the module docs.
pub fn face_from_rig(
    rig: &Rig,
    feature_points: Option<FeaturePointSet>,
    map: &FapMap,
) -> Result<(FaceModel, RigFatReport)> {
    rig.check()?;
    let mut face = rig.to_face();
    let mut report = RigFatReport {
        map: map.source.clone(),
        ..RigFatReport::default()
    };
    let fapu = match feature_points {
        Some(points) => {
            report.fp_matches = crate::face::attach::attach_feature_points(&mut face, points, &[])?;
            let fapu = Fapu::from_feature_points(&face.feature_points)?;
            report.fapu = Some(fapu.distances);
            Some(fapu)
        }
        None => None,
    };
    let lookup = ShapeLookup::new(rig);
    let mut used_shapes = vec![false; rig.shapes.len()];

    // 1. Sides to calibrate.
    let mut uses: Vec<Use> = Vec::new();
    for row in &map.rows {
        let TableKey::LowLevel(fap) = row.key else {
            continue;
        };
        let info = fap.info();
        if row.positive.is_empty() && row.negative.is_empty() {
            report.unmapped.push(Unmapped {
                key: fap.name().into(),
                reason: format!("no shapes in the map: {}", row.reasoning),
            });
            continue;
        }
        for (sign, side) in [(1.0, &row.positive), (-1.0, &row.negative)] {
            if side.is_empty() {
                continue;
            }
            let label = format!("{} ({})", fap.name(), if sign > 0.0 { '+' } else { '-' });
            let mut miss = |reason: String| {
                report.unmapped.push(Unmapped {
                    key: label.clone(),
                    reason,
                })
            };
            let Some(terms) = lookup.resolve(side) else {
                let names: Vec<String> = side
                    .iter()
                    .map(|c| {
                        c.iter()
                            .map(|t| t.shape.clone())
                            .collect::<Vec<_>>()
                            .join("+")
                    })
                    .collect();
                miss(format!("the rig has no {}", names.join(" or ")));
                continue;
            };
            if info.direction().is_none() && rotation_axis(fap).is_none() {
                miss("cannot be calibrated: the FAP has no direction or eyeball axis".into());
                continue;
            }
            if fapu.is_none() {
                miss("no feature points to calibrate on (--fp)".into());
                continue;
            }
            let Some((fp, (mi, v))) = info
                .feature_points
                .iter()
                .find_map(|&id| face.fp_vertex(id).map(|x| (id, x)))
            else {
                let fps: Vec<String> = info.feature_points.iter().map(|f| f.to_string()).collect();
                miss(format!(
                    "feature point {} is not on the face",
                    fps.join("/")
                ));
                continue;
            };
            uses.push(Use {
                fap,
                sign,
                terms,
                fp,
                fp_mesh: mi,
                fp_vertex: v,
                fp_pos: rig.meshes[mi].mesh.positions[v as usize],
            });
        }
    }

    for fap in FapId::low_level().filter(|f| !f.is_high_level()) {
        if map.row(TableKey::LowLevel(fap)).is_none() {
            report.unmapped.push(Unmapped {
                key: fap.name().into(),
                reason: "no row in the map".into(),
            });
        }
    }

    // 2. Partition shared shapes, calibrate, drop failures, repeat until stable.
    let mut components: HashMap<usize, Vec<u32>> = HashMap::new();
    let mut calibrated: Vec<(usize, f64, SparseMotion)> = Vec::new();
    let mut alive: Vec<bool> = vec![true; uses.len()];
    for _round in 0..8 {
        calibrated.clear();
        let mut failed = false;
        let shares = partition(rig, &uses, &alive);
        for (u, use_) in uses.iter().enumerate() {
            if !alive[u] {
                continue;
            }
            let delta = &shares[u];
            let unit = fapu
                .as_ref()
                .and_then(|f| f.unit_of(use_.fap))
                .unwrap_or(f64::NAN);
            let measured = match use_.fap.info().direction() {
                Some(dir) => {
                    let d = delta
                        .get(&(use_.fp_mesh, use_.fp_vertex))
                        .copied()
                        .unwrap_or(Vec3::ZERO);
                    Ok(d.as_dvec3().dot(dir.as_dvec3()) / unit)
                }
                None => {
                    let comp = components.entry(use_.fp_mesh).or_insert_with(|| {
                        crate::mesh::components::connected_components(
                            &rig.meshes[use_.fp_mesh].mesh,
                            &[],
                        )
                        .0
                    });
                    eyeball_angle(rig, use_, delta, comp).map(|a| a / unit)
                }
            };
            let value = match measured {
                Ok(v) if v.is_finite() && v * use_.sign >= MIN_CALIBRATED_VALUE => v,
                Ok(v) => {
                    report.unmapped.push(Unmapped {
                        key: format!("{} ({})", use_.fap.name(), sign_char(use_.sign)),
                        reason: format!(
                            "{} moves feature point {} by {v:.1} FAP units at weight 1 (needs {}{MIN_CALIBRATED_VALUE} or more)",
                            shape_list(rig, &use_.terms).join("+"),
                            use_.fp,
                            if use_.sign > 0.0 { "+" } else { "-" },
                        ),
                    });
                    alive[u] = false;
                    failed = true;
                    continue;
                }
                Err(reason) => {
                    report.unmapped.push(Unmapped {
                        key: format!("{} ({})", use_.fap.name(), sign_char(use_.sign)),
                        reason,
                    });
                    alive[u] = false;
                    failed = true;
                    continue;
                }
            };
            calibrated.push((u, value, shares[u].clone()));
        }
        if !failed {
            break;
        }
    }

    // 3. Low-level tables.
    let mut targets = Vec::new();
    for (u, value, delta) in &calibrated {
        let use_ = &uses[*u];
        for &(s, _) in &use_.terms {
            used_shapes[s] = true;
        }
        targets.push(morph_target(
            rig,
            TableKey::LowLevel(use_.fap),
            *value,
            delta,
        ));
        let kind = use_.fap.info().fapu.map_or("-", |k| k.abbreviation());
        report.calibrated.push(CalibratedSide {
            fap: use_.fap.name().into(),
            sign: sign_char(use_.sign),
            shapes: shape_list(rig, &use_.terms),
            feature_point: use_.fp.to_string(),
            value: *value,
            unit: kind.into(),
        });
    }
    targets.sort_by(|a, b| a.key.cmp(&b.key).then(a.value.total_cmp(&b.value)));
    face.fat = fat_from_morph_targets(&targets)?;

    // 4. Visemes and expressions.
    let low_level = face.fat.clone();
    let mut keys: Vec<TableKey> = Viseme::shapes().map(TableKey::Viseme).collect();
    keys.extend(Expression::basic().map(TableKey::Expression));
    let mut evaluator = if low_level.tables.is_empty() {
        None
    } else {
        Some(face.evaluator()?)
    };
    let mut high = Vec::new();
    // The nominal viseme vectors fitted to this face's lips: a rig's "push" or "stretch"
    // shapes need not move the lips as a compliant face's would (`face::visemes`).
    let fitted: std::collections::HashMap<Viseme, Vec<(FapId, f64)>> =
        crate::face::visemes::fitted_visemes(&face)
            .into_iter()
            .collect();
    for key in keys {
        let named = map.row(key).and_then(|r| lookup.resolve(&r.positive));
        if let Some(terms) = named {
            for &(s, _) in &terms {
                used_shapes[s] = true;
            }
            let mut delta = BTreeMap::new();
            add_shapes(rig, &terms, &mut delta, |_, _| 1.0);
            high.push(high_level_table(rig, key, &delta));
            report.high_level.push(HighLevelSource {
                key: key.name(),
                source: format!("shape {}", shape_list(rig, &terms).join("+")),
            });
            continue;
        }
        let faps = match key {
            TableKey::Viseme(v) => fitted
                .get(&v)
                .cloned()
                .unwrap_or_else(|| crate::synth::viseme_faps(v)),
            TableKey::Expression(e) => crate::synth::expression_faps(e),
            TableKey::LowLevel(_) => Vec::new(),
        };
        let realised: Vec<&(FapId, f64)> = faps
            .iter()
            .filter(|(f, _)| low_level.table(TableKey::LowLevel(*f)).is_some())
            .collect();
        let Some(ev) = evaluator.as_mut().filter(|_| !realised.is_empty()) else {
            report.unmapped.push(Unmapped {
                key: key.name(),
                reason: "no named shape, and none of its low-level FAPs is realised".into(),
            });
            continue;
        };
        let acts: Vec<Activation> = realised
            .iter()
            .map(|&&(f, value)| Activation {
                key: TableKey::LowLevel(f),
                value,
            })
            .collect();
        let mut out = ev.output();
        ev.evaluate(&acts, &mut out);
        let mut delta = BTreeMap::new();
        for (mi, disp) in out.displacements.iter().enumerate() {
            for (v, d) in disp.iter().enumerate() {
                if *d != Vec3::ZERO {
                    delta.insert((mi, v as u32), *d);
                }
            }
        }
        high.push(high_level_table(rig, key, &delta));
        report.high_level.push(HighLevelSource {
            key: key.name(),
            source: format!(
                "low-level FAPs ({} of {} realised)",
                realised.len(),
                faps.len()
            ),
        });
    }
    face.fat.tables.extend(high);
    // 5. Eye and head turns the shapes did not give: the standard's rotations about the
    // face's own eyeball centres and neck (they need the feature points, as calibration does).
    if fapu.is_some() {
        let added = crate::clone::face::standard::add_standard_rotations(&mut face);
        let names: Vec<String> = added.added.iter().map(|k| k.name()).collect();
        report.unmapped.retain(|u| {
            let key = u.key.split(" (").next().unwrap_or(&u.key);
            !names.iter().any(|n| n == key)
        });
        if !added.added.is_empty() {
            report.standard_rotations = Some(added);
        }
    }
    report.unused_shapes = rig
        .shapes
        .iter()
        .zip(&used_shapes)
        .filter(|(_, &u)| !u)
        .map(|(s, _)| s.name.clone())
        .collect();
    Ok((face, report))
}

fn sign_char(sign: f64) -> char {
    if sign > 0.0 {
        '+'
    } else {
        '-'
    }
}

fn shape_list(rig: &Rig, terms: &[(usize, f64)]) -> Vec<String> {
    terms
        .iter()
        .map(|&(s, w)| {
            if w == 1.0 {
                rig.shapes[s].name.clone()
            } else {
                format!("{}*{w}", rig.shapes[s].name)
            }
        })
        .collect()
}

/// The eyeball FAPs' rotation axes (the other angle FAPs are not realised from shapes).
fn rotation_axis(fap: FapId) -> Option<Vec3> {
    matches!(fap.number(), 23..=26)
        .then(|| fap.info().rotation_axis())
        .flatten()
}

/// Adds `Σ weight × shape × share(shape, position)` into `delta`.
fn add_shapes(
    rig: &Rig,
    terms: &[(usize, f64)],
    delta: &mut SparseMotion,
    share: impl Fn(usize, Vec3) -> f32,
) {
    for &(s, w) in terms {
        for d in &rig.shapes[s].deltas {
            let positions = &rig.meshes[d.mesh].mesh.positions;
            for (&v, &o) in d.vertices.iter().zip(&d.offsets) {
                let k = share(s, positions[v as usize]);
                if k > 0.0 {
                    *delta.entry((d.mesh, v)).or_insert(Vec3::ZERO) += o * (w as f32 * k);
                }
            }
        }
    }
}

/// Each live use's motion, shared shapes split by inverse-square distance to the feature
/// points of the live uses sharing them (module docs).
fn partition(rig: &Rig, uses: &[Use], alive: &[bool]) -> Vec<SparseMotion> {
    let mut sharers: HashMap<usize, Vec<usize>> = HashMap::new();
    for (u, use_) in uses.iter().enumerate() {
        if alive[u] {
            for &(s, _) in &use_.terms {
                sharers.entry(s).or_default().push(u);
            }
        }
    }
    uses.iter()
        .enumerate()
        .map(|(u, use_)| {
            let mut delta = BTreeMap::new();
            if alive[u] {
                add_shapes(rig, &use_.terms, &mut delta, |s, p| {
                    let list = &sharers[&s];
                    if list.len() == 1 {
                        return 1.0;
                    }
                    share_of(u, list, uses, p)
                });
            }
            delta
        })
        .collect()
}

/// Use `u`'s share of a vertex at `p` among `list` (inverse-square distance weights; a vertex
/// on feature points goes to the uses sitting there, split evenly).
fn share_of(u: usize, list: &[usize], uses: &[Use], p: Vec3) -> f32 {
    let d2: Vec<f64> = list
        .iter()
        .map(|&k| uses[k].fp_pos.as_dvec3().distance_squared(p.as_dvec3()))
        .collect();
    let at_zero = d2.iter().filter(|&&d| d < 1e-18).count();
    let mine = d2[list.iter().position(|&k| k == u).unwrap_or(0)];
    if at_zero > 0 {
        return if mine < 1e-18 {
            1.0 / at_zero as f32
        } else {
            0.0
        };
    }
    let total: f64 = d2.iter().map(|d| 1.0 / d).sum();
    ((1.0 / mine) / total) as f32
}

/// The morph target of `key` from a sparse delta that shows FAP value `value`. Interval
/// borders are integers in the standard (`intervalBorders` is `MFInt32`), so the target is
/// placed at the nearest whole FAP value (at least 1 in magnitude) with the delta scaled to
/// it: the motion per FAP unit, and so compliance, is unchanged.
fn morph_target(rig: &Rig, key: TableKey, value: f64, delta: &SparseMotion) -> MorphTarget {
    let border = value.round().abs().max(1.0).copysign(value);
    let scale = border / value;
    let tiny = negligible(delta);
    let mut meshes: Vec<MorphMesh> = Vec::new();
    for (&(mi, v), &o) in delta {
        if o == Vec3::ZERO || o.length() <= tiny {
            continue;
        }
        if meshes.last().is_none_or(|m| m.mesh != rig.meshes[mi].name) {
            meshes.push(MorphMesh {
                mesh: rig.meshes[mi].name.clone(),
                vertices: Vec::new(),
                offsets: Vec::new(),
            });
        }
        let m = meshes.last_mut().expect("pushed above");
        m.vertices.push(v);
        m.offsets.push(o.as_dvec3() * scale);
    }
    MorphTarget {
        key,
        value: border,
        meshes,
        transforms: Vec::new(),
    }
}

/// A high-level table `[0, 63]` showing `delta` at full strength.
fn high_level_table(rig: &Rig, key: TableKey, delta: &SparseMotion) -> FaceDefTable {
    let mut t = FaceDefTable::new(key);
    let full = HIGH_LEVEL_FULL as f32;
    let tiny = negligible(delta);
    for (&(mi, v), &o) in delta {
        if o == Vec3::ZERO || o.length() <= tiny {
            continue;
        }
        if t.meshes
            .last()
            .is_none_or(|m: &FaceDefMesh| m.mesh != rig.meshes[mi].name)
        {
            t.meshes.push(FaceDefMesh {
                mesh: rig.meshes[mi].name.clone(),
                interval_borders: vec![0.0, HIGH_LEVEL_FULL],
                coord_index: Vec::new(),
                displacements: Vec::new(),
            });
        }
        let m = t.meshes.last_mut().expect("pushed above");
        m.coord_index.push(v);
        m.displacements.push(o / full);
    }
    t
}

/// The rotation (radians, about the FAP's axis) of the mesh piece holding the use's feature
/// point under the use's motion, by a rigid least-squares fit.
fn eyeball_angle(
    rig: &Rig,
    use_: &Use,
    delta: &SparseMotion,
    components: &[u32],
) -> std::result::Result<f64, String> {
    let axis = rotation_axis(use_.fap).ok_or("no eyeball axis")?;
    let label = components[use_.fp_vertex as usize];
    let positions = &rig.meshes[use_.fp_mesh].mesh.positions;
    let pairs: Vec<(DVec3, DVec3)> = delta
        .range((use_.fp_mesh, 0)..=(use_.fp_mesh, u32::MAX))
        .filter(|((_, v), _)| components[*v as usize] == label)
        .map(|(&(_, v), &o)| {
            let p = positions[v as usize].as_dvec3();
            (p, p + o.as_dvec3())
        })
        .collect();
    if pairs.len() < 3 {
        return Err(format!(
            "{} does not move the eyeball (the mesh piece holding feature point {}): the rig \
             turns its eyes by other means, and an eyeball FAP needs that rotation",
            shape_list(rig, &use_.terms).join("+"),
            use_.fp
        ));
    }
    let (rotation, residual) = rigid_rotation(&pairs);
    if residual > MAX_ROTATION_RESIDUAL {
        return Err(format!(
            "the piece holding feature point {} does not turn rigidly (fit residual {:.0} % of the motion); bind {} to the eyeball",
            use_.fp,
            residual * 100.0,
            use_.fp
        ));
    }
    Ok(rotation.dot(axis.as_dvec3()))
}

/// Kabsch fit `q ≈ R p + t`: the rotation vector of `R` and the RMS residual relative to the
/// RMS motion.
fn rigid_rotation(pairs: &[(DVec3, DVec3)]) -> (DVec3, f64) {
    let n = pairs.len() as f64;
    let cp = pairs.iter().map(|p| p.0).sum::<DVec3>() / n;
    let cq = pairs.iter().map(|p| p.1).sum::<DVec3>() / n;
    let Some(fit) = fit_rotation(pairs.iter().map(|(p, q)| (*p - cp, *q - cq))) else {
        return (DVec3::ZERO, f64::INFINITY);
    };
    let r = fit.rotation;
    let (mut err, mut motion) = (0.0, 0.0);
    for (p, q) in pairs {
        let fitted = r * (*p - cp) + cq;
        err += (fitted - *q).length_squared();
        motion += (*q - *p).length_squared();
    }
    let residual = if motion > 0.0 {
        (err / motion).sqrt()
    } else {
        f64::INFINITY
    };
    (DQuat::from_mat3(&r).to_scaled_axis(), residual)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kabsch_finds_a_known_rotation() {
        let rot = glam::DQuat::from_axis_angle(DVec3::Y, 0.2);
        let c = DVec3::new(3.0, 1.0, -2.0);
        let pts = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(-1.0, 0.5, 0.2),
        ];
        let pairs: Vec<_> = pts.iter().map(|&p| (p + c, rot * p + c)).collect();
        let (sa, residual) = rigid_rotation(&pairs);
        assert!((sa - DVec3::new(0.0, 0.2, 0.0)).length() < 1e-9, "{sa}");
        assert!(residual < 1e-9);
    }

    #[test]
    fn shares_are_a_partition_of_unity() {
        let mk = |p: Vec3| Use {
            fap: FapId::new(12).unwrap(),
            sign: 1.0,
            terms: vec![],
            fp: FeaturePointId::new(2, 4).unwrap(),
            fp_mesh: 0,
            fp_vertex: 0,
            fp_pos: p,
        };
        let uses = vec![mk(Vec3::ZERO), mk(Vec3::X), mk(Vec3::Y * 2.0)];
        let list = [0, 1, 2];
        for p in [Vec3::new(0.3, 0.4, 0.1), Vec3::splat(5.0)] {
            let total: f32 = (0..3).map(|u| share_of(u, &list, &uses, p)).sum();
            assert!((total - 1.0).abs() < 1e-6);
        }
        assert_eq!(share_of(1, &list, &uses, Vec3::X), 1.0);
        assert_eq!(share_of(0, &list, &uses, Vec3::X), 0.0);
    }
}
