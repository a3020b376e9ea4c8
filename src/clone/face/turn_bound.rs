//! The `bound` step (module docs of [`super`]): after every other change to the skin's motion
//! (smoothing, the FAPU gain, the mouth fill), no target triangle may turn more than
//! `BOUND` × the source motion's largest turn (at least 1°). `smooth` works towards that
//! with uniform Laplacian steps, which cannot settle two kinds of triangle:
//!
//! - triangles much smaller than their neighbours (ICT's inner lip corners, a tenth of a
//!   millimetre wide between an upper and a lower lip that move apart): a uniform mean pulls
//!   their corners towards neighbours millimetres away, so the tiny triangle keeps a steep
//!   gradient across it;
//! - slivers (CANDIDE-3's nearly collinear triangles at the sides of the head): their height
//!   is so small that any motion short of an exactly affine one folds them, even the slight
//!   motion a brow FAP leaves on the temple.
//!
//! Per motion whose target still has a triangle above the bound: the corners of those triangles
//! and one ring around them are re-solved as a harmonic fill of the motion around them (edges
//! weighed by inverse length, so close vertices move alike whatever the mesh's scale there),
//! the rest held. Each further round, in every sliver still above the bound the corner
//! opposite the longest edge is made to *follow* that edge (its motion is the edge ends'
//! motion interpolated at its foot on the edge: a sliver then moves with its base and keeps
//! its shape, a thin triangle between two lips moves with the lip it hangs on) and the
//! region grows by one ring, up to `ROUNDS` rounds. Held, every motion as it was: the feature
//! points (compliance is measured there), the lips' slit (the surface's borders near the
//! mouth and two rings around them) and the lid margins: the slits' gaps and the lashes
//! riding on the lids must stay as cloned. Rigid parts are not on the skin surface and are not
//! touched. Each round's motion is measured over every triangle, also faded into the clone's
//! own motion over the region's outer rings, and the one turning least is kept, if it turns
//! less than the clone's own; a motion already under the bound is not changed at all.
//!
//! Before the rounds, when a triangle at the FAP's own feature point turns over the bound,
//! the point *pulls* its surroundings along: every vertex within a radius along the mesh
//! (lid margins not entered, the lips' slit entered: both lips near the point move alike)
//! moves towards the point's motion by a Wendland bump of its distance; radii of 2–16 mean
//! edges at the point are tried and the one turning least kept if it beats the clone's own.
//! A coarse target's point sampled at the peak of a dense source's motion overtakes its
//! neighbours otherwise — on the held slit no round could reach it (ICT's lip corner under
//! `stretch_r_cornerlip_o` on bruno's: 172°, bruno's own FAT 4.6°).

use std::collections::{BTreeMap, HashMap};

use glam::{Vec3, Vec3A};
use rayon::prelude::*;

use super::rescale::{bump, edge_ball, fap_fp};
use super::smooth::{dense_field, rough, sparse_offsets, touching, SmoothTopology};
use crate::clone::quality::NORMAL_TURN_FLOOR;
use crate::clone::{CloneSurface, SurfaceMotion};

/// Largest allowed target turn over the source's: the 1.5 less a margin for what the
/// later steps (rigid parts, the fold of a one-mesh head) add.
pub(super) const BOUND: f64 = 1.4;
/// Rounds at most (each makes the triangles still above the bound follow and grows the region).
const ROUNDS: usize = 4;
/// Gauss–Seidel sweeps at most per harmonic fill.
const SWEEPS: usize = 400;
/// Over-relaxation of each Gauss–Seidel step (successive over-relaxation): a plain step (1)
/// carries a change about one edge per sweep, and the fills are dozens of edges across
/// (CANDIDE-3's chin on the dense ICT head under `open_jaw`: 1 400 vertices, which settles
/// in about 50 sweeps over-relaxed).
const RELAX: f32 = 1.8;
/// A triangle whose apex (the corner opposite its longest edge) lies lower over that edge
/// than this share of its length is a sliver, whose apex follows the edge (module docs).
/// A well-shaped triangle keeps its apex in the fill: made to follow, a dense patch turning
/// as a whole (the ICT head's chin under CANDIDE-3's `open_jaw`: 1 400 triangles) flattened
/// into folds (93° → 167–174°) and its fills, over 1 000 followers, cost most of the step.
const SLIVER: f32 = 0.2;

/// A vertex that follows the edge opposite it in a triangle: its motion is the motion of the
/// edge's ends interpolated at its foot on that edge (`a`, `b`, parameter `t`).
type Follows = BTreeMap<u32, (u32, u32, f32)>;

/// A pull tried at one radius: its worst turn, the changed vertices and the moving set.
type PullTry = (f32, Vec<(u32, Vec3)>, Vec<u32>);

