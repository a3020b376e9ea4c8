//! Facial Motion Cloning after Pandžić 2003 ("Facial Motion Cloning", Graphical Models 65):
//! copies morph targets of a source face onto a target face that has only a neutral mesh and
//! MPEG-4 feature points, keeping the motion FAP-compliant.
//!
//! # The steps, and our choices where the paper is vague
//!
//! 1. **Normalisation** ([`normalise`](self) step, module `normalise`). Every vertex belongs to
//!    the region of its closest feature point (3D distance; a feature-point vertex to its own
//!    point). Each region has a FAPU triple N(FP) per axis, from the feature point's group:
//!
//!    | group | region | x | y | z |
//!    |---|---|---|---|---|
//!    | 2 | jaw, chin, inner lip | MW | MNS | MNS |
//!    | 3 | eyes | ES | IRISD | ES |
//!    | 4 | eyebrows | ES | ENS | ENS |
//!    | 5 | cheeks | ES | ENS | ES |
//!    | 6 | tongue | MW | MNS | MW |
//!    | 8 | outer lip | MW | MNS | MNS |
//!    | 9, 10 | nose, ears | ENS | ENS | ENS |
//!    | 7, 11 | neck, hair line | ES | ENS | ES |
//!
//!    Every translation FAP's unit sits on the axis its feature point moves along (a test pins
//!    this over the whole FAP table), so a normalised motion at a feature point is `value/1024
//!    × direction` on every face, and denormalising with the *target's* factors gives exactly
//!    `value × target FAPU × direction`: FAP compliance. The factors are the neutral distances
//!    (MW0, …), so the normalised face is about a few units across (mouth width 1 in the lips).
//!    Motions are always divided by this table (displacement / N(FP), which is the paper's
//!    "difference of normalised positions").
//!
//!    *Positions* are normalised with the same table except that the eyes' vertical factor is
//!    ENS instead of IRISD (IRISD ≈ ES/7 would fold the eye region over the brows). The face
//!    centre C is the midpoint between the pupils 3.5 and 3.6. Three placements are offered
//!    ([`NormalisationMode`]): `Paper` is the paper's `V' = (V − C) / N(FP)`; `Anchored`
//!    scales each vertex's offset from its region's feature point,
//!    `V' = (FP − C) / (ES, ENS, ES) + (V − FP) / N(FP)`; `Global` (default) scales positions
//!    by the face-wide `(ES, ENS, ES)` only. With `Paper`, regions far from C tear apart where
//!    their factors differ (on Candide-3 the chin, scaled by MNS, lands ~1.5 units below the
//!    jaw corners scaled by ENS); `Anchored` keeps the tears as small as the regions but still
//!    tears and folds where neighbouring vertices fall to feature points with different
//!    factors (a subdivided target's new edge midpoints show it: on Candide-3 → reshaped and
//!    subdivided Candide-3 the mean displacement error is 48 % anchored against 17 % global,
//!    and folds over feature points even break FAP compliance).
//!    `Global` is an affine map, so it adds no folds; the per-region proportions the paper
//!    normalises are matched by the piecewise-affine alignment instead, and motions keep the
//!    regional FAPU scaling (which is what FAP compliance needs). All three are measured in
//!    the tests; `Global` has the smallest errors.
//! 2. **Cylindrical projection** (module `project`): about a vertical axis through the nose
//!    tip's x (so 9.3 is at angle 0), at the depth z0 where the angle between the outer mouth
//!    corners 8.3 and 8.4 is [`FmcOptions::mouth_angle`] (0.8 rad) on every face — a 1D
//!    bisection on z0 (the angle grows monotonically as the axis approaches the mouth; closed
//!    form z0 = z_m − h / tan(θ/2) for a symmetric mouth). The 2D point is (angle in radians,
//!    normalised y); depth is the negated distance from the axis, so the smallest depth is the
//!    front-most surface. Triangles spanning more than π in angle (a seam behind the head) are
//!    not used for interpolation.
//! 3. **Alignment** (module `align`): the target's projected feature points move onto the
//!    source's; other points follow by barycentric interpolation of the feature points'
//!    displacements over our own 59-triangle feature-point triangulation
//!    (`align::FP_TRIANGLES`, 39 required points: brows, eyes with pupils, nose bridge,
//!    nostrils, nose tip and bottom, cheeks and cheek bones, outer and inner lip corners and
//!    midpoints, chin, jaw corners). Its upper-lip and lower-lip triangles meet along the lip
//!    line and are used only by points of their own lip region; points outside the hull use
//!    the closest-triangle rule. Every target feature-point vertex whose point the source
//!    also has is then put exactly on the source's point.
//! 4. **Interpolation from a 2D triangle mesh** (module `interp`), exactly as the paper:
//!    bounding-box test (a uniform grid of triangle boxes instead of a scan), barycentric
//!    coordinates, inside when all are in [0, 1] (within 1e-9), overlaps resolved by the
//!    smallest interpolated depth, outside points by the triangle with the smallest sum of
//!    excess coordinates (among the 16 nearest boxes, ties by triangle index), clamped to
//!    [0, 1] and renormalised.
//! 5. **Motion mapping**: normalised source motion vectors interpolated at each aligned target
//!    point from the source's projected triangles (weights computed once, applied to every
//!    motion).
//! 6. **Anti-aliasing filter**: the motion is the mean of the interpolations at the point and
//!    at [`FmcOptions::filter_samples`] points evenly spaced on a circle of diameter
//!    [`FmcOptions::filter_support`] (0.02, so the footprint is 0.02 wide as in the paper)
//!    around it. In our alignment space the mouth is 0.8 wide and the face about 3 × 4, so
//!    0.02 is 2.5 % of the mouth width. Target feature-point vertices are not filtered: their
//!    motion is the FAP itself, and a filter would flatten its peak.
//! 7. **Lip separation** (module `lips`): in each face's own projected space, the upper-lip
//!    polygon is the lip line (8.4, inner upper contour 2.5 2.7 2.2 2.6 2.4, 8.3) closed over
//!    the nose sides and bottom (9.1 9.15 9.2); the lower-lip polygon is the line with the
//!    inner lower contour (2.5 2.9 2.3 2.8 2.4) closed under the chin (2.11 2.1 2.12). Vertices
//!    exactly on a boundary (the coincident lip vertices of a closed mouth) take the region of
//!    their adjacent triangles' centroids (upper only → upper, lower only → lower, both → out).
//!    A source triangle is an upper-lip triangle when its three vertices are upper-lip, or
//!    when its centroid lies strictly inside the upper polygon and none of its vertices is
//!    lower-lip (this catches the triangles at the lip corners, whose corner vertex is "out":
//!    with the all-vertices rule alone they let a closed mouth's coincident line vertices pick
//!    the other lip's motion); likewise for the lower lip. A target vertex of the lower lip
//!    ignores upper-lip source triangles and every source triangle with an upper-lip vertex,
//!    and vice versa (so a closed mouth's coincident line vertices, which lie in triangles of
//!    both lips, take only their own lip's motion: a self-clone is exact there).
//! 8. **Denormalisation**: a source vertex's normalised motion is multiplied by the
//!    *target's* N(FP) of the *source vertex's* region before it is interpolated, i.e. each
//!    source motion is scaled by the target/source FAPU ratio of its own region. The paper
//!    multiplies the interpolated motion by the target vertex's region instead; where the two
//!    regions differ that multiplies one region's normalised motion by another region's unit
//!    (an eyebrow vertex of the target taking an eyelid's IRISD-normalised motion times ENS
//!    moved 2.5× further than its feature point on Candide-3 → ICT). At feature points the two
//!    agree (a feature-point vertex's motion comes from the source's same point).
//!
//! Rigid parts (eyes, teeth, tongue, head transforms) are not part of a [`CloneSurface`] and
//! are not handled here.
//!
//! # Default mode: what whole faces use, and how it differs from the paper
//!
//! [`FmcOptions::default`] is the paper (with the choices above). Whole faces clone with
//! [`face_fmc_options`](crate::clone::face::face_fmc_options): `Global` normalisation,
//! nearest-depth overlaps, no anti-aliasing filter, and **dense correspondence**
//! ([`FmcCorrespondence::Dense`]) in place of steps 3–6 and 7: each target vertex samples the
//! source where `fit`'s registration puts it ([`crate::clone::fit`]: side-restricted
//! closest points after a landmark-guided non-rigid registration, or vertex to vertex for
//! one topology). The paper aligns the two faces through 39 feature points in a 2D
//! cylindrical projection; between those points the alignment is piecewise affine, so
//! the cheeks, lids and lips of two real heads land on the wrong part of each other (and
//! the lip and lid separation of step 7 is then needed to repair the worst of it; the
//! registration's slit sides do that job). The motion scaling — each source motion
//! normalised by its own region's FAPU and denormalised by the target's (steps 1 and 8) — is
//! the paper's.
//!
//! Measured on ICT identity heads against their true FATs (`tests/clone_ict_identities.rs`,
//! per-case median over 14 FAPs): projected alignment 10.9–14.5 % (the paper's `Paper`
//! normalisation with its filter 30–32 %), dense correspondence 5.7–6.9 %.

