//! Small linear-algebra kernels shared by the enforcement methods and the solvers:
//! - [`dot`] / [`norm`]: reductions in fixed-size chunks summed in order, so results do not
//!   depend on the thread count;
//! - [`SignlessLaplacian`]: the operator (diag(Σ_j w_ij) + W)x of the row-sum constraints
//!   Σ_j w_ij(λ_i + λ_j) = r_i, on the pattern of S;
//! - [`Linear`]: any symmetric mat-vec as faer's matrix-free [`LinOp`];
//! - [`cg`]: the crate's one conjugate-gradient solve, faer's
//!   [`conjugate_gradient`] with a Jacobi preconditioner (the diagonal's inverse as a faer
//!   diagonal, which is a [`faer::matrix_free::Precond`]). It serves every symmetric positive
//!   (semi-)definite system: the closure constraints, the Newton steps of symmetric scaling,
//!   the lean net-radiation solve and its error propagation. From x = 0 it stays in the range
//!   of the operator, so it also solves the consistent singular bipartite case.
//!
//! Two details of faer 0.24.4's `conjugate_gradient` shape [`cg`]:
//! - with `InitialGuessStatus::Zero` it never writes its residual workspace (r is left as
//!   uninitialised scratch instead of r = b), so the first step reads garbage (NaN in
//!   practice); [`cg`] passes `MaybeNonZero` with x = 0, and [`Linear`] answers a zero input
//!   with zero at O(n), so that costs no mat-vec;
//! - p·Ap = 0 (a direction in the null space) gives a zero Cholesky pivot and a NaN step
//!   rather than an error, and `NoConvergence` reports the initial residual, not the last;
//!   [`cg`] keeps the last finite iterate and measures its residual.
//!
//! faer's own reductions run sequentially (`CG_PAR`); the mat-vec is the caller's (parallel,
//! with fixed row ownership), so the iterates are the same on any thread count.
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::matrix_free::conjugate_gradient::{conjugate_gradient, conjugate_gradient_scratch, CgParams};
use faer::matrix_free::{InitialGuessStatus, LinOp};
use faer::{Col, MatMut, MatRef, Par};
use rayon::prelude::*;

/// Chunk length of the ordered reductions (fixed, so the sum order never changes).
const CHUNK: usize = 4096;

/// Relative residual ‖b − Ax‖/‖b‖ at which the solves of the crate stop: a few hundred ulps
/// of the right-hand side, so the answer is as good as the data (closure to ~1e-14 of the
/// correction, heat rates within ~1e-12 of a direct factorisation).
pub const CG_TOL: f64 = 1e-14;

/// CG iterations allowed per node (plus [`ENFORCE_CG_ITER_FLOOR`]) in the enforcement solves: a
/// signless Laplacian of a view-factor graph converges in tens of iterations; this only stops
/// a runaway.
const CG_ITER_PER_NODE: usize = 4;
/// Floor of the enforcement solves' iteration budget (see [`CG_ITER_PER_NODE`]).
const ENFORCE_CG_ITER_FLOOR: usize = 2000;

/// Iterations allowed to an enforcement solve over `n` nodes.
pub fn max_iter(n: usize) -> usize {
    ENFORCE_CG_ITER_FLOOR + CG_ITER_PER_NODE * n
}

/// faer's parallelism inside [`cg`]: sequential, because faer splits its reductions (dot
/// products, norms) into one part per thread, which would make the iterates follow the
/// thread count; they are O(n) next to the caller's mat-vec.
const CG_PAR: Par = Par::Seq;

/// Σ a_i b_i, identical on any thread count.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum())
        .collect();
    parts.iter().sum()
}

/// Euclidean norm, identical on any thread count.
pub fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// The operator y_i = (Σ_j w_ij) x_i + Σ_j w_ij x_j on a CSR pattern (W symmetric, diagonal
/// entries counted in both terms: ∂/∂λ_i of w_ii(λ_i + λ_i) is 2w_ii).
pub struct SignlessLaplacian<'a> {
    /// CSR row pointer.
    pub indptr: &'a [usize],
    /// CSR columns.
    pub indices: &'a [usize],
    /// Weights w_ij aligned with `indices`.
    pub w: &'a [f64],
}

impl SignlessLaplacian<'_> {
    /// y = (diag(W·1) + W) x.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut().enumerate().for_each(|(i, yi)| {
            let (lo, hi) = (self.indptr[i], self.indptr[i + 1]);
            let mut acc = 0.0;
            for k in lo..hi {
                acc += self.w[k] * (x[i] + x[self.indices[k]]);
            }
            *yi = acc;
        });
    }

    /// Diagonal of the operator: Σ_j w_ij + w_ii.
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.indptr.len() - 1)
            .into_par_iter()
            .map(|i| {
                let (lo, hi) = (self.indptr[i], self.indptr[i + 1]);
                (lo..hi).map(|k| if self.indices[k] == i { 2.0 * self.w[k] } else { self.w[k] }).sum()
            })
            .collect()
    }
}