/// The vertex of triangle `t` opposite its longest edge, that edge's ends and the parameter
/// of the vertex's foot on it (clamped to the edge), when `t` is a sliver: the vertex's
/// height over the edge under `SLIVER` × the edge's length.
fn sliver_apex(positions: &[Vec3], t: &[u32; 3]) -> Option<(u32, (u32, u32, f32))> {
    let p = |v: u32| positions[v as usize];
    let k = (0..3)
        .max_by(|&i, &j| {
            let l = |k: usize| p(t[k]).distance_squared(p(t[(k + 1) % 3]));
            l(i).total_cmp(&l(j))
        })
        .unwrap_or(0);
    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
    let e = p(b) - p(a);
    let l2 = e.length_squared().max(f32::MIN_POSITIVE);
    let height = e.cross(p(c) - p(a)).length() / l2.sqrt();
    let s = (p(c) - p(a)).dot(e) / l2;
    (height < SLIVER * l2.sqrt()).then_some((c, (a, b, s.clamp(0.0, 1.0))))
}

/// The harmonic fill of `d` over the `region` (every other vertex held): each vertex takes
/// the inverse-length weighted mean of its neighbours, each follower (module docs) the motion
/// of its edge.
fn fill(positions: &[Vec3], adj: &[Vec<u32>], region: &[u32], follows: &Follows, d: &mut [Vec3]) {
    // The sweeps are most of the step's time: each free vertex's edges and weights are laid
    // out once in one array, and the sum of its weights taken once (in the order a sweep
    // would add them, so every sweep computes the very same values).
    let mut free: Vec<(u32, usize, f32)> = Vec::with_capacity(region.len());
    let mut edges: Vec<(u32, f32)> = Vec::new();
    for &v in region {
        if follows.contains_key(&v) || adj[v as usize].is_empty() {
            continue;
        }
        let start = edges.len();
        edges.extend(adj[v as usize].iter().map(|&w| {
            let l = positions[v as usize].distance(positions[w as usize]);
            (w, 1.0 / l.max(1e-9))
        }));
        let weight = edges[start..].iter().fold(0.0f32, |t, &(_, c)| t + c);
        free.push((v, edges.len(), weight));
    }
    let followers: Vec<(u32, (u32, u32, f32))> = follows.iter().map(|(&c, &e)| (c, e)).collect();
    let scale = region
        .iter()
        .map(|&v| d[v as usize].length())
        .fold(0.0f32, f32::max)
        .max(1e-12);
    // The sweeps run on four-lane vectors: each lane adds, multiplies and divides as the
    // three-component ones do, so the values are the same bits, reached in fewer steps.
    let mut v4: Vec<Vec3A> = d.iter().map(|&x| x.into()).collect();
    // A change measured as the three-component vectors measure it (the same bits).
    let moved = |a: Vec3A, b: Vec3A| Vec3::from(a - b).length();
    for _ in 0..SWEEPS {
        let mut change = 0.0f32;
        let mut start = 0;
        for &(v, end, weight) in &free {
            let sum = edges[start..end]
                .iter()
                .fold(Vec3A::ZERO, |s, &(w, c)| s + c * v4[w as usize]);
            start = end;
            let old = v4[v as usize];
            let value = old + RELAX * (sum / weight - old);
            change = change.max(moved(value, old));
            v4[v as usize] = value;
        }
        for &(c, (a, b, t)) in &followers {
            let value = (1.0 - t) * v4[a as usize] + t * v4[b as usize];
            change = change.max(moved(value, v4[c as usize]));
            v4[c as usize] = value;
        }
        if change < 1e-5 * scale {
            break;
        }
    }
    for v in free
        .iter()
        .map(|f| f.0)
        .chain(followers.iter().map(|f| f.0))
    {
        d[v as usize] = v4[v as usize].into();
    }
}

/// Rings over which a round's fill is faded into the clone's own motion at its rim.
const RIM: u8 = 3;

/// Per `region` vertex, its share of the fill when faded at the rim: (its hops from a vertex
/// outside the region) / (`RIM` + 1), 1 deeper in.
fn rim_shares(adj: &[Vec<u32>], region: &[u32], in_region: &[bool]) -> Vec<f32> {
    let mut hops: HashMap<u32, u8> = HashMap::new();
    let mut front: Vec<u32> = region
        .iter()
        .copied()
        .filter(|&v| adj[v as usize].iter().any(|&w| !in_region[w as usize]))
        .collect();
    for h in 1..=RIM {
        for &v in &front {
            hops.entry(v).or_insert(h);
        }
        front = front
            .iter()
            .flat_map(|&v| adj[v as usize].iter().copied())
            .filter(|&w| in_region[w as usize] && !hops.contains_key(&w))
            .collect();
    }
    region
        .iter()
        .map(|v| {
            hops.get(v)
                .map_or(1.0, |&h| f32::from(h) / f32::from(RIM + 1))
        })
        .collect()
}

/// The largest turn (cosine: smallest) over `tris` under `d`; 1 without triangles.
fn worst_cos(
    positions: &[Vec3],
    d: &[Vec3],
    triangles: &[[u32; 3]],
    tn: &[Vec3],
    tris: &[u32],
) -> f32 {
    tris.iter()
        .filter(|&&i| tn[i as usize] != Vec3::ZERO)
        .map(|&i| {
            let t = triangles[i as usize];
            let p = |k: usize| positions[t[k] as usize] + d[t[k] as usize];
            let n1 = (p(1) - p(0)).cross(p(2) - p(0));
            let l = n1.length();
            if l.is_finite() && l > 0.0 {
                tn[i as usize].dot(n1) / l
            } else {
                -1.0
            }
        })
        .fold(1.0, f32::min)
}

