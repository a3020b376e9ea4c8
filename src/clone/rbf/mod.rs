//! Fratarcangeli & Schaerf 2005, "Fast Facial Motion Cloning in MPEG-4": a Hardy multiquadric
//! volume morph `f` fits the source face onto the target, every target vertex is bound to a
//! triangle of the fitted source, and each source morph target, pushed through the same `f`,
//! moves the target vertices bound to it.
//!
//! # Steps (timings use these names)
//!
//! 1. **`contours`** — eye and inner-lip contours on both faces by the paper's greedy walks
//!    from the feature points (`contours.rs`): eyes round robin 3.2⇒3.8⇒3.4⇒3.12⇒3.2 and
//!    its mirror image 3.1⇒3.11⇒3.3⇒3.7⇒3.1 (top, inner corner, bottom, outer corner: the
//!    paper's 3.1⇒3.7 order walks the left eye the other way round, and a greedy walk
//!    depends on its direction), step to the neighbour pointing best towards the goal (the
//!    paper's unit step `‖v + n̂ − end‖` depends on the model's unit; we use its scale-free
//!    limit, the largest cosine); lips from 2.5 to 2.4 by the xy-plane angle rule, smallest
//!    angle for the upper lip, greatest for the lower, walked from each corner to the lip's
//!    midpoint (2.2, 2.3) when it is a surface vertex, so both halves are walked alike.
//!    Taken literally that rule picks the lower lip at the corner and cannot tell coincident
//!    vertices of a closed mouth apart, so candidate edges are ranked first by which side
//!    their triangles lie on (edges bordering the mouth on the lip's own side win) and only
//!    then by angle. Walks never revisit a vertex and are capped at the vertex count. A
//!    greedy walk that runs into a dead end (on meshes of mixed quads and triangles, where a
//!    lip curls into the mouth and no neighbour lies ahead in xy) is replaced by the shortest
//!    edge path between the same points (through unused vertices for the eyes); a contour
//!    that cannot be joined at all is dropped with a warning. The lip contours also yield
//!    upper/lower **lip regions** (`regions.rs`) for step 4.
//! 2. **`fit`** — correspondences: every feature point that is a surface vertex of both faces
//!    except groups 10 (ears) and 6 (tongue), 9.8–9.11 (teeth) and 11.5 (top of the head). A
//!    first `f` is fitted to them; then each source contour vertex is paired with the nearest
//!    point on the corresponding target contour (its edges, nearest to the vertex as placed
//!    by that first `f`) and `f` is refitted. `f(p) = p + Σ w_i·sqrt(‖p − p_i‖² + r_i²) +
//!    affine`, with `r_i` the distance from centre `i` to its nearest other centre (`interp.rs`);
//!    the `(n+4)²` system is solved by faer's dense LU with partial pivoting for the three
//!    coordinates at once. Coincident source centres (closed mouth: 2.2≡2.3, 81≡83) are merged
//!    into one centre: feature points and contour points at one source position get the
//!    *mean* of their targets (with a warning when the targets disagree, e.g. closed source
//!    mouth → open target mouth, which a volume morph cannot separate); a feature point wins
//!    over a contour point at the same position. Fewer than four distinct correspondences,
//!    coplanar ones, a singular system or a non-finite solution are errors.
//! 3. **`refine`** (off by default: `max_iterations` is 0, see below) — movable vertices are
//!    the source vertices any motion moves. Each round
//!    applies `f` to the source, computes area-weighted vertex normals of the deformed source,
//!    casts a ray from each movable vertex both ways along its normal, length
//!    `ray_length_factor × ENS0` (default 0.3125, the paper's figure). ENS0 is the **target's**:
//!    the rays run in the target's space, where the deformed source lives. Rays use a parry3d
//!    BVH of the target built once (per lip region, see step 4: an upper-lip source vertex
//!    never takes a lower-lip target point). A hit counts only on a target triangle facing
//!    the same side as the ray's vertex normal (normals under 90° apart) (the nearest surface along a normal is otherwise
//!    often another layer: a lip's inside, the mouth, an eyelid's other side). The
//!    `worst_per_round` (125) hits with the largest
//!    `e_i = ‖u_i − f(p_i)‖` above `min_error_factor × ENS0` are inserted — in mirror
//!    pairs: a movable vertex whose mirror image across the source's plane `x = mean x` is
//!    also a movable vertex brings it along, so a symmetric face keeps a symmetric fit where
//!    a cut of the ranking would split pairs whose errors differ by rounding — (or, if the source
//!    vertex — or one coincident with it — is already a refinement or contour centre, its
//!    target is updated; feature-point centres are never overridden) and `f` is refitted. The
//!    loop ends when a round inserts nothing new, after `max_iterations` rounds, or if a
//!    refit fails (the last good `f` is kept, with a warning).
//! 4. **`map`** — a target feature-point vertex whose point is a source vertex too is bound
//!    to that vertex (weight 1): the same anatomical point, whatever rays find near it. Every
//!    other target vertex casts a ray both ways along its normal (same length) onto the
//!    deformed neutral source, taking the nearest hit on a source triangle that faces the same
//!    side as the target normal (rays go on through other layers). If both miss (rays through
//!    vertices or edges can slip between triangles in a BVH), the closest point on the
//!    deformed source is used instead when it lies within the ray length
//!    (`ray_misses_fallback` counts these); farther away the source has no surface there (a
//!    face mask cloned onto a whole head) and the vertex gets no motion
//!    (`unbound_vertices`). The hit gets barycentric coordinates in its source triangle. **Lip separation**:
//!    a target vertex in the upper-lip region only sees source triangles that have no
//!    lower-lip vertex, and vice versa (regions from the inner-lip contours; see `regions.rs`).
//! 5. **`deform`** — per source motion (in parallel with rayon): for each moved vertex `p`
//!    with offset `d` that some target vertex is bound to, `g(p) = f(p + d) − f(p)` (computed
//!    without cancelling `p`, `f(p) − p` once per vertex for all motions); each target
//!    vertex bound to a triangle that has a moved vertex gets `Σ b_k g(p_k)`, i.e. the paper's
//!    barycentric position in the deformed displaced triangle minus its neutral position.
//!    A target feature-point vertex bound in step 4 moves in the direction of its source
//!    point's displacement `d` (with the length of `g`): a FAP moves its feature point in the
//!    same direction on every face, and the Jacobian of `f` would turn it (on alma → bruno
//!    by up to 7 % of the motion). Offsets shorter than `min_offset_factor × ENS0` (target) are dropped.
//!
//! Target vertices that belong to no triangle (Candide-3 has four unused duplicates of
//! midline vertices) are not part of the surface and get no motion.
//!
//! # What it does not do, and what that costs
//!
//! There is no FAPU normalisation: a displacement is carried through the local Jacobian of
//! `f`, so motions scale with the local shape ratio between the faces, not with the FAP unit
//! ratio. Measured on Candide-3 → Candide-3 reshaped (mouth width 0.5, eye width 0.3, head
//! height 0.2), against the exact FAP motion of the target (mean relative displacement
//! error): 13.4 % (12.5 % without refinement); the MW-unit lip-corner FAPs 6/7 are off by
//! 30 %, the MNS-unit outer-lip FAPs 55–58 by 0 %. Refinement makes the fit stick to the
//! target surface but the normal-ray correspondences do not control tangential sliding, so
//! against FAP ground truth it *raises* the error on denser meshes (subdivided 2× → 3×:
//! 12.5 % with no round, 20.6 % after 6). Self-cloning is exact (formula (1): 4e-9 %).
//! Rigid parts (eyes, teeth, tongue, head) are out of scope, as in the rest of [`super`].
//!
//! `max_iterations` defaults to 0 (the paper reports 3–9 rounds). On a real head the
//! refinement's correspondences are normal projections, not anatomical correspondences: each
//! pulls `f` along the surface, and hundreds of close centres with small radii wrinkle its
//! Jacobian, which carries the motions. ICT head → smoothly reshaped ICT head against its
//! true FAT (per-FAP median / worst): 5.6 % / 14 % with no round, about 40 % / 100 % after 6
//! (normal-facing hits; 78 % / 175 % before), and every round adds up to 125 centres to a
//! dense O(n³) solve.
//!
//! # Default mode: what whole faces use, and how it differs from the paper
//!
//! [`RbfOptions::default`] is the paper (plus the documented fixes above). Whole faces clone
//! with [`face_rbf_options`](crate::clone::face::face_rbf_options), which changes two steps
//! and keeps the rest (contours, the fitted morph, lip regions, feature-point binding):
//!
//! - **Step 4 binds by dense correspondence** ([`RbfCorrespondence::Dense`]): each target
//!   vertex takes its place on the source from `fit`'s registration ([`crate::clone::fit`]:
//!   side-restricted closest points, or vertex to vertex for one topology) instead of a
//!   normal ray onto the morphed source. The paper's morph is fitted to a few dozen feature
//!   points and contour points; between them rays land wherever the morph happens to put the
//!   source, and refinement rounds made that worse (above). The registration is the dense
//!   correspondence the paper lacks.
//! - **Step 5 carries displacements** ([`RbfTransport::Displacement`]): a source motion `d`
//!   is interpolated as it is, in the face frame, and the pipeline's FAPU rescale
//!   (`rbf_fapu_rescale`, on by default) scales it to the target's FAP units. The paper's
//!   `f(p + d) − f(p)` turns and stretches every motion with the local shape difference
//!   between the heads; MPEG-4 defines a FAP along the face's axes in the face's own units,
//!   and real heads of one rig (ICT-FaceKit identities) move exactly so.
//!
//! Measured on ICT identity heads against their true FATs (`tests/clone_ict_identities.rs`,
//! per-case median over 14 FAPs): the paper's rays and transport 8.7–9.8 % (with 3
//! refinement rounds and no rescale, the paper as printed, 29–34 %); the default mode
//! 4.4–5.0 %, the same as `fit`'s: with both changes the morph `f` no longer moves anything
//! (it is still fitted, and used by the paper's mode), so the default mode is `fit`'s
//! correspondence and transfer with rbf's contours, feature-point binding and FAPU rescale.