/// A symmetric operator of order `n` given by its mat-vec `apply(x, y)`: y = A x (every
/// entry of y written).
pub struct Linear<F> {
    /// Order.
    pub n: usize,
    /// The mat-vec.
    pub apply: F,
}

impl<F> std::fmt::Debug for Linear<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Linear({})", self.n)
    }
}

impl<F: Fn(&[f64], &mut [f64]) + Sync> LinOp<f64> for Linear<F> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.n
    }
    fn ncols(&self) -> usize {
        self.n
    }
    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let mut y = Vec::new();
        for j in 0..rhs.ncols() {
            let col = rhs.col(j);
            // faer's workspace columns are contiguous; copy only when one is not.
            let copy: Vec<f64>;
            let xs: &[f64] = match col.try_as_col_major() {
                Some(c) => c.as_slice(),
                None => {
                    copy = col.iter().copied().collect();
                    &copy
                }
            };
            let mut oj = out.as_mut().col_mut(j);
            if xs.iter().all(|&v| v == 0.0) {
                // A·0 = 0 without a mat-vec (the initial residual of a zero guess).
                oj.fill(0.0);
                continue;
            }
            match oj.as_mut().try_as_col_major_mut() {
                Some(o) => (self.apply)(xs, o.as_slice_mut()),
                None => {
                    y.resize(self.n, 0.0);
                    (self.apply)(xs, &mut y);
                    oj.iter_mut().zip(&y).for_each(|(o, v)| *o = *v);
                }
            }
        }
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack);
    }
}

/// Outcome of [`cg`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CgInfo {
    /// Iterations taken.
    pub iterations: usize,
    /// Final ‖b − Ax‖ / ‖b‖.
    pub residual: f64,
    /// True when `residual <= tol`.
    pub converged: bool,
}

/// y = A x through faer's [`LinOp`] interface.
fn apply_to<A: LinOp<f64>>(a: &A, x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut y = vec![0.0; n];
    let mut mem = MemBuffer::new(a.apply_scratch(1, CG_PAR));
    a.apply(
        MatMut::from_column_major_slice_mut(&mut y, n, 1),
        MatRef::from_column_major_slice(x, n, 1),
        CG_PAR,
        MemStack::new(&mut mem),
    );
    y
}

