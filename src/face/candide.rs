//! CANDIDE-3 as an MPEG-4 face with a FAT.
//!
//! [`candide_face`] turns a (shaped) CANDIDE model into a [`FaceModel`]: one triangle mesh
//! `candide`, feature points bound to its vertices (from the CANDIDE feature-point table; a
//! `mean` row binds several vertices), and one `FaceDefTables` per FAP unit of the model.
//!
//! **Tables.** A CANDIDE FAP unit gives each vertex a *direction*: its motion per unit of the
//! FAP's FAPU (e.g. FAP 3 `open_jaw` moves vertex 10 by `(0, -1, 0)` per MNS). The table's
//! rate for a vertex is that direction × the FAPU unit measured on this face
//! ([`crate::fdp::Fapu::unit`], the standard's FAPU of the FAP), in one interval with borders
//! `0 1024`. Evaluation extends the outermost intervals to ±∞ (see
//! [`crate::fat::interval_weights`]), so the same rate also applies to negative values and
//! beyond 1024: the motion is linear in the value, exactly what a CANDIDE unit is. Because the
//! FAPU are measured on the face *after* shaping, the tables are exact for every shape: the
//! feature point of FAP `n` moves by `P × FAPU × direction` at value `P`. A unit that moves its
//! FAP's own feature point against the standard's direction (CANDIDE-3's FAP 18
//! `depress_chin` lowers the chin boss 2.10; MPEG-4's positive `depress_chin` raises it) gets
//! the reversed table, with a note: a FAP stream means the standard's direction.
//!
//! **Left out (and listed in the notes).** FAPs 23–30 (eyeball yaw, pitch, thrust, pupil
//! dilation): the model implements them as translations of the four iris corners without a
//! FAPU, while MPEG-4 defines 23–28 as rotations in AU; no faithful linear table exists, so
//! they get no table. The action unit vectors (`AUV..`) are FACS units, not FAPs, and get no
//! table either. FAPs the model does not implement (43–50, 65–68) have none.

use glam::Vec3;

use crate::candide::CandideModel;
use crate::error::Result;
use crate::face::FaceModel;
use crate::fat::{FaceDefMesh, FaceDefTable, TableKey};
use crate::fdp::{FeaturePointSet, VertexBinding};

/// Name of the mesh of a CANDIDE face.
pub const CANDIDE_MESH: &str = "candide";

/// Interval borders of every CANDIDE table.
pub const CANDIDE_BORDERS: [f64; 2] = [0.0, 1024.0];

/// A CANDIDE face with notes on what was left out.
#[derive(Clone, Debug)]
pub struct CandideFace {
    /// The face.
    pub face: FaceModel,
    /// What was not turned into tables, and why.
    pub notes: Vec<String>,
}

/// The face of `model` shaped by `shape` (see [`CandideModel::with_shape`]) with feature
/// points `fp` (bindings to CANDIDE vertices, e.g. from the CSV table) and a FAT (see the
/// module docs).
pub fn candide_face(
    model: &CandideModel,
    fp: &FeaturePointSet,
    shape: &[(String, f32)],
) -> Result<FaceModel> {
    candide_face_with_notes(model, fp, shape).map(|c| c.face)
}

