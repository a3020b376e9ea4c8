//! Landmark-guided non-rigid registration of one surface onto another (after the
//! optimal-step non-rigid ICP of Amberg, Romdhani & Vetter 2007, with a displacement field
//! instead of per-vertex affine maps).
//!
//! Unknown: a displacement `u_i` per vertex of the moving surface (positions `p_i`). Each
//! step minimises
//!
//! ```text
//! E(u) = Σ_i w_i ‖p_i + u_i − c_i‖² + β Σ_l ‖p_l + u_l − L_l‖² + α (‖L u‖² + μ ‖∇u‖²) + ε ‖u‖²
//! ```
//!
//! where `c_i` is the closest allowed point of the fixed surface to the current `p_i + u_i`
//! (`w_i` = 1, or 0 when rejected: no allowed triangle, a hit on the fixed surface's border,
//! normals more than [`FitOptions::normal_degrees`] apart, or farther than the distance
//! limit), `L_l` the fixed surface's feature point for each shared feature-point vertex,
//! `L` the uniform Laplacian (bending: affine-like fields are cheap, so the surface may
//! stretch between landmarks) and `∇` the graph gradient (a little membrane keeps the system
//! definite along open borders). The normal equations
//! `(α(LᵀL + μL_g) + W + βB + εI) u = W(c − p) + βB(L − p)` are one sparse SPD system for
//! the three coordinates ([`super::system`]). The stiffness `α` runs from stiff to soft
//! ([`FitOptions::stiffness`]), with [`FitOptions::iterations`] closest-point updates per
//! value. Closest points are restricted by slit side ([`super::regions`]), so lips and lids
//! never pull across a closed mouth or eye.
//!
//! Speed: every closest-point search is bounded, which changes no accepted match. The
//! normal-compatible point is searched within the distance to the triangle the vertex matched
//! in the step before, and within a reach: 1.5 × the last step's outlier cut (first the
//! distance limit). A match beyond the cut is rejected anyway and a vertex with none within
//! the reach counts as an infinite gap in the median; when this step's median or cut turns
//! out beyond the reach, the vertices without a match are searched again up to the limit.
//! Without the bounds, the searches of the vertices with no compatible point nearby (a fifth
//! of dense CANDIDE's on the bundled head) scanned much of the target. Within the bounds, the
//! search skips whole subtrees of the target's BVH whose triangles all face away or lie on
//! the other side of a slit ([`super::filter_tree`]), which changes no match either.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::regions::{query_bit, Side};
use super::surface::{Filter, QuerySurface};
use super::system::SmoothSystem;
use super::FitOptions;
use crate::error::Result;
use crate::mesh::geometry::vertex_normals;

/// The next step searches normal-compatible points up to this many times the last step's
/// outlier cut (module docs).
const REACH: f32 = 1.5;

/// Damping that keeps pieces without any data or landmark where they are.
const DAMPING: f64 = 1e-6;

/// A step at the last factorisation's stiffness is solved by preconditioned conjugate
/// gradients ([`SmoothSystem::solve_near`]) down to this residual, relative to the
/// right-hand side's (the matches are single-precision points: ~1e-7 of the face), within
/// at most this many iterations (five of them cost about half a factorisation on dense
/// CANDIDE-3; beyond, a factorisation is cheaper).
const CG_TOL: f64 = 1e-6;
const CG_ITERATIONS: usize = 8;

/// A moving surface and what to pull it to.
pub(crate) struct Moving<'a> {
    /// Neutral positions.
    pub positions: &'a [Vec3],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
    /// Vertex adjacency.
    pub adjacency: &'a [Vec<u32>],
    /// Slit side of each vertex.
    pub sides: &'a [Side],
    /// Whether each vertex lies on a face piece ([`super::regions::face_pieces`]).
    pub face: &'a [bool],
    /// Whether each vertex lies in the mouth interior (`clone/mouth_interior.rs`;
    /// empty when the surface has none): such a vertex matches only the fixed surface's
    /// interior, and stays unmatched (held by its neighbours) when that has none.
    pub inside: &'a [bool],
    /// `(vertex, landmark position on the fixed surface)`.
    pub landmarks: &'a [(u32, Vec3)],
    /// A length of the face (ES0), for the distance limits.
    pub scale: f32,
}

/// The registered surface.
pub(crate) struct Registered {
    /// Moved positions (same order and topology as the moving surface).
    pub positions: Vec<Vec3>,
    /// Linear solves run.
    pub solves: usize,
    /// Share of vertices with an accepted closest point in the last step.
    pub matched: f64,
    /// Mean distance to the accepted closest points in the last step, in ES0.
    pub mean_gap: f64,
}

