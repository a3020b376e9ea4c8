//! Bounded least squares on small normal equations: the solver both directions of the ARKit
//! bridge ([`super::arkit_weights`]) use.
//!
//! ## The problem
//! Given a design matrix `A` (m × n), a target `b`, a Tikhonov weight `λ ≥ 0` and box bounds
//! `l ≤ x ≤ u`, find
//!
//! ```text
//! x* = argmin ‖A x − b‖² + λ ‖x‖²   subject to  l ≤ x ≤ u.
//! ```
//!
//! Expanding the square, this is the box-constrained quadratic programme
//! `min ½ xᵀQx − cᵀx` with `Q = AᵀA + λI` and `c = Aᵀb`. With `λ > 0`, `Q` is positive
//! definite, so the minimiser is unique even when columns of `A` coincide (two FAPs moving the
//! same feature points the same way share the motion evenly) or vanish (a FAP no feature point
//! sees stays at 0). `Q` depends only on the model, so callers build it once ([`NormalEquations`])
//! and solve it for many right-hand sides (one per animation frame).
//!
//! ## The method: an active-set solve (Lawson–Hanson NNLS generalised to boxes, as in
//! Stark & Parker's BVLS, here on `Q` instead of `A`)
//! Every variable is *at its lower bound*, *at its upper bound* or *free*. With the gradient
//! `g = Qx − c`, the Karush–Kuhn–Tucker conditions of the optimum are `g_i ≥ 0` at a lower
//! bound, `g_i ≤ 0` at an upper bound, `g_i = 0` when free. Starting with every variable at
//! its lower bound:
//!
//! 1. Compute `g`. If no bound variable violates its condition (within a tolerance), stop.
//! 2. Free the variable with the largest violation.
//! 3. Solve the equality-constrained problem on the free set: `Q_FF z_F = c_F − Q_FB x_B`
//!    (Cholesky; `Q_FF` is positive definite as a principal submatrix of `Q`).
//! 4. If `z_F` lies strictly inside the box, take it and go to 1. Otherwise move from `x_F`
//!    towards `z_F` as far as the box allows (`x ← x + α(z − x)`, `α` the largest step that
//!    keeps every free variable within its bounds), fix the variables that reached a bound,
//!    and go to 3.
//!
//! Each full step strictly lowers the objective and the free sets never repeat, so the loop
//! ends after finitely many steps; an iteration cap guards against rounding cycles (the last
//! feasible point is returned, still within the bounds).

/// `Q = AᵀA + λI` of a fixed design matrix, with `A` kept for right-hand sides `c = Aᵀb`.
#[derive(Clone, Debug)]
pub struct NormalEquations {
    /// Rows of `A`.
    rows: usize,
    /// Columns of `A` (unknowns).
    n: usize,
    /// `A`, column-major (`columns[j * rows + i]`).
    columns: Vec<f64>,
    /// `Q`, row-major n × n.
    q: Vec<f64>,
}

impl NormalEquations {
    /// The normal equations of the columns `columns` (each of the same length) with Tikhonov
    /// weight `lambda`.
    pub fn new(columns: &[Vec<f64>], lambda: f64) -> NormalEquations {
        let n = columns.len();
        let rows = columns.first().map_or(0, Vec::len);
        let mut flat = Vec::with_capacity(n * rows);
        for c in columns {
            flat.extend(c.iter().copied().chain(std::iter::repeat(0.0)).take(rows));
        }
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in i..n {
                let a = &flat[i * rows..(i + 1) * rows];
                let b = &flat[j * rows..(j + 1) * rows];
                let d: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
                q[i * n + j] = d;
                q[j * n + i] = d;
            }
            q[i * n + i] += lambda.max(0.0);
        }
        NormalEquations {
            rows,
            n,
            columns: flat,
            q,
        }
    }

    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        self.n
    }

    /// Mean of `AᵀA`'s diagonal (the squared column norms): a scale for choosing `λ`.
    pub fn mean_column_energy(columns: &[Vec<f64>]) -> f64 {
        if columns.is_empty() {
            return 0.0;
        }
        columns
            .iter()
            .map(|c| c.iter().map(|x| x * x).sum::<f64>())
            .sum::<f64>()
            / columns.len() as f64
    }

    /// `c = Aᵀb` (`b` shorter than the rows counts as zero-padded).
    pub fn rhs(&self, b: &[f64]) -> Vec<f64> {
        (0..self.n)
            .map(|j| {
                self.columns[j * self.rows..(j + 1) * self.rows]
                    .iter()
                    .zip(b)
                    .map(|(a, b)| a * b)
                    .sum()
            })
            .collect()
    }

    /// The bounded minimiser for target `b` (see the module docs).
    pub fn solve(&self, b: &[f64], lower: &[f64], upper: &[f64]) -> Vec<f64> {
        solve_box_qp(&self.q, &self.rhs(b), lower, upper)
    }
}