/// [`candide_face`] with the notes on left-out units.
pub fn candide_face_with_notes(
    model: &CandideModel,
    fp: &FeaturePointSet,
    shape: &[(String, f32)],
) -> Result<CandideFace> {
    let shaped = model.with_shape(shape)?;
    let mut face = FaceModel::single_mesh(CANDIDE_MESH, shaped.to_mesh());
    face.name = "candide".into();
    let mut points = fp.clone();
    let ids: Vec<_> = points.iter().map(|p| p.id).collect();
    for id in ids {
        if let Some(p) = points.get_mut(id) {
            if let Some(b) = p.binding.as_mut() {
                b.mesh = Some(CANDIDE_MESH.into());
            } else if p.position.is_some() {
                return Err(super::FaceError::UnboundCandidePoint { id }.into());
            }
        }
    }
    face.feature_points = points;
    face.resolve_feature_points()?;
    let fapu = face.fapu()?;

    let mut notes = Vec::new();
    let mut skipped_eyes = Vec::new();
    let n = shaped.vertices.len();
    for unit in &shaped.animation_units {
        let Some(fap) = unit.fap else {
            continue;
        };
        let Some(kind) = fap
            .info()
            .fapu
            .filter(|_| !(23..=30).contains(&fap.number()))
        else {
            skipped_eyes.push(fap.number().to_string());
            continue;
        };
        if let Some(k) = unit.fapu.filter(|k| *k != kind) {
            notes.push(format!(
                "FAP {} {}: the model's unit says {}, the standard {}; the standard's FAPU is used",
                fap.number(),
                fap.name(),
                k.abbreviation(),
                kind.abbreviation()
            ));
        }
        // A unit moving its FAP's own feature point against the standard's direction (FAP 18
        // `depress_chin` moves the chin boss 2.10 down; MPEG-4's positive is up) is played
        // reversed: a stream means the standard's direction, and every face cloned from this
        // one inherits the table (its own compliance was 200 % off).
        let sign = if reversed(&face, fap, &unit.displacements) {
            notes.push(format!(
                "FAP {} {}: the model moves its feature point against the standard's direction; the table is reversed",
                fap.number(),
                fap.name()
            ));
            -1.0
        } else {
            1.0
        };
        let u = sign * fapu.unit(kind);
        let mut coord_index = Vec::with_capacity(unit.displacements.len());
        let mut displacements = Vec::with_capacity(unit.displacements.len());
        for &(v, d) in &unit.displacements {
            if v as usize >= n {
                return Err(super::FaceError::AnimationUnitVertex {
                    fap: fap.number(),
                    vertex: v,
                }
                .into());
            }
            if coord_index.contains(&v) {
                return Err(super::FaceError::AnimationUnitRepeat {
                    fap: fap.number(),
                    vertex: v,
                }
                .into());
            }
            coord_index.push(v);
            displacements.push((d.as_dvec3() * u).as_vec3());
        }
        let mut table = FaceDefTable::new(TableKey::LowLevel(fap));
        table.meshes.push(FaceDefMesh {
            mesh: CANDIDE_MESH.into(),
            interval_borders: CANDIDE_BORDERS.to_vec(),
            coord_index,
            displacements,
        });
        face.fat.tables.push(table);
    }
    face.fat.tables.sort_by_key(|t| t.key);
    if !skipped_eyes.is_empty() {
        notes.push(format!(
            "FAPs {} (eyeball yaw/pitch/thrust, pupil dilation) have no table: CANDIDE implements them as iris-corner translations without a FAPU, MPEG-4 as rotations in AU",
            skipped_eyes.join(", ")
        ));
    }
    let auvs = shaped
        .animation_units
        .iter()
        .filter(|u| u.fap.is_none())
        .count();
    if auvs > 0 {
        notes.push(format!(
            "{auvs} action unit vector(s) (AUV) have no table: they are FACS units, not FAPs"
        ));
    }
    Ok(CandideFace { face, notes })
}

/// Whether a CANDIDE unit of `fap` moves the FAP's own (first placed) feature point against
/// the standard's direction for a positive value.
fn reversed(face: &FaceModel, fap: crate::spec::FapId, displacements: &[(u32, Vec3)]) -> bool {
    let info = fap.info();
    let Some(dir) = info.direction() else {
        return false;
    };
    info.feature_points
        .iter()
        .find_map(|&id| face.fp_vertex(id))
        .and_then(|(_, v)| displacements.iter().find(|(x, _)| *x == v))
        .is_some_and(|&(_, d)| d.dot(dir) < 0.0)
}

/// The feature points of the CANDIDE CSV table as bindings to the `candide` mesh (helper for
/// callers that read the table themselves).
pub fn bind_to_candide(points: &FeaturePointSet) -> FeaturePointSet {
    points
        .iter()
        .map(|p| {
            let mut p = p.clone();
            if let Some(b) = p.binding.as_mut() {
                *b = VertexBinding {
                    mesh: Some(CANDIDE_MESH.into()),
                    vertices: b.vertices.clone(),
                };
            }
            p
        })
        .collect()
}

