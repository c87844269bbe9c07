//! Constrained maximum likelihood for hit-count Monte Carlo (Daun, Morton & Howell 2005):
//! maximise Σ_{i≤j} M_ij ln s_ij, M_ij = N_ij + N_ji, subject to Σ_j s_ij = A_i. The KKT
//! conditions give s_ij = M_ij / (λ_i + λ_j) (docs/literature.md §3); Newton on λ solves
//! f_i(λ) = Σ_j M_ij/(λ_i + λ_j) − A_i = 0. The Newton matrix −∂f/∂λ is the signless Laplacian
//! with w_ij = M_ij/(λ_i + λ_j)², solved by CG. Non-negativity is automatic and pairs never hit
//! stay exactly 0.
use super::lsq::solve_constraints;
use super::Exchange;
use crate::{Error, Result};

/// Newton steps allowed (3–5 are typical from λ_i = n_i/A_i).
const ML_MAX_NEWTON: usize = 60;

/// Replaces the raw (non-symmetric) hit-count matrix `ex` by the ML closure; returns the
/// Newton steps taken. `ex.samples` must hold the rays per row.
pub fn max_likelihood(ex: &mut Exchange, tol: f64) -> Result<usize> {
    let n = ex.len();
    // Counts N_ij = n_i F_ij, then M = N + Nᵀ on the union pattern.
    let mut counts = ex.clone();
    let ip = counts.indptr().to_vec();
    {
        let data = counts.s.data_mut();
        for i in 0..n {
            let scale = ex.samples[i] as f64 / ex.areas[i];
            for v in &mut data[ip[i]..ip[i + 1]] {
                *v *= scale;
            }
        }
    }
    counts.symmetrize();
    let m: Vec<f64> = counts.s.data().iter().map(|v| 2.0 * v).collect();
    let ip = counts.indptr().to_vec();
    let idx = counts.s.indices().to_vec();
    *ex = counts;
    let mut lambda: Vec<f64> = (0..n).map(|i| ex.samples[i] as f64 / ex.areas[i]).collect();
    let eval = |lambda: &[f64], ex: &mut Exchange| -> Option<f64> {
        let data = ex.s.data_mut();
        for i in 0..n {
            for k in ip[i]..ip[i + 1] {
                let d = lambda[i] + lambda[idx[k]];
                if m[k] > 0.0 && d <= 0.0 {
                    return None;
                }
                data[k] = if m[k] > 0.0 { m[k] / d } else { 0.0 };
            }
        }
        Some(super::scaling::closure_error(&ex.row_sums(), &ex.areas))
    };
    let mut err = eval(&lambda, ex).ok_or_else(|| Error::Compute("ML closure: rows without rays".into()))?;
    for step in 0..ML_MAX_NEWTON {
        if err <= tol {
            return Ok(step);
        }
        // w_ij = s_ij² / M_ij; Newton: (diag(W·1) + W) δ = f.
        let w: Vec<f64> =
            ex.s.data().iter().zip(&m).map(|(s, m)| if *m > 0.0 { s * s / m } else { 0.0 }).collect();
        let sums = ex.row_sums();
        let f: Vec<f64> = sums.iter().zip(&ex.areas).map(|(s, a)| s - a).collect();
        let (delta, _) = solve_constraints(ex, &w, &f)?;
        let mut t = 1.0;
        loop {
            let trial: Vec<f64> = lambda.iter().zip(&delta).map(|(l, d)| l + t * d).collect();
            match eval(&trial, ex) {
                Some(e) if e < err || t < 1e-4 => {
                    (lambda, err) = (trial, e);
                    break;
                }
                _ => t *= 0.5,
            }
            if t < 1e-6 {
                return Err(Error::Compute(format!(
                    "ML closure: line search failed at closure error {err:.3e}"
                )));
            }
        }
    }
    if err <= tol {
        return Ok(ML_MAX_NEWTON);
    }
    Err(Error::Compute(format!(
        "ML closure did not converge: closure error {err:.3e} after {ML_MAX_NEWTON} Newton steps"
    )))
}
