//! `auto`, the default method: per pair, the cheapest method that meets `--tolerance`.
//!
//! **Decision rule.** `--tolerance` τ is an absolute goal on each F, so on each exchange area
//! the goal is τ·A_i. Per pair (i, j):
//! 1. back-facing or coplanar → 0 (exact);
//! 2. no blocker reaches the pair (exact classification, [`super::analytic::obstruction`]) →
//!    the analytic ladder with relative target [`LADDER_SHARE`]·τ (F ≤ 1, so the absolute goal
//!    holds, and so does every row sum and surface total);
//! 3. one blocker holds the whole receiver in its umbra → 0 (exact);
//! 4. partly obstructed → the cheaper of two estimators of the obstructed value, both anchored
//!    on the exact unobstructed value u = (A_i F_ij)_unobstructed:
//!    - **analytic-shadowed**: u − ∫_E g dA with the adaptive shadow integration
//!      ([`super::analytic::adaptive`], rules 2×2 vs 3×3 per cell, the emitter split at least
//!      once, refined until the rules agree to τ·A_i); expected cost [`SHADOW_EVAL_NS`] ×
//!      (1 + b·[`SHADOW_BLOCKER_FACTOR`]) per viewpoint, [`SHADOW_EVALS`] viewpoints at the
//!      minimum depth, times about √(u/(τA_i)) for the refinement;
//!    - **Monte Carlo** ([`mc_pair`]): u·ΣKV/ΣK; its standard error is at most
//!      u·√(¼/n), so n = ¼(Z·u/(τA_i))² samples (Z = [`MC_SIGMAS`]) always meet the goal,
//!      at [`MC_SAMPLE_NS`] × (1 + b·[`MC_BLOCKER_FACTOR`]) each, b the number of blockers.
//!
//!    The entry records which one produced it (`analytic-shadowed` or `mc-area`).
//!
//! Effort therefore goes only where the error needs it: nothing is sampled for clear or fully
//! hidden pairs, and a small pair far below the goal costs a handful of samples.
pub mod mc_pair;

use super::analytic::kernel::AnalyticKernel;
use super::analytic::obstructed::Policy;
use super::Params;
use crate::scene::Scene;

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

/// Monte Carlo must meet the goal at this many standard errors (about 95 %).
pub const MC_SIGMAS: f64 = 2.0;
/// Fewest Monte Carlo samples per pair: the half-count prior keeps the reported error honest,
/// and eight Sobol points stratify both patches at least in halves.
pub const MC_MIN_SAMPLES: u32 = 8;
/// Most Monte Carlo samples per pair; above this the shadow integration is always cheaper.
pub const MC_MAX_SAMPLES: u32 = 1 << 16;
/// Measured cost of one Monte Carlo sample without blockers, ns (examples/obstructed_room.rs).
pub const MC_SAMPLE_NS: f64 = 25.0;
/// Extra cost of one blocker per Monte Carlo sample, relative.
pub const MC_BLOCKER_FACTOR: f64 = 0.3;
/// Measured cost of one shadow viewpoint without blockers (Lambert on the receiver), ns.
pub const SHADOW_EVAL_NS: f64 = 150.0;
/// Extra cost of one blocker per viewpoint (projection, clipping, union), relative.
pub const SHADOW_BLOCKER_FACTOR: f64 = 1.0;
/// Viewpoints at the minimum depth: four cells of 4 + 9 points (rules 2×2 vs 3×3). Lower
/// orders lose twice: one cell of 1 + 4 points can agree on a wrong value when a shadow sweeps
/// over the receiver's edge between the points, and at fine goals the 1 vs 2×2 pair needs
/// ~100× more cells than 2×2 vs 3×3 (both measured in tests/auto.rs).
pub const SHADOW_EVALS: f64 = 52.0;

/// How a partly obstructed pair is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Choice {
    /// Adaptive shadow integration to the absolute goal.
    Shadowed,
    /// Monte Carlo with this many samples.
    MonteCarlo(u32),
}

/// The decision for one partly obstructed pair with unobstructed exchange area `u`, absolute
/// goal `goal` on the exchange area and `blockers` partial blockers.
pub fn choose(u: f64, goal: f64, blockers: usize) -> Choice {
    let b = blockers as f64;
    let ratio = u / goal;
    let n = (0.25 * (MC_SIGMAS * ratio).powi(2)).ceil();
    let n = if n.is_finite() { n.max(MC_MIN_SAMPLES as f64) } else { f64::INFINITY };
    let mc = n * MC_SAMPLE_NS * (1.0 + b * MC_BLOCKER_FACTOR);
    let cells = ratio.max(1.0).sqrt();
    let shadow = cells * SHADOW_EVALS * SHADOW_EVAL_NS * (1.0 + b * SHADOW_BLOCKER_FACTOR);
    if n <= MC_MAX_SAMPLES as f64 && mc < shadow {
        Choice::MonteCarlo(n as u32)
    } else {
        Choice::Shadowed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_pairs_sample_large_pairs_integrate() {
        // A patch pair three metres apart in a room (u ≈ 2e-6 m²) at τ = 1e-4 on 0.0078 m².
        assert!(matches!(choose(2.2e-6, 1e-4 * 0.0078, 1), Choice::MonteCarlo(n) if n <= 16));
        // Two unit squares with a blocker (u ≈ 0.2 m²) at τ = 1e-4: shadow integration.
        assert_eq!(choose(0.2, 1e-4, 1), Choice::Shadowed);
        // Tighter goals move the balance towards integration.
        assert_eq!(choose(2.2e-6, 1e-9, 1), Choice::Shadowed);
    }
}
