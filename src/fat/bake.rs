//! Baking a motion of some vertices into per-vertex displacement entries ([`FaceDefMesh`]).
//!
//! A FAT moves vertices piecewise linearly in the FAP value, while a transform moves them along
//! a curve (a rotation turns them on circles). Where a part that a transform would move is a set
//! of vertices inside a bigger mesh (an eyeball or the lower teeth of a one-mesh head, a glTF
//! primitive without its own node) the motion has to become displacements of those vertices.
//! [`bake_motion`] does it for any motion given as an affine map per FAP value.
//!
//! # The math
//!
//! Let `M(p)` be the motion's affine map at FAP value `p` (in the mesh's own frame, `M(0) = I`)
//! and `d_i(p) = M(p)·x_i − x_i` the displacement of vertex `x_i`. With interval borders
//! `b_0 < … < b_n` (0 among them) a [`FaceDefMesh`] represents the piecewise linear function
//! through the values `d_i(b_k)`: the rate of interval `j` is
//! `(d_i(b_{j+1}) − d_i(b_j)) / (b_{j+1} − b_j)`, and the evaluator's interval rule (sums of
//! rates times the covered part of each interval from 0) reproduces `d_i(b_k)` at every
//! border and interpolates linearly between them.
//!
//! The error on one interval is `max_i |d_i(p) − lerp|`. For a rotation whose angle is linear in
//! `p` (a `FaceDefTransform` rotation, possibly with a linear translation) a vertex at distance
//! `r` from the axis moves on an arc; the chord between two borders `Δ` radians apart strays
//! from the arc by at most `r·(1 − cos(Δ/2)) ≈ r·Δ²/8`, at the middle of the interval. Halving
//! an interval therefore divides its error by about four, and [`bake_motion`] bisects every
//! interval whose error, sampled at a quarter, half and three quarters of it, exceeds the
//! tolerance (between integer borders the new border is rounded to an integer, as VRML's
//! `intervalBorders` are integers). A part of size `s` baked with tolerance `0.01·s` needs intervals of at most
//! `√(0.08·s/r)` radians: about 0.4 rad (23°) for an eyeball (`r ≈ s/2`).
//!
//! Between `range.0` and `range.1` (the FAP values the FAT covers) the result is within the
//! tolerance at every sampled value; beyond them the outer intervals continue linearly, as the
//! evaluator's interval rule does for every table.

use glam::{Affine3A, DVec3, Vec3};

use super::{interval_weights, FaceDefMesh};

/// Most intervals a baked entry gets: bisection stops there even if the tolerance is not met
/// (the result's [`BakedMesh::max_error`] says by how much).
pub const MAX_INTERVALS: usize = 256;

/// What to bake: which vertices of which mesh, over which FAP values, how closely.
#[derive(Clone, Copy, Debug)]
pub struct BakeRequest<'a> {
    /// Name of the mesh the entry is for.
    pub mesh: &'a str,
    /// The moved vertices (indices into the mesh's points), in entry order.
    pub vertices: &'a [u32],
    /// Their neutral positions, in the frame the motion maps (one per vertex; extra ones on
    /// either list are ignored).
    pub neutral: &'a [Vec3],
    /// FAP values to cover, `range.0 ≤ range.1` (0 is always covered).
    pub range: (f64, f64),
    /// Borders the entry must have besides 0 and the range ends (e.g. those of the table it
    /// joins); non-finite ones are ignored.
    pub borders: &'a [f64],
    /// Largest allowed distance between the true and the interpolated position.
    pub tolerance: f32,
}

/// A baked entry and how well it fits.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedMesh {
    /// The displacement entry.
    pub entry: FaceDefMesh,
    /// Largest error found at the sampled values (below the tolerance unless
    /// [`MAX_INTERVALS`] was reached).
    pub max_error: f32,
}

/// Size of a part for tolerances: the diagonal of its points' bounding box (0 when empty).
pub fn part_size(points: &[Vec3]) -> f32 {
    let Some(&first) = points.first() else {
        return 0.0;
    };
    let (lo, hi) = points
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    (hi - lo).length()
}