mod contours;
mod interp;
mod mesh;
mod regions;
#[cfg(test)]
mod tests;

use std::collections::{BTreeMap, HashMap};
use std::time::Instant;

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::{CloneSurface, StepTimings, SurfaceCloneResult, SurfaceMotion};
use crate::clone::{CloneError, RbfFitError};
use crate::error::{Diagnostic, Result};
use crate::mesh::geometry::vertex_normals;
use crate::mesh::spatial::VertexIndex;
use crate::spec::FeaturePointId;

use interp::Multiquadric;
use mesh::{
    adjacency, barycentric, coincidence_classes, triangle_normals, RegionBvh, VertexTriangles,
};
use regions::{Region, TriRegion};

/// Settings of [`clone_rbf`].
#[derive(Clone, Debug, PartialEq)]
pub struct RbfOptions {
    /// Ray length for refinement and mapping, in units of the target's ENS0 (paper: 0.3125).
    pub ray_length_factor: f64,
    /// Correspondences added per refinement round: the worst-fitting movable vertices
    /// (paper: 125).
    pub worst_per_round: usize,
    /// Cap on refinement rounds (default 0: refinement raises the error against FAP ground
    /// truth, see the module docs).
    pub max_iterations: usize,
    /// Fit errors below this many target ENS0 are not worth a new correspondence.
    pub min_error_factor: f64,
    /// Target offsets shorter than this many target ENS0 are left out of the output.
    pub min_offset_factor: f64,
    /// Extract eye and lip contours (step 1) and add them to the correspondences.
    pub contours: bool,
    /// Keep upper- and lower-lip vertices from mapping onto the other lip.
    pub lip_separation: bool,
    /// How target vertices are bound to the source (step 4; default the paper's rays).
    pub correspondence: RbfCorrespondence,
    /// How a source motion is carried to the target (step 5; default the paper's).
    pub transport: RbfTransport,
}