mod align;
mod interp;
mod lips;
mod normalise;
mod project;
#[cfg(test)]
mod tests;

use std::collections::{BTreeMap, BTreeSet};
use std::time::Instant;

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use super::{CloneSurface, StepTimings, SurfaceCloneResult, SurfaceMotion};
use crate::clone::CloneError;
use crate::error::{Diagnostic, Result};
use crate::spec::FeaturePointId;
use interp::TriMesh2;
use lips::{LipPolygons, LipRegion};
use project::Cylinder;

/// Where normalised positions are placed (motions are normalised the same way in both).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalisationMode {
    /// The paper's `V' = (V − C) / N(FP)` about the face centre.
    Paper,
    /// `V' = (FP − C) / (ES0, ENS0, ES0) + (V − FP) / N(FP)`: regional scaling about each
    /// region's own feature point, which keeps the normalised face in one piece.
    Anchored,
    /// `V' = (V − C) / (ES0, ENS0, ES0)`: one affine scaling per face for positions (regions
    /// only scale motions), so the projected mesh has no folds the face itself lacks.
    #[default]
    Global,
}

/// How a point inside several overlapping projected source triangles picks one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OverlapRule {
    /// The paper's rule: the smallest interpolated depth, i.e. the front-most surface.
    #[default]
    FrontMost,
    /// The triangle whose interpolated depth is closest to the target point's own depth
    /// (shifted by the feature points' depth differences, like the alignment): inner layers
    /// such as eyeballs behind eyelids map onto inner layers instead of the skin in front.
    NearestDepth,
}

