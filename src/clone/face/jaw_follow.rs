//! The jaw's motion for target parts no source part or inner piece drives (module docs of
//! [`super`], step 7): a source without teeth (CANDIDE-3), or one whose teeth lie elsewhere
//! than the target's (ICT's teeth inside its skin mesh onto alma's own teeth meshes), gives
//! the target's lower teeth no motion of their own — they stayed still while the chin
//! dropped. The target's lower teeth (and its tongue, which rests on the floor of the mouth
//! and is carried by the jaw unless the source moves a tongue of its own) instead take the
//! rigid motion of the target's own cloned chin.
//!
//! # The fit
//!
//! The chin region is the target skin (aligned frame) below the lower lip and down to just
//! under the chin point, between the lip corners, in front of the chin's depth minus one
//! lip-to-chin height `h` = y(2.3) − y(2.1):
//! y(2.1) − h/4 ≤ y ≤ y(2.3) − h/4, |x − x(2.1)| ≤ 0.6·|8.4 − 8.3|, z ≥ z(2.1) − h.
//! Its vertices pᵢ move by the cloned dᵢ; a small rigid motion d(q) = t + ω × (q − c) is
//! fitted by least squares with c the region's centroid, rᵢ = pᵢ − c. The centroid decouples
//! the two: t = mean dᵢ, and
//!
//! (Σ (|rᵢ|² I − rᵢ rᵢᵀ) + λ I) ω = Σ rᵢ × (dᵢ − t),
//!
//! with λ = [`ROTATION_DAMPING`] × trace(Σ (|rᵢ|² I − rᵢ rᵢᵀ)) / 3: the patch is small and
//! bent, so a turn about an axis it barely spans is damped toward none (pure translation)
//! rather than amplified at the teeth, several centimetres behind it. Each part vertex q then
//! moves by d(q) = d(2.1) + ω × (q − p(2.1)): the fitted turn, but about the chin point and
//! with the chin's own cloned displacement, since the region's mean translation is smaller
//! than the chin's (its upper part and sides move less) and the teeth go where the chin goes.
//! Linear in the motion, as a morph target is. Only the jaw's FAPs
//! (open_jaw, thrust_jaw, shift_jaw) and the high-level tables (visemes, expressions open
//! the mouth) move the parts: a lip FAP moves the lip region, never the teeth; the upper
//! teeth and the eyeballs never take this motion.

use std::collections::HashMap;

use glam::{DMat3, DVec3};

use super::part_motion::PartMeshes;
use super::{Similarity, SkinSurface};
use crate::clone::SurfaceMotion;
use crate::face::FaceModel;
use crate::fat::morph::MorphMesh;
use crate::fat::TableKey;
use crate::spec::FeaturePointId as F;

/// Share of the patch's mean turning stiffness added to every axis (module docs).
const ROTATION_DAMPING: f64 = 0.1;

/// The low-level FAPs that move the jaw: open_jaw, thrust_jaw, shift_jaw.
const JAW_FAPS: [u8; 3] = [3, 14, 15];

/// Whether the table `key` moves the jaw (module docs).
pub(super) fn moves_jaw(key: TableKey) -> bool {
    match key {
        TableKey::LowLevel(f) => JAW_FAPS.contains(&f.number()),
        TableKey::Viseme(_) | TableKey::Expression(_) => true,
    }
}

/// Surface vertices of the chin region (module docs), aligned frame; empty when the target
/// lacks 2.1 or 2.3 or the region holds fewer than four vertices.
fn chin_region(tsurf: &SkinSurface) -> Vec<u32> {
    let s = &tsurf.surface;
    let (Some(chin), Some(lip)) = (s.fp(F::FP_2_1), s.fp(F::FP_2_3)) else {
        return Vec::new();
    };
    let h = lip.y - chin.y;
    if h <= 0.0 {
        return Vec::new();
    }
    let half_width = match (s.fp(F::FP_8_3), s.fp(F::FP_8_4)) {
        (Some(a), Some(b)) => 0.6 * (a.x - b.x).abs(),
        _ => h,
    };
    let region: Vec<u32> = s
        .positions
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            p.y >= chin.y - 0.25 * h
                && p.y <= lip.y - 0.25 * h
                && (p.x - chin.x).abs() <= half_width
                && p.z >= chin.z - h
        })
        .map(|(v, _)| v as u32)
        .collect();
    if region.len() < 4 {
        Vec::new()
    } else {
        region
    }
}

