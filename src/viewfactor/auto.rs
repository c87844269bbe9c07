//! `auto`, the default method: per pair, the cheapest method that meets `--tolerance`.
//!
//! **Decision rule.** `--tolerance` τ is an absolute goal on each F in both directions, so on
//! each exchange area the goal is τ·min(A_i, A_j) ([`super::shadow::policy::pair_goal`]).
//! Per pair (i, j):
//! 1. back-facing or coplanar → 0 (exact);
//! 2. no blocker reaches the pair (exact classification, [`super::shadow::classify`]) →
//!    the analytic ladder with relative target [`LADDER_SHARE`]·τ (F ≤ 1, so the absolute goal
//!    holds, and so does every row sum and surface total);
//! 3. one blocker holds the whole receiver in its umbra → 0 (exact);
//! 4. partly obstructed → the cheaper of two estimators of the obstructed value, both anchored
//!    on the exact unobstructed value u = (A_i F_ij)_unobstructed, chosen per pair by
//!    the [`CostModel`](super::shadow::policy::CostModel) whose prices
//!    [`super::shadow::calibrate`] measures on a few of the scene's own pairs (the model and
//!    its constants live in [`super::shadow::policy`]):
//!    - **analytic-shadowed**: u − ∫_E g dA with the adaptive shadow integration
//!      (`super::shadow::adaptive`, rules 2×2 vs 3×3 per cell, cut along at most 64 pieces'
//!      worth of kink planes, no cell above a quarter of the emitter accepted on its own rules,
//!      refined until the rules agree to the goal);
//!    - **Monte Carlo** (`super::shadow::mc_pair`): u·ΣKV/ΣK; its standard error is at most
//!      u·√(¼/n) for independent equal-weight samples, so n = ¼(Z·u/goal)² samples are tried
//!      first; where the kernel weights leave it short at the sample cap, the pair is
//!      integrated instead.
//!
//!    A pair priced for integration that sampling could also meet is integrated within
//!    sampling's price (counted work) and sampled past it: the fitted prices can be far off
//!    for pairs unlike the calibration pairs (a wall pair behind a whole meshed part).
//!
//!    An entry whose error estimate still exceeds its goal (integration at its depth limit)
//!    is counted, and the run names the worst (`super::shadow::misses`).
//!
//!    The entry records which one produced it (`analytic-shadowed` or `mc-area`).
//!
//! Effort therefore goes only where the error needs it: nothing is sampled for clear or fully
//! hidden pairs, and a small pair far below the goal costs a handful of samples.
use super::accuracy::{Knob, MethodInfo};
use super::analytic::kernel::{AnalyticKernel, ANALYTIC_LEAK_TOL};
use super::engine::RowKernel;
use super::shadow::policy::Policy;
use super::Params;
use crate::scene::Scene;
use crate::Result;

/// Share of the tolerance given to the Gauss ladder on clear pairs, as a relative target:
/// a tenfold margin on the ladder's error model costs little (its rules converge
/// exponentially) and keeps the ladder's systematic error well inside every total.
pub const LADDER_SHARE: f64 = 0.1;

/// The `auto` kernel for `scene`: the analytic kernel with the [`Policy::Auto`] obstructed
/// branch and the ladder's relative target [`LADDER_SHARE`] × `--tolerance`.
pub fn kernel<'s>(scene: &'s Scene, params: &Params) -> AnalyticKernel<'s> {
    let tol = params.tolerance;
    AnalyticKernel::with_policy(scene, LADDER_SHARE * tol, Policy::Auto { tol, seed: params.seed })
}

/// The `auto` row of the method registry: error its goal; its own rows close to
/// [`ANALYTIC_LEAK_TOL`] (or the ladder's target if looser) only when every entry came from
/// the ladder, since sampled and shadow-integrated entries are covered by the general check.
pub const INFO: MethodInfo = MethodInfo {
    knob: Knob::Tolerance,
    symmetric: true,
    monte_carlo: false,
    counts_hits: false,
    exact_shadows: true,
    kernel: row_kernel,
    error_bound: |params, _| params.tolerance,
    own_leak_tol: |tolerance, all_ladder| {
        all_ladder().then(|| ANALYTIC_LEAK_TOL.max(LADDER_SHARE * tolerance))
    },
    colour: (crate::palette::GREY, true),
};

fn row_kernel<'a>(scene: &'a Scene, params: &Params) -> Result<Option<Box<dyn RowKernel + 'a>>> {
    Ok(Some(Box::new(kernel(scene, params))))
}