/// Where each target vertex samples the source's motion (steps 3–6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FmcCorrespondence {
    /// The paper's: the target's projected feature points aligned onto the source's, each
    /// target vertex interpolated in the source's projected triangles (steps 3–6).
    #[default]
    Paper,
    /// `fit`'s dense correspondence ([`crate::clone::fit`], default settings): each target
    /// vertex's closest point on the source registered onto the target (module docs,
    /// "Default mode").
    Dense,
}

/// Options of [`clone_fmc`].
#[derive(Clone, Debug, PartialEq)]
pub struct FmcOptions {
    /// Width (diameter) of the anti-aliasing filter's footprint in alignment space; 0 turns
    /// the filter off. The paper's value is 0.02.
    pub filter_support: f32,
    /// Samples on the filter's circle, besides the point itself.
    pub filter_samples: usize,
    /// Fixed angular width of the mouth (8.3 to 8.4) in the cylindrical projection, radians.
    pub mouth_angle: f64,
    /// Placement of normalised positions.
    pub normalisation: NormalisationMode,
    /// Keep upper- and lower-lip motion apart (the paper's lip treatment).
    pub lip_separation: bool,
    /// Resolution of overlapping source triangles.
    pub overlap: OverlapRule,
    /// Where target vertices sample the source (default: the paper's projection).
    pub correspondence: FmcCorrespondence,
}

