//! The RBF method's FAPU rescale: each low-level translation FAP's motion is scaled so its
//! feature point moves FAPU-compliantly on the target (module docs of [`super`], step 6).

use std::collections::BTreeMap;

use glam::Vec3;

use crate::clone::{CloneSurface, SurfaceMotion};
use crate::fat::TableKey;
use crate::spec::{FapuKind, FeaturePointId};

/// The feature point a low-level translation FAP is measured at, if both surfaces have it.
fn fap_fp(key: TableKey, a: &CloneSurface, b: &CloneSurface) -> Option<(FeaturePointId, FapuKind)> {
    let TableKey::LowLevel(f) = key else {
        return None;
    };
    let info = f.info();
    let kind = info.fapu?;
    if kind == FapuKind::Au || info.direction().is_none() {
        return None;
    }
    info.feature_points
        .iter()
        .find(|id| a.fp_vertices.contains_key(id) && b.fp_vertices.contains_key(id))
        .map(|&id| (id, kind))
}

fn offset_at(m: &SurfaceMotion, v: u32) -> Vec3 {
    m.offsets
        .binary_search_by_key(&v, |o| o.0)
        .map_or(Vec3::ZERO, |i| m.offsets[i].1)
}

/// Step 6: scales each low-level translation motion so its feature point moves by the
/// FAPU-scaled source displacement. Returns the factors by FAP name.
pub(super) fn rescale_to_fapu(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    out: &mut [SurfaceMotion],
) -> BTreeMap<String, f64> {
    let mut factors = BTreeMap::new();
    for (src, dst) in motions.iter().zip(out.iter_mut()) {
        let Some((fp, kind)) = fap_fp(src.key, source, target) else {
            continue;
        };
        let ds = offset_at(src, source.fp_vertices[&fp]).length() as f64;
        let dt = offset_at(dst, target.fp_vertices[&fp]).length() as f64;
        if ds <= 0.0 || dt <= ds * 1e-6 {
            continue;
        }
        let want = ds * target.fapu.unit(kind) / source.fapu.unit(kind);
        let k = want / dt;
        if !k.is_finite() {
            continue;
        }
        for o in &mut dst.offsets {
            o.1 *= k as f32;
        }
        factors.insert(format!("{}@{}", src.key.name(), src.value), k);
    }
    factors
}
