//! `fit`: facial motion cloning by dense correspondence — a landmark-guided non-rigid
//! registration of the source's neutral surface onto the target's, every target vertex
//! located on the registered source, and each motion carried over by barycentric
//! interpolation and scaled to the target's FAP units.
//!
//! # The math
//!
//! 1. **Sides** ([`regions`](self) — `regions.rs`): vertices near the mouth and eye slits are
//!    labelled upper or lower from the feature points (lip corners and inner-lip points,
//!    eye corners and lid points). Every closest-point query below is restricted to its side:
//!    an upper-lip vertex never lands on the lower lip, an upper lid never on the lower lid,
//!    so a closed mouth or eye does not weld. A triangle bridging a slit (CANDIDE-3 covers
//!    its eyes, iris vertices between the lids) is seen from both sides, but a vertex landing
//!    on it takes none of the other side's corners. And a vertex of a *face piece* (a
//!    connected piece holding a skin feature point) only matches face pieces: ICT's eye
//!    occlusion shell lies against the lid margin and once took the upper lid's motion away.
//!    Likewise a vertex of the hidden mouth interior (`clone/mouth_interior.rs`: a
//!    rig head's mouth socket) only matches the other face's interior, and a vertex outside
//!    it never does: registered onto a face without a socket, ICT's socket was dragged onto
//!    the target's inner lips, which then read its motion (MediaPipe's canonical face: the
//!    right lip corner moved 0.6 % of `stretch_r_cornerlip`'s FAPU). Without a source
//!    interior the target's is matched like any skin (the `mouth` step moves it later).
//! 2. **Registration** (`register.rs`, `system.rs`): the source's displacement field `u`
//!    minimises, per step,
//!    `Σ w_i‖p_i+u_i−c_i‖² + βΣ_l‖p_l+u_l−L_l‖² + α(‖Lu‖² + μ‖∇u‖²) + ε‖u‖²` —
//!    closest target points `c_i` (side-restricted; rejected on the target's border, with
//!    normals more than 60° apart, or far off), the target's feature points `L_l` at the
//!    source's feature-point vertices, and a bending term (uniform Laplacian `L`) whose
//!    weight `α` goes from stiff to soft ([`FitOptions::stiffness`]), after Amberg et al.
//!    2007 ("Optimal Step Nonrigid ICP Algorithms for Surface Registration"). Each step is one
//!    sparse SPD system `(α(LᵀL+μL_g) + W + βB + εI) u = W(c−p) + βB(L−p)` in three
//!    right-hand sides, solved by a sparse Cholesky factorisation (faer) whose pattern and
//!    symbolic analysis are built once; a step at the stiffness of the step before, by
//!    conjugate gradients preconditioned by that step's factor when they converge within a
//!    few iterations (`system.rs`).
//!    Defaults: `α` = 300, 300, 100, 10, 1 with two closest-point updates each, and `β` = 10,
//!    or 100 on a dense source (median edge under [`DENSE_EDGE`] ES0; ICT's are 0.04).
//!    Along the surface only the bending term and the landmarks hold the source, so it
//!    slides into place slowly, and a landmark pins one vertex against the closest-point
//!    matches of every vertex around it — more of them the denser the source. ICT onto a 4×
//!    denser identity head, median error against its true FAT: 3.4 % with the old defaults
//!    (`α` = 100, 30, 10, 3, 1; `β` = 10), 3.4 % with the new `α` alone, 3.1 % with `β` =
//!    100 alone, 2.9 % with both (as many solves as before). `β` = 100 on every source drew
//!    CANDIDE-3's coarse lower lid across its slit (`close_b_l_eyelid` 30 % in a forced
//!    registration); `β` growing smoothly with density (10 × 0.4 ES0 / median edge) gave
//!    the ICT rig, at a slightly lower `β`, a brow crease on alma (normal-turn ratio 4.2):
//!    hence two settings, each measured on every suite.
//! 3. **Correspondence** (`correspond.rs`): every target vertex takes its closest point on
//!    the registered source (same side, compatible normal — either side's normal on a crease
//!    such as a lid margin): a source triangle and barycentric weights. Target vertices far from the source (beyond what the source covers) fade out.
//! 4. **Transfer** (`transfer.rs`): each motion's source displacements, interpolated at
//!    those weights, times the target / source FAPU ratio of the FAP's unit — so the same FAP
//!    value moves the target by its own FAPU (compliance), and no vertex exceeds the largest
//!    source displacement of the FAP in FAPU. Motions run in parallel (rayon).
//!
//! **One topology.** When both surfaces are one mesh — the same vertex count and the same
//! triangles, as a face and its reshaped, rescaled or re-posed copy, or two identities of one
//! template — vertex `i` of the target *is* vertex `i` of the source, so steps 1–3 are
//! skipped and each target vertex takes its own vertex's motion (times the FAPU ratio). A
//! registration could only approximate that correspondence
//! ([`FitOptions::shared_topology`] turns it off). Whole faces keep a one-mesh target that
//! is one mesh with the source whole for this ([`crate::clone::face`], step 1): cut into
//! eyes, teeth and skin, its skin would no longer match the source's, and a registration
//! put the ICT identities' lids 3–4 % and their jaws 3 % off their true FATs (vertex to
//! vertex: 0.0 %).
//!
//! The source is registered onto the target, not the other way: the source's motion field
//! is what must be sampled, and the target vertices then sample it where the registered
//! source lies under them. A surface cloned onto itself registers to itself (every closest
//! point is the vertex itself) and reproduces its motions exactly.
//!
//! Whole faces: [`crate::clone::face`] with [`Method::Fit`](crate::clone::face::Method::Fit);
//! the FAPU ratio is applied here, so the pipeline's RBF rescale does not run, and the
//! pipeline's guard checks the result like every method's.