/// The surface vertex nearest the chin point 2.1 (aligned frame).
fn chin_vertex(tsurf: &SkinSurface) -> Option<u32> {
    let s = &tsurf.surface;
    if let Some(&v) = s.fp_vertices.get(&F::FP_2_1) {
        return Some(v);
    }
    let chin = s.fp(F::FP_2_1)?;
    (0..s.positions.len() as u32).min_by(|&a, &b| {
        s.positions[a as usize]
            .distance(chin)
            .total_cmp(&s.positions[b as usize].distance(chin))
    })
}

/// A small rigid motion: displacement `t + ω × (q − c)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct SmallRigid {
    c: DVec3,
    t: DVec3,
    omega: DVec3,
}

impl SmallRigid {
    pub(super) fn at(&self, q: DVec3) -> DVec3 {
        self.t + self.omega.cross(q - self.c)
    }
}

/// The damped least-squares small rigid motion of points `p` moved by `d` (module docs).
fn fit_small_rigid(p: &[DVec3], d: &[DVec3]) -> SmallRigid {
    let n = p.len().max(1) as f64;
    let c = p.iter().copied().sum::<DVec3>() / n;
    let t = d.iter().copied().sum::<DVec3>() / n;
    let mut m = DMat3::ZERO;
    let mut b = DVec3::ZERO;
    for (pi, di) in p.iter().zip(d) {
        let r = *pi - c;
        m += DMat3::from_diagonal(DVec3::splat(r.length_squared()))
            - DMat3::from_cols(r * r.x, r * r.y, r * r.z);
        b += r.cross(*di - t);
    }
    let lambda = ROTATION_DAMPING * (m.x_axis.x + m.y_axis.y + m.z_axis.z) / 3.0;
    let m = m + DMat3::from_diagonal(DVec3::splat(lambda));
    let omega = if m.determinant().abs() > f64::EPSILON * lambda.powi(3).max(f64::MIN_POSITIVE) {
        m.inverse() * b
    } else {
        DVec3::ZERO
    };
    SmallRigid {
        c,
        t,
        omega: if omega.is_finite() {
            omega
        } else {
            DVec3::ZERO
        },
    }
}

/// The chin's small rigid motion under the cloned skin motion `m` (module docs), `None` when
/// the target has no chin region or the region does not move.
pub(super) fn chin_rigid(tsurf: &SkinSurface, m: &SurfaceMotion) -> Option<SmallRigid> {
    let region = chin_region(tsurf);
    let pos: Vec<DVec3> = region
        .iter()
        .map(|&v| tsurf.surface.positions[v as usize].as_dvec3())
        .collect();
    rigid_of(tsurf, &region, &pos, m)
}

/// [`chin_rigid`] on the chin region `region` (positions `pos`) found once.
fn rigid_of(
    tsurf: &SkinSurface,
    region: &[u32],
    pos: &[DVec3],
    m: &SurfaceMotion,
) -> Option<SmallRigid> {
    if region.is_empty() {
        return None;
    }
    let chin = chin_vertex(tsurf)?;
    let d: Vec<DVec3> = region.iter().map(|&v| m.offset_at(v).as_dvec3()).collect();
    if d.iter().all(|x| *x == DVec3::ZERO) {
        return None;
    }
    // The turn from the region, the translation from the chin itself: the region's mean is
    // less than the chin's (its upper part and sides move less), and the teeth should move
    // like the chin.
    let fitted = fit_small_rigid(pos, &d);
    Some(SmallRigid {
        c: tsurf.surface.positions[chin as usize].as_dvec3(),
        t: m.offset_at(chin).as_dvec3(),
        omega: fitted.omega,
    })
}

