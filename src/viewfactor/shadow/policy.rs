//! The policy for partly obstructed pairs: exact shadow integration (`analytic`) or, under
//! `auto`, the cheaper of shadow integration and Monte Carlo per pair, priced by a
//! [`CostModel`].
//!
//! **Prices.** Both estimators are priced in counted work, converted to nanoseconds by fixed
//! ratios ([`SHADOW_UNIT_NS`], [`MC_SAMPLE_NS`], [`MC_TEST_NS`]):
//! - shadow integration: W(b)·√max(1, u/goal) work units
//!   (`super::adaptive::AdaptInfo::work`), the √ for the cells the 2×2-vs-3×3 refinement
//!   adds as the goal tightens;
//! - Monte Carlo: n = ¼(Z·u/goal)² samples (Z = [`MC_SIGMAS`]), each [`MC_SAMPLE_NS`] plus
//!   T(b) box and blocker tests (`super::segtree`);
//!
//! b being the pair's number of partial blockers. W(b) = c·(1 + b)^γ and T(b) likewise are
//! power laws **fitted on the scene itself** ([`super::calibrate`]): a pair behind a 1,280-facet
//! sphere needs hundreds of times more viewpoints than a pair behind one plate (every facet's
//! shadow must be sampled before a cell is trusted), which no fixed constant prices. Without
//! sample pairs the prior ([`CostModel::default`]) is used. Counts, not clocks, decide: the
//! choice is the same on every run and thread count.
use super::adaptive::{AdaptParams, Cuts};
use super::viewpoint::VIEWPOINT_WORK;

/// Default relative target of `analytic` on obstructed pairs: below the Gauss ladder's own
/// target (5e-8, `kernel::GAUSS_REL_TOL`), so shadows never dominate the method's error.
pub const EXACT_REL_TOL: f64 = 1e-8;
/// `analytic` trusts a root cell's rules without a forced split: its roots are already cut along
/// every kink of g (`adaptive::split_cells`), where g is smooth, and the per-cell blocker
/// checks catch a body whose shadow no rule point saw.
pub const EXACT_MIN_DEPTH: u32 = 0;
/// Gauss orders per direction of `analytic`'s rule pair: on cells where g is smooth the 4×4 vs
/// 5×5 difference meets 1e-8 without splits where 3×3 vs 4×4 needed about three per pair
/// (box_500_block: 229 against 471 viewpoints per pair, same accuracy). On triangles the
/// higher one is the 16-point symmetric rule of the same degree (`adaptive::triangle_rule`):
/// box_2k_block 125 → 112 viewpoints per pair, the same cells. A 20-point degree-9 rule in
/// place of the 5×5 product on parallelograms and quadrilaterals (100 viewpoints) was not
/// kept: its own error is not far enough below the 4×4 product's to stand behind their
/// difference (the concentric boxes' F(outer → outer) 1.6e-8 off).
pub const EXACT_RULES: (usize, usize) = (4, 5);
/// Fewest faces of a convex solid behind which the shadow branch (`analytic`, and `auto` where
/// it integrates) sums the blocked exchange over the solid's faces (`super::solid`) instead of
/// integrating the shadow. A facetted curved body makes the shadow kink at every face plane
/// crossing the emitter, and the shadow integration came out wrong behind it: sphere_room 1e-5
/// of u off at 1e5 viewpoints per pair, the concentric spheres' F(outer → outer) 1.5e-8 off;
/// the facet sum agrees with the independent integrations at 660 viewpoints per pair. A block's
/// few large faces integrate faster as a shadow (box_500_block: 157 against 1,630 viewpoints
/// per pair, same values within 6e-10).
pub const SOLID_MIN_FACES: usize = 16;
/// Gauss orders per direction of `auto`'s rule pair: at a goal of 1e-4 on F the 2×2 vs 3×3
/// difference is trusted only with the minimum depth below ([`AUTO_MIN_DEPTH`]) and the
/// per-cell blocker checks, and is priced per viewpoint by the cost model.
pub const AUTO_RULES: (usize, usize) = (2, 3);
/// `auto` accepts no cell larger than a quarter of the emitter on its own rules: one cell's
/// rules alone can agree on a wrong value. Root cells already cut smaller along kink planes
/// are not split again (behind a 200-facet part their forced split quadrupled the viewpoints).
pub const AUTO_MIN_DEPTH: u32 = 1;
/// `auto` cuts the emitter along at most 64 pieces' worth of kink planes, the blockers' own
/// planes last (`Cuts::faces_last`); the adaptivity takes the rest. A curved meshed part
/// puts a face plane across the emitter per facet, and cutting along all of them (the 256
/// pieces of `analytic`) made a wall pair behind a 200-facet finger cost 20,000 viewpoints
/// for an error 30× below its goal. Measured against `analytic` on the real parts
/// (validation/cad.md): at 64 pieces every entry stays within its goal with a 4× margin;
/// at 16 a heat-sink entry ended at 1.08× its goal, at 4 a finger entry at 15×.
pub const AUTO_CUTS: Cuts = Cuts::up_to(64, true);
/// Deepest split (4⁸ = 65 536 cells per pair at most), as View3D's maxO.
pub const MAX_DEPTH: u32 = 8;