impl Default for FmcOptions {
    fn default() -> Self {
        FmcOptions {
            filter_support: 0.02,
            filter_samples: 8,
            mouth_angle: 0.8,
            normalisation: NormalisationMode::Anchored,
            lip_separation: true,
            overlap: OverlapRule::FrontMost,
            correspondence: FmcCorrespondence::Paper,
        }
    }
}

/// Feature points both faces must have: the triangulation's 39 points (which include the
/// pupils, nose tip and outer mouth corners used by normalisation and projection).
pub fn required_feature_points() -> Vec<FeaturePointId> {
    align::triangulation_points()
}

/// Feature points whose absence only degrades the result (a warning).
pub fn optional_feature_points() -> Vec<FeaturePointId> {
    lips::OPTIONAL.to_vec()
}

fn missing(surface: &CloneSurface, ids: &[FeaturePointId]) -> Vec<String> {
    ids.iter()
        .filter(|id| !surface.fp_positions.contains_key(id))
        .map(|id| id.to_string())
        .collect()
}

/// A face projected into the 2D space.
struct Projected {
    norm: normalise::Normalised,
    axis: Cylinder,
    uv: Vec<DVec2>,
    depth: Vec<f64>,
    fps: BTreeMap<FeaturePointId, DVec2>,
    fp_depth: BTreeMap<FeaturePointId, f64>,
}

fn project_face(norm: normalise::Normalised, mouth_angle: f64, name: &str) -> Result<Projected> {
    // The caller checked the required points, so a miss here is only a broken invariant;
    // it still becomes an error rather than a panic.
    let fp = |id: FeaturePointId| {
        norm.fps
            .get(&id)
            .copied()
            .ok_or_else(|| CloneError::MissingFeaturePoint {
                side: name.into(),
                id,
            })
    };
    let axis = Cylinder::solve(
        fp(FeaturePointId::FP_9_3)?,
        fp(FeaturePointId::FP_8_3)?,
        fp(FeaturePointId::FP_8_4)?,
        mouth_angle,
    )
    .map_err(|reason| CloneError::Projection {
        side: name.into(),
        reason,
    })?;
    let (uv, depth): (Vec<DVec2>, Vec<f64>) =
        norm.positions.par_iter().map(|&p| axis.project(p)).unzip();
    let fps = norm
        .fps
        .iter()
        .map(|(&id, &p)| (id, axis.project(p).0))
        .collect();
    let fp_depth = norm
        .fps
        .iter()
        .map(|(&id, &p)| (id, axis.project(p).1))
        .collect();
    Ok(Projected {
        norm,
        axis,
        uv,
        depth,
        fps,
        fp_depth,
    })
}