/// Where a variable is in the active-set method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Lower,
    Upper,
    Free,
}

/// `argmin ½ xᵀQx − cᵀx` subject to `lower ≤ x ≤ upper`, for a symmetric positive definite
/// `q` (row-major n × n). Bounds with `lower > upper` or non-finite entries are repaired
/// (the variable is pinned to a finite bound, or 0), so the result is always finite and in
/// the box.
pub fn solve_box_qp(q: &[f64], c: &[f64], lower: &[f64], upper: &[f64]) -> Vec<f64> {
    let n = c.len();
    debug_assert_eq!(q.len(), n * n);
    let lo: Vec<f64> = (0..n)
        .map(|i| {
            lower
                .get(i)
                .copied()
                .filter(|v| v.is_finite())
                .unwrap_or(0.0)
        })
        .collect();
    let hi: Vec<f64> = (0..n)
        .map(|i| {
            upper
                .get(i)
                .copied()
                .filter(|v| v.is_finite())
                .unwrap_or(lo[i])
                .max(lo[i])
        })
        .collect();
    let mut x = lo.clone();
    let mut state = vec![State::Lower; n];
    if n == 0 || q.len() != n * n || !q.iter().chain(c).all(|v| v.is_finite()) {
        return x;
    }
    let scale = c
        .iter()
        .map(|v| v.abs())
        .chain((0..n).map(|i| q[i * n + i].abs()))
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let tol = 1e-11 * scale;
    let gradient = |x: &[f64], i: usize| -> f64 {
        q[i * n..(i + 1) * n]
            .iter()
            .zip(x)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            - c[i]
    };
    let mut just_freed: Option<(usize, State)> = None;
    for _outer in 0..(4 * n + 20) {
        // 1–2: the bound variable violating its optimality condition most.
        let mut worst: Option<(usize, f64)> = None;
        for i in 0..n {
            let g = gradient(&x, i);
            let violation = match state[i] {
                State::Lower if hi[i] > lo[i] => -g,
                State::Upper if hi[i] > lo[i] => g,
                _ => continue,
            };
            if violation > tol && worst.is_none_or(|(_, w)| violation > w) {
                worst = Some((i, violation));
            }
        }
        let Some((enter, _)) = worst else { break };
        if just_freed == Some((enter, state[enter])) {
            // Rounding put the variable we just freed straight back where it was: it cannot
            // move, and freeing it again would cycle.
            break;
        }
        just_freed = Some((enter, state[enter]));
        state[enter] = State::Free;
        // 3–4: equality solves on the free set, stepping back into the box when needed.
        for _inner in 0..(n + 2) {
            let free: Vec<usize> = (0..n).filter(|&i| state[i] == State::Free).collect();
            if free.is_empty() {
                break;
            }
            let Some(z) = free_solve(q, c, &x, &free) else {
                break;
            };
            let inside = free
                .iter()
                .zip(&z)
                .all(|(&i, &zi)| zi > lo[i] && zi < hi[i]);
            if inside {
                for (&i, &zi) in free.iter().zip(&z) {
                    x[i] = zi;
                }
                break;
            }
            let mut alpha = 1.0f64;
            for (&i, &zi) in free.iter().zip(&z) {
                let d = zi - x[i];
                if zi <= lo[i] && d < 0.0 {
                    alpha = alpha.min((lo[i] - x[i]) / d);
                } else if zi >= hi[i] && d > 0.0 {
                    alpha = alpha.min((hi[i] - x[i]) / d);
                }
            }
            let alpha = alpha.clamp(0.0, 1.0);
            for (&i, &zi) in free.iter().zip(&z) {
                x[i] = (x[i] + alpha * (zi - x[i])).clamp(lo[i], hi[i]);
                let span = (hi[i] - lo[i]).max(1.0);
                if x[i] - lo[i] <= 1e-12 * span && zi <= lo[i] {
                    x[i] = lo[i];
                    state[i] = State::Lower;
                } else if hi[i] - x[i] <= 1e-12 * span && zi >= hi[i] {
                    x[i] = hi[i];
                    state[i] = State::Upper;
                }
            }
            if !free.iter().any(|&i| state[i] != State::Free) {
                // No variable reached a bound (rounding): take the clamped point and stop.
                break;
            }
        }
    }
    x
}

