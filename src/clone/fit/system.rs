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
//!
//! A step at the same stiffness as the last factorisation changes only the data weights of
//! the vertices whose closest-point match came or went: [`SmoothSystem::solve_near`] then
//! runs conjugate gradients from the last step's answer, preconditioned by that factor, and
//! factorises only when they would not reach the tolerance within a few iterations. Dense
//! CANDIDE-3 onto the bundled ICT head: 4 of the 11 solves (three at `α` = 300, one at 100)
//! take 5 iterations, each a pair of triangular solves and a product (about half a
//! factorisation's time for the five); the steps after a change of `α`, and the soft ones
//! (10, 1), whose matches move most, are factorised.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
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
    /// The stiffness `α` of the matrix `factor` holds a factorisation of (`None`: none).
    factored: Option<f64>,
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
            factored: None,
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

    /// Solves `(α·A_reg + diag(d)) u = b` for the three columns of `b` (row per vertex), by
    /// a new factorisation.
    #[cfg(test)]
    pub fn solve(&mut self, alpha: f64, diag: &[f64], rhs: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
        self.check(diag, rhs)?;
        self.load(alpha, diag);
        self.solve_loaded(alpha, rhs)
    }

    /// Solves `(α·A_reg + diag(d)) u = b` (three columns, row per vertex) by conjugate
    /// gradients from `guess`, preconditioned by the last factorisation when it was made at
    /// the same `α`, if they reach a residual of `tol` × the right-hand side's within
    /// `max_iter` iterations; else by a new factorisation. Also returns the iterations run
    /// (`None`: factorised).
    pub fn solve_near(
        &mut self,
        alpha: f64,
        diag: &[f64],
        rhs: &[[f64; 3]],
        guess: &[[f64; 3]],
        tol: f64,
        max_iter: usize,
    ) -> Result<(Vec<[f64; 3]>, Option<usize>)> {
        self.check(diag, rhs)?;
        if guess.len() != self.n {
            return Err(fail(FitSystemError::SizeMismatch));
        }
        self.load(alpha, diag);
        if self.factored == Some(alpha) && max_iter > 0 {
            if let Some((x, it)) = self.pcg(rhs, guess, tol, max_iter) {
                let out = (0..self.n).map(|v| x[self.row(v)]).collect();
                return Ok((finite(out)?, Some(it)));
            }
        }
        Ok((self.solve_loaded(alpha, rhs)?, None))
    }

    /// Factorises the loaded matrix (stiffness `alpha`) and solves it for `rhs`.
    fn solve_loaded(&mut self, alpha: f64, rhs: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
        self.factorize(alpha)?;
        let n = self.n;
        let mut b = Mat::<f64>::from_fn(n, 3, |i, k| rhs[self.vertex(i)][k]);
        self.precondition(b.as_mut());
        let out: Vec<[f64; 3]> = (0..n)
            .map(|v| {
                let i = self.row(v);
                [b[(i, 0)], b[(i, 1)], b[(i, 2)]]
            })
            .collect();
        finite(out)
    }

    fn check(&self, diag: &[f64], rhs: &[[f64; 3]]) -> Result<()> {
        if diag.len() != self.n || rhs.len() != self.n {
            return Err(fail(FitSystemError::SizeMismatch));
        }
        Ok(())
    }

    /// The stored row of vertex `v`.
    fn row(&self, v: usize) -> usize {
        self.ordered.as_ref().map_or(v, |o| o.inv[v] as usize)
    }

    /// The vertex of stored row `i`.
    fn vertex(&self, i: usize) -> usize {
        self.ordered.as_ref().map_or(i, |o| o.fwd[i] as usize)
    }

    /// Sets the matrix values to `α·A_reg + diag(d)`.
    fn load(&mut self, alpha: f64, diag: &[f64]) {
        let mut vals = std::mem::take(&mut self.vals);
        vals.clear();
        vals.extend(self.smooth.iter().map(|v| v * alpha));
        for (j, &d) in diag.iter().enumerate() {
            // The diagonal is the first entry of each column (rows ≥ column, sorted).
            vals[self.col_ptr[self.row(j)] as usize] += d;
        }
        self.vals = vals;
    }

    /// Factorises the loaded matrix, of stiffness `alpha`, into the kept factor.
    fn factorize(&mut self, alpha: f64) -> Result<()> {
        self.ensure_scratch()?;
        let n = self.n;
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(sym, &self.vals);
        let par = PAR;
        self.factored = None;
        if self.ordered.is_none() {
            self.factor.clear();
        }
        // (A supernodal factorisation zeroes its storage itself.)
        self.factor.resize(self.symbolic.len_val(), 0.0);
        let Some(buffer) = self.scratch.as_mut() else {
            return Err(faer_error("allocation", "no scratch"));
        };
        let stack = MemStack::new(buffer);
        self.symbolic
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
        self.factored = Some(alpha);
        Ok(())
    }

    /// The solver's scratch, allocated at first use.
    fn ensure_scratch(&mut self) -> Result<()> {
        if self.scratch.is_none() {
            let req = self
                .symbolic
                .factorize_numeric_llt_scratch::<f64>(PAR, Default::default())
                .or(self.symbolic.solve_in_place_scratch::<f64>(3, PAR));
            self.scratch = Some(MemBuffer::try_new(req).map_err(|e| faer_error("allocation", e))?);
        }
        Ok(())
    }

    /// Solves the factorised system in place (stored rows).
    fn precondition(&mut self, b: faer::MatMut<'_, f64>) {
        let Some(buffer) = self.scratch.as_mut() else {
            return;
        };
        let llt = LltRef::new(&self.symbolic, &self.factor);
        llt.solve_in_place_with_conj(Conj::No, b, PAR, MemStack::new(buffer));
    }

    /// `y = K x` for the loaded matrix `K` (stored rows, lower triangle kept).
    fn apply(&self, x: &[[f64; 3]], y: &mut [[f64; 3]]) {
        y.iter_mut().for_each(|v| *v = [0.0; 3]);
        for j in 0..self.n {
            let (a, b) = (self.col_ptr[j] as usize, self.col_ptr[j + 1] as usize);
            let xj = x[j];
            let mut yj = [0.0; 3];
            for s in a..b {
                let i = self.row_idx[s] as usize;
                let v = self.vals[s];
                if i == j {
                    for k in 0..3 {
                        yj[k] += v * xj[k];
                    }
                } else {
                    let xi = x[i];
                    for k in 0..3 {
                        y[i][k] += v * xj[k];
                        yj[k] += v * xi[k];
                    }
                }
            }
            for k in 0..3 {
                y[j][k] += yj[k];
            }
        }
    }

    /// Preconditioned conjugate gradients on the loaded matrix (see
    /// [`solve_near`](Self::solve_near)), in stored rows; `None` when not converged.
    fn pcg(
        &mut self,
        rhs: &[[f64; 3]],
        guess: &[[f64; 3]],
        tol: f64,
        max_iter: usize,
    ) -> Option<(Vec<[f64; 3]>, usize)> {
        let n = self.n;
        let dot = |a: &[[f64; 3]], b: &[[f64; 3]]| {
            let mut s = [0.0; 3];
            for (u, v) in a.iter().zip(b) {
                for k in 0..3 {
                    s[k] += u[k] * v[k];
                }
            }
            s
        };
        let b: Vec<[f64; 3]> = (0..n).map(|i| rhs[self.vertex(i)]).collect();
        let mut x: Vec<[f64; 3]> = (0..n).map(|i| guess[self.vertex(i)]).collect();
        let bb = dot(&b, &b);
        let goal: [f64; 3] = std::array::from_fn(|k| tol * tol * bb[k].max(f64::MIN_POSITIVE));
        let mut q = vec![[0.0; 3]; n];
        self.apply(&x, &mut q);
        let mut r: Vec<[f64; 3]> = b
            .iter()
            .zip(&q)
            .map(|(b, q)| std::array::from_fn(|k| b[k] - q[k]))
            .collect();
        let mut zm = Mat::<f64>::zeros(n, 3);
        let mut z = vec![[0.0; 3]; n];
        let mut precond = |this: &mut Self, r: &[[f64; 3]], z: &mut [[f64; 3]]| {
            for (i, v) in r.iter().enumerate() {
                for k in 0..3 {
                    zm[(i, k)] = v[k];
                }
            }
            this.precondition(zm.as_mut());
            for (i, v) in z.iter_mut().enumerate() {
                *v = std::array::from_fn(|k| zm[(i, k)]);
            }
        };
        let rr0 = dot(&r, &r);
        let mut active: [bool; 3] = std::array::from_fn(|k| rr0[k] > goal[k]);
        if active == [false; 3] {
            return Some((x, 0));
        }
        precond(self, &r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        for it in 1..=max_iter {
            self.apply(&p, &mut q);
            let pq = dot(&p, &q);
            let a = step_ratio(rz, pq, active);
            for i in 0..n {
                for k in 0..3 {
                    x[i][k] += a[k] * p[i][k];
                    r[i][k] -= a[k] * q[i][k];
                }
            }
            let rr = dot(&r, &r);
            for k in 0..3 {
                active[k] = active[k] && pq[k] > 0.0 && rr[k] > goal[k];
            }
            if active == [false; 3] {
                return Some((x, it));
            }
            // Give up as soon as the mean rate so far would need more than `max_iter`
            // iterations (a factorisation is then cheaper than going on).
            let hopeless = (0..3).any(|k| {
                let rate = (rr[k] / rr0[k]).ln() / it as f64;
                active[k] && (rate >= 0.0 || (goal[k] / rr0[k]).ln() / rate > max_iter as f64)
            });
            if it == max_iter || (it >= 2 && hopeless) {
                break;
            }
            precond(self, &r, &mut z);
            let rz_new = dot(&r, &z);
            let beta = step_ratio(rz_new, rz, active);
            rz = rz_new;
            for i in 0..n {
                for k in 0..3 {
                    p[i][k] = z[i][k] + beta[k] * p[i][k];
                }
            }
        }
        None
    }
}

