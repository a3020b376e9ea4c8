//! The `mouth` step (module docs of [`super`]): the hidden interior of the target's mouth — a
//! rig head's mouth socket, the lips' inner faces behind the contact line — moves as a
//! smooth extension of the lips' motion that fades into the jaw's motion below the lip line
//! and into stillness above it, not by the surface method's per-vertex motion.
//!
//! Why: the source's motion field there is whatever the registration lent those vertices.
//! A stylised source has no mouth socket (or a shallow one); ICT's reaches some 6 cm behind
//! the lips, where its upper and lower walls meet in a fold under a millimetre thick. The
//! vertices of that fold read unrelated source places, and a millimetre of difference turned
//! its triangles by 95–147° under the visemes (alma → ict: 24× the source's largest turn).
//!
//! # The region
//!
//! The target's hidden mouth interior (`clone/mouth_interior.rs`): in the mouth box,
//! behind the lips' front, hidden from the front and reached from the inner lip contour. A
//! face without one (CANDIDE-3) is not changed.
//!
//! # The fill
//!
//! Per cloned motion, with `m(q)` the prior — for the jaw's tables (open, thrust and shift
//! jaw, visemes, expressions) the small rigid motion `J` of the target's own cloned chin
//! (`jaw_follow`), weighted by `s(y)`, a smoothstep from 1 at `y_l − ½ MNS0` to 0 at
//! `y_l + ½ MNS0`; zero for every other table — the inside's displacement is `d = m + h`,
//! where `h` is harmonic (uniform graph Laplacian) over the inside, equal to the cloned
//! motion minus the prior on the inside's border, and zero deeper than [`DEEP`] × MNS0
//! behind the lips' front. A harmonic field has no crease, fold or spike; the prior is smooth
//! in space, so the fold's two walls (close in space) move alike. The system is factored
//! once per target (sparse Cholesky) and solved per motion.

use glam::{DVec3, Vec3};

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use super::jaw_follow::{chin_rigid, moves_jaw};
use super::SkinSurface;
use crate::clone::mouth_interior::{Extent, Mouth};
use crate::clone::SurfaceMotion;
use crate::mesh::geometry::adjacency;

/// Deeper than this behind the lips' front (MNS0) the interior takes the prior exactly.
const DEEP: f32 = 1.5;
/// Half the height (MNS0) of the band across the lip line where the jaw's share fades.
const BAND: f32 = 0.5;

