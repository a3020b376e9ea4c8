//! Step 3 — alignment: the target's projected feature points move onto the source's, and
//! every other target point is pulled by the barycentric interpolation of the feature points'
//! displacements over a fixed triangulation of the feature points.

use std::collections::{BTreeMap, BTreeSet};

use glam::{DVec2, DVec3};

use super::interp::TriMesh2;
use super::lips::LipRegion;
use crate::spec::FeaturePointId;

const fn fp(group: u8, index: u8) -> FeaturePointId {
    FeaturePointId::from_parts(group, index)
}

/// Which lip a feature-point triangle belongs to, so upper- and lower-lip points are pulled
/// only by their own lip (the inner-lip points split the two; on a closed mouth their
/// triangles touch along the lip line without crossing it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TriangleLip {
    Upper,
    Lower,
    Neither,
}

use TriangleLip::{Lower as Lo, Neither as No, Upper as Up};

/// The feature-point triangulation (our own; the paper's Figure 7 is not available), written
/// out for both sides of the face. Seen from the front, rows from top to bottom:
/// - brows 4.5 4.3 4.1 | 4.2 4.4 4.6 over eyes 3.7 3.1/3.5/3.3 3.11 | 3.8 … 3.12 (each eye a
///   fan of four triangles around its pupil);
/// - the nose bridge 9.12 between the inner eye corners (joined to the inner brows), the nostrils 9.1/9.2, the tip 9.3,
///   the bottom 9.15, and the cheek bones 5.3/5.4 below the lower eyelids;
/// - the outer upper lip 8.1 between the nose and the lip corners 8.3/8.4, the cheeks 5.1/5.2
///   beside the corners, the jaw corners 2.13/2.14;
/// - upper lip: 8.1–8.3/8.4 above the inner contour 2.4–2.2–2.5; lower lip: 8.2 below the
///   inner contour 2.4–2.3–2.5 (the lip line 8.3–2.4–2.2≡2.3–2.5–8.4 is shared, not crossed);
/// - chin 2.10, chin corners 2.11/2.12 and chin bottom 2.1.
///
/// Points outside the hull (forehead, temples, ears, neck) use the closest-triangle rule.
pub(crate) static FP_TRIANGLES: &[([FeaturePointId; 3], TriangleLip)] = &[
    // Between the brows and the inner eye corners.
    ([fp(4, 1), fp(4, 2), fp(9, 12)], No),
    ([fp(4, 1), fp(9, 12), fp(3, 11)], No),
    ([fp(4, 2), fp(3, 8), fp(9, 12)], No),
    // Left (+x) brow band and eye.
    ([fp(4, 1), fp(3, 11), fp(3, 1)], No),
    ([fp(4, 1), fp(3, 1), fp(4, 3)], No),
    ([fp(4, 3), fp(3, 1), fp(3, 7)], No),
    ([fp(4, 3), fp(3, 7), fp(4, 5)], No),
    ([fp(3, 11), fp(3, 5), fp(3, 1)], No),
    ([fp(3, 1), fp(3, 5), fp(3, 7)], No),
    ([fp(3, 7), fp(3, 5), fp(3, 3)], No),
    ([fp(3, 3), fp(3, 5), fp(3, 11)], No),
    // Right (−x) brow band and eye.
    ([fp(4, 2), fp(3, 8), fp(3, 2)], No),
    ([fp(4, 2), fp(3, 2), fp(4, 4)], No),
    ([fp(4, 4), fp(3, 2), fp(3, 12)], No),
    ([fp(4, 4), fp(3, 12), fp(4, 6)], No),
    ([fp(3, 8), fp(3, 6), fp(3, 2)], No),
    ([fp(3, 2), fp(3, 6), fp(3, 12)], No),
    ([fp(3, 12), fp(3, 6), fp(3, 4)], No),
    ([fp(3, 4), fp(3, 6), fp(3, 8)], No),
    // Left nose and cheek bone.
    ([fp(3, 11), fp(3, 3), fp(9, 1)], No),
    ([fp(3, 11), fp(9, 1), fp(9, 12)], No),
    ([fp(9, 12), fp(9, 1), fp(9, 3)], No),
    ([fp(3, 3), fp(5, 3), fp(9, 1)], No),
    ([fp(3, 3), fp(3, 7), fp(5, 3)], No),
    ([fp(9, 3), fp(9, 1), fp(9, 15)], No),
    // Right nose and cheek bone.
    ([fp(3, 8), fp(3, 4), fp(9, 2)], No),
    ([fp(3, 8), fp(9, 2), fp(9, 12)], No),
    ([fp(9, 12), fp(9, 2), fp(9, 3)], No),
    ([fp(3, 4), fp(5, 4), fp(9, 2)], No),
    ([fp(3, 4), fp(3, 12), fp(5, 4)], No),
    ([fp(9, 3), fp(9, 2), fp(9, 15)], No),
    // Left: nose to mouth, cheek, jaw corner.
    ([fp(9, 15), fp(9, 1), fp(8, 1)], No),
    ([fp(9, 1), fp(8, 3), fp(8, 1)], No),
    ([fp(9, 1), fp(5, 3), fp(8, 3)], No),
    ([fp(5, 3), fp(5, 1), fp(8, 3)], No),
    ([fp(5, 3), fp(2, 13), fp(5, 1)], No),
    // Right: nose to mouth, cheek, jaw corner.
    ([fp(9, 15), fp(9, 2), fp(8, 1)], No),
    ([fp(9, 2), fp(8, 4), fp(8, 1)], No),
    ([fp(9, 2), fp(5, 4), fp(8, 4)], No),
    ([fp(5, 4), fp(5, 2), fp(8, 4)], No),
    ([fp(5, 4), fp(2, 14), fp(5, 2)], No),
    // Upper lip.
    ([fp(8, 1), fp(8, 3), fp(2, 4)], Up),
    ([fp(8, 1), fp(2, 4), fp(2, 2)], Up),
    ([fp(8, 1), fp(8, 4), fp(2, 5)], Up),
    ([fp(8, 1), fp(2, 5), fp(2, 2)], Up),
    // Lower lip.
    ([fp(8, 2), fp(2, 4), fp(8, 3)], Lo),
    ([fp(8, 2), fp(2, 3), fp(2, 4)], Lo),
    ([fp(8, 2), fp(2, 5), fp(8, 4)], Lo),
    ([fp(8, 2), fp(2, 3), fp(2, 5)], Lo),
    // Left chin and jaw.
    ([fp(8, 3), fp(5, 1), fp(2, 11)], No),
    ([fp(5, 1), fp(2, 13), fp(2, 11)], No),
    ([fp(8, 2), fp(8, 3), fp(2, 10)], No),
    ([fp(8, 3), fp(2, 11), fp(2, 10)], No),
    ([fp(2, 10), fp(2, 11), fp(2, 1)], No),
    // Right chin and jaw.
    ([fp(8, 4), fp(5, 2), fp(2, 12)], No),
    ([fp(5, 2), fp(2, 14), fp(2, 12)], No),
    ([fp(8, 2), fp(8, 4), fp(2, 10)], No),
    ([fp(8, 4), fp(2, 12), fp(2, 10)], No),
    ([fp(2, 10), fp(2, 12), fp(2, 1)], No),
];