/// Bakes `motion` (the affine map at a FAP value, identity at 0) of the requested vertices into
/// one [`FaceDefMesh`] (module docs): borders are the request's, 0 and the range ends, and
/// midpoints are added until linear interpolation is within the tolerance.
pub fn bake_motion(req: &BakeRequest, mut motion: impl FnMut(f64) -> Affine3A) -> BakedMesh {
    let n = req.vertices.len().min(req.neutral.len());
    let neutral: Vec<DVec3> = req.neutral[..n].iter().map(|p| p.as_dvec3()).collect();
    let (lo, hi) = if req.range.0 <= req.range.1 {
        req.range
    } else {
        (req.range.1, req.range.0)
    };
    let mut borders: Vec<f64> = req
        .borders
        .iter()
        .copied()
        .chain([0.0, lo, hi])
        .filter(|b| b.is_finite())
        .collect();
    borders.sort_by(f64::total_cmp);
    borders.dedup();
    if borders.len() < 2 {
        // Nothing to cover: one unit interval, rates of the motion's derivative there.
        borders.push(1.0);
    }
    let mut displaced = |p: f64| -> Vec<DVec3> {
        if p == 0.0 {
            return vec![DVec3::ZERO; n];
        }
        let m = motion(p);
        neutral
            .iter()
            .map(|&x| m.transform_point3(x.as_vec3()).as_dvec3() - x)
            .collect()
    };
    let mut at: Vec<Vec<DVec3>> = borders.iter().map(|&b| displaced(b)).collect();
    let tol = f64::from(req.tolerance.max(0.0));
    let mut max_error = 0.0f64;
    let mut j = 0;
    // Intervals left of `j` are final; the one starting at `j` is checked and bisected in place.
    while j + 1 < borders.len() {
        let (a, b) = (borders[j], borders[j + 1]);
        let mut err = 0.0f64;
        for t in [0.25, 0.5, 0.75] {
            let truth = displaced(a + (b - a) * t);
            for (i, d) in truth.iter().enumerate() {
                let lin = at[j][i].lerp(at[j + 1][i], t);
                err = err.max(d.distance(lin));
            }
        }
        let mid = midpoint(a, b);
        let splittable = borders.len() - 1 < MAX_INTERVALS
            && mid > a
            && mid < b
            && (b - a) > (b.abs() + a.abs()) * 1e-9;
        if err > tol && splittable {
            borders.insert(j + 1, mid);
            at.insert(j + 1, displaced(mid));
        } else {
            max_error = max_error.max(err);
            j += 1;
        }
    }
    let rates = rates_between(&at, &borders, n);
    BakedMesh {
        entry: FaceDefMesh {
            mesh: req.mesh.to_string(),
            interval_borders: borders,
            coord_index: req.vertices[..n].to_vec(),
            displacements: rates,
        },
        max_error: max_error as f32,
    }
}

/// Rates, vertex-major, of `n` vertices whose displacements at each border are `at[border]`.
fn rates_between(at: &[Vec<DVec3>], borders: &[f64], n: usize) -> Vec<Vec3> {
    let spans: Vec<f64> = borders.windows(2).map(|w| w[1] - w[0]).collect();
    let spans = &spans;
    (0..n)
        .flat_map(|i| {
            at.windows(2)
                .zip(spans)
                .map(move |(w, &s)| ((w[1][i] - w[0][i]) / s).as_vec3())
        })
        .collect()
}

/// The border that bisects `[a, b]`: rounded to an integer between integer borders (VRML's
/// `intervalBorders` are integers), so it may equal an end when they are 1 apart.
fn midpoint(a: f64, b: f64) -> f64 {
    let mid = a + (b - a) / 2.0;
    if a.fract() == 0.0 && b.fract() == 0.0 {
        mid.round()
    } else {
        mid
    }
}

