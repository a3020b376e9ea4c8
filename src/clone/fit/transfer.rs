//! Motion transfer: each source motion carried to the target through the correspondences,
//! then scaled to the target's FAP units.
//!
//! A target vertex lying at barycentric weights `w` in source triangle `(a, b, c)` moves by
//! `f · r · (w_a d_a + w_b d_b + w_c d_c)`, `d` the source displacements, `f` the
//! correspondence's distance fade and `r` the target / source FAPU ratio of the FAP's unit
//! (low-level translation FAPs; 1 for angular FAPs and high-level tables, which the
//! alignment already puts at the target's size). FAT rates are per FAP unit, and the unit is a
//! fraction of the face's own FAPU distance, so this keeps every FAP compliant on the target.
//! A convex combination never exceeds the largest source displacement of the motion, so no
//! vertex moves more (in FAPU) than the source's largest motion of that FAP.

use glam::Vec3;
use rayon::prelude::*;

use super::correspond::Correspondence;
use crate::clone::{CloneSurface, SurfaceMotion};
use crate::fat::TableKey;
use crate::spec::FapuKind;

/// Target / source FAPU ratio of a motion's unit (1 when it has none, or it is angular).
pub(crate) fn fapu_ratio(key: TableKey, source: &CloneSurface, target: &CloneSurface) -> f32 {
    let TableKey::LowLevel(f) = key else {
        return 1.0;
    };
    let Some(kind) = f.info().fapu else {
        return 1.0;
    };
    if kind == FapuKind::Au {
        return 1.0;
    }
    let (s, t) = (source.fapu.unit(kind), target.fapu.unit(kind));
    let r = t / s;
    if r.is_finite() && r > 0.0 {
        r as f32
    } else {
        1.0
    }
}

/// Every motion on the target's vertices.
pub(crate) fn transfer(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    corr: &[Option<Correspondence>],
    fapu_scale: bool,
) -> Vec<SurfaceMotion> {
    let n = source.positions.len();
    motions
        .par_iter()
        .map(|m| {
            let mut dense = vec![Vec3::ZERO; n];
            for &(v, d) in &m.offsets {
                if let Some(slot) = dense.get_mut(v as usize) {
                    *slot = if d.is_finite() { d } else { Vec3::ZERO };
                }
            }
            let r = if fapu_scale {
                fapu_ratio(m.key, source, target)
            } else {
                1.0
            };
            let offsets = corr
                .iter()
                .enumerate()
                .filter_map(|(t, c)| {
                    let c = c.as_ref()?;
                    let mut d = Vec3::ZERO;
                    for k in 0..3 {
                        let s = dense
                            .get(c.vertices[k] as usize)
                            .copied()
                            .unwrap_or(Vec3::ZERO);
                        d += s * c.weights[k];
                    }
                    let d = d * (c.fade * r);
                    (d != Vec3::ZERO && d.is_finite()).then_some((t as u32, d))
                })
                .collect();
            SurfaceMotion {
                key: m.key,
                value: m.value,
                offsets,
            }
        })
        .collect()
}
