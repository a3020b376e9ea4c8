//! Step 7 — upper/lower lip regions in the projected 2D space.

use std::collections::BTreeMap;

use glam::DVec2;

use crate::spec::FeaturePointId;

/// Which lip region a vertex is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LipRegion {
    /// Between the inner upper lip contour and the nose.
    Upper,
    /// Between the inner lower lip contour and the chin.
    Lower,
    /// Elsewhere (including the lip corners, which border both lips).
    Out,
}

/// Points closer than this (alignment units) to a polygon's boundary are "on" it and are
/// classified through their triangles.
const ON_LINE: f64 = 1e-6;

/// Inner-lip contour points whose absence only coarsens the polygons.
pub(crate) const OPTIONAL: [FeaturePointId; 4] = [
    FeaturePointId::FP_2_6,
    FeaturePointId::FP_2_7,
    FeaturePointId::FP_2_8,
    FeaturePointId::FP_2_9,
];

/// The two lip polygons of one face.
#[derive(Clone, Debug)]
pub(crate) struct LipPolygons {
    pub upper: Vec<DVec2>,
    pub lower: Vec<DVec2>,
}

impl LipPolygons {
    /// Upper: the lip line (outer corner 8.4, inner contour 2.5, 2.7, 2.2, 2.6, 2.4, outer
    /// corner 8.3 — sorted by angle, so the left/right naming of the midpoints does not
    /// matter) closed over the sides and bottom of the nose (9.1, 9.15, 9.2). Lower: the same
    /// corners with the inner lower contour (2.5, 2.9, 2.3, 2.8, 2.4) closed under the chin
    /// corners and bottom (2.11, 2.1, 2.12). Extending the line to the outer corners keeps
    /// the lip corners' flesh apart too; both polygons share the line.
    pub fn new(fps: &BTreeMap<FeaturePointId, DVec2>) -> LipPolygons {
        let get = |ids: &[FeaturePointId]| -> Vec<DVec2> {
            ids.iter().filter_map(|id| fps.get(id)).copied().collect()
        };
        let polygon = |line: &[FeaturePointId], cap: &[FeaturePointId]| {
            let mut l = get(line);
            l.sort_by(|a, b| a.x.total_cmp(&b.x));
            let mut c = get(cap);
            c.sort_by(|a, b| b.x.total_cmp(&a.x));
            l.extend(c);
            l
        };
        LipPolygons {
            upper: polygon(
                &[
                    FeaturePointId::FP_8_4,
                    FeaturePointId::FP_2_5,
                    FeaturePointId::FP_2_7,
                    FeaturePointId::FP_2_2,
                    FeaturePointId::FP_2_6,
                    FeaturePointId::FP_2_4,
                    FeaturePointId::FP_8_3,
                ],
                &[
                    FeaturePointId::FP_9_1,
                    FeaturePointId::FP_9_15,
                    FeaturePointId::FP_9_2,
                ],
            ),
            lower: polygon(
                &[
                    FeaturePointId::FP_8_4,
                    FeaturePointId::FP_2_5,
                    FeaturePointId::FP_2_9,
                    FeaturePointId::FP_2_3,
                    FeaturePointId::FP_2_8,
                    FeaturePointId::FP_2_4,
                    FeaturePointId::FP_8_3,
                ],
                &[
                    FeaturePointId::FP_2_11,
                    FeaturePointId::FP_2_1,
                    FeaturePointId::FP_2_12,
                ],
            ),
        }
    }

    /// The region of a point and whether it lies on a polygon boundary (ambiguous).
    fn classify_point(&self, p: DVec2) -> (LipRegion, bool) {
        let on = boundary_distance(&self.upper, p) < ON_LINE
            || boundary_distance(&self.lower, p) < ON_LINE;
        let region = match (inside(&self.upper, p), inside(&self.lower, p)) {
            (true, false) => LipRegion::Upper,
            (false, true) => LipRegion::Lower,
            _ => LipRegion::Out,
        };
        (region, on)
    }