/// How step 5 carries a source vertex's displacement `d` at `p`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RbfTransport {
    /// The paper's: `f(p + d) − f(p)`, the displacement through the volume morph.
    #[default]
    Morph,
    /// `d` itself, in the face frame (the whole-face pipeline scales it to the target's FAP
    /// units): FAPs move along the face's axes on every face (module docs, "Default mode").
    Displacement,
}

/// How step 4 binds each target vertex to a place on the source.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RbfCorrespondence {
    /// The paper's: a ray along the target vertex's normal onto the morphed source.
    #[default]
    Rays,
    /// `fit`'s dense correspondence ([`crate::clone::fit`], default settings): the target
    /// vertex's closest point on the source registered onto the target (module docs,
    /// "Default mode").
    Dense,
}

impl Default for RbfOptions {
    fn default() -> Self {
        RbfOptions {
            ray_length_factor: 0.3125,
            worst_per_round: 125,
            max_iterations: 0,
            min_error_factor: 1e-4,
            min_offset_factor: 1e-6,
            contours: true,
            lip_separation: true,
            correspondence: RbfCorrespondence::Rays,
            transport: RbfTransport::Morph,
        }
    }
}

/// A ray hit counts only on a surface facing the same side as the ray's own surface (normals
/// less than 90° apart): the nearest hit along a normal is otherwise often another layer —
/// the inside of a lip, the mouth or an eyelid's other side — whose pull folds the volume
/// morph. (A tighter cone rejects a vertex's own triangles at sharp creases.)
const MIN_NORMAL_COSINE: f32 = 0.0;