/// Registers `m` onto the surface `fixed` builds (module docs). The fixed surface is built
/// while the smoothness system is analysed (unless `system` holds it, analysed ahead for
/// `m.adjacency` and `opts.membrane`) and the landmark-only step solved, which need only
/// the moving surface.
pub(crate) fn register(
    m: &Moving,
    fixed: impl FnOnce() -> QuerySurface + Send,
    opts: &FitOptions,
    system: Option<Result<SmoothSystem>>,
) -> Result<Registered> {
    let n = m.positions.len();
    let p: Vec<DVec3> = m.positions.iter().map(|v| v.as_dvec3()).collect();
    let beta = opts.landmark_weight;
    let mut lm_diag = vec![0.0; n];
    let mut lm_rhs = vec![DVec3::ZERO; n];
    for &(v, l) in m.landmarks {
        if let Some(pv) = p.get(v as usize) {
            lm_diag[v as usize] += beta;
            lm_rhs[v as usize] += beta * (l.as_dvec3() - *pv);
        }
    }
    let solve = |system: &mut SmoothSystem,
                 alpha: f64,
                 w: &[f64],
                 c: &[DVec3],
                 u: &mut Vec<DVec3>|
     -> Result<()> {
        let diag: Vec<f64> = (0..n).map(|i| w[i] + lm_diag[i] + DAMPING).collect();
        let rhs: Vec<[f64; 3]> = (0..n)
            .map(|i| (w[i] * (c[i] - p[i]) + lm_rhs[i]).to_array())
            .collect();
        // From the last step's answer: near it when the stiffness is the same
        // ([`SmoothSystem::solve_near`]).
        let guess: Vec<[f64; 3]> = u.iter().map(|v| v.to_array()).collect();
        let (sol, _) = system.solve_near(alpha, &diag, &rhs, &guess, CG_TOL, CG_ITERATIONS)?;
        for (ui, s) in u.iter_mut().zip(sol) {
            *ui = DVec3::from_array(s);
        }
        Ok(())
    };
    let stiff = opts.stiffness.first().copied().unwrap_or(1.0);
    let start = || -> Result<(SmoothSystem, Vec<DVec3>, usize)> {
        let mut system = match system {
            Some(s) => s?,
            None => SmoothSystem::new(m.adjacency, opts.membrane)?,
        };
        let mut u = vec![DVec3::ZERO; n];
        if m.landmarks.is_empty() {
            return Ok((system, u, 0));
        }
        // Landmarks alone first: a smooth warp that brings the surfaces close.
        solve(
            &mut system,
            stiff,
            &vec![0.0; n],
            &vec![DVec3::ZERO; n],
            &mut u,
        )?;
        Ok((system, u, 1))
    };
    let (fixed, started) = rayon::join(fixed, start);
    let fixed = &fixed;
    let (mut system, mut u, mut solves) = started?;
    let cos = (opts.normal_degrees.to_radians()).cos() as f32;
    let limit = opts.max_distance as f32 * m.scale;
    let snap = super::correspond::SNAP * m.scale;
    let bounds = Bounds {
        cos,
        snap,
        reach: limit,
    };
    // How far the next step searches for normal-compatible points (module docs).
    let mut reach = limit;
    // Each vertex's last matched triangle: its distance bounds the next search.
    let mut previous: Vec<Option<u32>> = vec![None; n];
    // Searches run in a spatial order of the vertices: queries one after the other walk the
    // same part of the tree (the vertex order may scatter them, module docs of
    // [`crate::mesh::morton`]).
    let order = crate::mesh::morton::morton_order(m.positions);
    let (mut matched, mut mean_gap) = (0.0, 0.0);
    for &alpha in &opts.stiffness {
        for _ in 0..opts.iterations.max(1) {
            let x: Vec<Vec3> = p.iter().zip(&u).map(|(a, b)| (*a + *b).as_vec3()).collect();
            let normals = vertex_normals(&x, m.triangles);
            let search = |i: usize, reach: f32| {
                let b = Bounds { reach, ..bounds };
                match_point(
                    fixed,
                    x[i],
                    normals[i],
                    query_bit(
                        m.sides[i],
                        m.face.get(i).copied().unwrap_or(true),
                        m.inside.get(i).copied().unwrap_or(false),
                    ),
                    b,
                    previous[i],
                )
            };
            let found: Vec<Option<(Vec3, f32, u32)>> = order
                .par_iter()
                .map(|&i| search(i as usize, reach))
                .collect();
            let mut hits: Vec<Option<(Vec3, f32, u32)>> = vec![None; n];
            for (&i, h) in order.iter().zip(found) {
                hits[i as usize] = h;
            }
            // Outliers: farther than the limit, or than a few times the typical gap.
            let (median, mut cut) = outlier_cut(&hits, limit);
            if reach < limit && (median > reach || cut > reach) {
                // The cut reaches beyond the searched distance: search the unmatched
                // vertices again, up to the limit.
                hits.par_iter_mut().enumerate().for_each(|(i, h)| {
                    if h.is_some_and(|h| h.1.is_infinite()) {
                        *h = search(i, limit);
                    }
                });
                cut = outlier_cut(&hits, limit).1;
            }
            reach = (REACH * cut).min(limit);
            for (prev, h) in previous.iter_mut().zip(&hits) {
                *prev = h.and_then(|h| (h.2 != u32::MAX).then_some(h.2));
            }
            let mut w = vec![0.0; n];
            let mut c = vec![DVec3::ZERO; n];
            let (mut count, mut sum) = (0usize, 0.0f64);
            for (i, h) in hits.iter().enumerate() {
                if let Some((pt, d, _)) = h {
                    if *d <= cut {
                        w[i] = 1.0;
                        c[i] = pt.as_dvec3();
                        count += 1;
                        sum += *d as f64;
                    }
                }
            }
            if count == 0 && m.landmarks.is_empty() {
                break;
            }
            solve(&mut system, alpha, &w, &c, &mut u)?;
            solves += 1;
            matched = count as f64 / n.max(1) as f64;
            mean_gap = if count > 0 {
                sum / count as f64 / m.scale.max(f32::MIN_POSITIVE) as f64
            } else {
                0.0
            };
        }
    }
    let positions = p.iter().zip(&u).map(|(a, b)| (*a + *b).as_vec3()).collect();
    Ok(Registered {
        positions,
        solves,
        matched,
        mean_gap,
    })
}

