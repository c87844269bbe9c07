//! The policy for partly obstructed pairs: exact shadow integration (`analytic`) or, under
//! `auto`, the cheaper of shadow integration and Monte Carlo per pair ([`choose`]).
//!
//! The cost model of [`choose`]: shadow integration costs [`SHADOW_EVAL_NS`] ×
//! (1 + b·[`SHADOW_BLOCKER_FACTOR`]) per viewpoint, [`SHADOW_EVALS`] viewpoints at the minimum
//! depth, times about √(u/goal) for the refinement; Monte Carlo needs n = ¼(Z·u/goal)²
//! samples (Z = [`MC_SIGMAS`]) at [`MC_SAMPLE_NS`] × (1 + b·[`MC_BLOCKER_FACTOR`]) each, b the
//! number of partial blockers.

/// Default relative target of `analytic` on obstructed pairs: below the Gauss ladder's own
/// target (5e-8, `kernel::GAUSS_REL_TOL`), so shadows never dominate the method's error.
pub const EXACT_REL_TOL: f64 = 1e-8;
/// `analytic` splits every emitter at least once: four cells, 100 viewpoints, before trusting
/// the rules (the per-cell blocker checks then catch what coarse rules would miss).
pub const EXACT_MIN_DEPTH: u32 = 1;
/// `auto` also splits every emitter once: one cell's rules alone can agree on a wrong value.
pub const AUTO_MIN_DEPTH: u32 = 1;
/// Deepest split (4⁸ = 65 536 cells per pair at most), as View3D's maxO.
pub const MAX_DEPTH: u32 = 8;

/// How partly obstructed pairs are computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Policy {
    /// Shadow integration to `rel_tol` × the unobstructed value.
    Exact {
        /// Relative target.
        rel_tol: f64,
    },
    /// Cheapest estimator meeting `tol` on each F.
    Auto {
        /// Absolute goal on each F.
        tol: f64,
        /// Monte Carlo seed.
        seed: u64,
    },
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