/// `analytic`'s integration controls: [`EXACT_RULES`], [`EXACT_MIN_DEPTH`], [`MAX_DEPTH`].
pub const EXACT_ADAPT: AdaptParams =
    AdaptParams { low: EXACT_RULES.0, high: EXACT_RULES.1, min_depth: EXACT_MIN_DEPTH, max_depth: MAX_DEPTH };
/// `auto`'s integration controls: [`AUTO_RULES`], [`AUTO_MIN_DEPTH`], [`MAX_DEPTH`].
pub const AUTO_ADAPT: AdaptParams =
    AdaptParams { low: AUTO_RULES.0, high: AUTO_RULES.1, min_depth: AUTO_MIN_DEPTH, max_depth: MAX_DEPTH };

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

/// `auto`'s absolute goal on the exchange area A_i F_ij = A_j F_ji of a pair: `tol`·min(A_i, A_j),
/// so that both F_ij and F_ji are within `tol`. A goal of `tol`·A_i alone lets a small patch
/// facing a large one carry an error of `tol`·A_i/A_j on its F_ji (a part's triangle beside a
/// room wall: thousands of times the goal).
pub fn pair_goal(tol: f64, area_i: f64, area_j: f64) -> f64 {
    tol * area_i.min(area_j)
}

/// Monte Carlo must meet the goal at this many standard errors (about 95 %).
pub const MC_SIGMAS: f64 = 2.0;
/// Fewest Monte Carlo samples per pair: the half-count prior keeps the reported error honest,
/// and eight Sobol points stratify both patches at least in halves.
pub const MC_MIN_SAMPLES: u32 = 8;
/// A sample starts at this share of the worst-case count ¼(Z·u/goal)² (the count a ratio of ½
/// needs) and doubles until its standard error meets the goal: a pair mostly hidden or mostly
/// seen needs r(1 − r)/¼ of it (a channel wall pair at r = 0.08 a third, at r = 0.99 a
/// twenty-fifth), and the doubling stops there instead of drawing the worst case.
pub const MC_PILOT_SHARE: f64 = 1.0 / 16.0;
/// The first draw of a sample whose worst case is `n` points ([`MC_PILOT_SHARE`] of it, at least
/// [`MC_MIN_SAMPLES`]).
pub fn pilot(n: u32) -> u32 {
    share_of(n, MC_PILOT_SHARE)
}
/// `share` of a worst case of `n` points, rounded up, at least [`MC_MIN_SAMPLES`] (at most `n`).
fn share_of(n: u32, share: f64) -> u32 {
    ((f64::from(n) * share).ceil() as u32).clamp(MC_MIN_SAMPLES.min(n), n)
}
/// Share of the worst-case sample a probe draws to price the sample for its pair's own
/// shadow (`super::branch`): a quarter of [`MC_PILOT_SHARE`]. On pairs that end integrated
/// the probe is pure cost (a finger triangle's wall pairs: 135 µs of a 460 µs integration at
/// a sixteenth); a quarter of that still tells a pair a tenth in shadow from one half in
/// shadow, and the sample, where drawn, starts from its own pilot (validation/cad.md).
pub const MC_PROBE_SHARE: f64 = 1.0 / 64.0;
/// The points a probe draws for a sample whose worst case is `n` points ([`MC_PROBE_SHARE`]
/// of it, at least [`MC_MIN_SAMPLES`]).
pub fn probe_pilot(n: u32) -> u32 {
    share_of(n, MC_PROBE_SHARE)
}
/// Most Monte Carlo samples per pair; above this the shadow integration is always cheaper.
pub const MC_MAX_SAMPLES: u32 = 1 << 16;
/// Cost of one Monte Carlo sample besides its segment tests (two Sobol points, the kernel, the
/// tree walk's set-up), ns: `examples/price_units.rs`, one thread on 2 shared cores, least
/// squares over the calibration pairs (63 ns on sphere_room's parallelograms, 99 ns on
/// box_500_block's triangles).
pub const MC_SAMPLE_NS: f64 = 80.0;
/// Cost of one box or blocker test of a Monte Carlo sample, ns (same measurement: 19 and 12).
pub const MC_TEST_NS: f64 = 15.0;
/// Cost of one unit of shadow-integration work (`super::adaptive::AdaptInfo::work`: a
/// viewpoint counts [`VIEWPOINT_WORK`], a blocker projected, a shadow piece subtracted or a
/// blocker re-classified one), ns (same measurement: 55 and 63).
pub const SHADOW_UNIT_NS: f64 = 60.0;
/// Work units a shadow-integrated pair costs before its first viewpoint (the blockers clipped,
/// the pair's frame and kink splits built): 6–24 µs measured on pairs that end there.
pub const SHADOW_SETUP_UNITS: u64 = 128;
/// Work units per partial blocker of an integration's set-up before its first root cell (the
/// blockers clipped to the pair, the kink cuts): 1.7–2.3 µs a blocker on the wall pairs behind
/// finger_n4's part (38–140 blockers, 75 roots), 4 µs in all on its pairs of under 10
/// (`shadow_stats`, one thread).
pub const SHADOW_SETUP_BLOCKER_UNITS: u64 = 32;
/// Work units of an integration's set-up for `blockers` partial blockers.
pub fn setup_units(blockers: usize) -> u64 {
    SHADOW_SETUP_UNITS + SHADOW_SETUP_BLOCKER_UNITS * blockers as u64
}
/// Share of the probed sample's price within which a pair priced for integration is integrated
/// before it is sampled (`super::branch`): the capped attempt is thrown away, so a smaller
/// share wastes less on pairs the model underprices (the wall pairs behind a meshed part) and
/// samples more of those it prices right. One thread, side by side against the whole price:
/// ½ and ¼ took finger_n4 0.40 → 0.31 / 0.30 CPU-s and the two fingers 1.93 → 1.74 / 1.67, the
/// heat sink, U-channel and boards unchanged or 2–7 % faster; ⅛ gained 3 % more on the
/// fingers and lost 5 % on the heat sink and the boards.
pub const CAP_PRICE_SHARE: f64 = 0.25;
/// Multiple of the model's price at which the integration of a pair whose worst-case sample is
/// past [`MC_MAX_SAMPLES`] stops to draw a probe (`super::branch`). On the two fingers and the
/// heat sink every such pair that ended integrated did so within 64× its price (39 of them
/// at 16–64×), and each of the 24 past it (64–1,024×, 5 ms each) was a triangle beside a
/// sliver neighbour, refined to the depth limit with no shadow found: its sample took 60–230 µs.
pub const OVERRUN_RATIO: f64 = 64.0;
/// Prior viewpoints per pair at u ≤ goal: four cells of 4 + 9 points (rules 2×2 vs 3×3).
/// Lower orders lose twice: one cell of 1 + 4 points can agree on a wrong value when a shadow
/// sweeps over the receiver's edge between the points, and at fine goals the 1 vs 2×2 pair
/// needs ~100× more cells than 2×2 vs 3×3 (both measured in tests/auto.rs).
pub const SHADOW_EVALS: f64 = 52.0;

