//! The sparse linear system of one registration step (faer): `(A_reg·α + D) u = b`, with
//! `A_reg` the fixed smoothness matrix of the surface and `D` a diagonal of data, landmark
//! and damping weights that changes every step. The sparsity pattern and the symbolic
//! Cholesky factorisation are built once; each step only refactors numerically, in one
//! thread ([`PAR`]), into storage kept from step to step.
//!
//! The fill-reducing ordering (faer's AMD) is applied once, to the pattern: the matrix is
//! kept in that order and factorised without a reordering ([`Ordered`]), where faer would
//! permute every step's matrix and right-hand sides again. Same factor bit for bit (the
//! same supernodes, checked when the system is built; else faer permutes as before); dense
//! CANDIDE-3 (5 993 vertices): 20.5 → 18.2 ms per factorisation and solve under load.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, Par, Side};

use crate::clone::{CloneError, FitSystemError};
use crate::error::{Error, Result};

/// The smoothness matrix (lower triangle, compressed columns) and its symbolic factorisation.
pub(crate) struct SmoothSystem {
    n: usize,
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    /// `LᵀL + μ·Lg` values, aligned with `row_idx`.
    smooth: Vec<f64>,
    symbolic: SymbolicCholesky<u32>,
    /// The ordering applied to the pattern (`None`: faer orders each factorisation itself).
    ordered: Option<Ordered>,
    /// The numeric factor and the solver's scratch, reused by every solve (allocating and
    /// touching them afresh cost about as much as a small factorisation).
    factor: Vec<f64>,
    scratch: Option<MemBuffer>,
    /// The matrix values of the last solve (kept for their storage).
    vals: Vec<f64>,
}

/// A system stored in its fill-reducing order (module docs): row `i` of the ordered system
/// is vertex `fwd[i]`, vertex `v` is row `inv[v]`.
struct Ordered {
    fwd: Vec<u32>,
    inv: Vec<u32>,
}

/// The supernodal structure of a symbolic factorisation (`None`: simplicial).
#[allow(clippy::type_complexity)]
fn supernodes(s: &SymbolicCholesky<u32>) -> Option<(&[u32], &[u32], &[u32], &[u32])> {
    match s.raw() {
        SymbolicCholeskyRaw::Supernodal(x) => Some((
            x.supernode_begin(),
            x.col_ptr_for_row_idx(),
            x.col_ptr_for_val(),
            x.row_idx(),
        )),
        SymbolicCholeskyRaw::Simplicial(_) => None,
    }
}

/// The lower-triangular pattern `(col_ptr, row_idx)` and values reordered by `inv` (vertex →
/// row), with its upper-triangular pattern for the symbolic analysis (faer reads the upper
/// triangle when it does not reorder), each column's rows sorted.
#[allow(clippy::type_complexity)]
fn reorder(
    col_ptr: &[u32],
    row_idx: &[u32],
    values: &[f64],
    inv: &[u32],
) -> ((Vec<u32>, Vec<u32>, Vec<f64>), (Vec<u32>, Vec<u32>)) {
    let n = col_ptr.len() - 1;
    let mut lower: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    let mut upper: Vec<Vec<u32>> = vec![Vec::new(); n];
    for j in 0..n {
        for s in col_ptr[j] as usize..col_ptr[j + 1] as usize {
            let (a, b) = (inv[row_idx[s] as usize], inv[j]);
            let (r, c) = (a.max(b), a.min(b));
            lower[c as usize].push((r, values[s]));
            upper[r as usize].push(c);
        }
    }
    let flatten = |cols: Vec<Vec<u32>>| {
        let mut ptr = vec![0u32];
        let mut idx = Vec::new();
        for mut c in cols {
            c.sort_unstable();
            idx.extend_from_slice(&c);
            ptr.push(idx.len() as u32);
        }
        (ptr, idx)
    };
    let mut vals = Vec::with_capacity(values.len());
    let rows: Vec<Vec<u32>> = lower
        .into_iter()
        .map(|mut c| {
            c.sort_unstable_by_key(|e| e.0);
            vals.extend(c.iter().map(|e| e.1));
            c.into_iter().map(|e| e.0).collect()
        })
        .collect();
    let (ptr, idx) = flatten(rows);
    ((ptr, idx, vals), flatten(upper))
}

/// Parallelism of the factorisation and solves: none. On a surface of a few thousand
/// vertices the supernodes are small, and faer's rayon split cost more than it saved (dense
/// CANDIDE, 5 993 vertices, 2 cores: 10 ms sequential against 13 ms in parallel per
/// factorisation, 17 against 30–57 ms with other work on the cores).
const PAR: Par = Par::Seq;