/// The median gap of `hits` and the distance beyond which a match is an outlier: farther
/// than `limit`, or than four times the median gap (not below 2 % of the limit).
fn outlier_cut(hits: &[Option<(Vec3, f32, u32)>], limit: f32) -> (f32, f32) {
    let mut gaps: Vec<f32> = hits.iter().flatten().map(|h| h.1).collect();
    gaps.sort_by(f32::total_cmp);
    let median = gaps.get(gaps.len() / 2).copied().unwrap_or(0.0);
    (median, limit.min((4.0 * median).max(0.02 * limit)))
}

/// Distance limits of one closest-point match.
#[derive(Clone, Copy)]
struct Bounds {
    /// Least cosine between the vertex normal and a triangle normal.
    cos: f32,
    /// Nearer than this, a point is on the surface and matches whatever the normals.
    snap: f32,
    /// Points beyond this are not searched for.
    reach: f32,
}

/// The match of moving point `x` (unit normal `nrm`, side mask bit `bit`) on `fixed`:
/// `(point, distance, triangle)`, with distance `∞` (and triangle `u32::MAX`) when no
/// compatible point lies within `b.reach` (an outlier that still counts in the median gap),
/// or `None` (no match at all, or a hit on the fixed surface's border).
///
/// The nearest point of the side comes first when it lies within the snap distance (a
/// point on the surface matches there, whatever a crease's normals say); otherwise the
/// nearest normal-compatible point (both in one search), searched only within `b.reach` and
/// within the distance to `previous`, the triangle matched in the step before, when the filter still allows it
/// (the nearest point is no farther than that triangle). The bounds keep the BVH from
/// scanning the fixed surface for triangles the normal filter rejects.
fn match_point(
    fixed: &QuerySurface,
    x: Vec3,
    nrm: Vec3,
    bit: super::regions::TriMask,
    b: Bounds,
    previous: Option<u32>,
) -> Option<(Vec3, f32, u32)> {
    let plain = Filter {
        bit,
        normal: None,
        crease: None,
    };
    let h = if nrm == Vec3::ZERO {
        fixed.closest(x, plain)?
    } else {
        let oriented = Filter {
            bit,
            normal: Some((nrm, b.cos)),
            crease: None,
        };
        // The previous triangle bounds the compatible point, and the nearest point of the
        // side too (within the snap distance it wins, whatever its normal).
        let warm = previous
            .and_then(|t| fixed.distance_to(x, oriented, t))
            .map_or(f32::INFINITY, |d| d * 1.0001 + 0.01 * b.snap);
        match fixed.closest_snapping(x, oriented, b.snap, warm.min(b.reach * 1.001)) {
            Some(h) => h,
            None => return Some((x, f32::INFINITY, u32::MAX)),
        }
    };
    if fixed.on_border(&h) {
        return None;
    }
    Some((h.point, h.point.distance(x), h.triangle))
}
