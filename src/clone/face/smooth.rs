//! The `smooth` step (module docs of [`super`]): a cloned motion must not crease, fold or
//! spike where its source does not. Cloning between faces of different styles leaves such
//! defects where the target's neighbouring vertices read unrelated parts of the source motion
//! — a vertex the correspondence left still between moving ones, lips or lids read across
//! the slit at a corner, a guard repair by nearest vertex (piecewise constant) — and they
//! show as triangles whose normals turn far more than any of the source's.
//!
//! Per motion, with `θ_s` the source's largest normal turn
//! ([`crate::clone::quality::max_normal_turn`]) and `τ = 1.25 · max(θ_s, 1°)`: every target
//! triangle turning more than `τ` is *rough*. Optionally
//! ([`CloneOptions::smooth_shares`](super::CloneOptions::smooth_shares)) the same holds at a
//! quarter and a half of the motion ([`SHARES`]), against the larger of the source's turn there and that share of
//! `θ_s`: a FAT interpolates between its borders, and a lid turning about its eyeball (alma's:
//! 170° at ±1024, beyond any slack) is checked on the way — cloned onto ICT it folded at the
//! eye corners at 256 and 512 (87.6° and 167.2° under `close_t_l_eyelid`, ICT's own FAT 63.5°
//! and 97.3°; now 73.1° and 102.7°). Its corners and one ring of neighbours around
//! them are smoothed by damped Laplacian steps (`d_v ← ½ d_v + ½ · mean of its mesh
//! neighbours`, [`SWEEPS`] of them, everything else held), the rough triangles found again,
//! and so on up to [`ROUNDS`] times. Small steps take out a spike or a crease (high
//! frequencies go first) while a motion's broad peak, which has no rough triangle, keeps its
//! height; every vertex away from the defects keeps its motion exactly, and so does every
//! low-level FAP's own feature point (its motion is what the FAP defines). A smooth clone (no
//! triangle above `τ`, the usual case between faces of one style) is not changed at all. Only a
//! triangle with a moved corner can turn, so only those are measured, on the source and on the
//! target. The fill follows mesh edges, so the open lips and lids of the target (not
//! joined by edges across the slit) do not mix.

use std::collections::BTreeMap;

use glam::Vec3;
use rayon::prelude::*;

use super::lid_margin::LidMargins;
use super::rescale::fap_fp;
use crate::clone::quality::{max_normal_turn, NORMAL_TURN_FLOOR};
use crate::clone::{CloneSurface, SurfaceMotion};
use crate::fat::TableKey;
use crate::mesh::geometry::adjacency;
use crate::spec::FapId;

/// Slack over the source's largest turn before a target triangle counts as rough.
const SLACK: f64 = 1.25;
/// Smoothing rounds at most (each re-finds the rough triangles).
const ROUNDS: usize = 40;
/// Damped Laplacian sweeps per round.
const SWEEPS: usize = 2;
/// Shares of each motion, besides the whole, whose turns are checked too: a FAT
/// interpolates between its borders, and a lid turning about its eyeball folds on the way
/// (alma's closing lid turns 170° at ±1024, above any slack, but only 5–28° at 256–512).
pub(super) const SHARES: [f32; 2] = [0.25, 0.5];