mod correspond;
mod filter_tree;
mod regions;
mod register;
mod surface;
mod system;
mod transfer;

use std::collections::BTreeMap;
use std::time::Instant;

use glam::Vec3;

use super::{CloneSurface, StepTimings, SurfaceCloneResult, SurfaceMotion};
use crate::clone::mouth_interior::{Extent, MouthInterior};
use crate::error::Result;
use crate::mesh::spatial::find_coincident_vertices;
pub(crate) use correspond::Correspondence;
use regions::{classify, face_pieces, triangle_masks};
use register::{register, Moving};
use surface::{adjacency, QuerySurface};
use system::SmoothSystem;

/// Settings of [`clone_fit`].
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// Bending weights `α` of the registration, stiff to soft (each value runs
    /// [`iterations`](Self::iterations) closest-point updates). Default
    /// `[300, 300, 100, 10, 1]`: the stiff steps come twice, since a surface slides along
    /// the other only slowly under them (module docs, step 2).
    pub stiffness: Vec<f64>,
    /// Closest-point updates per stiffness value. Default 2.
    pub iterations: usize,
    /// Weight `β` of the feature-point landmarks against one closest-point match; a dense
    /// source (median edge under [`DENSE_EDGE`] ES0) takes [`DENSE_GAIN`]× this (module docs,
    /// step 2). Default 10.
    pub landmark_weight: f64,
    /// Membrane weight `μ` relative to bending. Default 0.01.
    pub membrane: f64,
    /// Closest points whose surface normals differ by more than this many degrees are
    /// rejected. Default 60.
    pub normal_degrees: f64,
    /// Registration matches farther than this many ES0 are rejected. Default 0.25.
    pub max_distance: f64,
    /// A target vertex farther than `.0` × ES0 from the registered source takes less of its
    /// motion, none beyond `.1` × ES0. Default `(0.05, 0.25)`.
    pub fade: (f64, f64),
    /// Scale each low-level translation FAP by the target / source FAPU ratio of its unit.
    /// Default on.
    pub fapu_scale: bool,
    /// Surfaces with the same vertex count and triangles correspond vertex to vertex, without
    /// registration (module docs). Default on.
    pub shared_topology: bool,
    /// How displacements are carried. Default [`FitTransfer::Barycentric`].
    pub transfer: FitTransfer,
}