/// How a low-level FAP's own feature point keeps its motion when a triangle at it turns
/// over the bound: the point joins the fill, and afterwards the difference between its
/// motion and the fill's is added back as a smooth bump (Wendland's, 1 at the point) over a
/// ball as wide as the source's triangles around its own feature point. Held as one vertex
/// beside its re-solved neighbours, the point stood out as a spike: the fill of a field
/// pinned at one vertex falls off within one edge (CANDIDE-3's chin point under `open_jaw`
/// moved 21 mm, its neighbours 4 mm away 13.5 mm: 86°, 12× the source's turn), while the
/// source moves a whole coarse triangle fan with its point.
struct PointSpread {
    /// The feature point's vertex and its motion.
    vertex: u32,
    motion: Vec3,
    /// The vertices of the ball that may move (not held) and their bump weights.
    ball: Vec<(u32, f32)>,
}

impl PointSpread {
    /// The spread of the feature point `vertex` of `target` under motion `motion`, with the
    /// source's point at `source_vertex`; `None` without a usable radius.
    fn new(
        source: &CloneSurface,
        source_incident: &[Vec<u32>],
        source_vertex: u32,
        target: &CloneSurface,
        vertex: u32,
        motion: Vec3,
        fixed: &[bool],
    ) -> Option<PointSpread> {
        // The source's reach at its point: the mean length of its edges there (both faces
        // are in the aligned frame).
        let at = *source.positions.get(source_vertex as usize)?;
        let (sum, count) = source_incident
            .get(source_vertex as usize)?
            .iter()
            .flat_map(|&i| source.triangles[i as usize])
            .filter(|&w| w != source_vertex)
            .filter_map(|w| source.positions.get(w as usize))
            .fold((0.0f32, 0usize), |(s, c), p| (s + p.distance(at), c + 1));
        let radius = sum / count.max(1) as f32;
        if !(radius > 0.0 && radius.is_finite()) {
            return None;
        }
        let centre = *target.positions.get(vertex as usize)?;
        let ball = target
            .positions
            .iter()
            .enumerate()
            .filter(|&(v, p)| !fixed[v] && v as u32 != vertex && p.distance(centre) < radius)
            .map(|(v, p)| (v as u32, bump(p.distance(centre) / radius)))
            .collect();
        Some(PointSpread {
            vertex,
            motion,
            ball,
        })
    }

    /// Puts the point's motion back on `d` after a fill changed it, the difference spread
    /// over the ball; every changed vertex joins the `region`.
    fn apply(&self, d: &mut [Vec3], mut add: impl FnMut(u32)) {
        let e = self.motion - d[self.vertex as usize];
        d[self.vertex as usize] = self.motion;
        for &(v, w) in &self.ball {
            d[v as usize] += w * e;
            add(v);
        }
    }
}

/// Radii of the pull's ball (along the mesh) tried, as multiples of the mean length of the
/// target's edges at the feature point: a pull one ring wide only moves the fold one ring
/// out (ict → bruno's right lip corner: 2×, 3× and 5× leave 173°, 173°, 159°; 8× 31°).
const PULL_REACH: [f32; 6] = [2.0, 3.0, 5.0, 8.0, 12.0, 16.0];

/// The FAP's own feature point `p` pulling its surroundings along (module docs): every
/// vertex within `radius` along the mesh moves towards the point's motion by a Wendland
/// bump of its distance, 1 at the point. A coarse target's point sampled at the peak of a
/// dense source's motion (ICT's lip corner under `stretch_cornerlip_o`, 0.48 MNS0 back and
/// out) otherwise overtakes its neighbours, which read the source beside the peak: its
/// triangles fold (ict → bruno: 172°, bruno's own FAT 4.6°). `held` vertices (the lid
/// margins) are not entered. Returns the changed vertices with their new motion.
fn pull(
    positions: &[Vec3],
    adj: &[Vec<u32>],
    d: &[Vec3],
    p: u32,
    radius: f32,
    held: &[bool],
) -> Vec<(u32, Vec3)> {
    let at = d[p as usize];
    edge_ball(positions, adj, p, radius, held)
        .into_iter()
        .filter(|&(v, _)| v != p)
        .map(|(v, r)| {
            let o = d[v as usize];
            (v, o + bump(r / radius) * (at - o))
        })
        .collect()
}

/// The vertices every motion keeps (module docs): the surface's borders near the mouth with
/// two rings around them and the `held` ones (the lid margins). A motion's own feature point
/// is kept by [`bound_turns`].
fn fixed_vertices(target: &CloneSurface, adj: &[Vec<u32>], held: &[u32]) -> Vec<bool> {
    let n = target.positions.len();
    let mut fixed = vec![false; n];
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &target.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    // The lips' slit: borders near the mouth (within ¾ of the lip corners' distance of
    // their midpoint); without both corners, every border. Not the outline of a face mask,
    // whose slivers must follow their base.
    let corners = ["8.3", "8.4"].map(|id| id.parse().ok().and_then(|f| target.fp(f)));
    let near_mouth = |v: u32| match corners {
        [Some(a), Some(b)] => {
            target.positions[v as usize].distance(0.5 * (a + b)) < 0.75 * a.distance(b)
        }
        _ => true,
    };
    let border = edges
        .into_iter()
        .filter(|&(_, c)| c == 1)
        .flat_map(|((a, b), _)| [a, b])
        .filter(|&v| (v as usize) < n && near_mouth(v));
    // The lips' margins and two rings around them: the slit's gap is read off the lips there.
    let mut lips: Vec<u32> = border.collect();
    for _ in 0..2 {
        let ring: Vec<u32> = lips
            .iter()
            .flat_map(|&v| adj[v as usize].iter().copied())
            .collect();
        lips.extend(ring);
    }
    for v in held.iter().copied().chain(lips) {
        if let Some(f) = fixed.get_mut(v as usize) {
            *f = true;
        }
    }
    fixed
}