/// Clones `motions` (morph targets on `source`) onto `target` by Facial Motion Cloning.
///
/// Returns one motion per input motion (same key and value) on the target's vertices,
/// per-step timings (`normalise`, `project`, `lips`, `align`, `map`, `motions`,
/// `denormalise`) and statistics. Errors when either face lacks required feature points (all
/// are listed), has invalid geometry, or a motion names a vertex the source lacks.
pub fn clone_fmc(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    opts: &FmcOptions,
) -> Result<SurfaceCloneResult> {
    source.check("source")?;
    target.check("target")?;
    let required = required_feature_points();
    let (ms, mt) = (missing(source, &required), missing(target, &required));
    if !ms.is_empty() || !mt.is_empty() {
        return Err(CloneError::MissingFeaturePoints {
            source_lacks: ms,
            target_lacks: mt,
        }
        .into());
    }
    let mut warnings = Vec::new();
    let optional = optional_feature_points();
    for (face, name) in [(source, "source"), (target, "target")] {
        let m = missing(face, &optional);
        if !m.is_empty() {
            warnings.push(Diagnostic::warning(format!(
                "{name} face lacks inner-lip points {}; the lip regions are coarser",
                m.join(", ")
            )));
        }
    }
    source.check_motions(motions)?;
    if !(opts.filter_support.is_finite() && opts.filter_support >= 0.0) {
        return Err(CloneError::BadOption {
            method: "fmc",
            option: "filter_support",
            value: opts.filter_support.into(),
        }
        .into());
    }
    let mut timings = StepTimings::default();
    let mut stats = BTreeMap::new();
    let mut fit_warnings = Vec::new();

    // 1. Normalisation.
    let t = Instant::now();
    let (ns, nt) = rayon::join(
        || normalise::normalise(source, opts.normalisation),
        || normalise::normalise(target, opts.normalisation),
    );
    timings.push("normalise", t.elapsed().as_secs_f64());

    // 2. Projection.
    let t = Instant::now();
    let src = project_face(ns, opts.mouth_angle, "source")?;
    let tgt = project_face(nt, opts.mouth_angle, "target")?;
    stats.insert("source_axis_z".into(), src.axis.z0);
    stats.insert("target_axis_z".into(), tgt.axis.z0);
    timings.push("project", t.elapsed().as_secs_f64());

    let mapped = match opts.correspondence {
        FmcCorrespondence::Paper => {
            map_paper(source, target, &src, &tgt, opts, &mut timings, &mut stats)?
        }
        FmcCorrespondence::Dense => {
            let (corr, _) = crate::clone::fit::correspondences(
                source,
                target,
                &crate::clone::fit::FitOptions::default(),
                &mut timings,
                &mut stats,
                &mut fit_warnings,
            )?;
            // As in step 3, a target feature-point vertex whose point the source has samples
            // exactly that point: its motion is the FAP itself.
            let fp_source: BTreeMap<u32, u32> = target
                .fp_vertices
                .iter()
                .filter_map(|(id, &tv)| Some((tv, *source.fp_vertices.get(id)?)))
                .collect();
            corr.iter()
                .enumerate()
                .map(|(q, c)| Mapped {
                    weights: match fp_source.get(&(q as u32)) {
                        Some(&sv) => vec![(sv, 1.0)],
                        None => c.map_or_else(Vec::new, |c| {
                            c.vertices
                                .iter()
                                .zip(c.weights)
                                .filter(|(_, w)| *w != 0.0)
                                .map(|(&v, w)| (v, f64::from(w * c.fade)))
                                .collect()
                        }),
                    },
                    outside: 0,
                    overlaps: 0,
                })
                .collect()
        }
    };
    warnings.extend(fit_warnings.into_iter().map(Diagnostic::warning));

    // 5 and 8. Motion mapping; each source motion is normalised by its own vertex's region
    // and denormalised by the target's factors of that same region (see step 8).
    let t = Instant::now();
    let ratio: Vec<DVec3> = src
        .norm
        .region
        .iter()
        .zip(&src.norm.motion_factors)
        .map(|(id, n)| normalise::factors(&target.fapu, normalise::motion_kinds(id.group())) / *n)
        .collect();
    let normalised: Vec<Vec<DVec3>> = motions
        .par_iter()
        .map(|m| {
            let mut dense = vec![DVec3::ZERO; source.positions.len()];
            for &(v, d) in &m.offsets {
                dense[v as usize] = d.as_dvec3() * ratio[v as usize];
            }
            mapped
                .iter()
                .map(|mp| mp.weights.iter().map(|&(v, w)| dense[v as usize] * w).sum())
                .collect()
        })
        .collect();
    timings.push("motions", t.elapsed().as_secs_f64());

    // 8. Output (the target's factors were applied per source region above).
    let t = Instant::now();
    let mut out = Vec::with_capacity(motions.len());
    for (m, field) in motions.iter().zip(normalised) {
        let offsets: Vec<(u32, Vec3)> = field
            .iter()
            .enumerate()
            .filter(|(_, d)| **d != DVec3::ZERO)
            .map(|(i, d)| (i as u32, d.as_vec3()))
            .collect();
        if let Some(&(vertex, _)) = offsets.iter().find(|(_, d)| !d.is_finite()) {
            return Err(CloneError::NonFiniteOutput {
                method: "fmc",
                key: m.key,
                vertex,
            }
            .into());
        }
        out.push(SurfaceMotion {
            key: m.key,
            value: m.value,
            offsets,
        });
    }
    timings.push("denormalise", t.elapsed().as_secs_f64());

    Ok(SurfaceCloneResult {
        motions: out,
        timings,
        stats,
        warnings,
    })
}