/// y = c·(1 + b)^exp, b the number of partial blockers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerLaw {
    /// Value at b = 0.
    pub c: f64,
    /// Exponent.
    pub exp: f64,
}

impl PowerLaw {
    /// The value at `b` blockers.
    pub fn at(&self, b: usize) -> f64 {
        self.c * (1.0 + b as f64).powf(self.exp)
    }
}

/// Price of Monte Carlo with `n` samples of `tests` box and blocker tests each, ns.
pub fn mc_ns_at(n: f64, tests: f64) -> f64 {
    n * (MC_SAMPLE_NS + MC_TEST_NS * tests)
}

/// The prices of one scene's partly obstructed pairs (see the module notes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostModel {
    /// Shadow work units per pair at u ≤ goal, set-up included.
    pub shadow: PowerLaw,
    /// Box and blocker tests per Monte Carlo sample.
    pub mc: PowerLaw,
}

impl Default for CostModel {
    /// The prior: [`SHADOW_EVALS`] viewpoints of [`VIEWPOINT_WORK`]·(1 + b) units each (a
    /// bound on [`VIEWPOINT_WORK`] + b), 1 + b tests per sample (a scan). Used where the scene
    /// has no sample pairs to measure.
    fn default() -> Self {
        let c = SHADOW_EVALS * VIEWPOINT_WORK as f64;
        Self { shadow: PowerLaw { c, exp: 1.0 }, mc: PowerLaw { c: 1.0, exp: 1.0 } }
    }
}

