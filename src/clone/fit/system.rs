//! The sparse linear system of one registration step (faer): `(A_reg·α + D) u = b`, with
//! `A_reg` the fixed smoothness matrix of the surface and `D` a diagonal of data, landmark
//! and damping weights that changes every step. The sparsity pattern and the symbolic
//! Cholesky factorisation are built once; each step only refactors numerically, in one
//! thread ([`PAR`]), into storage kept from step to step.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymbolicCholesky};
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
    /// The numeric factor and the solver's scratch, reused by every solve (allocating and
    /// touching them afresh cost about as much as a small factorisation).
    factor: Vec<f64>,
    scratch: Option<MemBuffer>,
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
        Ok(SmoothSystem {
            n,
            col_ptr,
            row_idx,
            smooth,
            symbolic,
            factor: Vec::new(),
            scratch: None,
        })
    }

    /// Solves `(α·A_reg + diag(d)) u = b` for the three columns of `b` (row per vertex).
    pub fn solve(&mut self, alpha: f64, diag: &[f64], rhs: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
        let n = self.n;
        if diag.len() != n || rhs.len() != n {
            return Err(fail(FitSystemError::SizeMismatch));
        }
        let mut vals: Vec<f64> = self.smooth.iter().map(|v| v * alpha).collect();
        for (j, &d) in diag.iter().enumerate() {
            // The diagonal is the first entry of each column (rows ≥ column, sorted).
            vals[self.col_ptr[j] as usize] += d;
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(sym, &vals);
        let par = PAR;
        self.factor.clear();
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
        let mut b = Mat::<f64>::from_fn(n, 3, |i, k| rhs[i][k]);
        llt.solve_in_place_with_conj(Conj::No, b.as_mut(), par, stack);
        let out: Vec<[f64; 3]> = (0..n).map(|i| [b[(i, 0)], b[(i, 1)], b[(i, 2)]]).collect();
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
}