/// `entry` re-expressed on `borders` (sorted, 0 among them): the rates between its own
/// displacements at the new borders. Exact when `borders` include the entry's own (a piecewise
/// linear function stays one on finer intervals), which is how entries with different borders
/// for one mesh are merged into one.
pub fn on_borders(entry: &FaceDefMesh, borders: &[f64]) -> FaceDefMesh {
    let n = entry.coord_index.len();
    let own = entry.interval_count();
    let mut weights = Vec::new();
    // Displacement of every listed vertex at every new border.
    let at: Vec<Vec<DVec3>> = borders
        .iter()
        .map(|&b| {
            interval_weights(&entry.interval_borders, b, &mut weights);
            (0..n)
                .map(|i| {
                    weights
                        .iter()
                        .enumerate()
                        .map(|(j, &w)| {
                            entry
                                .displacements
                                .get(i * own + j)
                                .map_or(DVec3::ZERO, |r| r.as_dvec3() * w)
                        })
                        .sum()
                })
                .collect()
        })
        .collect();
    let rates = rates_between(&at, borders, n);
    FaceDefMesh {
        mesh: entry.mesh.clone(),
        interval_borders: borders.to_vec(),
        coord_index: entry.coord_index.clone(),
        displacements: rates,
    }
}

#[cfg(test)]
mod tests {
    use glam::Quat;

    use super::*;
    use crate::spec::AU_RADIANS;

    /// An eyeball-like ring of points around a centre off the origin.
    fn ball(centre: Vec3, r: f32) -> Vec<Vec3> {
        let mut out = Vec::new();
        for i in 0..12 {
            for k in 1..6 {
                let (th, ph) = (i as f32 * 0.52, k as f32 * 0.52);
                out.push(
                    centre + r * Vec3::new(ph.sin() * th.cos(), ph.sin() * th.sin(), ph.cos()),
                );
            }
        }
        out
    }

    /// Rotation about `axis` through `centre` by `rate × p` radians.
    fn turn(centre: Vec3, axis: Vec3, rate: f64) -> impl Fn(f64) -> Affine3A {
        move |p| {
            Affine3A::from_translation(centre)
                * Affine3A::from_quat(Quat::from_axis_angle(axis, (rate * p) as f32))
                * Affine3A::from_translation(-centre)
        }
    }

    /// The worst distance between the entry's displacement and the motion's over `range`.
    fn worst(
        entry: &FaceDefMesh,
        pts: &[Vec3],
        motion: &impl Fn(f64) -> Affine3A,
        range: (f64, f64),
    ) -> f32 {
        let mut w: f32 = 0.0;
        for s in 0..=400 {
            let p = range.0 + (range.1 - range.0) * s as f64 / 400.0;
            let m = motion(p);
            for (i, &x) in pts.iter().enumerate() {
                let truth = m.transform_point3(x) - x;
                w = w.max(truth.distance(entry.displacement(i, p)));
            }
        }
        w
    }

    #[test]
    fn an_eyeball_turn_over_its_range_stays_within_one_percent() {
        let centre = Vec3::new(3.0, 4.0, 2.0);
        let pts = ball(centre, 1.2);
        let size = part_size(&pts);
        let vertices: Vec<u32> = (0..pts.len() as u32).collect();
        // Eyeball yaw at 1e-5 rad per AU, ±100 000 AU (±1 rad, beyond a real eye's reach).
        let motion = turn(centre, Vec3::Y, AU_RADIANS);
        let range = (-100_000.0, 100_000.0);
        let req = BakeRequest {
            mesh: "eye",
            vertices: &vertices,
            neutral: &pts,
            range,
            borders: &[],
            tolerance: 0.01 * size,
        };
        let baked = bake_motion(&req, &motion);
        let e = &baked.entry;
        assert!(e.interval_borders.contains(&0.0));
        assert_eq!(e.interval_borders.first(), Some(&range.0));
        assert_eq!(e.interval_borders.last(), Some(&range.1));
        assert!(
            e.interval_count() > 2,
            "a 2 rad sweep needs several intervals"
        );
        assert!(e.interval_count() < 32, "{} intervals", e.interval_count());
        assert_eq!(e.displacements.len(), pts.len() * e.interval_count());
        assert!(baked.max_error <= 0.01 * size);
        let w = worst(e, &pts, &motion, range);
        assert!(w <= 0.0101 * size, "worst {w} of size {size}");
        // A tenth of the tolerance takes more intervals and is met too.
        let fine = bake_motion(
            &BakeRequest {
                tolerance: 0.001 * size,
                ..req
            },
            &motion,
        );
        assert!(fine.entry.interval_count() > e.interval_count());
        assert!(worst(&fine.entry, &pts, &motion, range) <= 0.00101 * size);
    }