/// What every motion's rounds read: the target's tables and the vertices held for all.
struct Bounds<'a> {
    topology: &'a SmoothTopology,
    source: &'a CloneSurface,
    target: &'a CloneSurface,
    fixed: &'a [bool],
}

/// One motion's best round: its worst turn (cosine) and the values it gave its region.
struct Round {
    worst: f32,
    values: Vec<(u32, Vec3)>,
}

impl Bounds<'_> {
    /// The rounds of one motion (module docs) from the clone's field `d0`, whose triangles
    /// that can turn are `measure`; the FAP's own feature point `own` (source and target vertex)
    /// is held, or, with `spread`, spread ([`PointSpread`]) once a triangle at it is above
    /// the bound. Returns the round turning least (`None` when none turned less than `best`,
    /// the clone's own) and whether a triangle at the feature point was above the bound.
    fn rounds(
        &self,
        d0: &[Vec3],
        mut measure: Vec<u32>,
        cos_tau: f32,
        own: Option<(u32, u32)>,
        spread_point: bool,
        best: f32,
    ) -> (Option<Round>, bool) {
        let (adj, incident, tn) = (
            &self.topology.adj,
            &self.topology.incident,
            &self.topology.tn,
        );
        let (pos, tris, fixed) = (&self.target.positions, &self.target.triangles, self.fixed);
        let n = pos.len();
        let mut d = d0.to_vec();
        let mut bad: Vec<u32> = measure
            .iter()
            .copied()
            .filter(|&i| rough(pos, &d, &tris[i as usize], tn[i as usize], cos_tau))
            .collect();
        let mut measured = vec![false; tris.len()];
        for &i in &measure {
            measured[i as usize] = true;
        }
        let mut best = (best, None::<Vec<Vec3>>);
        let mut follows = Follows::new();
        let mut in_region = vec![false; n];
        let mut region: Vec<u32> = Vec::new();
        let add = |v: u32, region: &mut Vec<u32>, in_region: &mut Vec<bool>| {
            if !in_region[v as usize] && !fixed[v as usize] {
                in_region[v as usize] = true;
                region.push(v);
            }
        };
        let own_target = own.map(|o| o.1);
        let mut spread: Option<PointSpread> = None;
        let mut at_own = false;
        for round in 0..ROUNDS {
            if round > 0 {
                for &i in &bad {
                    let Some((c, edge)) = sliver_apex(pos, &tris[i as usize]) else {
                        continue;
                    };
                    if !fixed[c as usize] && Some(c) != own_target {
                        follows.entry(c).or_insert(edge);
                    }
                }
            }
            for &i in &bad {
                for &v in &tris[i as usize] {
                    if Some(v) == own_target && spread.is_none() {
                        at_own = true;
                        if let (Some((sv, tv)), true) = (own, spread_point) {
                            spread = PointSpread::new(
                                self.source,
                                &self.topology.source_incident,
                                sv,
                                self.target,
                                tv,
                                d[tv as usize],
                                fixed,
                            );
                        }
                        if spread.is_none() {
                            continue;
                        }
                    }
                    add(v, &mut region, &mut in_region);
                }
            }
            // One ring around the whole region.
            let ring: Vec<u32> = region
                .iter()
                .flat_map(|&v| adj[v as usize].iter().copied())
                .collect();
            for w in ring {
                if Some(w) != own_target || spread.is_some() {
                    add(w, &mut region, &mut in_region);
                }
            }
            fill(pos, adj, &region, &follows, &mut d);
            if let Some(s) = &spread {
                s.apply(&mut d, |v| add(v, &mut region, &mut in_region));
            }
            for &v in &region {
                for &i in &incident[v as usize] {
                    if !std::mem::replace(&mut measured[i as usize], true) {
                        measure.push(i);
                    }
                }
            }
            let worst = worst_cos(pos, &d, tris, tn, &measure);
            if worst > best.0 {
                best = (worst, Some(region.iter().map(|&v| d[v as usize]).collect()));
            }
            // The same round faded into the clone's own motion towards the region's rim
            // (`RIM` rings): a fill meets the motion it holds at a hard rim, and where the
            // rim crosses small triangles the step there turns them (CANDIDE-3's `open_jaw`
            // on the ICT head: the chin's region reached the lower lip's inner face, whose
            // feature point 2.3 stayed outside and still: 66°).
            let faded = rim_shares(adj, &region, &in_region);
            let mut t = d.clone();
            for (&v, &w) in region.iter().zip(&faded) {
                if Some(v) != own_target {
                    t[v as usize] = d0[v as usize] + w * (d[v as usize] - d0[v as usize]);
                }
            }
            let worst = worst_cos(pos, &t, tris, tn, &measure);
            if worst > best.0 {
                best = (worst, Some(region.iter().map(|&v| t[v as usize]).collect()));
            }
            let mut seen = std::collections::HashSet::new();
            bad = region
                .iter()
                .flat_map(|&v| incident[v as usize].iter().copied())
                .filter(|&i| seen.insert(i))
                .filter(|&i| rough(pos, &d, &tris[i as usize], tn[i as usize], cos_tau))
                .collect();
            if bad.is_empty() {
                break;
            }
        }
        // The best round's region is the start of the last one's (the region only grows).
        let round = best.1.map(|values| Round {
            worst: best.0,
            values: region.iter().copied().zip(values).collect(),
        });
        (round, at_own)
    }
}