/// How [`clone_fit`] carries a displacement from the source to the target.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FitTransfer {
    /// Interpolated as it is, in the aligned face frame (FAP directions stay on the face's
    /// axes).
    #[default]
    Barycentric,
    /// Turned first by its source vertex's local rotation under the registration (module
    /// docs of `transfer.rs`).
    LocalFrame,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            stiffness: vec![300.0, 300.0, 100.0, 10.0, 1.0],
            iterations: 2,
            landmark_weight: 10.0,
            membrane: 0.01,
            normal_degrees: 60.0,
            max_distance: 0.25,
            fade: (0.05, 0.25),
            fapu_scale: true,
            shared_topology: true,
            transfer: FitTransfer::Barycentric,
        }
    }
}

/// A source whose median edge is shorter than this many ES0 is dense (a scanned or
/// sculpted head: ICT's are 0.04; CANDIDE-3's, even subdivided once, are longer) and takes
/// [`DENSE_GAIN`] × [`FitOptions::landmark_weight`] (module docs, step 2).
pub const DENSE_EDGE: f64 = 0.08;

/// The landmark weight's factor on a dense source.
pub const DENSE_GAIN: f64 = 10.0;

/// The landmark weight `β` on `s` (module docs, step 2): `base`, times `DENSE_GAIN` when the
/// median edge of `s` is shorter than `DENSE_EDGE` in units of `scale`.
fn landmark_weight(s: &CloneSurface, scale: f32, base: f64) -> f64 {
    let mut edges: Vec<f32> = s
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .filter_map(|(a, b)| {
            let (pa, pb) = (s.positions.get(a as usize)?, s.positions.get(b as usize)?);
            Some(pa.distance(*pb))
        })
        .collect();
    if edges.is_empty() || scale.is_nan() || scale <= 0.0 {
        return base;
    }
    let mid = edges.len() / 2;
    let median = *edges.select_nth_unstable_by(mid, f32::total_cmp).1 as f64 / scale as f64;
    if median < DENSE_EDGE {
        base * DENSE_GAIN
    } else {
        base
    }
}

/// Which vertices some triangle uses.
fn used_vertices(s: &CloneSurface) -> Vec<bool> {
    let mut used = vec![false; s.positions.len()];
    for &v in s.triangles.iter().flatten() {
        if let Some(u) = used.get_mut(v as usize) {
            *u = true;
        }
    }
    used
}

/// Whether `a` and `b` are one mesh: as many vertices and the same triangles.
fn same_topology(a: &CloneSurface, b: &CloneSurface) -> bool {
    a.positions.len() == b.positions.len() && a.triangles == b.triangles
}

/// Vertices coinciding with another one (within 1e-6 of the face scale) outside the slits.
fn loose_duplicates(s: &CloneSurface, sides: &[regions::Side]) -> usize {
    let eps = face_scale(s) * 1e-6;
    find_coincident_vertices(&s.positions, eps)
        .clusters
        .iter()
        .flatten()
        .filter(|&&v| sides.get(v as usize) == Some(&regions::Side::Other))
        .count()
}