/// Displacement of `vertex` at FAP value `p` predicted by the CANDIDE unit (direction × FAPU ×
/// p), for compliance checks.
pub fn expected_displacement(direction: Vec3, fapu_unit: f64, p: f64) -> Vec3 {
    (direction.as_dvec3() * fapu_unit * p).as_vec3()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fat::eval::Activation;
    use crate::spec::FapId;
    use std::path::Path;

    fn data() -> Option<(CandideModel, FeaturePointSet)> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/candide3");
        if !dir.join("candide3.wfm").exists() {
            eprintln!("note: {} absent; CANDIDE face tests skipped", dir.display());
            return None;
        }
        let model = crate::candide::read_wfm_file(&dir.join("candide3.wfm")).unwrap();
        let fp = crate::fdp::read_feature_points(dir.join("feature-points.csv"))
            .unwrap()
            .points;
        Some((model, fp))
    }

    /// Every included FAP moves its vertices by exactly P × FAPU × direction, on two shapes
    /// with different FAPUs.
    #[test]
    fn tables_are_compliant_for_any_shape() {
        let Some((model, fp)) = data() else { return };
        let shapes: [Vec<(String, f32)>; 2] = [
            vec![],
            crate::candide::parse_shape_spec("Mouth width=0.6,Eyes, width=0.4,Head height=0.5")
                .unwrap(),
        ];
        let mut fapus = Vec::new();
        for shape in &shapes {
            let c = candide_face_with_notes(&model, &fp, shape).unwrap();
            let face = &c.face;
            assert!(
                c.notes.iter().any(|n| n.contains("23, 24")),
                "{:?}",
                c.notes
            );
            let fapu = face.fapu().unwrap();
            fapus.push(fapu);
            let mut eval = face.evaluator().unwrap();
            let mut out = eval.output();
            let mut checked_fp = 0;
            for t in &face.fat.tables {
                let TableKey::LowLevel(fap) = t.key else {
                    panic!()
                };
                let unit = model.fap_unit(fap).unwrap();
                // FAP 18 is the one CANDIDE-3 unit against the standard's direction.
                let sign = if fap.number() == 18 { -1.0 } else { 1.0 };
                let u = sign * fapu.unit(fap.info().fapu.unwrap());
                for p in [300.0, -700.0, 2000.0] {
                    eval.evaluate(
                        &[Activation {
                            key: t.key,
                            value: p,
                        }],
                        &mut out,
                    );
                    for &(v, dir) in &unit.displacements {
                        let want = expected_displacement(dir, u, p);
                        let got = out.displacements[0][v as usize];
                        assert!(
                            (got - want).length() <= 1e-5 * want.length().max(1e-3),
                            "FAP {} vertex {v} at {p}: {got} vs {want}",
                            fap.number()
                        );
                    }
                }
                // The FAP's own feature point moves along the standard direction by P × FAPU.
                let own = fap.info().feature_points.first().copied();
                if let Some((_, v)) = own.and_then(|id| face.fp_vertex(id)) {
                    if let Some(&(_, dir)) = unit.displacements.iter().find(|(x, _)| *x == v) {
                        let sd = fap.info().direction().unwrap();
                        if (dir * sign as f32 - sd).length() < 1e-6 {
                            checked_fp += 1;
                        }
                    }
                }
            }
            assert!(checked_fp >= 31, "{checked_fp}");
            assert!(
                c.notes.iter().any(|n| n.starts_with("FAP 18 depress_chin")),
                "{:?}",
                c.notes
            );
            // FAP 3 on vertex 10 (FP 2.1), explicitly.
            let jaw = TableKey::LowLevel(FapId::from_name("open_jaw").unwrap());
            eval.evaluate(
                &[Activation {
                    key: jaw,
                    value: 512.0,
                }],
                &mut out,
            );
            let want = Vec3::new(
                0.0,
                -(512.0 * fapu.unit(crate::spec::FapuKind::Mns)) as f32,
                0.0,
            );
            assert!((out.displacements[0][10] - want).length() < 1e-6);
            assert_eq!(face.fp_vertex("2.1".parse().unwrap()), Some((0, 10)));
        }
        assert_ne!(fapus[0], fapus[1], "the shapes must change the FAPUs");
        assert!(
            fapus[1].unit(crate::spec::FapuKind::Mw) > fapus[0].unit(crate::spec::FapuKind::Mw)
        );
    }

    #[test]
    fn tables_cover_the_model_fap_units() {
        let Some((model, fp)) = data() else { return };
        let face = candide_face(&model, &fp, &[]).unwrap();
        // 54 FAP units, 8 of them (23..=30) left out.
        assert_eq!(face.fat.tables.len(), 46);
        assert!(face
            .fat
            .tables
            .iter()
            .all(|t| t.meshes[0].interval_borders == CANDIDE_BORDERS));
        let (meshes, transforms) = (face.mesh_sizes(), face.transform_names());
        assert!(crate::fat::validate::validate_fat(&face.fat, &meshes, &transforms).is_empty());
        // Bad shape names and bad feature points are errors.
        assert!(candide_face(&model, &fp, &[("Nope".into(), 1.0)]).is_err());
        let mut few = FeaturePointSet::new();
        few.insert(fp.get("2.1".parse().unwrap()).unwrap().clone());
        let e = candide_face(&model, &few, &[]).unwrap_err();
        assert!(e.to_string().contains("FAPU"), "{e}");
    }
}
