//! The `solve` run on the hierarchical exchange ([`crate::exchange::hierarchy`]): links built
//! for the relative heat-rate tolerance, enforced (closure or capped scaling with the
//! ambient), solved by the same Jacobi-preconditioned CG as the dense path, and each patch's
//! heat rate given an error estimate: the links' direct errors carried through the
//! inter-reflections ([`super::dense::propagate_errors`]).
use super::{Params, Solution};
use crate::exchange::hierarchy::Hierarchy;
use crate::exchange::{Enforce, EnforceReport};
use crate::scene::Scene;
use crate::Result;

/// Everything the hierarchical `solve` run produced.
#[derive(Debug, Clone)]
pub struct ClusteredRun {
    /// The per-patch solution, with heat-rate error estimates.
    pub solution: Solution,
    /// What enforcement did.
    pub report: EnforceReport,
    /// Build statistics.
    pub stats: crate::exchange::hierarchy::Stats,
}

/// Closure tolerance of the enforcement (as the dense path's default).
const CLOSURE_TOL: f64 = 1e-12;

/// Links for relative heat-rate tolerance `tol`, enforcement (`mode`) and the gray solve.
pub fn solve_scene(
    scene: &Scene,
    vf: &crate::viewfactor::Params,
    mode: Enforce,
    tol: f64,
    params: &Params,
) -> Result<ClusteredRun> {
    let mut h = Hierarchy::build(scene, vf, tol)?;
    let report = h.enforce(scene, mode, !scene.is_closed(), CLOSURE_TOL)?;
    let mut solution = super::dense::solve_operator(scene, &h, &h.names, h.ambient.as_deref(), params)?;
    let j: Vec<f64> = solution.results.iter().map(|r| r.radiosity).collect();
    let e_amb = scene.ambient.map(|a| crate::SIGMA * a.temperature.powi(4));
    let direct = h.heat_rate_errors(&j, e_amb);
    solution.heat_rate_error = Some(super::dense::propagate_errors(scene, &h, &direct)?);
    solution.info.solver = "conjugate gradients on the link hierarchy".into();
    Ok(ClusteredRun { solution, report, stats: h.stats })
}