/// A length of the face: ES0, else a tenth of the bounding-box diagonal.
fn face_scale(s: &CloneSurface) -> f32 {
    let es0 = s.fapu.distances.es0 as f32;
    if es0.is_finite() && es0 > 0.0 {
        return es0;
    }
    let (lo, hi) = s.positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let d = 0.1 * lo.distance(hi);
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

/// Clones `motions` of `source` onto `target` (module docs). The result has one motion per
/// source motion, in the same order, on the target's vertices.
///
/// Errors: a surface failing [`CloneSurface::check`], or a failing linear solve. Feature points missing on either side (fewer landmarks, slits not
/// found) are warnings.
pub fn clone_fit(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    opts: &FitOptions,
) -> Result<SurfaceCloneResult> {
    clone_fit_prepared(source, motions, target, opts, None)
}

/// [`clone_fit`] with what it reads of the source alone built ahead ([`SourcePrep`]; `None`:
/// built here). The same result bit for bit.
pub(crate) fn clone_fit_prepared(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    opts: &FitOptions,
    prep: Option<SourcePrep>,
) -> Result<SurfaceCloneResult> {
    source.check("source")?;
    target.check("target")?;
    let mut timings = StepTimings::default();
    let mut stats = BTreeMap::new();
    let mut warnings: Vec<String> = Vec::new();
    let (corr, rotations) = prepared_correspondences(
        source,
        target,
        opts,
        prep,
        &mut timings,
        &mut stats,
        &mut warnings,
    )?;
    // 4. Transfer.
    let clock = Instant::now();
    let out = transfer::transfer(
        source,
        motions,
        target,
        &corr,
        opts.fapu_scale,
        rotations.as_deref(),
    );
    timings.push("transfer", clock.elapsed().as_secs_f64());
    Ok(SurfaceCloneResult {
        motions: out,
        timings,
        stats,
        warnings: warnings
            .into_iter()
            .map(crate::error::Diagnostic::warning)
            .collect(),
    })
}

/// Where each target vertex lies on the source (steps 1–3, or vertex to vertex for one
/// topology), with the source vertices' local rotations when `opts.transfer` asks for them.
/// `fmc` and `rbf` take these in their default modes (their module docs).
#[allow(clippy::type_complexity)]
pub(crate) fn correspondences(
    source: &CloneSurface,
    target: &CloneSurface,
    opts: &FitOptions,
    timings: &mut StepTimings,
    stats: &mut BTreeMap<String, f64>,
    warnings: &mut Vec<String>,
) -> Result<(Vec<Option<Correspondence>>, Option<Vec<glam::Mat3>>)> {
    prepared_correspondences(source, target, opts, None, timings, stats, warnings)
}

/// [`correspondences`] with the source's [`SourcePrep`] built ahead (or `None`).
#[allow(clippy::type_complexity)]
fn prepared_correspondences(
    source: &CloneSurface,
    target: &CloneSurface,
    opts: &FitOptions,
    prep: Option<SourcePrep>,
    timings: &mut StepTimings,
    stats: &mut BTreeMap<String, f64>,
    warnings: &mut Vec<String>,
) -> Result<(Vec<Option<Correspondence>>, Option<Vec<glam::Mat3>>)> {
    if opts.shared_topology && same_topology(source, target) {
        let clock = Instant::now();
        let corr = (0..target.positions.len() as u32)
            .map(|v| {
                Some(Correspondence {
                    vertices: [v; 3],
                    weights: [1.0, 0.0, 0.0],
                    fade: 1.0,
                })
            })
            .collect();
        stats.insert("fit_shared_topology".into(), 1.0);
        timings.push("correspond", clock.elapsed().as_secs_f64());
        Ok((corr, None))
    } else {
        register_and_correspond(source, target, opts, prep, timings, stats, warnings)
    }
}

/// What `fit` reads of one surface alone: its vertex adjacency, slit sides (and how many of
/// the three slits were found), face pieces and mouth interior (socket extent; empty
/// without one).
struct SurfaceLabels {
    adj: Vec<Vec<u32>>,
    sides: Vec<regions::Side>,
    slits: usize,
    face: Vec<bool>,
    inside: Vec<bool>,
}

impl SurfaceLabels {
    fn of(s: &CloneSurface) -> Self {
        let adj = adjacency(s.positions.len(), &s.triangles);
        let (sides, slits) = classify(s, &adj);
        let inside = MouthInterior::of(s, &adj, Extent::SOCKET).map_or_else(Vec::new, |m| m.inside);
        SurfaceLabels {
            face: face_pieces(s),
            adj,
            sides,
            slits,
            inside,
        }
    }
}

/// What `fit` reads of the source surface alone: its labels and its smoothness system (the
/// symbolic analysis of the registration's matrix). The whole-face pipeline builds it while
/// its serial cut of the target leaves a core free (`clone::face`, step 1); the clone is the
/// same bit for bit as with everything built in [`clone_fit`] (dense CANDIDE-3 onto the
/// bundled ICT head: the symbolic analysis, the source's labels and its skin surface were
/// ~10–15 ms on the registration's path).
pub(crate) struct SourcePrep {
    /// The surface (its positions and triangles) and the membrane weight the system was
    /// built for: a preparation for another surface or weight is not used.
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    membrane: f64,
    labels: SurfaceLabels,
    system: Result<SmoothSystem>,
}

impl SourcePrep {
    /// The preparation of `source` for a clone with `opts`; `None` when the surface fails
    /// [`CloneSurface::check`] (the clone reports that itself).
    pub(crate) fn new(source: &CloneSurface, opts: &FitOptions) -> Option<Self> {
        source.check("source").ok()?;
        let labels = SurfaceLabels::of(source);
        let system = SmoothSystem::new(&labels.adj, opts.membrane);
        Some(SourcePrep {
            positions: source.positions.clone(),
            triangles: source.triangles.clone(),
            membrane: opts.membrane,
            labels,
            system,
        })
    }

    /// Whether this is the preparation of `source` for a clone with `opts`.
    fn fits(&self, source: &CloneSurface, opts: &FitOptions) -> bool {
        self.positions == source.positions
            && self.triangles == source.triangles
            && self.membrane == opts.membrane
    }
}

/// Steps 1–3 (module docs): sides, registration of the source onto the target, and each
/// target vertex's place on the registered source; with the source vertices' local rotations
/// when `opts.transfer` asks for them.
#[allow(clippy::type_complexity)]
fn register_and_correspond(
    source: &CloneSurface,
    target: &CloneSurface,
    opts: &FitOptions,
    prep: Option<SourcePrep>,
    timings: &mut StepTimings,
    stats: &mut BTreeMap<String, f64>,
    warnings: &mut Vec<String>,
) -> Result<(
    Vec<Option<correspond::Correspondence>>,
    Option<Vec<glam::Mat3>>,
)> {
    // 1. Sides.
    let clock = Instant::now();
    let (s_labels, system) = match prep.filter(|p| p.fits(source, opts)) {
        Some(p) => (Some(p.labels), Some(p.system)),
        None => (None, None),
    };
    // The two surfaces' labels are independent: one core each.
    let (
        SurfaceLabels {
            adj,
            sides: s_sides,
            slits: s_slits,
            face: s_face,
            inside: s_inside,
        },
        (
            SurfaceLabels {
                sides: t_sides,
                slits: t_slits,
                face: t_face,
                inside: t_inside,
                ..
            },
            loose,
        ),
    ) = rayon::join(
        || s_labels.unwrap_or_else(|| SurfaceLabels::of(source)),
        || {
            let t = SurfaceLabels::of(target);
            let loose = loose_duplicates(target, &t.sides);
            (t, loose)
        },
    );
    for (n, side) in [(s_slits, "source"), (t_slits, "target")] {
        if n < 3 {
            warnings.push(format!(
                "fit: only {n} of the 3 slits (mouth, eyes) found on the {side}'s feature \
                 points; lips or lids there may be matched across"
            ));
        }
    }
    // Landmarks: feature points that are surface vertices (on a triangle) of both faces.
    let (s_used, t_used) = (used_vertices(source), used_vertices(target));
    let mut off_mesh = 0;
    let landmarks: Vec<(u32, Vec3)> = source
        .fp_vertices
        .iter()
        .filter_map(|(id, &sv)| {
            let tv = *target.fp_vertices.get(id)?;
            let on = |used: &[bool], v: u32| used.get(v as usize).copied().unwrap_or(false);
            if !on(&s_used, sv) || !on(&t_used, tv) {
                off_mesh += 1;
                return None;
            }
            Some((sv, target.positions[tv as usize]))
        })
        .collect();
    if off_mesh > 0 {
        warnings.push(format!(
            "fit: {off_mesh} feature points are not on any triangle of the source or target \
             surface; they are not used as landmarks"
        ));
    }
    if loose > 0 {
        warnings.push(format!(
            "fit: {loose} target vertices duplicate another vertex away from the mouth and \
             eyes (an unwelded seam); each side is mapped on its own"
        ));
    }
    if landmarks.len() < 8 {
        warnings.push(format!(
            "fit: only {} feature points are vertices of both surfaces; the registration \
             relies on closest points",
            landmarks.len()
        ));
    }
    stats.insert("fit_landmarks".into(), landmarks.len() as f64);
    for (key, inside) in [
        ("fit_source_mouth_interior", &s_inside),
        ("fit_target_mouth_interior", &t_inside),
    ] {
        stats.insert(key.into(), inside.iter().filter(|&&i| i).count() as f64);
    }
    timings.push("sides", clock.elapsed().as_secs_f64());
    // 2. Registration of the source onto the target. The interiors are kept apart only when
    // both faces have one: a socket left without matches on a face without one changes
    // which matches the outlier cut keeps elsewhere (the ICT rig onto alma: a brow crease,
    // normal-turn ratio 1.35 → 3.57), and the correspondence below keeps the target's lips
    // off it anyway.
    let clock = Instant::now();
    let both = !s_inside.is_empty() && !t_inside.is_empty();
    let (s_reg_inside, t_reg_inside): (&[bool], &[bool]) = if both {
        (&s_inside, &t_inside)
    } else {
        (&[], &[])
    };
    let scale = face_scale(source);
    let fixed = || {
        QuerySurface::new(
            &target.positions,
            &target.triangles,
            triangle_masks(&t_sides, &t_face, t_reg_inside, &target.triangles),
        )
    };
    let moving = Moving {
        positions: &source.positions,
        triangles: &source.triangles,
        adjacency: &adj,
        sides: &s_sides,
        face: &s_face,
        inside: s_reg_inside,
        landmarks: &landmarks,
        scale,
    };
    let beta = landmark_weight(source, scale, opts.landmark_weight);
    stats.insert("fit_landmark_weight".into(), beta);
    let reg = register(
        &moving,
        fixed,
        &FitOptions {
            landmark_weight: beta,
            ..opts.clone()
        },
        system,
    )?;
    stats.insert("fit_solves".into(), reg.solves as f64);
    stats.insert("fit_matched".into(), reg.matched);
    stats.insert("fit_gap_es0".into(), reg.mean_gap);
    timings.push("register", clock.elapsed().as_secs_f64());
    // 3. Correspondence.
    let clock = Instant::now();
    let registered = || {
        QuerySurface::new(
            &reg.positions,
            &source.triangles,
            triangle_masks(&s_sides, &s_face, &s_inside, &source.triangles),
        )
    };
    let corr = correspond::correspond(
        &target.positions,
        &target.triangles,
        correspond::Labels {
            sides: &t_sides,
            face: &t_face,
            // Without a source interior, the target's own is matched like any skin (the
            // `mouth` step moves it afterwards).
            inside: if s_inside.is_empty() { &[] } else { &t_inside },
        },
        registered,
        (&source.triangles, &s_sides),
        scale,
        opts,
    );
    let unmatched = corr.iter().filter(|c| c.is_none()).count();
    stats.insert("fit_unmatched".into(), unmatched as f64);
    if unmatched > 0 {
        warnings.push(format!(
            "fit: {unmatched} of {} target vertices lie beyond the source surface and stay \
             still",
            target.positions.len()
        ));
    }
    timings.push("correspond", clock.elapsed().as_secs_f64());
    let rotations = (opts.transfer == FitTransfer::LocalFrame)
        .then(|| transfer::local_rotations(&source.positions, &reg.positions, &adj));
    Ok((corr, rotations))
}

#[cfg(test)]
mod tests;