/// Solves `Q_FF z = c_F − Q_FB x_B` by Cholesky; `None` if `Q_FF` is not positive definite.
fn free_solve(q: &[f64], c: &[f64], x: &[f64], free: &[usize]) -> Option<Vec<f64>> {
    let n = c.len();
    let k = free.len();
    let is_free = {
        let mut f = vec![false; n];
        for &i in free {
            f[i] = true;
        }
        f
    };
    let mut rhs: Vec<f64> = free
        .iter()
        .map(|&i| {
            c[i] - (0..n)
                .filter(|&j| !is_free[j])
                .map(|j| q[i * n + j] * x[j])
                .sum::<f64>()
        })
        .collect();
    // Cholesky L Lᵀ of Q_FF, lower triangle in `l`.
    let mut l = vec![0.0; k * k];
    for a in 0..k {
        for b in 0..=a {
            let mut s = q[free[a] * n + free[b]];
            for p in 0..b {
                s -= l[a * k + p] * l[b * k + p];
            }
            if a == b {
                if s <= 0.0 || !s.is_finite() {
                    return None;
                }
                l[a * k + a] = s.sqrt();
            } else {
                l[a * k + b] = s / l[b * k + b];
            }
        }
    }
    for a in 0..k {
        let s: f64 = (0..a).map(|p| l[a * k + p] * rhs[p]).sum();
        rhs[a] = (rhs[a] - s) / l[a * k + a];
    }
    for a in (0..k).rev() {
        let s: f64 = (a + 1..k).map(|p| l[p * k + a] * rhs[p]).sum();
        rhs[a] = (rhs[a] - s) / l[a * k + a];
    }
    rhs.iter().all(|v| v.is_finite()).then_some(rhs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn interior_solution_is_the_unconstrained_one() {
        // A = I (2×2), b = (0.3, 0.6): x = b, well inside [0, 1].
        let ne = NormalEquations::new(&[vec![1.0, 0.0], vec![0.0, 1.0]], 0.0);
        let x = ne.solve(&[0.3, 0.6], &[0.0, 0.0], &[1.0, 1.0]);
        assert!(close(&x, &[0.3, 0.6], 1e-12), "{x:?}");
    }

    #[test]
    fn upper_and_lower_bounds_become_active() {
        // Unconstrained optimum (2, −1): clamped to (1, 0) because the problem separates.
        let ne = NormalEquations::new(&[vec![1.0, 0.0], vec![0.0, 1.0]], 0.0);
        let x = ne.solve(&[2.0, -1.0], &[0.0, 0.0], &[1.0, 1.0]);
        assert!(close(&x, &[1.0, 0.0], 1e-12), "{x:?}");
    }

    #[test]
    fn coupled_bounds_reoptimise_the_free_variable() {
        // A = [[1, 1], [0, 1]], b = (1, −1): unconstrained x = (2, −1). With x₂ ≥ 0 the
        // optimum is x₂ = 0, x₁ = 1 (the free variable re-solved, not just clamped).
        let ne = NormalEquations::new(&[vec![1.0, 0.0], vec![1.0, 1.0]], 0.0);
        let x = ne.solve(&[1.0, -1.0], &[0.0, 0.0], &[10.0, 10.0]);
        assert!(close(&x, &[1.0, 0.0], 1e-12), "{x:?}");
    }

    #[test]
    fn classic_nnls_example() {
        // min ‖Ax − b‖, x ≥ 0 with A = [[1, 0], [1, 1], [0, 1]] (columns below), b = (2, 1, −1):
        // unconstrained x = (5/3, −4/3); NNLS gives x = (1.5, 0).
        let ne = NormalEquations::new(&[vec![1.0, 1.0, 0.0], vec![0.0, 1.0, 1.0]], 0.0);
        let x = ne.solve(&[2.0, 1.0, -1.0], &[0.0, 0.0], &[f64::MAX, f64::MAX]);
        assert!(close(&x, &[1.5, 0.0], 1e-12), "{x:?}");
    }

    #[test]
    fn tikhonov_splits_identical_columns_and_zeroes_blind_ones() {
        // Two identical columns and one zero column: the target needs 1 unit of the shared
        // direction; with a small λ both share it (≈ 0.5 each) and the blind one stays 0.
        let cols = vec![vec![1.0, 0.0], vec![1.0, 0.0], vec![0.0, 0.0]];
        let ne = NormalEquations::new(&cols, 1e-6);
        let x = ne.solve(&[1.0, 0.0], &[0.0; 3], &[2.0; 3]);
        assert!(close(&x, &[0.5, 0.5, 0.0], 1e-5), "{x:?}");
    }

    #[test]
    fn bad_inputs_give_finite_points_in_the_box() {
        let q = vec![1.0, 0.0, 0.0, 1.0];
        let x = solve_box_qp(&q, &[f64::NAN, 1.0], &[0.0, 0.0], &[1.0, 1.0]);
        assert_eq!(x, vec![0.0, 0.0]);
        // Inverted bounds pin the variable at its lower bound.
        let x = solve_box_qp(&q, &[5.0, 5.0], &[0.5, 0.0], &[0.2, 1.0]);
        assert!(close(&x, &[0.5, 1.0], 1e-12), "{x:?}");
        assert!(solve_box_qp(&[], &[], &[], &[]).is_empty());
    }

    #[test]
    fn random_problems_satisfy_kkt() {
        // Deterministic pseudo-random dense problems: the result is in the box and meets the
        // optimality conditions.
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for _ in 0..50 {
            let (m, n) = (12, 7);
            let cols: Vec<Vec<f64>> = (0..n).map(|_| (0..m).map(|_| rnd()).collect()).collect();
            let b: Vec<f64> = (0..m).map(|_| rnd() * 3.0).collect();
            let ne = NormalEquations::new(&cols, 1e-3);
            let (lo, hi) = (vec![0.0; n], vec![1.0; n]);
            let x = ne.solve(&b, &lo, &hi);
            let c = ne.rhs(&b);
            for i in 0..n {
                assert!((0.0..=1.0).contains(&x[i]));
                let g: f64 = (0..n).map(|j| ne.q[i * n + j] * x[j]).sum::<f64>() - c[i];
                if x[i] <= 0.0 {
                    assert!(g >= -1e-8, "g {g} at lower bound");
                } else if x[i] >= 1.0 {
                    assert!(g <= 1e-8, "g {g} at upper bound");
                } else {
                    assert!(g.abs() < 1e-8, "g {g} free");
                }
            }
        }
    }
}
