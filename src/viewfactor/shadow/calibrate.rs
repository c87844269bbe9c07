//! `auto`'s prices measured on the scene itself: both estimators run on a few of the scene's
//! partly obstructed pairs, their counted work is fitted ([`fit`]) and the fitted
//! [`CostModel`] prices every pair.
//!
//! - **Which pairs** ([`sample_pairs`]): [`CAL_ROWS`] rows spread evenly over the patch
//!   indices are classified as the kernel would; of their partly obstructed pairs, those whose
//!   choice is open (Monte Carlo would need more than [`MC_MIN_SAMPLES`] and at most
//!   [`MC_MAX_SAMPLES`] samples) are listed in row order and [`CAL_PAIRS`] are taken evenly
//!   from the list. Chosen by index only.
//! - **What is measured** ([`measure`]): the Monte Carlo estimate as `auto` would run it
//!   (box and blocker tests per sample), and the shadow integration to the pair's goal, cut
//!   short at [`CAL_CAP`] × the sampling price ([`CAL_MIN_WORK`] at least): past that the
//!   choice is no longer close, and a pair behind a meshed body could cost seconds.
//! - **The fit**: W(b) = c·(1 + b)^γ through the shadow work divided by √max(1, u/goal), and
//!   T(b) through the tests per sample, by least squares in logarithms ([`power_law`]).
//! - **Deterministic**: counts, never clocks, and a serial loop: the same prices on every run
//!   and thread count. The sample pairs' results are discarded; the kernel computes them
//!   again in their rows (a few pairs).
//!
//! The unobstructed value u of a sample pair comes from the exact contour integral
//! ([`crate::viewfactor::exact::pair::polygon_polygon`]).
use super::branch::{PairAt, PairWork, Shadows};
use super::classify::{RowShadows, Status};
use super::policy::Policy;
use super::policy::{
    pair_goal, setup_units, CostModel, PowerLaw, MC_MAX_SAMPLES, MC_MIN_SAMPLES, MC_SAMPLE_NS, MC_TEST_NS,
    SHADOW_UNIT_NS,
};
use crate::scene::Scene;
use crate::viewfactor::exact::pair::polygon_polygon;

/// Rows classified to find sample pairs.
pub const CAL_ROWS: usize = 16;
/// Sample pairs measured: enough for a two-parameter fit per estimator, few enough to cost a
/// small share of a scene worth calibrating.
pub const CAL_PAIRS: usize = 12;
/// A sample's shadow integration stops at this multiple of its sampling price.
pub const CAL_CAP: f64 = 16.0;
/// ... but never below this much work (a plate's pair integrates in about a thousand units).
pub const CAL_MIN_WORK: u64 = 1 << 13;
/// Bounds of a fitted exponent: costs neither fall with the blockers nor grow faster than
/// their cube.
pub const EXP_RANGE: (f64, f64) = (0.0, 3.0);
/// Below this spread of ln(1 + b) over the samples the exponent is not fitted (the prior's is
/// kept, only the level is).
const MIN_SPREAD: f64 = 0.1;

/// One sample pair.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Row patch.
    pub i: usize,
    /// Receiver.
    pub j: usize,
    /// Unobstructed A_i F_ij, m².
    pub u: f64,
    /// Absolute goal on A_i F_ij, m².
    pub goal: f64,
    /// Partial blockers.
    pub partial: Vec<u32>,
}

impl Sample {
    /// The pair as the branch's estimators take it.
    pub fn at(&self) -> PairAt<'_> {
        PairAt::new(self.i, self.j, self.u, &self.partial)
    }
}

/// What the two estimators cost on one sample pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Partial blockers b.
    pub blockers: usize,
    /// u/goal.
    pub ratio: f64,
    /// Shadow work units (set-up [`setup_units`] included: the same charge the branch takes out of its cap).
    pub shadow_work: u64,
    /// The integration was cut short at its cap.
    pub capped: bool,
    /// Monte Carlo samples drawn.
    pub samples: u32,
    /// Their box and blocker tests.
    pub tests: u64,
}

impl<'s> Shadows<'s> {
    /// Collects the blockers of `scene`; `None` when nothing can block (convex enclosures).
    /// Under `auto` the pricing model is fitted to a few of the scene's own pairs
    /// ([`measure`], [`fit`]).
    pub fn new(scene: &'s Scene, policy: Policy) -> Option<Self> {
        let mut me = Self::uncalibrated(scene, policy)?;
        if let Policy::Auto { tol, seed } = policy {
            let measured = measure(&me, tol, seed);
            let model = fit(&measured, *me.model());
            me.set_model(model);
            let mut b: Vec<usize> = measured.iter().map(|m| m.blockers).collect();
            b.sort_unstable();
            if let Some(&median) = b.get(b.len() / 2) {
                me.set_typical_blockers(median.max(1));
            }
        }
        Some(me)
    }
}