/// `(vertex, coefficient)` pairs of the uniform Laplacian row of every vertex:
/// `u_i − mean(u_j, j ∈ N(i))` (an isolated vertex has an empty row).
fn laplacian_rows(adj: &[Vec<u32>]) -> Vec<Vec<(u32, f64)>> {
    adj.iter()
        .enumerate()
        .map(|(i, nb)| {
            if nb.is_empty() {
                return Vec::new();
            }
            let w = 1.0 / nb.len() as f64;
            let mut row: Vec<(u32, f64)> = nb.iter().map(|&j| (j, -w)).collect();
            row.push((i as u32, 1.0));
            row
        })
        .collect()
}

fn fail(e: FitSystemError) -> Error {
    CloneError::FitSystem(e).into()
}

fn faer_error(step: &'static str, e: impl std::fmt::Debug) -> Error {
    fail(FitSystemError::Solver {
        step,
        details: format!("{e:?}"),
    })
}

impl SmoothSystem {
    /// The bending (`‖L u‖²`, uniform Laplacian `L`) plus `membrane` × `‖∇u‖²` (graph
    /// Laplacian) energy of a surface with vertex adjacency `adj`.
    pub fn new(adj: &[Vec<u32>], membrane: f64) -> Result<Self> {
        Self::build(adj, membrane, true)
    }