/// Where one target vertex samples the source: weights of source vertices.
struct Mapped {
    weights: Vec<(u32, f64)>,
    outside: u32,
    overlaps: u32,
}

/// Steps 3–7 of the paper (module docs): lip regions, alignment and the interpolation
/// weights of every target vertex in the source's projected triangles.
fn map_paper(
    source: &CloneSurface,
    target: &CloneSurface,
    src: &Projected,
    tgt: &Projected,
    opts: &FmcOptions,
    timings: &mut StepTimings,
    stats: &mut BTreeMap<String, f64>,
) -> Result<Vec<Mapped>> {
    // 7 (needed by 3 and 5). Lip regions, each face in its own projected space.
    let t = Instant::now();
    let (src_lips, tgt_lips) = if opts.lip_separation {
        (
            LipPolygons::new(&src.fps).classify(&src.uv, &source.triangles),
            LipPolygons::new(&tgt.fps).classify(&tgt.uv, &target.triangles),
        )
    } else {
        (
            vec![LipRegion::Out; src.uv.len()],
            vec![LipRegion::Out; tgt.uv.len()],
        )
    };
    let count = |l: &[LipRegion], r: LipRegion| l.iter().filter(|&&x| x == r).count() as f64;
    stats.insert(
        "upper_lip_vertices".into(),
        count(&tgt_lips, LipRegion::Upper),
    );
    stats.insert(
        "lower_lip_vertices".into(),
        count(&tgt_lips, LipRegion::Lower),
    );
    stats.insert(
        "source_upper_lip_vertices".into(),
        count(&src_lips, LipRegion::Upper),
    );
    stats.insert(
        "source_lower_lip_vertices".into(),
        count(&src_lips, LipRegion::Lower),
    );
    timings.push("lips", t.elapsed().as_secs_f64());

    // 3. Alignment.
    let t = Instant::now();
    let snap: Vec<(u32, FeaturePointId)> = target
        .fp_vertices
        .iter()
        .filter(|(id, _)| src.fps.contains_key(id))
        .map(|(&id, &v)| (v, id))
        .collect();
    let aligned = align::align(
        &tgt.uv,
        &tgt.depth,
        &tgt_lips,
        (&tgt.fps, &tgt.fp_depth),
        (&src.fps, &src.fp_depth),
        &snap,
    );
    stats.insert("alignment_outside".into(), aligned.outside as f64);
    timings.push("align", t.elapsed().as_secs_f64());

    // 4–6. Interpolation weights (with the filter) for every target vertex.
    let t = Instant::now();
    let mesh = TriMesh2::new(
        src.uv.clone(),
        src.depth.clone(),
        &source.triangles,
        std::f64::consts::PI,
    );
    if mesh.triangles.is_empty() {
        return Err(CloneError::NoUsableTriangles.into());
    }
    let src_polys = LipPolygons::new(&src.fps);
    let tri_lip: Vec<LipRegion> = mesh
        .triangles
        .iter()
        .map(|t| {
            if !opts.lip_separation {
                return LipRegion::Out;
            }
            let r = t.map(|v| src_lips[v as usize]);
            let centroid = t.iter().map(|&v| src.uv[v as usize]).sum::<DVec2>() / 3.0;
            let has = |x: LipRegion| r.contains(&x);
            match src_polys.region_of(centroid) {
                Some(LipRegion::Upper) if !has(LipRegion::Lower) => LipRegion::Upper,
                Some(LipRegion::Lower) if !has(LipRegion::Upper) => LipRegion::Lower,
                _ if r.iter().all(|&x| x == LipRegion::Upper) => LipRegion::Upper,
                _ if r.iter().all(|&x| x == LipRegion::Lower) => LipRegion::Lower,
                _ => LipRegion::Out,
            }
        })
        .collect();
    // (has an upper-lip vertex, has a lower-lip vertex) per kept source triangle.
    let tri_has: Vec<(bool, bool)> = mesh
        .triangles
        .iter()
        .map(|t| {
            let r = t.map(|v| src_lips[v as usize]);
            (r.contains(&LipRegion::Upper), r.contains(&LipRegion::Lower))
        })
        .collect();
    let fp_vertex: BTreeSet<u32> = target.fp_vertices.values().copied().collect();
    let ring: Vec<DVec2> = if opts.filter_support > 0.0 && opts.filter_samples > 0 {
        let r = f64::from(opts.filter_support) * 0.5;
        (0..opts.filter_samples)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / opts.filter_samples as f64;
                DVec2::new(a.cos(), a.sin()) * r
            })
            .collect()
    } else {
        Vec::new()
    };
    let mapped: Vec<Mapped> = aligned
        .points
        .par_iter()
        .enumerate()
        .map(|(i, &p)| {
            let lip = tgt_lips[i];
            let near = match opts.overlap {
                OverlapRule::FrontMost => None,
                OverlapRule::NearestDepth => Some(aligned.depth[i]),
            };
            // A lip vertex never takes weight from the other lip: neither its triangles nor
            // any triangle with one of its vertices (at a closed mouth's coincident line
            // vertices an "out" corner triangle can hold the other lip's vertex, and the tie
            // between the two coincident vertices would otherwise go to the lower index).
            let allowed = |t: u32| match lip {
                LipRegion::Upper => {
                    tri_lip[t as usize] != LipRegion::Lower && !tri_has[t as usize].1
                }
                LipRegion::Lower => {
                    tri_lip[t as usize] != LipRegion::Upper && !tri_has[t as usize].0
                }
                LipRegion::Out => true,
            };
            let offsets: &[DVec2] = if fp_vertex.contains(&(i as u32)) {
                &[]
            } else {
                &ring
            };
            let n = 1 + offsets.len();
            let mut weights: Vec<(u32, f64)> = Vec::with_capacity(3 * n);
            let (mut outside, mut overlaps) = (0, 0);
            for q in std::iter::once(p).chain(offsets.iter().map(|o| p + *o)) {
                let hit = mesh
                    .locate(q, near, allowed)
                    .or_else(|| mesh.locate(q, near, |_| true));
                // `mesh` has triangles, so the unrestricted search always finds one.
                let Some(hit) = hit else { continue };
                outside += u32::from(hit.outside);
                overlaps += u32::from(hit.overlap);
                for (v, w) in mesh.weights(&hit) {
                    if w == 0.0 {
                        continue;
                    }
                    match weights.iter_mut().find(|x| x.0 == v) {
                        Some(x) => x.1 += w / n as f64,
                        None => weights.push((v, w / n as f64)),
                    }
                }
            }
            Mapped {
                weights,
                outside,
                overlaps,
            }
        })
        .collect();
    stats.insert(
        "outside_points".into(),
        mapped.iter().map(|m| f64::from(m.outside)).sum(),
    );
    stats.insert(
        "overlaps_resolved".into(),
        mapped.iter().map(|m| f64::from(m.overlaps)).sum(),
    );
    stats.insert("source_triangles_used".into(), mesh.triangles.len() as f64);
    timings.push("map", t.elapsed().as_secs_f64());
    Ok(mapped)
}