/// The sample pairs of `shadows`' scene at the tolerance `tol` (see the module notes).
pub fn sample_pairs(shadows: &Shadows<'_>, tol: f64) -> Vec<Sample> {
    let scene = shadows.scene();
    let n = scene.patches.len();
    let mut rows: Vec<usize> = (0..CAL_ROWS).map(|k| (2 * k + 1) * n / (2 * CAL_ROWS)).collect();
    rows.dedup();
    let mut row = RowShadows::default();
    let mut open = Vec::new();
    for i in rows {
        shadows.classify_row(i, &mut row);
        let pi = &scene.patches[i].polygon;
        for j in i + 1..n {
            let Status::Partial(partial) = row.status(j) else { continue };
            let pj = &scene.patches[j].polygon;
            let goal = pair_goal(tol, pi.area(), pj.area());
            let u = polygon_polygon(pi, pj);
            let m = CostModel::samples(u, goal);
            if u > 0.0 && m > MC_MIN_SAMPLES as f64 && m <= MC_MAX_SAMPLES as f64 {
                open.push(Sample { i, j, u, goal, partial: partial.to_vec() });
            }
        }
    }
    let k = open.len();
    if k <= CAL_PAIRS {
        return open;
    }
    (0..CAL_PAIRS).map(|m| open[(2 * m + 1) * k / (2 * CAL_PAIRS)].clone()).collect()
}

/// Both estimators on the sample pairs of `shadows` at tolerance `tol`, in order.
pub fn measure(shadows: &Shadows<'_>, tol: f64, seed: u64) -> Vec<Measured> {
    let mut work = PairWork::default();
    sample_pairs(shadows, tol)
        .iter()
        .map(|p| {
            let b = p.partial.len();
            let n = CostModel::samples(p.u, p.goal) as u32;
            let mc = shadows.sample(p.at(), (n, p.goal), seed, &mut work);
            // The cap in shadow units: CAL_CAP times the sampling just measured.
            let mc_ns = mc.samples as f64 * MC_SAMPLE_NS + mc.tests as f64 * MC_TEST_NS;
            let cap = ((CAL_CAP * mc_ns / SHADOW_UNIT_NS) as u64).max(CAL_MIN_WORK);
            let sh = shadows.integrate(p.at(), p.goal, cap, &mut work);
            Measured {
                blockers: b,
                ratio: p.u / p.goal,
                shadow_work: capped_work(sh.info.work, sh.info.capped, cap) + setup_units(b),
                capped: sh.info.capped,
                samples: mc.samples,
                tests: mc.tests,
            }
        })
        .collect()
}

/// Work a calibration integration is charged: a capped one costs at least its cap, wherever it
/// stopped (at the cap, within a cell's rules, or once its roots projected past the cap).
fn capped_work(work: u64, capped: bool, cap: u64) -> u64 {
    if capped {
        work.max(cap)
    } else {
        work
    }
}

/// The cost model fitted to `measured`; `prior` where there is nothing to fit.
pub fn fit(measured: &[Measured], prior: CostModel) -> CostModel {
    let shadow: Vec<(usize, f64)> =
        measured.iter().map(|m| (m.blockers, m.shadow_work as f64 / m.ratio.max(1.0).sqrt())).collect();
    let mc: Vec<(usize, f64)> =
        measured.iter().map(|m| (m.blockers, m.tests as f64 / m.samples.max(1) as f64)).collect();
    CostModel { shadow: power_law(&shadow, prior.shadow), mc: power_law(&mc, prior.mc) }
}

/// Least-squares fit of ln y = ln c + γ·ln(1 + b) over the points (b, y > 0); `prior` when
/// there are none, the prior's exponent when the b hardly vary; γ within [`EXP_RANGE`].
pub fn power_law(points: &[(usize, f64)], prior: PowerLaw) -> PowerLaw {
    let pts: Vec<(f64, f64)> =
        points.iter().filter(|p| p.1 > 0.0).map(|&(b, y)| ((1.0 + b as f64).ln(), y.ln())).collect();
    if pts.is_empty() {
        return prior;
    }
    let k = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / k, pts.iter().map(|p| p.1).sum::<f64>() / k);
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let exp = if (sxx / k).sqrt() < MIN_SPREAD { prior.exp } else { sxy / sxx };
    let exp = exp.clamp(EXP_RANGE.0, EXP_RANGE.1);
    PowerLaw { c: (my - exp * mx).exp(), exp }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_capped_calibration_integration_is_charged_at_least_its_cap() {
        // Stopped early by the roots' projection (an eighth of the cap spent): charged the cap.
        assert_eq!(capped_work(125, true, 1000), 1000);
        // Stopped past the cap (the last cell ran over): charged what it spent.
        assert_eq!(capped_work(1100, true, 1000), 1100);
        // Finished below the cap: charged what it spent.
        assert_eq!(capped_work(400, false, 1000), 400);
    }

    #[test]
    fn power_law_recovers_its_parameters() {
        let truth = PowerLaw { c: 40.0, exp: 1.7 };
        let pts: Vec<(usize, f64)> = [1, 3, 10, 40, 120].iter().map(|&b| (b, truth.at(b))).collect();
        let fitted = power_law(&pts, PowerLaw { c: 1.0, exp: 1.0 });
        assert!((fitted.c - 40.0).abs() < 1e-9 && (fitted.exp - 1.7).abs() < 1e-12, "{fitted:?}");
        // One blocker count only: the prior's exponent, the level fitted.
        let fitted = power_law(&[(5, 60.0), (5, 60.0)], PowerLaw { c: 1.0, exp: 1.0 });
        assert!((fitted.exp - 1.0).abs() < 1e-15 && (fitted.at(5) - 60.0).abs() < 1e-9, "{fitted:?}");
        // Nothing measured: the prior.
        let prior = PowerLaw { c: 3.0, exp: 0.5 };
        assert_eq!(power_law(&[], prior), prior);
    }
}