    /// [`new`](Self::new), with the ordering applied once to the pattern or (`order_once`
    /// false) by faer at every factorisation.
    fn build(adj: &[Vec<u32>], membrane: f64, order_once: bool) -> Result<Self> {
        let n = adj.len();
        if n == 0 || n >= u32::MAX as usize / 2 {
            return Err(fail(FitSystemError::Size { vertices: n }));
        }
        let rows = laplacian_rows(adj);
        // Pattern: every pair inside a closed one-ring (the two-ring), lower triangle, and
        // the diagonal.
        let mut cols: Vec<Vec<u32>> = (0..n).map(|j| vec![j as u32]).collect();
        for r in &rows {
            for &(j, _) in r {
                for &(k, _) in r {
                    if k > j {
                        cols[j as usize].push(k);
                    }
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0u32);
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len() as u32);
        }
        drop(cols);
        let mut smooth = vec![0.0; row_idx.len()];
        let slot = |col_ptr: &[u32], row_idx: &[u32], j: u32, k: u32| -> Option<usize> {
            let (a, b) = (
                col_ptr[j as usize] as usize,
                col_ptr[j as usize + 1] as usize,
            );
            row_idx[a..b].binary_search(&k).ok().map(|s| a + s)
        };
        for r in &rows {
            for &(j, cj) in r {
                for &(k, ck) in r {
                    if k >= j {
                        if let Some(s) = slot(&col_ptr, &row_idx, j, k) {
                            smooth[s] += cj * ck;
                        }
                    }
                }
            }
        }
        for (i, nb) in adj.iter().enumerate() {
            let i = i as u32;
            // Each edge once (the adjacency lists it from both ends).
            for &j in nb.iter().filter(|&&j| j > i) {
                if let Some(s) = slot(&col_ptr, &row_idx, i, j) {
                    smooth[s] -= membrane;
                }
            }
            if let Some(s) = slot(&col_ptr, &row_idx, i, i) {
                smooth[s] += membrane * nb.len() as f64;
            }
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic =
            factorize_symbolic_cholesky(sym, Side::Lower, Default::default(), Default::default())
                .map_err(|e| faer_error("symbolic factorisation", e))?;
        let mut system = SmoothSystem {
            n,
            col_ptr,
            row_idx,
            smooth,
            symbolic,
            ordered: None,
            factor: Vec::new(),
            scratch: None,
            vals: Vec::new(),
        };
        if order_once {
            system.order_once();
        }
        Ok(system)
    }

    /// Stores the system in the symbolic factorisation's own order, when an analysis of the
    /// reordered pattern without reordering finds the same supernodes (module docs).
    fn order_once(&mut self) {
        let Some(perm) = self.symbolic.perm() else {
            return;
        };
        let (fwd, inv) = perm.arrays();
        let ((col_ptr, row_idx, smooth), (up_ptr, up_idx)) =
            reorder(&self.col_ptr, &self.row_idx, &self.smooth, inv);
        let n = self.n;
        let up = SymbolicSparseColMatRef::new_checked(n, n, &up_ptr, None, &up_idx);
        let Ok(symbolic) = factorize_symbolic_cholesky(
            up,
            Side::Upper,
            SymmetricOrdering::Identity,
            Default::default(),
        ) else {
            return;
        };
        let same = supernodes(&self.symbolic).is_some()
            && supernodes(&self.symbolic) == supernodes(&symbolic)
            && symbolic.len_val() == self.symbolic.len_val();
        if !same {
            return;
        }
        self.ordered = Some(Ordered {
            fwd: fwd.to_vec(),
            inv: inv.to_vec(),
        });
        self.col_ptr = col_ptr;
        self.row_idx = row_idx;
        self.smooth = smooth;
        self.symbolic = symbolic;
    }

    /// Solves `(α·A_reg + diag(d)) u = b` for the three columns of `b` (row per vertex).
    pub fn solve(&mut self, alpha: f64, diag: &[f64], rhs: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
        let n = self.n;
        if diag.len() != n || rhs.len() != n {
            return Err(fail(FitSystemError::SizeMismatch));
        }
        let mut vals = std::mem::take(&mut self.vals);
        vals.clear();
        vals.extend(self.smooth.iter().map(|v| v * alpha));
        let row = |v: usize| self.ordered.as_ref().map_or(v, |o| o.inv[v] as usize);
        for (j, &d) in diag.iter().enumerate() {
            // The diagonal is the first entry of each column (rows ≥ column, sorted).
            vals[self.col_ptr[row(j)] as usize] += d;
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(sym, &vals);
        let par = PAR;
        if self.ordered.is_none() {
            self.factor.clear();
        }
        // (A supernodal factorisation zeroes its storage itself.)
        self.factor.resize(self.symbolic.len_val(), 0.0);
        let buffer = match &mut self.scratch {
            Some(b) => b,
            None => {
                let scratch = self
                    .symbolic
                    .factorize_numeric_llt_scratch::<f64>(par, Default::default())
                    .or(self.symbolic.solve_in_place_scratch::<f64>(3, par));
                self.scratch
                    .insert(MemBuffer::try_new(scratch).map_err(|e| faer_error("allocation", e))?)
            }
        };
        let stack = MemStack::new(buffer);
        let llt = self
            .symbolic
            .factorize_numeric_llt(
                &mut self.factor,
                mat,
                Side::Lower,
                Default::default(),
                par,
                stack,
                Default::default(),
            )
            .map_err(|e| faer_error("Cholesky factorisation", e))?;
        let vertex = |i: usize| self.ordered.as_ref().map_or(i, |o| o.fwd[i] as usize);
        let mut b = Mat::<f64>::from_fn(n, 3, |i, k| rhs[vertex(i)][k]);
        llt.solve_in_place_with_conj(Conj::No, b.as_mut(), par, stack);
        let out: Vec<[f64; 3]> = (0..n)
            .map(|v| {
                let i = row(v);
                [b[(i, 0)], b[(i, 1)], b[(i, 2)]]
            })
            .collect();
        self.vals = vals;
        if out.iter().flatten().any(|x| !x.is_finite()) {
            return Err(fail(FitSystemError::NonFinite));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chain_interpolates_its_ends() {
        // Path 0-1-2-3-4, ends held at 0 and 4 by strong diagonal weights: the middle
        // follows smoothly and symmetrically.
        let adj: Vec<Vec<u32>> = vec![vec![1], vec![0, 2], vec![1, 3], vec![2, 4], vec![3]];
        let mut s = SmoothSystem::new(&adj, 0.0).unwrap();
        let w = 1e6;
        let diag = [w, 1e-9, 1e-9, 1e-9, w];
        let mut rhs = vec![[0.0; 3]; 5];
        rhs[4] = [4.0 * w, 0.0, 0.0];
        let u = s.solve(1.0, &diag, &rhs).unwrap();
        assert!(
            u[0][0].abs() < 1e-3 && (u[4][0] - 4.0).abs() < 1e-3,
            "{u:?}"
        );
        assert!((u[2][0] - 2.0).abs() < 1e-6, "{u:?}");
        assert!(u.windows(2).all(|w| w[1][0] > w[0][0]), "{u:?}");
    }

    #[test]
    fn ordering_once_gives_the_same_bits() {
        // A triangulated 60 × 60 grid: large enough for a supernodal factorisation.
        let w = 60u32;
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); (w * w) as usize];
        let mut link = |a: u32, b: u32| {
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        };
        for y in 0..w {
            for x in 0..w {
                let v = y * w + x;
                if x + 1 < w {
                    link(v, v + 1);
                }
                if y + 1 < w {
                    link(v, v + w);
                }
                if x + 1 < w && y + 1 < w {
                    link(v, v + w + 1);
                }
            }
        }
        for a in &mut adj {
            a.sort_unstable();
        }
        let n = adj.len();
        let mut ordered = SmoothSystem::build(&adj, 0.01, true).unwrap();
        let mut plain = SmoothSystem::build(&adj, 0.01, false).unwrap();
        assert!(ordered.ordered.is_some() && plain.ordered.is_none());
        let bits = |u: Vec<[f64; 3]>| u.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (step, alpha) in [300.0, 10.0, 1.0].into_iter().enumerate() {
            let diag: Vec<f64> = (0..n)
                .map(|i| if (i * 7 + step) % 3 == 0 { 1.0 } else { 1e-6 })
                .collect();
            let rhs: Vec<[f64; 3]> = (0..n)
                .map(|i| [i as f64 * 1e-3, (i % 11) as f64, -(((i + step) % 5) as f64)])
                .collect();
            let a = ordered.solve(alpha, &diag, &rhs).unwrap();
            let b = plain.solve(alpha, &diag, &rhs).unwrap();
            assert_eq!(bits(a), bits(b), "step {step}");
        }
    }
}