/// The jaw's share at height `y` (module docs).
fn jaw_share(mouth: &Mouth, y: f64) -> f64 {
    let b = f64::from(BAND * mouth.mns);
    let t = ((f64::from(mouth.y) + b - y) / (2.0 * b)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A harmonic fill over a set of mesh vertices (uniform graph Laplacian, the vertices around
/// them given): factored once, solved for any number of fields.
pub(super) struct HarmonicFill {
    /// The unknown vertices, in order.
    free: Vec<u32>,
    /// Per free vertex, its neighbours outside the set (their values are given) and the
    /// edges' weights.
    given: Vec<Vec<(u32, f64)>>,
    llt: faer::sparse::linalg::solvers::Llt<u32, f64>,
}

impl HarmonicFill {
    /// The fill of the vertices `inside` of a mesh with vertex adjacency `adj` and vertex
    /// `positions`; `None` when none is inside or the system cannot be factored. Edges weigh
    /// by their inverse length, so the field is smooth in space, not only along the graph: a
    /// fold of sub-millimetre triangles beside centimetre ones would otherwise take steps of
    /// one edge each and crease.
    pub(super) fn new(
        adj: &[Vec<u32>],
        positions: &[Vec3],
        inside: &[bool],
    ) -> Option<HarmonicFill> {
        let n = adj.len().min(inside.len()).min(positions.len());
        let free: Vec<u32> = (0..n as u32).filter(|&v| inside[v as usize]).collect();
        if free.is_empty() {
            return None;
        }
        let mut slot = vec![u32::MAX; n];
        for (k, &v) in free.iter().enumerate() {
            slot[v as usize] = k as u32;
        }
        let length = |a: u32, b: u32| -> f64 {
            match (positions.get(a as usize), positions.get(b as usize)) {
                (Some(p), Some(q)) => f64::from(p.distance(*q)),
                _ => 0.0,
            }
        };
        // The shortest edge counted: a thousandth of the mean (coincident vertices).
        let (sum, count) = free
            .iter()
            .flat_map(|&v| adj[v as usize].iter().map(move |&w| (v, w)))
            .fold((0.0, 0usize), |(s, c), (v, w)| (s + length(v, w), c + 1));
        let floor = 1e-3 * sum / count.max(1) as f64;
        if !(floor > 0.0 && floor.is_finite()) {
            return None;
        }
        let weight = |a: u32, b: u32| 1.0 / length(a, b).max(floor);
        let mut triplets = Vec::new();
        let mut given = Vec::with_capacity(free.len());
        for (k, &v) in free.iter().enumerate() {
            let nb = &adj[v as usize];
            let mut diagonal = 0.0;
            let mut out = Vec::new();
            for &w in nb {
                let c = weight(v, w);
                diagonal += c;
                match slot.get(w as usize) {
                    Some(&sw) if sw != u32::MAX => {
                        if sw < k as u32 {
                            triplets.push(Triplet::new(k as u32, sw, -c));
                        }
                    }
                    _ => out.push((w, c)),
                }
            }
            // A tiny diagonal keeps a piece with no given neighbour solvable (it then
            // stays at zero).
            triplets.push(Triplet::new(
                k as u32,
                k as u32,
                diagonal * (1.0 + 1e-9) + 1e-12,
            ));
            given.push(out);
        }
        let m = free.len();
        let a = SparseColMat::<u32, f64>::try_new_from_triplets(m, m, &triplets).ok()?;
        let llt = a.sp_cholesky(Side::Lower).ok()?;
        Some(HarmonicFill { free, given, llt })
    }

    /// The unknown vertices.
    pub(super) fn free(&self) -> &[u32] {
        &self.free
    }

    /// The harmonic fields (`columns` of them) inside, given `value(w, c)` of column `c` at
    /// every vertex `w` around: per free vertex (in [`Self::free`] order), per column.
    pub(super) fn solve(&self, columns: usize, value: impl Fn(u32, usize) -> f64) -> Mat<f64> {
        let mut rhs = Mat::<f64>::zeros(self.free.len(), columns);
        for (k, given) in self.given.iter().enumerate() {
            for &(w, weight) in given {
                for c in 0..columns {
                    rhs[(k, c)] += weight * value(w, c);
                }
            }
        }
        self.llt.solve(&rhs)
    }
}

/// The hidden mouth interior of a target and the factored system of its fill.
pub(super) struct MouthInterior {
    mouth: Mouth,
    fill: HarmonicFill,
    /// Per surface vertex: deep inside (takes the prior).
    deep: Vec<bool>,
}

impl MouthInterior {
    /// The interior of `tsurf` (module docs), `None` when it has none.
    pub(super) fn new(tsurf: &SkinSurface) -> Option<MouthInterior> {
        let s = &tsurf.surface;
        let n = s.positions.len();
        let adj = adjacency(n, &s.triangles);
        let region = crate::clone::mouth_interior::MouthInterior::of(s, &adj, Extent::LIPS)?;
        let (mouth, reached) = (region.mouth, region.inside);
        let mut free = vec![false; n];
        let mut deep = vec![false; n];
        for (v, p) in s.positions.iter().enumerate() {
            if reached[v] {
                if p.z < mouth.z - DEEP * mouth.mns {
                    deep[v] = true;
                } else {
                    free[v] = true;
                }
            }
        }
        let fill = HarmonicFill::new(&adj, &s.positions, &free)?;
        Some(MouthInterior { mouth, fill, deep })
    }

    /// Inside vertices (free and deep).
    pub(super) fn vertices(&self) -> usize {
        self.fill.free().len() + self.deep.iter().filter(|&&d| d).count()
    }

    /// Replaces `motion`'s displacements inside the mouth by the fill (module docs).
    pub(super) fn fill(&self, tsurf: &SkinSurface, motion: &mut SurfaceMotion) {
        let s = &tsurf.surface;
        let n = s.positions.len();
        let mut d: Vec<Vec3> = vec![Vec3::ZERO; n];
        for &(v, o) in &motion.offsets {
            if let Some(x) = d.get_mut(v as usize) {
                *x = o;
            }
        }
        let rigid = if moves_jaw(motion.key) {
            chin_rigid(tsurf, motion)
        } else {
            None
        };
        let prior = |v: u32| -> DVec3 {
            match &rigid {
                Some(r) => {
                    let q = s.positions[v as usize].as_dvec3();
                    r.at(q) * jaw_share(&self.mouth, q.y)
                }
                None => DVec3::ZERO,
            }
        };
        // `h = d − prior` around the free vertices: zero at deep ones.
        let h = self.fill.solve(3, |w, c| {
            if self.deep[w as usize] {
                0.0
            } else {
                (d[w as usize].as_dvec3() - prior(w))[c]
            }
        });
        for (k, &v) in self.fill.free().iter().enumerate() {
            let o = prior(v) + DVec3::new(h[(k, 0)], h[(k, 1)], h[(k, 2)]);
            if o.is_finite() {
                d[v as usize] = o.as_vec3();
            }
        }
        for (v, _) in self.deep.iter().enumerate().filter(|(_, &x)| x) {
            let o = prior(v as u32);
            if o.is_finite() {
                d[v] = o.as_vec3();
            }
        }
        motion.offsets = d
            .iter()
            .enumerate()
            .filter(|(_, o)| **o != Vec3::ZERO)
            .map(|(v, &o)| (v as u32, o))
            .collect();
    }
}