    /// The region of a point strictly inside one polygon, `None` on a boundary.
    pub fn region_of(&self, p: DVec2) -> Option<LipRegion> {
        match self.classify_point(p) {
            (_, true) => None,
            (r, false) => Some(r),
        }
    }

    /// Classifies every vertex. A vertex on a boundary (the lip line of a closed mouth holds
    /// coincident upper and lower lip vertices) takes the region of the triangles around it:
    /// upper if some adjacent triangle's centroid is in the upper region and none in the lower,
    /// and vice versa; a vertex touching both (a lip corner) or neither is out of the lips.
    pub fn classify(&self, points: &[DVec2], triangles: &[[u32; 3]]) -> Vec<LipRegion> {
        let mut out: Vec<(LipRegion, bool)> =
            points.iter().map(|&p| self.classify_point(p)).collect();
        let mut votes = vec![(0u32, 0u32); points.len()];
        for t in triangles {
            if t.iter().any(|&v| v as usize >= points.len()) {
                continue;
            }
            if !t.iter().any(|&v| out[v as usize].1) {
                continue;
            }
            let c = t.iter().map(|&v| points[v as usize]).sum::<DVec2>() / 3.0;
            let (region, on) = self.classify_point(c);
            if on {
                continue;
            }
            for &v in t {
                match region {
                    LipRegion::Upper => votes[v as usize].0 += 1,
                    LipRegion::Lower => votes[v as usize].1 += 1,
                    LipRegion::Out => {}
                }
            }
        }
        for (slot, &(up, lo)) in out.iter_mut().zip(&votes) {
            if slot.1 {
                slot.0 = match (up > 0, lo > 0) {
                    (true, false) => LipRegion::Upper,
                    (false, true) => LipRegion::Lower,
                    _ => LipRegion::Out,
                };
            }
        }
        out.into_iter().map(|x| x.0).collect()
    }
}

/// Even-odd point-in-polygon test.
fn inside(poly: &[DVec2], p: DVec2) -> bool {
    let mut c = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + n - 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            c = !c;
        }
    }
    c
}

/// Distance from `p` to the polygon's boundary.
fn boundary_distance(poly: &[DVec2], p: DVec2) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let ab = b - a;
            let t = if ab.length_squared() > 0.0 {
                ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (a + ab * t).distance(p)
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_mouth_line_vertices_follow_their_triangles() {
        // A closed mouth: corners at x ±1, line y = 0; nose above, chin below.
        let mut fps = BTreeMap::new();
        for (id, x, y) in [
            ("8.3", 1.2, 0.0),
            ("8.4", -1.2, 0.0),
            ("2.4", 1.0, 0.0),
            ("2.5", -1.0, 0.0),
            ("2.2", 0.0, 0.0),
            ("2.3", 0.0, 0.0),
            ("9.1", 0.6, 1.0),
            ("9.2", -0.6, 1.0),
            ("9.15", 0.0, 1.0),
            ("2.11", 0.6, -1.0),
            ("2.12", -0.6, -1.0),
            ("2.1", 0.0, -1.2),
        ] {
            fps.insert(id.parse().unwrap(), DVec2::new(x, y));
        }
        let polys = LipPolygons::new(&fps);
        // Vertices: 0 upper-lip line vertex, 1 lower-lip line vertex (same place), 2 above,
        // 3 below, 4 a lip corner, 5 far away.
        let points = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(0.0, 0.0),
            DVec2::new(0.2, 0.3),
            DVec2::new(0.2, -0.3),
            DVec2::new(1.0, 0.0),
            DVec2::new(3.0, 3.0),
        ];
        let tris = [[0, 4, 2], [1, 3, 4]];
        let r = polys.classify(&points, &tris);
        use LipRegion::*;
        assert_eq!(r, vec![Upper, Lower, Upper, Lower, Out, Out]);
    }
}