/// Feature points the paper leaves out of the correspondences: ears (10), tongue (6), teeth
/// (9.8–9.11) and the top of the head (11.5).
fn excluded_fp(id: FeaturePointId) -> bool {
    matches!(id.group(), 10 | 6)
        || (id.group() == 9 && (8..=11).contains(&id.index()))
        || (id.group() == 11 && id.index() == 5)
}

/// Where a target vertex lies on the source: the source vertices, their barycentric weights,
/// and whether the closest point stood in for a missed ray.
type Binding = ([u32; 3], [f32; 3], bool);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    FeaturePoint,
    Contour,
    Refined,
}

/// Correspondences keyed by the source vertex's coincidence class, so coincident source
/// points always share one centre.
#[derive(Default)]
struct Correspondences {
    by_class: HashMap<u32, usize>,
    /// `(source point, target point, how many were averaged, kind)`.
    pairs: Vec<(Vec3, Vec3, u32, Kind)>,
}

impl Correspondences {
    /// Adds a feature-point or contour pair; coincident ones are averaged. Returns the
    /// disagreement distance when a pair was merged into an existing one of the same kind.
    fn add_mean(&mut self, class: u32, p: Vec3, u: Vec3, kind: Kind) -> Option<f32> {
        match self.by_class.get(&class) {
            Some(&i) => {
                let e = &mut self.pairs[i];
                if e.3 == Kind::FeaturePoint && kind != Kind::FeaturePoint {
                    return None;
                }
                let gap = e.1.distance(u);
                let n = e.2 as f32;
                e.1 = (e.1 * n + u) / (n + 1.0);
                e.2 += 1;
                Some(gap)
            }
            None => {
                self.by_class.insert(class, self.pairs.len());
                self.pairs.push((p, u, 1, kind));
                None
            }
        }
    }

    /// Inserts a refinement pair or updates the target of an existing non-feature-point
    /// pair. Returns whether a new centre was inserted.
    fn refine(&mut self, class: u32, p: Vec3, u: Vec3) -> bool {
        match self.by_class.get(&class) {
            Some(&i) => {
                if self.pairs[i].3 != Kind::FeaturePoint {
                    self.pairs[i].1 = u;
                }
                false
            }
            None => {
                self.by_class.insert(class, self.pairs.len());
                self.pairs.push((p, u, 1, Kind::Refined));
                true
            }
        }
    }

    fn fit(&self) -> Result<Multiquadric, RbfFitError> {
        let pairs: Vec<(Vec3, Vec3)> = self.pairs.iter().map(|e| (e.0, e.1)).collect();
        Multiquadric::fit(&pairs)
    }
}

/// The mirror image of each movable vertex across the plane `x = mean x` of the source, when
/// a vertex lies there (within `tol`): on a mirror-symmetric source every movable vertex
/// has one. Used to pick refinement centres in mirror pairs.
fn mirror_partners(positions: &[Vec3], movable: &[u32], tol: f32) -> HashMap<u32, u32> {
    if positions.is_empty() {
        return HashMap::new();
    }
    let cx = positions.iter().map(|p| f64::from(p.x)).sum::<f64>() / positions.len() as f64;
    let index = VertexIndex::new(positions);
    movable
        .par_iter()
        .filter_map(|&v| {
            let p = positions[v as usize];
            let m = Vec3::new((2.0 * cx - f64::from(p.x)) as f32, p.y, p.z);
            let (w, d) = index.nearest_vertex(m)?;
            (d <= tol && w != v).then_some((v, w))
        })
        .collect()
}