/// Every feature point of the triangulation (all required on both faces).
pub(crate) fn triangulation_points() -> Vec<FeaturePointId> {
    let set: BTreeSet<FeaturePointId> = FP_TRIANGLES.iter().flat_map(|t| t.0).collect();
    set.into_iter().collect()
}

/// A face's projected feature points and their depths.
pub(crate) type FpMaps<'a> = (
    &'a BTreeMap<FeaturePointId, DVec2>,
    &'a BTreeMap<FeaturePointId, f64>,
);

/// Result of the alignment step.
pub(crate) struct Alignment {
    /// Aligned target points.
    pub points: Vec<DVec2>,
    /// Target depths shifted by the interpolated depth differences of the feature points, so
    /// they compare with the source's depths.
    pub depth: Vec<f64>,
    /// Target points outside every feature-point triangle (closest-triangle rule).
    pub outside: usize,
}

/// Aligns target points `uv` (projected) given both faces' projected feature points.
/// `snap` lists target vertices that are feature points known on both faces: they land
/// exactly on the source's point.
pub(crate) fn align(
    uv: &[DVec2],
    depth: &[f64],
    lips: &[LipRegion],
    (target_fps, target_fp_depth): FpMaps<'_>,
    (source_fps, source_fp_depth): FpMaps<'_>,
    snap: &[(u32, FeaturePointId)],
) -> Alignment {
    use rayon::prelude::*;
    let ids = triangulation_points();
    let index: BTreeMap<FeaturePointId, u32> = ids
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i as u32))
        .collect();
    let points: Vec<DVec2> = ids.iter().map(|id| target_fps[id]).collect();
    let shift: Vec<DVec3> = ids
        .iter()
        .map(|id| {
            let d = source_fps[id] - target_fps[id];
            DVec3::new(d.x, d.y, source_fp_depth[id] - target_fp_depth[id])
        })
        .collect();
    let tris: Vec<[u32; 3]> = FP_TRIANGLES
        .iter()
        .map(|(t, _)| t.map(|id| index[&id]))
        .collect();
    let mesh = TriMesh2::new(points, vec![0.0; ids.len()], &tris, f64::INFINITY);
    let lip_of = |kept: u32| FP_TRIANGLES[mesh.original[kept as usize] as usize].1;
    let moved: Vec<(DVec3, bool)> = uv
        .par_iter()
        .zip(depth.par_iter())
        .zip(lips.par_iter())
        .map(|((&p, &z), &lip)| {
            let allowed = |t: u32| {
                !matches!(
                    (lip, lip_of(t)),
                    (LipRegion::Upper, TriangleLip::Lower) | (LipRegion::Lower, TriangleLip::Upper)
                )
            };
            let hit = mesh
                .locate(p, None, allowed)
                .or_else(|| mesh.locate(p, None, |_| true));
            let here = DVec3::new(p.x, p.y, z);
            match hit {
                Some(h) => {
                    let d: DVec3 = mesh
                        .weights(&h)
                        .iter()
                        .map(|&(k, w)| shift[k as usize] * w)
                        .sum();
                    (here + d, h.outside)
                }
                None => (here, true),
            }
        })
        .collect();
    let outside = moved.iter().filter(|m| m.1).count();
    let mut points: Vec<DVec2> = moved.iter().map(|m| m.0.truncate()).collect();
    let mut depth: Vec<f64> = moved.iter().map(|m| m.0.z).collect();
    for &(v, id) in snap {
        if let (Some(&s), Some(&d)) = (source_fps.get(&id), source_fp_depth.get(&id)) {
            if let Some(slot) = points.get_mut(v as usize) {
                *slot = s;
                depth[v as usize] = d;
            }
        }
    }
    Alignment {
        points,
        depth,
        outside,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_mirror_symmetric_and_without_duplicates() {
        let mirror = |id: FeaturePointId| -> FeaturePointId {
            let s = id.to_string();
            let pairs = [
                ("4.1", "4.2"),
                ("4.3", "4.4"),
                ("4.5", "4.6"),
                ("3.1", "3.2"),
                ("3.3", "3.4"),
                ("3.5", "3.6"),
                ("3.7", "3.12"),
                ("3.11", "3.8"),
                ("9.1", "9.2"),
                ("5.1", "5.2"),
                ("5.3", "5.4"),
                ("8.3", "8.4"),
                ("2.4", "2.5"),
                ("2.11", "2.12"),
                ("2.13", "2.14"),
            ];
            for (a, b) in pairs {
                if s == a {
                    return b.parse().unwrap();
                }
                if s == b {
                    return a.parse().unwrap();
                }
            }
            id
        };
        let sorted = |t: [FeaturePointId; 3]| {
            let mut t = t;
            t.sort();
            t
        };
        let all: BTreeSet<_> = FP_TRIANGLES.iter().map(|t| sorted(t.0)).collect();
        assert_eq!(all.len(), FP_TRIANGLES.len(), "duplicate triangle");
        for (t, lip) in FP_TRIANGLES {
            let m = sorted(t.map(mirror));
            let found = FP_TRIANGLES.iter().find(|x| sorted(x.0) == m);
            assert_eq!(found.map(|x| x.1), Some(*lip), "mirror of {t:?}");
        }
        assert_eq!(triangulation_points().len(), 39);
    }
}