/// Per column `num / den` where the column still iterates and `den > 0`, else 0 (a column
/// that converged, or met no positive curvature, takes no step).
fn step_ratio(num: [f64; 3], den: [f64; 3], active: [bool; 3]) -> [f64; 3] {
    std::array::from_fn(|k| {
        if active[k] && den[k] > 0.0 {
            num[k] / den[k]
        } else {
            0.0
        }
    })
}

fn finite(out: Vec<[f64; 3]>) -> Result<Vec<[f64; 3]>> {
    if out.iter().flatten().any(|x| !x.is_finite()) {
        return Err(fail(FitSystemError::NonFinite));
    }
    Ok(out)
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

    /// A triangulated `w` × `w` grid's adjacency.
    fn grid(w: u32) -> Vec<Vec<u32>> {
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
        adj
    }

    #[test]
    fn a_near_system_is_solved_by_gradients_to_the_factorised_answer() {
        let adj = grid(40);
        let n = adj.len();
        let mut near = SmoothSystem::new(&adj, 0.01).unwrap();
        let mut exact = SmoothSystem::new(&adj, 0.01).unwrap();
        let rhs: Vec<[f64; 3]> = (0..n)
            .map(|i| [(i % 7) as f64, (i % 13) as f64 * 0.5, -((i % 3) as f64)])
            .collect();
        // Data weights on two vertices in three, then a few of them switched off or on, as
        // a registration's next closest-point step does.
        let diag = |flip: usize| -> Vec<f64> {
            (0..n)
                .map(|i| {
                    let on = (i % 3 != 0) ^ (i % 97 == flip);
                    if on {
                        1.0
                    } else {
                        1e-6
                    }
                })
                .collect()
        };
        let (first, it) = near
            .solve_near(300.0, &diag(1000), &rhs, &vec![[0.0; 3]; n], 1e-8, 8)
            .unwrap();
        assert_eq!(it, None, "no factor yet: factorised");
        let guess: Vec<[f64; 3]> = first.clone();
        let (u, it) = near
            .solve_near(300.0, &diag(5), &rhs, &guess, 1e-8, 30)
            .unwrap();
        assert!(it.is_some_and(|it| it > 0), "{it:?}");
        let v = exact.solve(300.0, &diag(5), &rhs).unwrap();
        let scale = v.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let err = u
            .iter()
            .flatten()
            .zip(v.iter().flatten())
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-6 * scale, "{err} of {scale}");
        // Another stiffness: the factor is not near enough, a new one is made.
        let (w, it) = near.solve_near(10.0, &diag(5), &rhs, &u, 1e-8, 30).unwrap();
        assert_eq!(it, None);
        assert_eq!(w, exact.solve(10.0, &diag(5), &rhs).unwrap());
        // Too few iterations allowed: factorised, the same bits as a plain solve.
        let (w, it) = near
            .solve_near(10.0, &diag(1000), &rhs, &vec![[0.0; 3]; n], 1e-12, 1)
            .unwrap();
        assert_eq!(it, None);
        assert_eq!(w, exact.solve(10.0, &diag(1000), &rhs).unwrap());
    }

    #[test]
    fn ordering_once_gives_the_same_bits() {
        // A triangulated 60 × 60 grid: large enough for a supernodal factorisation.
        let adj = grid(60);
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
