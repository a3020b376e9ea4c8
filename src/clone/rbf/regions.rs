//! Upper / lower lip regions, used to keep the lips apart when mapping between surfaces.
//!
//! On a closed mouth the upper and lower lips touch (Candide-3: 81≡83, 82≡84, 2.2≡2.3), so a
//! nearest-surface or ray query from one lip can land on the other, and the lower lip's motion
//! would then drag the upper lip (Pandzic 2003 treats the lip region for the same reason).
//!
//! Classification of a face's vertices, from its extracted inner-lip contours:
//! - the interior vertices of the upper contour are [`Region::Upper`], of the lower contour
//!   [`Region::Lower`] (the corners 2.4/2.5, shared by both lips, stay [`Region::Other`]);
//! - the regions grow from those seeds along mesh edges, through vertices that lie strictly
//!   between the corners in x, above (upper) or below (lower) the mid line of the two
//!   contours at that x, at most 0.9·MNS0 above (below the nose) or 1.5·MNS0 below (the chin) the
//!   mouth, and not more than 0.5·MW0 behind the contours (so the walk cannot leak to the
//!   back of the head).
//!
//! A triangle is upper if it has an upper vertex and no lower one, lower likewise, mixed if it
//! has both (a mesh whose lips are fused) and other otherwise. Queries for upper vertices see
//! only other and upper triangles; for lower vertices only other and lower ones.

use std::collections::VecDeque;

use glam::Vec3;

/// A vertex's lip region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Region {
    /// Not in a lip region.
    Other,
    /// Upper lip.
    Upper,
    /// Lower lip.
    Lower,
}

/// A triangle's lip region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TriRegion {
    /// No lip vertex.
    Other,
    /// Upper-lip vertices only (besides other ones).
    Upper,
    /// Lower-lip vertices only.
    Lower,
    /// Both upper- and lower-lip vertices.
    Mixed,
}

/// y of a polyline (xy-projected) at `x`, by linear interpolation on the first segment that
/// spans `x`.
fn y_at(pts: &[Vec3], x: f32) -> Option<f32> {
    pts.windows(2).find_map(|w| {
        let (a, b) = (w[0], w[1]);
        let (lo, hi) = (a.x.min(b.x), a.x.max(b.x));
        if x < lo || x > hi {
            return None;
        }
        if hi - lo <= 0.0 {
            return Some(a.y.max(b.y));
        }
        Some(a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x))
    })
}

/// Classifies vertices (see the module doc). `mns0`, `mw0` are the face's FAPU distances.
pub(crate) fn classify(
    pos: &[Vec3],
    adj: &[Vec<u32>],
    upper: &[u32],
    lower: &[u32],
    mns0: f32,
    mw0: f32,
) -> Vec<Region> {
    let mut region = vec![Region::Other; pos.len()];
    if upper.len() < 2 || lower.len() < 2 {
        return region;
    }
    let up_pts: Vec<Vec3> = upper.iter().map(|&v| pos[v as usize]).collect();
    let lo_pts: Vec<Vec3> = lower.iter().map(|&v| pos[v as usize]).collect();
    let (c0, c1) = (up_pts[0].x, up_pts[up_pts.len() - 1].x);
    let (xmin, xmax) = (c0.min(c1), c0.max(c1));
    let zmin = up_pts
        .iter()
        .chain(&lo_pts)
        .map(|p| p.z)
        .fold(f32::INFINITY, f32::min)
        - 0.5 * mw0;
    let mid = |x: f32| -> Option<(f32, f32, f32)> {
        let (yu, yl) = (y_at(&up_pts, x)?, y_at(&lo_pts, x)?);
        Some((yu, yl, 0.5 * (yu + yl)))
    };
    let allowed = |v: u32, want: Region| -> bool {
        let p = pos[v as usize];
        if !(p.x > xmin && p.x < xmax) || p.z < zmin {
            return false;
        }
        let Some((yu, yl, ym)) = mid(p.x) else {
            return false;
        };
        match want {
            Region::Upper => p.y >= ym && p.y <= yu + 0.9 * mns0,
            Region::Lower => p.y <= ym && p.y >= yl - 1.5 * mns0,
            Region::Other => false,
        }
    };
    let seeds_u = &upper[1..upper.len() - 1];
    let seeds_l = &lower[1..lower.len() - 1];
    for &v in seeds_u {
        region[v as usize] = Region::Upper;
    }
    for &v in seeds_l {
        // A vertex on both contours (fused lips) belongs to neither.
        region[v as usize] = if region[v as usize] == Region::Upper {
            Region::Other
        } else {
            Region::Lower
        };
    }
    let corners = [
        upper[0],
        upper[upper.len() - 1],
        lower[0],
        lower[lower.len() - 1],
    ];
    for (seeds, want) in [(seeds_u, Region::Upper), (seeds_l, Region::Lower)] {
        let mut queue: VecDeque<u32> = seeds
            .iter()
            .copied()
            .filter(|&v| region[v as usize] == want)
            .collect();
        while let Some(v) = queue.pop_front() {
            for &n in &adj[v as usize] {
                if region[n as usize] == Region::Other
                    && !corners.contains(&n)
                    && !upper.contains(&n)
                    && !lower.contains(&n)
                    && allowed(n, want)
                {
                    region[n as usize] = want;
                    queue.push_back(n);
                }
            }
        }
    }
    region
}

/// Triangle regions from vertex regions.
pub(crate) fn triangles(regions: &[Region], tris: &[[u32; 3]]) -> Vec<TriRegion> {
    tris.iter()
        .map(|t| {
            let has = |r: Region| t.iter().any(|&v| regions[v as usize] == r);
            match (has(Region::Upper), has(Region::Lower)) {
                (true, true) => TriRegion::Mixed,
                (true, false) => TriRegion::Upper,
                (false, true) => TriRegion::Lower,
                (false, false) => TriRegion::Other,
            }
        })
        .collect()
}