/// Solves the symmetric positive (semi-)definite system A x = b from x = 0 by faer's
/// conjugate gradients, Jacobi-preconditioned by `diag` (a row whose entry is ≤ 0 gets 0 in
/// the preconditioner); stops at relative residual `tol` or after `max_iter` iterations and
/// returns the last finite iterate either way.
pub fn cg<A: LinOp<f64>>(a: &A, diag: &[f64], b: &[f64], tol: f64, max_iter: usize) -> (Vec<f64>, CgInfo) {
    let n = b.len();
    let inv = Col::<f64>::from_fn(n, |i| if diag[i] > 0.0 { 1.0 / diag[i] } else { 0.0 });
    let precond = inv.as_diagonal();
    let mut x = vec![0.0; n];
    let mut last = vec![0.0; n];
    let params = CgParams {
        // Zero would leave faer's residual uninitialised (see the module docs).
        initial_guess: InitialGuessStatus::MaybeNonZero,
        abs_tolerance: 0.0,
        rel_tolerance: tol,
        max_iters: max_iter,
        ..Default::default()
    };
    let mut iterations = 0;
    let mut finite = true;
    let mut mem = MemBuffer::new(conjugate_gradient_scratch(precond, a, 1, CG_PAR));
    let out = conjugate_gradient(
        MatMut::from_column_major_slice_mut(&mut x, n, 1),
        precond,
        a,
        MatRef::from_column_major_slice(b, n, 1),
        params,
        |xk| {
            let xk = xk.col(0);
            if finite && xk.iter().all(|v| v.is_finite()) {
                iterations += 1;
                last.iter_mut().zip(xk.iter()).for_each(|(l, v)| *l = *v);
            } else {
                finite = false;
            }
        },
        CG_PAR,
        MemStack::new(&mut mem),
    );
    match out {
        Ok(info) if finite => {
            (x, CgInfo { iterations: info.iter_count, residual: info.rel_residual, converged: true })
        }
        // Out of iterations (faer then reports the initial residual, so it is measured), p·Ap ≤
        // 0 or a NaN step (the direction left the range of a singular operator): the last
        // finite iterate is what the iteration reached.
        _ => {
            let ax = apply_to(a, &last);
            let r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
            let bn = norm(b);
            let residual = if bn > 0.0 { norm(&r) / bn } else { norm(&r) };
            (last, CgInfo { iterations, residual, converged: residual <= tol })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signless Laplacian of the given rows (a symmetric CSR pattern) through [`cg`].
    fn solve(rows: &[&[(usize, f64)]], b: &[f64]) -> (Vec<f64>, CgInfo) {
        let mut indptr = vec![0];
        let (mut indices, mut w) = (Vec::new(), Vec::new());
        for r in rows {
            indices.extend(r.iter().map(|e| e.0));
            w.extend(r.iter().map(|e| e.1));
            indptr.push(indices.len());
        }
        let op = SignlessLaplacian { indptr: &indptr, indices: &indices, w: &w };
        let lin = Linear { n: b.len(), apply: |x: &[f64], y: &mut [f64]| op.apply(x, y) };
        cg(&lin, &op.diagonal(), b, CG_TOL, 100)
    }

    #[test]
    fn cg_matches_a_dense_solve_of_a_3x3_spd_system() {
        // A triangle of couplings: an odd cycle, so the signless Laplacian is definite.
        // A = [[3, 1, 2], [1, 1.5, 0.5], [2, 0.5, 2.5]].
        let tri: [&[(usize, f64)]; 3] = [&[(1, 1.0), (2, 2.0)], &[(0, 1.0), (2, 0.5)], &[(0, 2.0), (1, 0.5)]];
        let b = [1.0, -2.0, 3.0];
        let (x, info) = solve(&tri, &b);
        assert!(info.converged && info.residual <= CG_TOL, "{info:?}");
        assert!(info.iterations >= 1 && info.iterations <= 3, "{info:?}");
        let a = faer::mat![[3.0, 1.0, 2.0], [1.0, 1.5, 0.5], [2.0, 0.5, 2.5]];
        let rhs = faer::Mat::from_fn(3, 1, |i, _| b[i]);
        let exact = faer::linalg::solvers::Solve::solve(&a.partial_piv_lu(), &rhs);
        for i in 0..3 {
            assert!((x[i] - exact[(i, 0)]).abs() < 1e-13, "x = {x:?}, dense {:?}", exact.col(0));
        }
    }

    #[test]
    fn cg_solves_a_consistent_singular_system_and_reports_an_inconsistent_one() {
        // Two plates that see only each other (bipartite, singular): solvable iff the two
        // sides ask for the same total.
        let pair: [&[(usize, f64)]; 2] = [&[(1, 1.0)], &[(0, 1.0)]];
        let (x, info) = solve(&pair, &[2.0, 2.0]);
        assert!(info.converged, "{info:?}");
        assert!((x[0] + x[1] - 2.0).abs() < 1e-14, "{x:?}");
        let (x, info) = solve(&pair, &[2.0, 1.0]);
        assert!(!info.converged && info.residual > 1e-8, "{info:?}");
        assert!(x.iter().all(|v| v.is_finite()), "{x:?}");
    }

    #[test]
    fn cg_of_a_zero_right_hand_side_is_zero() {
        let tri: [&[(usize, f64)]; 2] = [&[(1, 1.0)], &[(0, 1.0)]];
        let (x, info) = solve(&tri, &[0.0, 0.0]);
        assert_eq!(x, vec![0.0, 0.0]);
        assert_eq!(info, CgInfo { iterations: 0, residual: 0.0, converged: true });
    }

    #[test]
    fn cg_is_deterministic_across_thread_counts() {
        let n = 10_000;
        let mut indptr = vec![0];
        let (mut indices, mut w) = (Vec::new(), Vec::new());
        // Symmetric weights w_ij = w_ji on a ring with chords of two (odd cycles: definite).
        let weight = |i: usize, j: usize| 1.0 + ((i.min(j) * 31 + i.max(j) * 17) % 13) as f64 / 13.0;
        for i in 0..n {
            for j in [(i + n - 1) % n, (i + 1) % n, (i + 2) % n, (i + n - 2) % n] {
                indices.push(j);
                w.push(weight(i, j));
            }
            indptr.push(indices.len());
        }
        let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            pool.install(|| {
                let op = SignlessLaplacian { indptr: &indptr, indices: &indices, w: &w };
                let lin = Linear { n, apply: |x: &[f64], y: &mut [f64]| op.apply(x, y) };
                cg(&lin, &op.diagonal(), &b, CG_TOL, 10_000)
            })
        };
        let (x1, i1) = run(1);
        let (x2, i2) = run(2);
        assert!(i1.converged, "{i1:?}");
        assert_eq!(i1, i2);
        assert!(x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}