/// Per cloned skin motion (key, value bits), the displacements of the target meshes `meshes`
/// (lower teeth, a tongue the source does not move) by the chin's fitted rigid motion.
pub(super) fn jaw_motions(
    face: &FaceModel,
    meshes: &[usize],
    tsurf: &SkinSurface,
    frame: &Similarity,
    cloned: &[SurfaceMotion],
) -> PartMeshes {
    let mut out: PartMeshes = HashMap::new();
    if meshes.is_empty() {
        return out;
    }
    let region = chin_region(tsurf);
    if region.is_empty() {
        return out;
    }
    let pos: Vec<DVec3> = region
        .iter()
        .map(|&v| tsurf.surface.positions[v as usize].as_dvec3())
        .collect();
    let frames = face.frames();
    // Each mesh's vertices in the aligned frame, and its inverse world 3×3.
    let parts: Vec<(usize, Vec<DVec3>, DMat3)> = meshes
        .iter()
        .filter_map(|&mi| {
            let world = *frames.meshes.get(mi)?;
            let q = face
                .mesh_world(&frames, mi)
                .into_iter()
                .map(|p| frame.point(p).as_dvec3())
                .collect();
            Some((mi, q, world.matrix3.as_dmat3().inverse()))
        })
        .collect();
    for m in cloned.iter().filter(|m| moves_jaw(m.key)) {
        let Some(rigid) = rigid_of(tsurf, &region, &pos, m) else {
            continue;
        };
        for (mi, q, inv) in &parts {
            let offsets: Vec<DVec3> = q
                .iter()
                .map(|&q| *inv * frame.inverse_vector(rigid.at(q)))
                .collect();
            if !offsets.iter().all(|o| o.is_finite()) {
                continue;
            }
            out.entry((m.key, m.value.to_bits()))
                .or_default()
                .push(MorphMesh {
                    mesh: face.meshes[*mi].name.clone(),
                    vertices: (0..offsets.len() as u32).collect(),
                    offsets,
                });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A patch turned about a far hinge: the fit recovers the turn, and a point nearer the
    /// hinge moves less than the patch.
    #[test]
    fn a_turn_about_a_hinge_is_recovered() {
        let hinge = DVec3::new(0.0, 0.0, -8.0);
        let omega = DVec3::new(0.05, 0.0, 0.0);
        let mut p = Vec::new();
        for i in -3..=3 {
            for j in -3..=3 {
                let (x, y) = (f64::from(i) * 0.5, f64::from(j) * 0.4);
                // A bent patch: the chin's front curves back at its sides and bottom.
                p.push(DVec3::new(x, y, -0.1 * (x * x + y * y)));
            }
        }
        let d: Vec<DVec3> = p.iter().map(|&q| omega.cross(q - hinge)).collect();
        let fit = fit_small_rigid(&p, &d);
        let tooth = DVec3::new(0.0, 1.0, -3.0);
        let want = omega.cross(tooth - hinge);
        let got = fit.at(tooth);
        assert!(got.x.abs() < 1e-9, "{got}");
        assert!(
            (got - want).length() < 0.15 * want.length(),
            "{got} vs {want}"
        );
        // Pure translation stays pure translation.
        let t = DVec3::new(0.0, -0.2, 0.1);
        let fit = fit_small_rigid(&p, &vec![t; p.len()]);
        assert!((fit.at(tooth) - t).length() < 1e-12);
    }

    #[test]
    fn only_jaw_and_high_level_tables_move_the_jaw() {
        use crate::spec::FapId;
        for (f, want) in [(3, true), (14, true), (15, true), (5, false), (18, false)] {
            assert_eq!(
                moves_jaw(TableKey::LowLevel(FapId::new(f).unwrap())),
                want,
                "{f}"
            );
        }
    }
}