/// The bound on every cloned motion (module docs). Returns, per repaired motion
/// (`name@value`), how many target vertices were re-solved.
/// `topology` is the one both `smooth` passes read, built for `source`, the same `motions`
/// and `target`.
pub(super) fn bound_turns(
    topology: &SmoothTopology,
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    held: &[u32],
    out: &mut [SurfaceMotion],
) -> BTreeMap<String, usize> {
    let n = target.positions.len();
    let (incident, tn) = (&topology.incident, &topology.tn);
    let fixed = fixed_vertices(target, &topology.adj, held);
    let mut held_lids = vec![false; n];
    for &v in held {
        if let Some(h) = held_lids.get_mut(v as usize) {
            *h = true;
        }
    }
    let bounds = Bounds {
        topology,
        source,
        target,
        fixed: &fixed,
    };
    let pos = &target.positions;
    let tris = &target.triangles;
    let results: Vec<Option<(String, usize)>> = motions
        .par_iter()
        .zip(&topology.source_turns)
        .zip(out.par_iter_mut())
        .map(|((src, &theta), dst)| {
            if dst.offsets.is_empty() {
                return None;
            }
            let tau = BOUND * theta.max(NORMAL_TURN_FLOOR);
            if tau >= std::f64::consts::PI {
                return None;
            }
            let cos_tau = tau.cos() as f32;
            let d = dense_field(n, &dst.offsets);
            // Only triangles with a moving corner can turn: those of the clone's motion and,
            // as the fill spreads it, those around the region.
            let moving = touching(incident, &dst.offsets);
            if !moving
                .iter()
                .any(|&i| rough(pos, &d, &tris[i as usize], tn[i as usize], cos_tau))
            {
                return None;
            }
            // Each round's field is measured over every triangle that can turn; the best one
            // is kept, and only if it turns less than the clone's own.
            let own_cos = worst_cos(pos, &d, tris, tn, &moving);
            // The FAP's own feature point keeps its motion (what the FAP defines, where
            // compliance is measured); other feature points are skin like any other. Held
            // as one vertex it can stand out as a spike, spread it can bend a wide ball:
            // when a triangle at it turns over the bound and holding it leaves the motion
            // over the bound, the spread is tried too and the better kept. A held round
            // that meets the bound is kept as it is: the spread's rounds cost as much again
            // (the bound step 38 → 70–79 ms on dense CANDIDE-3 → ICT) for a motion that is
            // already smooth enough.
            let own = fap_fp(src.key, source, target)
                .map(|(fp, _)| (source.fp_vertices[&fp], target.fp_vertices[&fp]));
            // When a triangle at the point turns over the bound from the start, the held
            // and the spread rounds run side by side: one motion's rounds (CANDIDE-3's
            // `open_jaw` on the dense ICT head: 2 900 vertices re-solved, most of the step)
            // otherwise keep one core busy long after the other motions are done. The spread
            // is then judged as if it had run after the held rounds: its best round beats
            // the clone's own and the held one's, or it is dropped (its best round is the
            // same whichever of the two it was told to beat).
            // Whether a triangle at the point, among `moving`, turns over the bound under `d`.
            let rough_at_own = |moving: &[u32], d: &[Vec3]| {
                own.is_some_and(|(_, tv)| {
                    moving.iter().any(|&i| {
                        let t = &tris[i as usize];
                        t.contains(&tv) && rough(pos, d, t, tn[i as usize], cos_tau)
                    })
                })
            };
            let starts_at_own = rough_at_own(&moving, &d);
            // The point pulls its surroundings along first, when a triangle at it turns over
            // the bound ([`pull`]; the lips' slit is not held: the pull moves both lips
            // near the point alike): of the radii tried, the pull turning least is kept if
            // it turns less than the clone's own, and the rounds start from it.
            let (mut d, mut moving, mut own_cos) = (d, moving, own_cos);
            let mut pulled = 0usize;
            if let (Some((_, tv)), true) = (own, starts_at_own) {
                let at = pos[tv as usize];
                let nb = &topology.adj[tv as usize];
                let mean = nb
                    .iter()
                    .map(|&w| pos[w as usize].distance(at))
                    .sum::<f32>()
                    / nb.len().max(1) as f32;
                let mut best: Option<PullTry> = None;
                for k in PULL_REACH {
                    let changed = pull(pos, &topology.adj, &d, tv, k * mean, &held_lids);
                    let mut t = d.clone();
                    for &(v, o) in &changed {
                        t[v as usize] = o;
                    }
                    let mut m = moving.clone();
                    m.extend(
                        changed
                            .iter()
                            .flat_map(|&(v, _)| incident[v as usize].iter().copied()),
                    );
                    m.sort_unstable();
                    m.dedup();
                    let c = worst_cos(pos, &t, tris, tn, &m);
                    if c > best.as_ref().map_or(own_cos, |b| b.0) {
                        best = Some((c, changed, m));
                    }
                }
                if let Some((c, changed, m)) = best {
                    let changed_len = changed.len();
                    for (v, o) in changed {
                        d[v as usize] = o;
                    }
                    (moving, own_cos) = (m, c);
                    pulled = changed_len;
                }
            }
            let starts_at_own = rough_at_own(&moving, &d);
            let (held_round, spread_round) = if starts_at_own {
                let held_moving = moving.clone();
                let (held, spread) = rayon::join(
                    || bounds.rounds(&d, held_moving, cos_tau, own, false, own_cos),
                    || bounds.rounds(&d, moving, cos_tau, own, true, own_cos).0,
                );
                let floor = held.0.as_ref().map_or(own_cos, |r| r.worst);
                let spread = spread.filter(|r| floor < cos_tau && r.worst > floor);
                (held.0, spread)
            } else {
                let (held, at_own) =
                    bounds.rounds(&d, moving.clone(), cos_tau, own, false, own_cos);
                let floor = held.as_ref().map_or(own_cos, |r| r.worst);
                let spread = if at_own && floor < cos_tau {
                    bounds.rounds(&d, moving, cos_tau, own, true, floor).0
                } else {
                    None
                };
                (held, spread)
            };
            let kept = spread_round.or(held_round);
            if kept.is_none() && pulled == 0 {
                return None;
            }
            // The clone's own motion with the best round's region put back.
            for &(v, o) in kept.iter().flat_map(|k| &k.values) {
                d[v as usize] = o;
            }
            dst.offsets = sparse_offsets(&d);
            Some((
                format!("{}@{}", src.key.name(), src.value),
                kept.map_or(0, |k| k.values.len()).max(pulled),
            ))
        })
        .collect();
    results.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clone::quality::max_normal_turn;
    use crate::fat::TableKey;
    use crate::spec::FapId;

    fn surface(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> CloneSurface {
        CloneSurface {
            positions,
            triangles,
            fp_vertices: Default::default(),
            fp_positions: Default::default(),
            fapu: crate::clone::fixtures::unit_fapu(),
        }
    }

    /// A flat grid of `k × k` vertices (spacing 1) in the xy plane.
    fn grid(k: u32) -> CloneSurface {
        let mut positions = Vec::new();
        for j in 0..k {
            for i in 0..k {
                positions.push(Vec3::new(i as f32, j as f32, 0.0));
            }
        }
        surface(positions, crate::clone::fixtures::grid_triangles(k))
    }

    fn motion(offsets: Vec<(u32, Vec3)>) -> SurfaceMotion {
        SurfaceMotion {
            key: TableKey::LowLevel(FapId::new(3).unwrap()),
            value: 512.0,
            offsets,
        }
    }

    /// The largest turn of `m` on `s`, radians.
    fn turn(s: &CloneSurface, m: &SurfaceMotion) -> f64 {
        let d = crate::clone::quality::dense(m, s.positions.len());
        let posed: Vec<Vec3> = s.positions.iter().zip(&d).map(|(p, o)| *p + *o).collect();
        max_normal_turn(&s.positions, &posed, &s.triangles).angle
    }

    /// A gentle slope in z over the grid: every triangle turns by the same small angle.
    fn slope(s: &CloneSurface) -> Vec<(u32, Vec3)> {
        s.positions
            .iter()
            .enumerate()
            .map(|(v, p)| (v as u32, Vec3::Z * (0.05 * p.x + 0.5)))
            .collect()
    }

    /// A `k × k` grid of spacing `h` with feature point 2.1 at its centre vertex.
    fn chin_grid(k: u32, h: f32) -> CloneSurface {
        let mut s = grid(k);
        for p in &mut s.positions {
            *p *= h;
        }
        s.fp_vertices
            .insert(crate::spec::FeaturePointId::FP_2_1, (k / 2) * k + k / 2);
        s
    }

    /// A tent in z: 1 at the centre (4, 4), 0 at a distance of 4 along each axis.
    fn tent(s: &CloneSurface) -> Vec<(u32, Vec3)> {
        s.positions
            .iter()
            .enumerate()
            .map(|(v, p)| {
                let r = ((p.x - 4.0).abs()).max((p.y - 4.0).abs());
                (v as u32, Vec3::Z * (1.0 - r / 4.0).max(0.0))
            })
            .collect()
    }

    /// `bound_turns` on one motion `out[0]` of target `t` cloned from `src` on `s`: the
    /// target's largest turn before and after.
    fn bounded(
        s: &CloneSurface,
        src: &[SurfaceMotion],
        t: &CloneSurface,
        out: &mut [SurfaceMotion],
    ) -> (f64, f64) {
        let before = turn(t, &out[0]);
        bound_turns(&SmoothTopology::new(s, src, t, false), s, src, t, &[], out);
        (before, turn(t, &out[0]))
    }

    #[test]
    fn a_feature_point_standing_out_of_its_fill_is_spread_not_held() {
        // The source: a coarse 3 × 3 grid (spacing 4) whose centre, the FAP's feature
        // point, carries a tent (CANDIDE-3's chin under `open_jaw`). The target: the same
        // square as a fine grid (spacing 0.5), the tent sampled, its feature point 0.3
        // higher than the tent (the registration's exact point beside its neighbours).
        let (s, t) = (chin_grid(3, 4.0), chin_grid(17, 0.5));
        let src = vec![motion(tent(&s))];
        let fp = t.fp_vertices[&crate::spec::FeaturePointId::FP_2_1];
        let mut offsets = tent(&t);
        offsets[fp as usize].1.z += 0.3;
        let wanted = offsets[fp as usize].1;
        let mut out = vec![motion(offsets)];
        let theta = turn(&s, &src[0]);
        let (before, after) = bounded(&s, &src, &t, &mut out);
        assert!(before > BOUND * theta, "{before} {theta}");
        // Held as one vertex the point stays a spike whatever its neighbours do (the fill
        // pinned at one vertex falls off within an edge); spread, its neighbours rise with it.
        assert!(after < 0.75 * before, "{after} {before} {theta}");
        // The FAP still moves its point exactly.
        let d = crate::clone::quality::dense(&out[0], t.positions.len());
        assert_eq!(d[fp as usize], wanted);
    }

    #[test]
    fn a_feature_point_overtaking_its_neighbours_pulls_them_along() {
        // A fine grid (spacing 0.5) whose feature point sits on the border (every border is
        // held with two rings: no round reaches it, like a lip corner on the slit), moving
        // sideways by more than an edge beyond the tent its neighbours read: its triangles
        // fold. The source: a coarse grid under the tent.
        let s = chin_grid(3, 4.0);
        let mut t = chin_grid(17, 0.5);
        let fp = 8; // (4, 0): the middle of the bottom row
        t.fp_vertices
            .insert(crate::spec::FeaturePointId::FP_2_1, fp);
        let src = vec![motion(tent(&s))];
        let mut offsets = tent(&t);
        offsets[fp as usize].1 += Vec3::new(0.8, 0.0, 0.0);
        let wanted = offsets[fp as usize].1;
        let mut out = vec![motion(offsets)];
        let (before, after) = bounded(&s, &src, &t, &mut out);
        assert!(before > 2.0, "{before}");
        assert!(after < 0.5 * before, "{after} {before}");
        // The FAP still moves its point exactly; far away the motion is the clone's own.
        let d = crate::clone::quality::dense(&out[0], t.positions.len());
        assert_eq!(d[fp as usize], wanted);
        assert_eq!(d[16 * 17 + 16], tent(&t)[16 * 17 + 16].1);
    }

    #[test]
    fn only_a_sliver_has_an_apex_that_follows() {
        let p = [
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
        ];
        // Nearly collinear: vertex 2 follows the edge 0–1 at a quarter of its length.
        assert_eq!(sliver_apex(&p, &[0, 1, 2]), Some((2, (0, 1, 0.25))));
        // Well shaped (apex as high as half the longest edge): it stays in the fill.
        assert_eq!(sliver_apex(&p, &[0, 1, 3]), None);
    }

    #[test]
    fn a_fill_fades_over_its_outer_rings() {
        // A path 0–1–…–9 with the region 1..=8: vertices 0 and 9 lie outside.
        let adj: Vec<Vec<u32>> = (0..10u32)
            .map(|v| {
                [v.checked_sub(1), (v < 9).then_some(v + 1)]
                    .into_iter()
                    .flatten()
                    .collect()
            })
            .collect();
        let region: Vec<u32> = (1..=8).collect();
        let in_region: Vec<bool> = (0..10).map(|v| (1..=8).contains(&v)).collect();
        let w = rim_shares(&adj, &region, &in_region);
        // One, two and three hops from the outside on each end take ¼, ½, ¾; the middle,
        // four hops in, takes the whole fill.
        assert_eq!(w, vec![0.25, 0.5, 0.75, 1.0, 1.0, 0.75, 0.5, 0.25]);
    }

    #[test]
    fn a_motion_under_the_bound_is_untouched() {
        let s = grid(9);
        let src = vec![motion(slope(&s))];
        let mut out = src.clone();
        assert!(bound_turns(
            &SmoothTopology::new(&s, &src, &s, false),
            &s,
            &src,
            &s,
            &[],
            &mut out
        )
        .is_empty());
        assert_eq!(out, src);
    }

    #[test]
    fn a_sliver_folded_by_a_slight_motion_is_brought_under_the_bound() {
        // The source: the grid under the slope. The target: the same grid with one more
        // vertex just off the middle of an edge inside it, splitting a triangle into a sliver
        // (CANDIDE-3's nearly collinear triangles at the sides of the head).
        let s = grid(9);
        let src = vec![motion(slope(&s))];
        let mut positions = s.positions.clone();
        let (a, b) = (4 * 9 + 3, 4 * 9 + 4);
        let mid = positions.len() as u32;
        positions.push(0.5 * (positions[a as usize] + positions[b as usize]) + Vec3::Y * 1e-3);
        let mut triangles = Vec::new();
        for t in &s.triangles {
            // The triangle on the edge a–b on the new vertex's side (+y) is split at it, and
            // the sliver a–b–new fills the gap to the edge.
            let k = (0..3).find(|&k| {
                let (p, q) = (t[k], t[(k + 1) % 3]);
                ((p, q) == (a, b) || (p, q) == (b, a))
                    && s.positions[t[(k + 2) % 3] as usize].y > 4.0
            });
            match k {
                Some(k) => {
                    let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                    triangles.push([p, mid, r]);
                    triangles.push([mid, q, r]);
                    triangles.push([p, q, mid]);
                }
                None => triangles.push(*t),
            }
        }
        let t = surface(positions, triangles);
        // The clone moves the new vertex a little off the slope: the sliver folds.
        let mut offsets = slope(&t);
        let z = offsets[mid as usize].1.z;
        offsets[mid as usize].1 = Vec3::new(0.0, -0.01, z + 0.02);
        assert_eq!(t.triangles.len(), s.triangles.len() + 2);
        let mut out = vec![motion(offsets)];
        let before = turn(&t, &out[0]);
        let theta = turn(&s, &src[0]);
        assert!(
            before > 3.0 * BOUND * theta.max(NORMAL_TURN_FLOOR),
            "{before} {theta}"
        );
        let done = bound_turns(
            &SmoothTopology::new(&s, &src, &t, false),
            &s,
            &src,
            &t,
            &[],
            &mut out,
        );
        assert_eq!(done.len(), 1, "{done:?}");
        let after = turn(&t, &out[0]);
        assert!(
            after <= BOUND * theta.max(NORMAL_TURN_FLOOR),
            "{after} {theta}"
        );
        // Far from the sliver the motion is the clone's own.
        let d = crate::clone::quality::dense(&out[0], t.positions.len());
        assert_eq!(d[0], slope(&t)[0].1);
        assert_eq!(d[80], slope(&t)[80].1);
    }

    /// The sweeps as written on three-component vectors, one edge list per vertex: what
    /// `fill` computes, kept here to pin that its flat tables and four lanes change no bit.
    fn plain_fill(
        positions: &[Vec3],
        adj: &[Vec<u32>],
        region: &[u32],
        follows: &Follows,
        d: &mut [Vec3],
    ) {
        let free: Vec<(u32, Vec<(u32, f32)>)> = region
            .iter()
            .filter(|v| !follows.contains_key(v) && !adj[**v as usize].is_empty())
            .map(|&v| {
                let edges = adj[v as usize]
                    .iter()
                    .map(|&w| {
                        (
                            w,
                            1.0 / positions[v as usize]
                                .distance(positions[w as usize])
                                .max(1e-9),
                        )
                    })
                    .collect();
                (v, edges)
            })
            .collect();
        let scale = region
            .iter()
            .map(|&v| d[v as usize].length())
            .fold(0.0f32, f32::max)
            .max(1e-12);
        for _ in 0..SWEEPS {
            let mut change = 0.0f32;
            for (v, edges) in &free {
                let (sum, weight) = edges.iter().fold((Vec3::ZERO, 0.0f32), |(s, t), &(w, c)| {
                    (s + c * d[w as usize], t + c)
                });
                let old = d[*v as usize];
                let value = old + RELAX * (sum / weight - old);
                change = change.max(value.distance(old));
                d[*v as usize] = value;
            }
            for (&c, &(a, b, t)) in follows {
                let value = (1.0 - t) * d[a as usize] + t * d[b as usize];
                change = change.max(value.distance(d[c as usize]));
                d[c as usize] = value;
            }
            if change < 1e-5 * scale {
                break;
            }
        }
    }

    #[test]
    fn the_fill_computes_the_plain_sweeps_bit_for_bit() {
        // An uneven grid (edge weights all different) with a wavy motion, the middle re-solved
        // and one vertex following an edge.
        let mut s = grid(9);
        for (v, p) in s.positions.iter_mut().enumerate() {
            let f = v as f32;
            *p += Vec3::new(
                0.3 * (1.7 * f).sin(),
                0.3 * (2.3 * f).cos(),
                0.2 * (0.9 * f).sin(),
            );
        }
        let src = vec![motion(slope(&s))];
        let adj = SmoothTopology::new(&s, &src, &s, false).adj;
        let d0: Vec<Vec3> = s
            .positions
            .iter()
            .map(|p| Vec3::new((p.x * 0.7).sin(), (p.y * 1.3).cos(), p.x * p.y * 0.01))
            .collect();
        let region: Vec<u32> = (0..81u32)
            .filter(|v| (2..7).contains(&(v % 9)) && (2..7).contains(&(v / 9)))
            .collect();
        let follows = Follows::from([(40, (39, 41, 0.4))]);
        let (mut a, mut b) = (d0.clone(), d0.clone());
        fill(&s.positions, &adj, &region, &follows, &mut a);
        plain_fill(&s.positions, &adj, &region, &follows, &mut b);
        let bits = |d: &[Vec3]| -> Vec<[u32; 3]> {
            d.iter().map(|v| v.to_array().map(f32::to_bits)).collect()
        };
        assert_ne!(bits(&a), bits(&d0));
        assert_eq!(bits(&a), bits(&b));
    }
}