/// The `count` worst hits (`hits` sorted worst first), taken in mirror pairs: a vertex's
/// mirror partner, if it has a hit, comes in with it (so a symmetric face gets symmetric
/// centres; cutting the ranking at `count` would otherwise split pairs whose errors differ
/// by rounding). The result may exceed `count` by one to complete the last pair.
fn worst_in_mirror_pairs(
    hits: &[(u32, Vec3, f32)],
    mirror: &HashMap<u32, u32>,
    count: usize,
) -> Vec<(u32, Vec3, f32)> {
    let at: HashMap<u32, usize> = hits.iter().enumerate().map(|(i, h)| (h.0, i)).collect();
    let mut taken = vec![false; hits.len()];
    let mut out = Vec::with_capacity(count + 1);
    for i in 0..hits.len() {
        if out.len() >= count {
            break;
        }
        if taken[i] {
            continue;
        }
        taken[i] = true;
        out.push(hits[i]);
        if let Some(&j) = mirror.get(&hits[i].0).and_then(|w| at.get(w)) {
            if !taken[j] {
                taken[j] = true;
                out.push(hits[j]);
            }
        }
    }
    out
}

fn lip_regions(
    surface: &CloneSurface,
    adj: &[Vec<u32>],
    contours: &contours::Contours,
    enabled: bool,
) -> (Vec<Region>, Vec<TriRegion>) {
    match (&contours.upper_lip, &contours.lower_lip) {
        (Some(u), Some(l)) if enabled => {
            let d = &surface.fapu.distances;
            let r = regions::classify(&surface.positions, adj, u, l, d.mns0 as f32, d.mw0 as f32);
            let t = regions::triangles(&r, &surface.triangles);
            (r, t)
        }
        _ => (vec![Region::Other; surface.positions.len()], Vec::new()),
    }
}

