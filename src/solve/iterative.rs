//! The classic iterations on K J = b: Jacobi (parallel sweeps) and Gauss–Seidel (in-place,
//! sequential). K is weakly diagonally dominant, so both converge whenever K is SPD; the rate
//! degrades as reflectivities approach 1 (crates.md: hundreds of sweeps at ρ ≈ 0.95).
use super::system::{diagonal, residual};
use crate::exchange::linalg::norm;
use rayon::prelude::*;
use sprs::CsMat;

/// An iterative solve stopped before reaching its goal; carries the numbers reached.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{solver} did not converge: relative residual {residual:.3e} after {iterations} iterations (goal {tolerance:.1e})")]
pub struct NoConvergence {
    /// "Jacobi" or "Gauss-Seidel".
    pub solver: &'static str,
    /// Sweeps done.
    pub iterations: usize,
    /// ‖b − Kx‖/‖b‖ reached.
    pub residual: f64,
    /// The goal.
    pub tolerance: f64,
}

impl From<NoConvergence> for crate::Error {
    fn from(e: NoConvergence) -> Self {
        crate::Error::Compute(e.to_string())
    }
}

/// Solves K x = b by Jacobi (`gauss_seidel = false`) or Gauss–Seidel; returns (x, sweeps,
/// relative residual).
pub fn solve(
    k: &CsMat<f64>,
    b: &[f64],
    gauss_seidel: bool,
    tol: f64,
    max_iter: usize,
) -> Result<(Vec<f64>, usize, f64), NoConvergence> {
    let n = k.rows();
    let diag = diagonal(k);
    let (ip, idx, d) = (k.indptr(), k.indices(), k.data());
    let ip = ip.raw_storage();
    let bn = norm(b);
    let mut x: Vec<f64> = b.iter().zip(&diag).map(|(b, d)| b / d).collect();
    if bn == 0.0 {
        return Ok((vec![0.0; n], 0, 0.0));
    }
    let off = |i: usize, x: &[f64]| -> f64 {
        (ip[i]..ip[i + 1]).filter(|&p| idx[p] != i).map(|p| d[p] * x[idx[p]]).sum()
    };
    let mut res = residual(k, &x, b);
    for it in 1..=max_iter {
        if gauss_seidel {
            for i in 0..n {
                x[i] = (b[i] - off(i, &x)) / diag[i];
            }
        } else {
            let next: Vec<f64> = (0..n).into_par_iter().map(|i| (b[i] - off(i, &x)) / diag[i]).collect();
            x = next;
        }
        // A residual costs one extra mat-vec per sweep; it is what the caller asked for.
        res = residual(k, &x, b);
        if !res.is_finite() {
            break;
        }
        if res <= tol {
            return Ok((x, it, res));
        }
    }
    Err(NoConvergence {
        solver: if gauss_seidel { "Gauss-Seidel" } else { "Jacobi" },
        iterations: max_iter,
        residual: res,
        tolerance: tol,
    })
}