    #[test]
    fn exact_at_borders_and_given_borders_are_kept() {
        let centre = Vec3::new(0.0, -2.0, 1.0);
        let pts = ball(centre, 0.5);
        let vertices: Vec<u32> = (10..10 + pts.len() as u32).collect();
        let motion = turn(centre, Vec3::X, 2.0 * AU_RADIANS);
        let baked = bake_motion(
            &BakeRequest {
                mesh: "skin",
                vertices: &vertices,
                neutral: &pts,
                range: (0.0, 40_000.0),
                borders: &[12_345.0],
                tolerance: 1e-3,
            },
            &motion,
        );
        let e = &baked.entry;
        assert_eq!(e.mesh, "skin");
        assert_eq!(e.coord_index, vertices);
        assert!(e.interval_borders.contains(&12_345.0));
        assert!(e.interval_borders.windows(2).all(|w| w[0] < w[1]));
        for &b in &e.interval_borders {
            let m = motion(b);
            for (i, &x) in pts.iter().enumerate() {
                let d = e.displacement(i, b);
                assert!((m.transform_point3(x) - x).distance(d) < 1e-5, "at {b}");
            }
        }
    }

    #[test]
    fn a_translation_needs_no_extra_border() {
        let pts = ball(Vec3::ZERO, 1.0);
        let vertices: Vec<u32> = (0..pts.len() as u32).collect();
        let baked = bake_motion(
            &BakeRequest {
                mesh: "teeth",
                vertices: &vertices,
                neutral: &pts,
                range: (0.0, 1024.0),
                borders: &[],
                tolerance: 1e-6,
            },
            |p| Affine3A::from_translation(Vec3::new(0.0, -1e-3, 2e-4) * p as f32),
        );
        assert_eq!(baked.entry.interval_borders, vec![0.0, 1024.0]);
        assert!(baked.max_error < 1e-6);
        let d = baked.entry.displacement(3, 512.0);
        assert!(d.distance(Vec3::new(0.0, -0.512, 0.1024)) < 1e-5);
    }

    #[test]
    fn degenerate_requests_do_not_panic() {
        let baked = bake_motion(
            &BakeRequest {
                mesh: "m",
                vertices: &[0, 1, 2],
                neutral: &[Vec3::ONE],
                range: (0.0, 0.0),
                borders: &[f64::NAN],
                tolerance: -1.0,
            },
            |_| Affine3A::IDENTITY,
        );
        assert_eq!(baked.entry.coord_index, vec![0]);
        assert_eq!(baked.entry.interval_borders, vec![0.0, 1.0]);
        assert_eq!(baked.entry.displacements, vec![Vec3::ZERO]);
        // A motion that jumps cannot be met: bisection stops at the interval limit.
        let jump = bake_motion(
            &BakeRequest {
                mesh: "m",
                vertices: &[0],
                neutral: &[Vec3::ZERO],
                range: (0.0, 1.0),
                borders: &[],
                tolerance: 1e-3,
            },
            |p| Affine3A::from_translation(Vec3::X * if p > 0.3 { 1.0 } else { 0.0 }),
        );
        assert!(jump.entry.interval_count() <= MAX_INTERVALS);
        assert!(jump.max_error > 1e-3);
    }

    #[test]
    fn finer_borders_keep_the_motion() {
        let e = FaceDefMesh {
            mesh: "m".into(),
            interval_borders: vec![-10.0, 0.0, 20.0],
            coord_index: vec![4, 7],
            displacements: vec![Vec3::X, Vec3::Y, Vec3::new(0.5, 0.0, -1.0), Vec3::Z],
        };
        let fine = on_borders(&e, &[-30.0, -10.0, -5.0, 0.0, 7.0, 20.0, 50.0]);
        assert_eq!(fine.interval_count(), 6);
        assert_eq!(fine.coord_index, e.coord_index);
        for p in [-40.0, -30.0, -12.0, -3.0, 0.0, 5.0, 19.0, 33.0, 60.0] {
            for i in 0..2 {
                assert!(
                    fine.displacement(i, p).distance(e.displacement(i, p)) < 1e-4,
                    "{p}"
                );
            }
        }
    }
}
