//! Symmetric diagonal scaling s_ij = s̄_ij g_i g_j (View3D `NormAF`): keeps reciprocity,
//! structural zeros and signs exactly.
//! - [`symmetric_scaling`]: closure Σ_j s_ij = A_i by Newton on log g; each Newton step is
//!   the weighted least-squares step with w = the current s (see [`super::lsq`]), so the method
//!   converges quadratically from the WLS w = s̄ answer.
//! - [`capped_scaling`]: open scenes: only rows whose sum exceeds A_i are scaled down
//!   (g_i ≤ 1), by the damped fixed point g_i ← min(1, √(g_i A_i / (S g)_i)); the ambient
//!   takes the rest of every row.
use super::lsq::solve_constraints;
use super::Exchange;
use crate::{Error, Result};
use rayon::prelude::*;

/// Newton steps allowed; quadratic convergence needs 3–6 from any sane start.
pub(super) const MAX_NEWTON: usize = 50;
/// Fixed-point sweeps allowed for the capped variant (only noise-level overshoots occur).
pub(super) const MAX_CAPPED: usize = 10_000;

/// max_i |Σ_j S_ij / A_i − 1|.
pub fn closure_error(ex: &Exchange) -> f64 {
    ex.row_sums().iter().zip(&ex.areas).map(|(s, a)| (s / a - 1.0).abs()).fold(0.0, f64::max)
}

/// Scales a symmetric `ex` in place to Σ_j S_ij = A_i within `tol`; returns CG iterations.
pub fn symmetric_scaling(ex: &mut Exchange, tol: f64) -> Result<usize> {
    let base = ex.s.data().to_vec();
    let ip = ex.indptr().to_vec();
    let idx = ex.s.indices().to_vec();
    let mut logg = vec![0.0; ex.len()];
    let mut total = 0;
    let mut err = closure_error(ex);
    for _ in 0..MAX_NEWTON {
        if err <= tol {
            return Ok(total);
        }
        // Newton step: Σ_j s_ij (u_i + u_j) = A_i − Σ_j s_ij, then g ← g·exp(u).
        let w = ex.s.data().to_vec();
        let sums = ex.row_sums();
        let r: Vec<f64> = ex.areas.iter().zip(&sums).map(|(a, s)| a - s).collect();
        let (u, it) = solve_constraints(ex, &w, &r)?;
        total += it;
        // Backtrack until the closure error falls.
        let mut t = 1.0;
        loop {
            let trial: Vec<f64> = logg.iter().zip(&u).map(|(l, u)| l + t * u).collect();
            apply(ex, &base, &ip, &idx, &trial);
            let e = closure_error(ex);
            if e < err || t < 1e-3 {
                (logg, err) = (trial, e);
                break;
            }
            t *= 0.5;
        }
    }
    if err <= tol {
        return Ok(total);
    }
    Err(Error::Compute(format!(
        "symmetric scaling did not converge: closure error {err:.3e} after {MAX_NEWTON} Newton steps"
    )))
}

fn apply(ex: &mut Exchange, base: &[f64], ip: &[usize], idx: &[usize], logg: &[f64]) {
    let data = ex.s.data_mut();
    for i in 0..ip.len() - 1 {
        for k in ip[i]..ip[i + 1] {
            data[k] = base[k] * (logg[i] + logg[idx[k]]).exp();
        }
    }
}

/// Scales rows whose sum exceeds A_i(1 + tol) down until Σ_j S_ij ≤ A_i; returns sweeps.
pub fn capped_scaling(ex: &mut Exchange, tol: f64) -> Result<usize> {
    let base = ex.s.data().to_vec();
    let ip = ex.indptr().to_vec();
    let idx = ex.s.indices().to_vec();
    let n = ex.len();
    let mut g = vec![1.0; n];
    for sweep in 0..MAX_CAPPED {
        let r: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|i| (ip[i]..ip[i + 1]).map(|k| base[k] * g[idx[k]]).sum::<f64>())
            .collect();
        let over = (0..n).any(|i| g[i] * r[i] > ex.areas[i] * (1.0 + tol));
        if !over {
            let data = ex.s.data_mut();
            for i in 0..n {
                for k in ip[i]..ip[i + 1] {
                    data[k] = base[k] * (g[i] * g[idx[k]]);
                }
            }
            return Ok(sweep);
        }
        for i in 0..n {
            if r[i] > 0.0 {
                g[i] = (g[i] * ex.areas[i] / r[i]).sqrt().min(1.0);
            }
        }
    }
    Err(Error::Compute(format!("capped scaling of over-full rows did not converge in {MAX_CAPPED} sweeps")))
}
