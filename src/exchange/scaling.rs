//! Symmetric diagonal scaling s_ij = s̄_ij g_i g_j (View3D `NormAF`) on any exchange
//! [`Operator`]: keeps reciprocity, structural zeros and signs exactly. The scales are found on
//! the operator applied as g ∘ S̄(g ∘ x), so the store is only read until
//! [`Operator::scale`] applies them once.
//! - [`closure_scales`]: closure Σ_j s_ij = A_i by Newton on log g; each Newton step is the
//!   weighted least-squares step with w = the current s (see `super::lsq`), solved inexactly
//!   to the current closure error, so the method converges quadratically from the WLS w = s̄
//!   answer;
//! - [`capped_scales`]: open scenes: only rows whose sum exceeds A_i are scaled down
//!   (g_i ≤ 1), by the damped fixed point g_i ← min(1, √(g_i A_i / (S g)_i)); the ambient
//!   takes the rest of every row.
use super::linalg::{cg, max_iter, Linear, CG_TOL};
use super::operator::Operator;
use crate::{Error, Result};

/// Newton steps allowed; quadratic convergence needs 3–6 from any sane start.
const MAX_NEWTON: usize = 50;
/// Fixed-point sweeps allowed for the capped variant (only noise-level overshoots occur).
const MAX_CAPPED: usize = 10_000;
/// Loosest relative CG residual of a Newton step (inexact Newton forcing term).
const NEWTON_FORCING: f64 = 1e-2;

/// max_i |r_i / A_i − 1| of row sums `sums` over `areas`.
pub fn closure_error(sums: &[f64], areas: &[f64]) -> f64 {
    sums.iter().zip(areas).map(|(s, a)| (s / a - 1.0).abs()).fold(0.0, f64::max)
}

/// The scales g with Σ_j s_ij g_i g_j = A_i within `tol` on a symmetric operator, and the
/// CG iterations spent; the operator itself is left as it is.
pub fn closure_scales(t: &dyn Operator, tol: f64) -> Result<(Vec<f64>, usize)> {
    let n = t.len();
    let areas = t.areas();
    let ones = vec![1.0; n];
    let mut logg = vec![0.0; n];
    let mut g = ones.clone();
    let mut sums = t.matvec_scaled(Some(&g), &ones);
    let mut err = closure_error(&sums, areas);
    let mut total = 0;
    for _ in 0..MAX_NEWTON {
        if err <= tol {
            break;
        }
        // Newton step: Σ_j w_ij (u_i + u_j) = A_i − Σ_j w_ij with w = the current scaled s,
        // then g ← g·exp(u). The operator's diagonal is Σ_j w_ij + w_ii.
        let r: Vec<f64> = areas.iter().zip(&sums).map(|(a, s)| a - s).collect();
        let diag: Vec<f64> = (0..n).map(|i| sums[i] + t.self_term(i) * g[i] * g[i]).collect();
        let apply = Linear {
            n,
            apply: |x: &[f64], y: &mut [f64]| {
                let wx = t.matvec_scaled(Some(&g), x);
                y.iter_mut().zip(wx).zip(&sums).zip(x).for_each(|(((y, w), s), x)| *y = w + s * x);
            },
        };
        // Inexact Newton: each step solved to the current closure error (quadratic
        // convergence is kept), never looser than NEWTON_FORCING.
        let goal = err.clamp(CG_TOL, NEWTON_FORCING);
        let (u, info) = cg(&apply, &diag, &r, goal, max_iter(n));
        let (it, res) = (info.iterations, info.residual);
        total += it;
        if res > goal && res > 1e-8 {
            return Err(Error::Compute(format!(
                "closure constraints have no solution (CG stopped at relative residual {res:.3e} after \
                 {it} iterations): a group of patches that see only each other has unequal areas on its two sides"
            )));
        }
        // Backtrack until the closure error falls.
        let mut step = 1.0;
        loop {
            let trial: Vec<f64> = logg.iter().zip(&u).map(|(l, u)| l + step * u).collect();
            let tg: Vec<f64> = trial.iter().map(|l| l.exp()).collect();
            let ts = t.matvec_scaled(Some(&tg), &ones);
            let e = closure_error(&ts, areas);
            if e < err || step < 1e-3 {
                (logg, g, sums, err) = (trial, tg, ts, e);
                break;
            }
            step *= 0.5;
        }
    }
    if err > tol {
        return Err(Error::Compute(format!(
            "symmetric scaling did not converge: closure error {err:.3e} after {MAX_NEWTON} Newton steps"
        )));
    }
    Ok((g, total))
}

/// The scales g ≤ 1 that bring rows whose sum exceeds A_i(1 + tol) down to Σ_j S_ij ≤ A_i,
/// by g_i ← min(1, √(g_i A_i / (S̄g)_i)), and the sweeps spent.
pub fn capped_scales(t: &dyn Operator, tol: f64) -> Result<(Vec<f64>, usize)> {
    let n = t.len();
    let areas = t.areas();
    let mut g = vec![1.0; n];
    for sweep in 0..MAX_CAPPED {
        let r = t.matvec_scaled(None, &g);
        let over = (0..n).any(|i| g[i] * r[i] > areas[i] * (1.0 + tol));
        if !over {
            return Ok((g, sweep));
        }
        for i in 0..n {
            if r[i] > 0.0 {
                g[i] = (g[i] * areas[i] / r[i]).sqrt().min(1.0);
            }
        }
    }
    Err(Error::Compute(format!("capped scaling of over-full rows did not converge in {MAX_CAPPED} sweeps")))
}
