//! Least-squares closure: minimise ½Σ(s_ij − s̄_ij)²/w_ij subject to Σ_j s_ij = A_i. The
//! Lagrange solution is s_ij = s̄_ij + w_ij(λ_i + λ_j) with (diag(W·1) + W)λ = A − s̄·1
//! (docs/literature.md §3). The matrix is a signless Laplacian: singular for a bipartite component
//! (two plates that see only each other); CG from λ = 0 still solves it when the closure is
//! feasible (equal areas on both sides), and reports otherwise.
//!
//! Weights: w = s̄ (the linearisation of symmetric scaling; keeps structural zeros and, for
//! small corrections, signs) and w = 1 on the stored pattern (Larsen & Howell, zeros masked;
//! may create negatives, which the diagnostics count).
use super::linalg::{cg, max_iter, Linear, SignlessLaplacian, CG_TOL};
use super::Exchange;
use crate::{Error, Result};

/// Weight choice for [`weighted_least_squares`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weight {
    /// w_ij = s̄_ij.
    Sbar,
    /// w_ij = 1 on the stored pattern.
    Unit,
}

/// Solves Σ_j w_ij(λ_i + λ_j) = r_i on the pattern of `ex`; errors when infeasible.
pub fn solve_constraints(ex: &Exchange, w: &[f64], r: &[f64]) -> Result<(Vec<f64>, usize)> {
    let op = SignlessLaplacian { indptr: ex.indptr(), indices: ex.s.indices(), w };
    let lin = Linear { n: ex.len(), apply: |x: &[f64], y: &mut [f64]| op.apply(x, y) };
    let (x, info) = cg(&lin, &op.diagonal(), r, CG_TOL, max_iter(ex.len()));
    // Near-consistency is enough when the right-hand side itself is at round-off level.
    if !info.converged && info.residual > 1e-8 {
        return Err(Error::Compute(format!(
            "closure constraints have no solution (CG stopped at relative residual {:.3e} after {} \
             iterations): a group of patches that see only each other has unequal areas on its two sides",
            info.residual, info.iterations
        )));
    }
    Ok((x, info.iterations))
}

/// One weighted least-squares projection onto the closure constraints (in place; `ex` must be
/// symmetric). Returns CG iterations.
pub fn weighted_least_squares(ex: &mut Exchange, weight: Weight) -> Result<usize> {
    let w: Vec<f64> = match weight {
        Weight::Sbar => ex.s.data().to_vec(),
        Weight::Unit => vec![1.0; ex.s.nnz()],
    };
    let sums = ex.row_sums();
    let r: Vec<f64> = ex.areas.iter().zip(&sums).map(|(a, s)| a - s).collect();
    let (lambda, iters) = solve_constraints(ex, &w, &r)?;
    let ip = ex.indptr().to_vec();
    let idx = ex.s.indices().to_vec();
    let data = ex.s.data_mut();
    for i in 0..ip.len() - 1 {
        for k in ip[i]..ip[i + 1] {
            data[k] += w[k] * (lambda[i] + lambda[idx[k]]);
        }
    }
    Ok(iters)
}