/// Unit normal and doubled area of each triangle at `positions` (zero normal: degenerate or
/// out of range).
pub(super) fn normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    triangles
        .iter()
        .map(|t| {
            let [Some(&a), Some(&b), Some(&c)] = t.map(|v| positions.get(v as usize)) else {
                return Vec3::ZERO;
            };
            let n = (b - a).cross(c - a);
            let l = n.length();
            let longest = (b - a)
                .length_squared()
                .max((c - a).length_squared())
                .max((c - b).length_squared());
            if l > 1e-12 * longest && l.is_finite() {
                n / l
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Whether triangle `t` (neutral unit normal `n0`) turns by more than the angle whose cosine
/// is `cos_tau` under displacements `d`.
pub(super) fn rough(positions: &[Vec3], d: &[Vec3], t: &[u32; 3], n0: Vec3, cos_tau: f32) -> bool {
    rough_at(positions, d, 1.0, t, n0, cos_tau)
}

/// The cosine of triangle `t`'s turn from its neutral unit normal `n0` under `share` of the
/// displacements `d`; `None` when it collapses (a fold, [`max_normal_turn`]).
fn posed_cos(positions: &[Vec3], d: &[Vec3], share: f32, t: &[u32; 3], n0: Vec3) -> Option<f32> {
    let p = |k: usize| positions[t[k] as usize] + share * d[t[k] as usize];
    let n1 = (p(1) - p(0)).cross(p(2) - p(0));
    let l = n1.length();
    (l.is_finite() && l > 0.0).then(|| n0.dot(n1) / l)
}

/// [`rough`] under `share` of the displacements `d`.
fn rough_at(
    positions: &[Vec3],
    d: &[Vec3],
    share: f32,
    t: &[u32; 3],
    n0: Vec3,
    cos_tau: f32,
) -> bool {
    if n0 == Vec3::ZERO {
        return false;
    }
    posed_cos(positions, d, share, t, n0).is_none_or(|c| c < cos_tau)
}

/// The turn of triangle `t` (neutral unit normal `n0`) under `share` of the displacements
/// `d`, over the angle whose cosine is `cos_tau` (a collapsed triangle: a half turn).
fn turn_ratio(
    positions: &[Vec3],
    d: &[Vec3],
    share: f32,
    t: &[u32; 3],
    n0: Vec3,
    cos_tau: f32,
) -> f32 {
    if n0 == Vec3::ZERO {
        return 0.0;
    }
    let angle = posed_cos(positions, d, share, t, n0)
        .map_or(std::f32::consts::PI, |c| c.clamp(-1.0, 1.0).acos());
    angle / cos_tau.clamp(-1.0, 1.0).acos().max(1e-6)
}

/// The triangles using each of `n` vertices.
pub(super) fn incident_triangles(n: usize, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (i, t) in triangles.iter().enumerate() {
        for &v in t {
            if let Some(l) = incident.get_mut(v as usize) {
                l.push(i as u32);
            }
        }
    }
    incident
}

/// A motion's sparse `offsets` as a field over `n` vertices, zero elsewhere (offsets of
/// vertices past `n` are ignored).
pub(super) fn dense_field(n: usize, offsets: &[(u32, Vec3)]) -> Vec<Vec3> {
    let mut d = vec![Vec3::ZERO; n];
    for &(v, o) in offsets {
        if let Some(s) = d.get_mut(v as usize) {
            *s = o;
        }
    }
    d
}

/// The non-zero, finite entries of a field, as a motion's sparse offsets.
pub(super) fn sparse_offsets(d: &[Vec3]) -> Vec<(u32, Vec3)> {
    d.iter()
        .enumerate()
        .filter(|(_, o)| **o != Vec3::ZERO && o.is_finite())
        .map(|(v, &o)| (v as u32, o))
        .collect()
}

/// The triangles (each once, ascending) with a corner among the `offsets`' vertices: the
/// only ones a motion can turn, so the only ones its checks need to look at.
pub(super) fn touching(incident: &[Vec<u32>], offsets: &[(u32, Vec3)]) -> Vec<u32> {
    let mut tris: Vec<u32> = offsets
        .iter()
        .filter_map(|&(v, _)| incident.get(v as usize))
        .flatten()
        .copied()
        .collect();
    // Many motions move most of a large mesh: marking is cheaper than sorting there.
    let max = tris.iter().copied().max().unwrap_or(0) as usize;
    if tris.len() > 64 && max < 8 * tris.len() {
        let mut seen = vec![false; max + 1];
        for &t in &tris {
            seen[t as usize] = true;
        }
        tris.clear();
        tris.extend((0..=max as u32).filter(|&t| seen[t as usize]));
        return tris;
    }
    tris.sort_unstable();
    tris.dedup();
    tris
}

/// What `smooth_motions` reads of the two surfaces' neutral shapes and of the source
/// motions, built once for both passes (before and after the gain): the same surfaces and
/// source motions give the same tables.
pub(super) struct SmoothTopology {
    /// Target vertex adjacency.
    pub(super) adj: Vec<Vec<u32>>,
    /// Target triangles of each target vertex.
    pub(super) incident: Vec<Vec<u32>>,
    /// Source triangles of each source vertex.
    pub(super) source_incident: Vec<Vec<u32>>,
    /// Target triangles' neutral unit normals.
    pub(super) tn: Vec<Vec3>,
    /// The largest normal turn of each source motion (`source_turn`), in the order of the
    /// motions both passes get.
    pub(super) source_turns: Vec<f64>,
    /// The same at each of the [`SHARES`] of each source motion (empty unless built
    /// `with_shares`).
    pub(super) share_turns: Vec<[f64; SHARES.len()]>,
    /// Per lid FAP, the middle of its lid's margin on the target
    /// ([`LidMargins::middle`]), held with the FAP's own feature point when the shares are
    /// checked (empty until [`Self::with_lid_middles`]).
    pub(super) lid_middles: Vec<(TableKey, Vec<u32>)>,
}

impl SmoothTopology {
    /// The tables of `source` and `target`, and the turns of the source `motions` (also at
    /// [`SHARES`] of them if `with_shares`: two more passes over every motion, only for
    /// [`CloneOptions::smooth_shares`](super::CloneOptions::smooth_shares)).
    pub(super) fn new(
        source: &CloneSurface,
        motions: &[SurfaceMotion],
        target: &CloneSurface,
        with_shares: bool,
    ) -> Self {
        let n = target.positions.len();
        let source_incident = incident_triangles(source.positions.len(), &source.triangles);
        let source_turns = motions
            .par_iter()
            .map(|m| source_turn(source, &source_incident, m, 1.0))
            .collect();
        let share_turns = if with_shares {
            motions
                .par_iter()
                .map(|m| {
                    if on_the_way(m.key) {
                        SHARES.map(|s| source_turn(source, &source_incident, m, s))
                    } else {
                        [0.0; SHARES.len()]
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        SmoothTopology {
            adj: adjacency(n, &target.triangles),
            incident: incident_triangles(n, &target.triangles),
            source_incident,
            tn: normals(&target.positions, &target.triangles),
            source_turns,
            share_turns,
            lid_middles: Vec::new(),
        }
    }

    /// The same holding the middles of the target's lid margins (`margins`) under their lid
    /// FAPs (19–22) when the shares are checked: smoothing a fold at an eye corner at a
    /// quarter of the motion otherwise drew the margin's middle up against its held lid
    /// point (alma → ICT's lashes, riding the margin, followed 75 % of the lid point).
    pub(super) fn with_lid_middles(mut self, margins: &LidMargins) -> Self {
        self.lid_middles = [
            (19, true, true),
            (20, false, true),
            (21, true, false),
            (22, false, false),
        ]
        .into_iter()
        .filter_map(|(fap, left, upper)| {
            let key = TableKey::LowLevel(FapId::new(fap)?);
            let middle = margins.middle(left, upper);
            (!middle.is_empty()).then_some((key, middle))
        })
        .collect();
        self
    }
}

/// Whether the turns of a motion of `key` are checked at [`SHARES`] of it too (with
/// [`CloneOptions::smooth_shares`](super::CloneOptions::smooth_shares)): the lid FAPs (19–22)
/// alone, the motions that turn a lid about its eyeball between borders. On other FAPs the
/// shares smoothed motions that were right: ICT's identity head +2.5/−3, cloned vertex to
/// vertex, `stretch_r_cornerlip` 0.00 → 0.32 % off at ICT's tiny lip-corner triangles.
fn on_the_way(key: TableKey) -> bool {
    matches!(key, TableKey::LowLevel(f) if (19..=22).contains(&f.number()))
}

/// The largest normal turn of source motion `src` at `share` of it ([`max_normal_turn`],
/// radians).
fn source_turn(
    source: &CloneSurface,
    source_incident: &[Vec<u32>],
    src: &SurfaceMotion,
    share: f32,
) -> f64 {
    let mut sd = source.positions.clone();
    for &(v, o) in &src.offsets {
        if let Some(p) = sd.get_mut(v as usize) {
            *p += share * o;
        }
    }
    // Only a triangle with a moved corner turns.
    let moved: Vec<[u32; 3]> = touching(source_incident, &src.offsets)
        .into_iter()
        .map(|i| source.triangles[i as usize])
        .collect();
    max_normal_turn(&source.positions, &sd, &moved).angle
}

/// The smoothing of every cloned motion (module docs), on the `topology` of `source` and
/// `target`; `with_shares`: the turns at [`SHARES`] of each motion are checked too. Returns, per smoothed motion (`name@value`), how many target vertices were
/// re-solved.
pub(super) fn smooth_motions(
    topology: &SmoothTopology,
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    with_shares: bool,
    out: &mut [SurfaceMotion],
) -> BTreeMap<String, usize> {
    let n = target.positions.len();
    let SmoothTopology {
        adj,
        incident,
        source_incident,
        tn,
        source_turns,
        share_turns,
        lid_middles,
    } = topology;
    let results: Vec<Option<(String, usize)>> = motions
        .par_iter()
        .zip(out.par_iter_mut())
        .enumerate()
        .map(|(k, (src, dst))| {
            if dst.offsets.is_empty() {
                return None;
            }
            // The shares only under the lid FAPs (`on_the_way`).
            let with_shares = with_shares && on_the_way(src.key);
            let theta = source_turns
                .get(k)
                .copied()
                .unwrap_or_else(|| source_turn(source, source_incident, src, 1.0));
            let shares = if with_shares {
                share_turns
                    .get(k)
                    .copied()
                    .unwrap_or_else(|| SHARES.map(|s| source_turn(source, source_incident, src, s)))
            } else {
                [0.0; SHARES.len()]
            };
            // Each share of the motion against the source's turn at that share, or the
            // share of its whole turn if more: a triangle displaced straight towards a
            // rigid turn by θ turns at most share × θ up to half way (alma's lid: 5° at a
            // quarter of its 170°), and a target's triangles may do what the source's
            // largest turn does. A share whose slack reaches a half turn checks nothing.
            let checks: Vec<(f32, f32)> = std::iter::once((1.0, theta))
                .chain(
                    SHARES
                        .into_iter()
                        .zip(shares)
                        .filter(|_| with_shares)
                        .map(|(s, th)| (s, th.max(s as f64 * theta))),
                )
                .map(|(s, th)| (s, SLACK * th.max(NORMAL_TURN_FLOOR)))
                .filter(|&(_, tau)| tau < std::f64::consts::PI)
                .map(|(s, tau)| (s, tau.cos() as f32))
                .collect();
            if checks.is_empty() {
                return None;
            }
            let mut d = dense_field(n, &dst.offsets);
            let pos = &target.positions;
            let tris = &target.triangles;
            let is_rough = |d: &[Vec3], i: u32| {
                let (t, n0) = (&tris[i as usize], tn[i as usize]);
                checks.iter().any(|&(s, c)| rough_at(pos, d, s, t, n0, c))
            };
            let mut bad: Vec<u32> = touching(incident, &dst.offsets)
                .into_iter()
                .filter(|&i| is_rough(&d, i))
                .collect();
            if bad.is_empty() {
                return None;
            }
            // A FAP's own feature point keeps its motion: it is what the FAP defines.
            let mut pinned = vec![false; n];
            if let Some((fp, _)) = fap_fp(src.key, source, target) {
                if let Some(p) = pinned.get_mut(target.fp_vertices[&fp] as usize) {
                    *p = true;
                }
            }
            // So does the middle of a lid FAP's margin when the shares are checked
            // ([`SmoothTopology::with_lid_middles`]).
            let mut held_middle = false;
            if with_shares {
                for (_, middle) in lid_middles.iter().filter(|m| m.0 == src.key) {
                    held_middle = true;
                    for &v in middle {
                        if let Some(p) = pinned.get_mut(v as usize) {
                            *p = true;
                        }
                    }
                }
            }
            // The worst turn over the checks, against each check's limit.
            let worst = |d: &[Vec3], offsets: &[(u32, Vec3)]| -> f32 {
                touching(incident, offsets)
                    .into_iter()
                    .map(|i| {
                        let (t, n0) = (&tris[i as usize], tn[i as usize]);
                        checks
                            .iter()
                            .map(|&(s, c)| turn_ratio(pos, d, s, t, n0, c))
                            .fold(0.0, f32::max)
                    })
                    .fold(0.0, f32::max)
            };
            let before = if held_middle {
                worst(&d, &dst.offsets)
            } else {
                0.0
            };
            let mut touched = vec![false; n];
            let mut count = 0usize;
            let mut next = d.clone();
            let mut seen = vec![false; tris.len()];
            let mut listed: Vec<u32> = Vec::new();
            for _ in 0..ROUNDS {
                // The corners of the rough triangles and one ring around them.
                let mut region: Vec<u32> = Vec::new();
                let mut marked = vec![false; n];
                for &i in &bad {
                    for &v in &tris[i as usize] {
                        for w in std::iter::once(v).chain(adj[v as usize].iter().copied()) {
                            if !marked[w as usize] && !pinned[w as usize] {
                                marked[w as usize] = true;
                                region.push(w);
                            }
                        }
                    }
                }
                for _ in 0..SWEEPS {
                    for &v in &region {
                        let nb = &adj[v as usize];
                        if !nb.is_empty() {
                            let mean =
                                nb.iter().map(|&w| d[w as usize]).sum::<Vec3>() / nb.len() as f32;
                            next[v as usize] = 0.5 * (d[v as usize] + mean);
                        }
                    }
                    for &v in &region {
                        d[v as usize] = next[v as usize];
                    }
                }
                for &v in &region {
                    if !touched[v as usize] {
                        touched[v as usize] = true;
                        count += 1;
                    }
                }
                // Each triangle around the region once, in order of first sight (a mark per
                // triangle, cleared after: hashing them cost more than the checks).
                listed.clear();
                for &v in &region {
                    for &i in &incident[v as usize] {
                        if !seen[i as usize] {
                            seen[i as usize] = true;
                            listed.push(i);
                        }
                    }
                }
                for &i in &listed {
                    seen[i as usize] = false;
                }
                bad = listed
                    .iter()
                    .copied()
                    .filter(|&i| is_rough(&d, i))
                    .collect();
                if bad.is_empty() {
                    break;
                }
            }
            let smoothed = sparse_offsets(&d);
            // With a lid's middle held the smoothing can fold the lid next to it (ICT's
            // `close_t_l_eyelid` onto alma: 31° → 178°): then it is undone.
            if held_middle && worst(&d, &smoothed) > before {
                return None;
            }
            dst.offsets = smoothed;
            Some((format!("{}@{}", src.key.name(), src.value), count))
        })
        .collect();
    results.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat grid of `k × k` vertices (spacing 1) in the xy plane.
    fn grid(k: u32) -> CloneSurface {
        let mut positions = Vec::new();
        for j in 0..k {
            for i in 0..k {
                positions.push(Vec3::new(i as f32, j as f32, 0.0));
            }
        }
        let triangles = crate::clone::fixtures::grid_triangles(k);
        CloneSurface {
            positions,
            triangles,
            fp_vertices: Default::default(),
            fp_positions: Default::default(),
            fapu: crate::clone::fixtures::unit_fapu(),
        }
    }

    fn motion(offsets: Vec<(u32, Vec3)>) -> SurfaceMotion {
        SurfaceMotion {
            key: TableKey::LowLevel(FapId::new(3).unwrap()),
            value: 512.0,
            offsets,
        }
    }

    /// A smooth bump in z: `h · cos²` over a radius of 4 around the grid's centre.
    fn bump(s: &CloneSurface, h: f32) -> Vec<(u32, Vec3)> {
        let c = Vec3::new(5.0, 5.0, 0.0);
        s.positions
            .iter()
            .enumerate()
            .filter_map(|(v, p)| {
                let r = p.distance(c) / 4.0;
                (r < 1.0).then(|| {
                    let y = (r * std::f32::consts::FRAC_PI_2).cos();
                    (v as u32, Vec3::Z * h * y * y)
                })
            })
            .collect()
    }

    #[test]
    fn a_smooth_clone_is_untouched_and_a_spike_is_filled() {
        let s = grid(11);
        let src = vec![motion(bump(&s, 1.0))];
        // The same smooth motion on the target: nothing to do.
        let mut out = src.clone();
        // Built once, as the pipeline does for its two passes.
        let topology = SmoothTopology::new(&s, &src, &s, true);
        assert!(smooth_motions(&topology, &s, &src, &s, true, &mut out).is_empty());
        assert_eq!(out, src);
        // One vertex left still inside the bump (a hole in the correspondence) is a spike.
        let centre = 5 * 11 + 5;
        let mut holed = src.clone();
        holed[0].offsets.retain(|o| o.0 != centre);
        let before = max_normal_turn(
            &s.positions,
            &s.positions
                .iter()
                .enumerate()
                .map(|(v, p)| *p + crate::clone::quality::dense(&holed[0], 121)[v])
                .collect::<Vec<_>>(),
            &s.triangles,
        );
        let done = smooth_motions(&topology, &s, &src, &s, true, &mut holed);
        assert_eq!(done.len(), 1, "{done:?}");
        let d = crate::clone::quality::dense(&holed[0], 121);
        let posed: Vec<Vec3> = s.positions.iter().zip(&d).map(|(p, o)| *p + *o).collect();
        let after = max_normal_turn(&s.positions, &posed, &s.triangles);
        let source = max_normal_turn(
            &s.positions,
            &s.positions
                .iter()
                .zip(crate::clone::quality::dense(&src[0], 121))
                .map(|(p, o)| *p + o)
                .collect::<Vec<_>>(),
            &s.triangles,
        );
        assert!(before.angle > 1.5 * source.angle, "{before:?} {source:?}");
        assert!(after.angle <= SLACK * source.angle, "{after:?} {source:?}");
        // The hole is lifted towards the bump (smoothing stops once nothing is rough, here
        // at about half the height); the bump's border stays where it was.
        assert!(d[centre as usize].z > 0.4, "{:?}", d[centre as usize]);
        assert_eq!(d[0], Vec3::ZERO);
        // The pipeline runs the step again after the gain: a motion it settled is left as it is.
        let settled = holed.clone();
        assert!(smooth_motions(&topology, &s, &src, &s, true, &mut holed).is_empty());
        assert_eq!(holed, settled);
    }
}