/// Clones `motions` (morph targets on `source`) onto `target`: one output motion per input
/// motion, same key and value, with offsets on target vertices. See the module doc for the
/// steps; `timings` names them `contours`, `fit`, `refine`, `map`, `deform`, and `stats` holds
/// `iterations`, `correspondences`, `contour_correspondences`, `movable_vertices`,
/// `ray_misses_fallback`, `unbound_vertices`, `rbf_condition` (LU pivot ratio of the final system) and
/// `fit_max_error` (largest remaining refinement ray error, in target ENS0).
pub fn clone_rbf(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    opts: &RbfOptions,
) -> Result<SurfaceCloneResult> {
    source.check("source")?;
    target.check("target")?;
    source.check_motions(motions)?;
    for (name, x) in [
        ("ray_length_factor", opts.ray_length_factor),
        ("min_error_factor", opts.min_error_factor),
        ("min_offset_factor", opts.min_offset_factor),
    ] {
        if !x.is_finite() || x < 0.0 {
            return Err(CloneError::BadOption {
                method: "rbf",
                option: name,
                value: x,
            }
            .into());
        }
    }
    let mut warnings = Vec::new();
    let mut fit_warnings = Vec::new();
    let mut timings = StepTimings::default();
    let mut stats = BTreeMap::new();
    let ens_t = target.fapu.distances.ens0 as f32;
    let ray_len = opts.ray_length_factor as f32 * ens_t;

    // 1. Contours and lip regions.
    let clock = Instant::now();
    let want_contours = opts.contours || opts.lip_separation;
    let prepare = |face: &CloneSurface, name: &str| {
        let adj = adjacency(face.positions.len(), &face.triangles);
        let mut warnings = Vec::new();
        let contours = if want_contours {
            let incidence = VertexTriangles::new(face.positions.len(), &face.triangles);
            contours::extract(face, &adj, &incidence, name, &mut warnings)
        } else {
            contours::Contours::default()
        };
        let (regions, tri_regions) = lip_regions(face, &adj, &contours, opts.lip_separation);
        (contours, regions, tri_regions, warnings)
    };
    let ((s_cont, s_regions, s_tri_regions, s_warn), (t_cont, t_regions, t_tri_regions, t_warn)) =
        rayon::join(|| prepare(source, "source"), || prepare(target, "target"));
    warnings.extend(s_warn);
    warnings.extend(t_warn);
    timings.push("contours", clock.elapsed().as_secs_f64());

    // 2. Feature points, then contours.
    let clock = Instant::now();
    let (lo, hi) = source
        .positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let eps = 1e-6 * (hi - lo).length().max(f32::MIN_POSITIVE);
    let class = coincidence_classes(&source.positions, eps);
    let merge_eps = 1e-4 * ens_t;
    let mut set = Correspondences::default();
    for (&id, &sv) in &source.fp_vertices {
        if excluded_fp(id) {
            continue;
        }
        let Some(&tv) = target.fp_vertices.get(&id) else {
            continue;
        };
        let (p, u) = (source.positions[sv as usize], target.positions[tv as usize]);
        if let Some(gap) = set.add_mean(class[sv as usize], p, u, Kind::FeaturePoint) {
            if gap > merge_eps {
                warnings.push(Diagnostic::warning(format!(
                    "feature point {id} coincides with another on the source but not on the \
                     target ({gap:.3e} apart); their targets were averaged"
                )));
            }
        }
    }
    let fp_count = set.pairs.len();
    let mut f = set.fit().map_err(|source| CloneError::RbfFeaturePointFit {
        correspondences: fp_count,
        source,
    })?;
    let mut contour_pairs = 0usize;
    if opts.contours {
        let pairs = [
            (&s_cont.right_eye, &t_cont.right_eye, true),
            (&s_cont.left_eye, &t_cont.left_eye, true),
            (&s_cont.upper_lip, &t_cont.upper_lip, false),
            (&s_cont.lower_lip, &t_cont.lower_lip, false),
        ];
        let mut disagreements = 0;
        for (sc, tc, closed) in pairs {
            let (Some(sc), Some(tc)) = (sc, tc) else {
                continue;
            };
            let tpts: Vec<Vec3> = tc.iter().map(|&v| target.positions[v as usize]).collect();
            for &v in sc {
                let p = source.positions[v as usize];
                let Some(u) = contours::nearest_on_polyline(f.apply(p), &tpts, closed) else {
                    continue;
                };
                let before = set.pairs.len();
                if let Some(gap) = set.add_mean(class[v as usize], p, u, Kind::Contour) {
                    if gap > merge_eps {
                        disagreements += 1;
                    }
                }
                contour_pairs += set.pairs.len() - before;
            }
        }
        if disagreements > 0 {
            warnings.push(Diagnostic::warning(format!(
                "{disagreements} coincident source contour vertices have distinct target \
                 points (e.g. a closed source mouth on an open target); targets averaged"
            )));
        }
        if contour_pairs > 0 {
            match set.fit() {
                Ok(g) => f = g,
                Err(e) => warnings.push(Diagnostic::warning(format!(
                    "RBF refit with contour correspondences failed ({e}); using feature points only"
                ))),
            }
        }
    }
    timings.push("fit", clock.elapsed().as_secs_f64());

    // Default mode: fit's dense correspondence binds the target (step 4).
    let dense = match opts.correspondence {
        RbfCorrespondence::Rays => None,
        RbfCorrespondence::Dense => Some(
            crate::clone::fit::correspondences(
                source,
                target,
                &crate::clone::fit::FitOptions::default(),
                &mut timings,
                &mut stats,
                &mut fit_warnings,
            )?
            .0,
        ),
    };

    // 3. Iterative refinement on the movable vertices.
    let clock = Instant::now();
    let mut movable: Vec<u32> = motions
        .iter()
        .flat_map(|m| m.offsets.iter().filter(|o| o.1 != Vec3::ZERO).map(|o| o.0))
        .collect();
    movable.sort_unstable();
    movable.dedup();
    let target_bvh = RegionBvh::new(&target.positions, &target.triangles, &t_tri_regions);
    let t_tri_normals = triangle_normals(&target.positions, &target.triangles);
    let tol = opts.min_error_factor as f32 * ens_t;
    let mirror = mirror_partners(&source.positions, &movable, eps.max(1e-5 * ens_t));
    let mut iterations = 0usize;
    let mut max_error: f32 = 0.0;
    // With dense binding and no rounds, `f` binds nothing: no rays to cast.
    while dense.is_none() || opts.max_iterations > 0 {
        let deformed: Vec<Vec3> = source.positions.par_iter().map(|&p| f.apply(p)).collect();
        let normals = vertex_normals(&deformed, &source.triangles);
        let mut hits: Vec<(u32, Vec3, f32)> = movable
            .par_iter()
            .filter_map(|&v| {
                let p = deformed[v as usize];
                let n = normals[v as usize];
                let h = target_bvh.ray_both_ways_where(
                    s_regions[v as usize],
                    p,
                    n,
                    ray_len,
                    |tri| t_tri_normals[tri as usize].dot(n) >= MIN_NORMAL_COSINE,
                )?;
                Some((v, h.point, h.point.distance(p)))
            })
            .collect();
        max_error = hits.iter().map(|h| h.2).fold(0.0, f32::max);
        hits.retain(|h| h.2 > tol);
        if hits.is_empty() || iterations >= opts.max_iterations {
            break;
        }
        hits.sort_by(|a, b| b.2.total_cmp(&a.2).then(a.0.cmp(&b.0)));
        let hits = worst_in_mirror_pairs(&hits, &mirror, opts.worst_per_round.max(1));
        let mut inserted = 0;
        for &(v, u, _) in &hits {
            if set.refine(class[v as usize], source.positions[v as usize], u) {
                inserted += 1;
            }
        }
        let fitted = set.fit();
        match fitted {
            Ok(g) => f = g,
            Err(e) => {
                warnings.push(Diagnostic::warning(format!(
                    "RBF refit in refinement round {} failed ({e}); keeping the previous fit",
                    iterations + 1
                )));
                break;
            }
        }
        if inserted == 0 {
            break;
        }
        iterations += 1;
    }
    let deformed: Vec<Vec3> = source.positions.par_iter().map(|&p| f.apply(p)).collect();
    timings.push("refine", clock.elapsed().as_secs_f64());

    // 4. Bind target vertices to deformed source triangles.
    let clock = Instant::now();
    let source_bvh = RegionBvh::new(&deformed, &source.triangles, &s_tri_regions);
    // Normals from consistently wound triangles: a few flipped polygons (CANDIDE-3 has 29
    // such edges) would turn a vertex normal, and its map ray, away from its mirror image's.
    let s_tri_normals = triangle_normals(
        &deformed,
        &crate::mesh::orient::orient_outwards(&source.triangles, &deformed),
    );
    let t_normals = vertex_normals(
        &target.positions,
        &crate::mesh::orient::orient_outwards(&target.triangles, &target.positions),
    );
    // Vertices outside every triangle are not part of the surface (Candide-3 has four such
    // unused duplicates of midline vertices); they get no motion.
    let mut in_surface = vec![false; target.positions.len()];
    for t in &target.triangles {
        for &v in t {
            in_surface[v as usize] = true;
        }
    }
    // A target feature-point vertex takes its source feature point's motion: the same
    // anatomical point, whatever the rays find around it (an eyelid's ray can slip to the
    // other lid of a narrow eye).
    let mut fp_binding: HashMap<u32, (u32, [f32; 3])> = HashMap::new();
    // Target feature-point vertex → its source feature-point vertex.
    let mut fp_source: HashMap<u32, u32> = HashMap::new();
    let incident = VertexTriangles::new(source.positions.len(), &source.triangles);
    for (id, &tv) in &target.fp_vertices {
        let Some(&sv) = source.fp_vertices.get(id) else {
            continue;
        };
        if let Some(tri) = incident.around(sv).next() {
            let t = source.triangles[tri as usize];
            fp_binding.insert(tv, (tri, t.map(|v| if v == sv { 1.0 } else { 0.0 })));
            fp_source.insert(tv, sv);
        }
    }
    let rays = || -> Vec<Option<Binding>> {
        (0..target.positions.len())
            .into_par_iter()
            .map(|q| {
                if !in_surface[q] {
                    return None;
                }
                if let Some(&(tri, w)) = fp_binding.get(&(q as u32)) {
                    return Some((source.triangles[tri as usize], w, false));
                }
                let p = target.positions[q];
                let region = t_regions[q];
                let n = t_normals[q];
                let facing = |tri: u32| s_tri_normals[tri as usize].dot(n) >= MIN_NORMAL_COSINE;
                let (hit, fallback) =
                    match source_bvh.ray_both_ways_where(region, p, n, ray_len, facing) {
                        Some(h) => (h, false),
                        // Beyond the rays' reach the source has no surface here (a face mask on a
                        // whole head): no motion rather than the motion of its nearest border.
                        None => (
                            source_bvh
                                .closest(region, p)
                                .filter(|h| h.point.distance(p) <= ray_len)?,
                            true,
                        ),
                    };
                let t = source.triangles[hit.triangle as usize].map(|i| deformed[i as usize]);
                Some((
                    source.triangles[hit.triangle as usize],
                    barycentric(hit.point, t[0], t[1], t[2]),
                    fallback,
                ))
            })
            .collect()
    };
    let binding = match dense {
        None => rays(),
        Some(corr) => corr
            .into_iter()
            .enumerate()
            .map(|(q, c)| {
                if let Some(&(tri, w)) = fp_binding.get(&(q as u32)) {
                    return Some((source.triangles[tri as usize], w, false));
                }
                let c = c?;
                Some((c.vertices, c.weights.map(|w| w * c.fade), false))
            })
            .collect(),
    };
    warnings.extend(fit_warnings.drain(..).map(Diagnostic::warning));
    let fallbacks = binding.iter().flatten().filter(|b| b.2).count();
    let unbound = (0..binding.len())
        .filter(|&q| in_surface[q] && binding[q].is_none())
        .count();
    let mut bound_to: Vec<Vec<u32>> = vec![Vec::new(); source.positions.len()];
    for (q, b) in binding.iter().enumerate() {
        if let Some((tri, _, _)) = b {
            for &v in tri {
                if bound_to[v as usize].last() != Some(&(q as u32)) {
                    bound_to[v as usize].push(q as u32);
                }
            }
        }
    }
    timings.push("map", clock.elapsed().as_secs_f64());

    // 5. Deform every morph target through f and carry it over.
    let clock = Instant::now();
    let min_offset = opts.min_offset_factor as f32 * ens_t;
    // f(p) − p once per movable vertex that some target vertex is bound to; motions on
    // vertices no target vertex sees are not carried at all.
    let disp: HashMap<u32, DVec3> = movable
        .par_iter()
        .filter(|&&v| !bound_to[v as usize].is_empty())
        .map(|&v| match opts.transport {
            RbfTransport::Morph => (v, f.displacement(source.positions[v as usize].as_dvec3())),
            RbfTransport::Displacement => (v, DVec3::ZERO),
        })
        .collect();
    let fp_source_vertices: std::collections::HashSet<u32> = fp_source.values().copied().collect();
    let out: Vec<SurfaceMotion> = motions
        .par_iter()
        .map(|m| {
            let moved: HashMap<u32, Vec3> = m
                .offsets
                .par_iter()
                .filter(|o| o.1 != Vec3::ZERO)
                .filter_map(|&(v, d)| {
                    let p = source.positions[v as usize].as_dvec3();
                    if opts.transport == RbfTransport::Displacement {
                        return disp.contains_key(&v).then_some((v, d));
                    }
                    Some((v, f.moved_from(p, *disp.get(&v)?, d)))
                })
                .collect();
            let raw: HashMap<u32, Vec3> = m
                .offsets
                .iter()
                .filter(|o| fp_source_vertices.contains(&o.0))
                .copied()
                .collect();
            let mut qs: Vec<u32> = moved
                .keys()
                .flat_map(|&v| bound_to[v as usize].iter().copied())
                .collect();
            qs.sort_unstable();
            qs.dedup();
            let offsets = qs
                .into_iter()
                .filter_map(|q| {
                    // A feature point moves the way its FAP says on every face: in its source
                    // displacement's direction, not turned by the Jacobian of `f` (whose
                    // stretch still sets the length).
                    if let Some(&sv) = fp_source.get(&q) {
                        let d = raw.get(&sv).copied().unwrap_or(Vec3::ZERO);
                        let len = moved.get(&sv).map_or(0.0, |g| g.length());
                        let o = d.normalize_or_zero() * len;
                        return (o.length() > min_offset).then_some((q, o));
                    }
                    let (t, w, _) = binding[q as usize]?;
                    let o = (0..3)
                        .map(|k| moved.get(&t[k]).copied().unwrap_or(Vec3::ZERO) * w[k])
                        .sum::<Vec3>();
                    (o.length() > min_offset).then_some((q, o))
                })
                .collect();
            SurfaceMotion {
                key: m.key,
                value: m.value,
                offsets,
            }
        })
        .collect();
    timings.push("deform", clock.elapsed().as_secs_f64());
    if let Some((key, vertex)) = out.iter().find_map(|m| {
        m.offsets
            .iter()
            .find(|(_, o)| !o.is_finite())
            .map(|&(v, _)| (m.key, v))
    }) {
        return Err(CloneError::NonFiniteOutput {
            method: "rbf",
            key,
            vertex,
        }
        .into());
    }

    stats.insert("iterations".into(), iterations as f64);
    stats.insert("correspondences".into(), set.pairs.len() as f64);
    stats.insert("feature_point_correspondences".into(), fp_count as f64);
    stats.insert("contour_correspondences".into(), contour_pairs as f64);
    stats.insert("movable_vertices".into(), movable.len() as f64);
    stats.insert("ray_misses_fallback".into(), fallbacks as f64);
    stats.insert("unbound_vertices".into(), unbound as f64);
    stats.insert("rbf_condition".into(), f.pivot_ratio);
    stats.insert("rbf_centres".into(), f.len() as f64);
    stats.insert("fit_max_error".into(), (max_error / ens_t) as f64);
    Ok(SurfaceCloneResult {
        motions: out,
        timings,
        stats,
        warnings,
    })
}