impl CostModel {
    /// Monte Carlo samples that meet the goal whatever the penumbra: ¼(Z·u/goal)², at least
    /// [`MC_MIN_SAMPLES`]; infinite for a zero goal.
    pub fn samples(u: f64, goal: f64) -> f64 {
        let n = (0.25 * (MC_SIGMAS * u / goal).powi(2)).ceil();
        if n.is_finite() {
            n.max(MC_MIN_SAMPLES as f64)
        } else {
            f64::INFINITY
        }
    }
    /// Price of shadow integration, ns.
    pub fn shadow_ns(&self, u: f64, goal: f64, blockers: usize) -> f64 {
        (u / goal).max(1.0).sqrt() * self.shadow.at(blockers) * SHADOW_UNIT_NS
    }
    /// Price of Monte Carlo with `n` samples, ns.
    pub fn mc_ns(&self, n: f64, blockers: usize) -> f64 {
        mc_ns_at(n, self.mc.at(blockers))
    }
    /// The decision for one partly obstructed pair with unobstructed exchange area `u`,
    /// absolute goal `goal` on the exchange area and `blockers` partial blockers.
    pub fn choose(&self, u: f64, goal: f64, blockers: usize) -> Choice {
        let n = Self::samples(u, goal);
        if n <= MC_MAX_SAMPLES as f64 && self.mc_ns(n, blockers) < self.shadow_ns(u, goal, blockers) {
            Choice::MonteCarlo(n as u32)
        } else {
            Choice::Shadowed
        }
    }
}

/// How a partly obstructed pair is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Choice {
    /// Adaptive shadow integration to the absolute goal.
    Shadowed,
    /// Monte Carlo with this many samples.
    MonteCarlo(u32),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_pairs_sample_large_pairs_integrate() {
        let prior = CostModel::default();
        // A patch pair three metres apart in a room (u ≈ 2e-6 m²) at τ = 1e-4 on 0.0078 m².
        assert!(matches!(prior.choose(2.2e-6, 1e-4 * 0.0078, 1), Choice::MonteCarlo(n) if n <= 16));
        // Two unit squares with a blocker (u ≈ 0.2 m²) at τ = 1e-4: shadow integration.
        assert_eq!(prior.choose(0.2, 1e-4, 1), Choice::Shadowed);
        // Tighter goals move the balance towards integration.
        assert_eq!(prior.choose(2.2e-6, 1e-9, 1), Choice::Shadowed);
    }

    #[test]
    fn a_steep_shadow_price_sends_many_blocker_pairs_to_sampling() {
        // u/goal = 150 (22,500 samples) behind 80 facets: the prior integrates; a scene whose
        // pairs were measured at c = 50, γ = 1.8 (viewpoints multiply with the facets) samples.
        let (u, goal, b) = (1.5e-2, 1e-4, 80);
        let prior = CostModel::default();
        assert_eq!(prior.choose(u, goal, b), Choice::Shadowed);
        let steep = CostModel { shadow: PowerLaw { c: 50.0, exp: 1.8 }, ..prior };
        assert!(matches!(steep.choose(u, goal, b), Choice::MonteCarlo(n) if n >= 22_500));
        // One blocker: the same measured law still integrates a large pair.
        assert_eq!(steep.choose(0.2, 1e-4, 1), Choice::Shadowed);
        // Cheaper sample tests (a box tree: T ∝ log b rather than b) also tip it.
        let tree = CostModel { mc: PowerLaw { c: 4.0, exp: 0.3 }, ..prior };
        assert!(matches!(tree.choose(u, goal, b), Choice::MonteCarlo(_)));
    }
}
