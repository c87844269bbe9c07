//! The analytic [`RowKernel`]: row i, columns j > i, each pair by the cheapest exact-enough
//! rung of the ladder.
//!
//! Per row, when the scene has blockers, the receivers are first classified against them
//! ([`Shadows`]): clear, blocked by one blocker (F = 0), or partly blocked.
//!
//! Per pair, cheapest test first:
//! 1. same plane (plane id) → 0;
//! 2. one patch entirely behind the other's plane (bounding sphere, then vertices) → 0;
//! 3. blocked → 0;
//! 4. both patches entirely in front of each other's plane and far enough apart that the
//!    [`ErrorModel`] guarantees the per-pair relative target → tensor Gauss rules ("2AI");
//! 5. otherwise the exact double contour integral (clips straddling patches itself);
//! 6. partly blocked → the unobstructed value of 4–5 minus the shadowed part, under the
//!    kernel's [`Policy`] (exact shadow integration for `analytic`, the cheapest estimator
//!    meeting the tolerance for `auto`).
//!
//! The unobstructed value of 1–5 between two gridded surfaces whose grid steps match comes
//! from a table built once per lattice offset ([`super::lattice`]), not from the ladder.
use super::ladder::{gauss_exchange, ErrorModel, PatchRules, Points};
use super::lattice::{Reuse, RowLookup};
use crate::geometry::planes::PlaneGroups;
use crate::geometry::shaft::Shaft;
use crate::geometry::tolerance::PATCH_COPLANAR_REL;
use crate::scene::Scene;
use crate::viewfactor::accuracy::ANALYTIC_REL;
use crate::viewfactor::engine::{RawEntry, Row, RowKernel};
use crate::viewfactor::exact::pair::polygon_polygon_with_round_off;
use crate::viewfactor::flags::{Flag, FlagLog};
use crate::viewfactor::shadow::blockers::{bounds, Blockers};
use crate::viewfactor::shadow::branch::PairWork;
use crate::viewfactor::shadow::classify::{may_cut, Status};
use crate::viewfactor::shadow::detect::Occlusion;
use crate::viewfactor::shadow::policy::{pair_goal, CostModel, Policy, EXACT_REL_TOL, MC_MAX_SAMPLES};
use crate::viewfactor::shadow::{PairAt, ShadowScratch, Shadows};
use crate::viewfactor::{MethodSet, ViewFactors};
use crate::Result;
use glam::DVec3;
use std::cell::RefCell;
use std::sync::OnceLock;

/// A closed scene's row computed by this method alone that falls short of 1 by more than this
/// leaks (a gap, a flipped normal): every pair is exact or within [`GAUSS_REL_TOL`], so rows
/// close to 5e-8; 1e-6 leaves a 20× margin.
pub const ANALYTIC_LEAK_TOL: f64 = 1e-6;

/// Output rows of `vf` whose sum falls short of 1 by more than `tol` ([`ANALYTIC_LEAK_TOL`] for this
/// method's own rows), worst first, with their sums. Meaningful for closed scenes only.
pub fn leaks(vf: &ViewFactors, tol: f64) -> Vec<(usize, f64)> {
    let mut out: Vec<(usize, f64)> =
        vf.row_sums().into_iter().enumerate().filter(|&(_, s)| 1.0 - s > tol).collect();
    out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    out
}

/// Per-pair relative error target of the Gauss rungs: 5e-8 keeps every surface total within
/// 5e-8·F_IJ ≤ 1e-8 for F_IJ ≤ 0.2 (the cube's faces) and every row sum within 5e-8, while
/// letting most pairs of a 36²-per-face cube use 3×3-point rules.
pub const GAUSS_REL_TOL: f64 = 5e-8;

/// An exact entry is flagged when its round-off bound exceeds the method's promise
/// (`ANALYTIC_REL` relative) and this absolute error on F (the range check's slack), so
/// that factors far below round-off of the row (grazing pairs at 1e-15) stay quiet.
pub const FLAG_ABS: f64 = 1e-12;

/// Progress estimate only (never a number): a pair behind a plane, a clear front-facing pair,
/// ns. Guesses of the order (a plane test; a Gauss rule or contour integral); their ratio to
/// the shadow price matters, the report's measured rate fixes the overall scale.
const COST_ZERO_PAIR_NS: f64 = 10.0;
/// See [`COST_ZERO_PAIR_NS`].
const COST_CLEAR_PAIR_NS: f64 = 500.0;
/// Progress estimate only: the share of a row's front-facing receivers taken as partly hidden
/// when blockers stand in front of the emitter (a guess; which ones are is known only once
/// the row is classified), each priced by the scene's [`CostModel`] at its own u/goal.
const COST_PARTIAL_SHARE: f64 = 0.5;

/// Progress estimate only: the classification of a row per blocker it shadows from (a shadow
/// volume built, the patch tree walked near its boundary), ns: 2–7 µs measured on the
/// channel's rows (validation/cad.md); the last rows of a meshed part hold few pairs but
/// classify against thousands of the part's faces.
const COST_ROW_BLOCKER_NS: f64 = 4000.0;

/// Progress estimate only: the obstructed branch's prices at the scene's typical count of
/// partial blockers ([`Shadows::typical_blockers`]).
#[derive(Debug, Clone, Copy)]
struct PairPrices {
    /// One Monte Carlo sample, ns.
    sample_ns: f64,
    /// A shadow integration at u ≤ goal, ns.
    shadow_ns: f64,
}

/// Per-patch data the pair loop reads, packed for locality.
#[derive(Debug, Clone, Copy)]
struct PatchInfo {
    normal: DVec3,
    /// Plane offset n·x.
    offset: f64,
    centroid: DVec3,
    radius: f64,
    /// Unoriented plane group.
    plane: u32,
    /// 1 / Gauss parameter length (the L of the error model).
    inv_len: f64,
    /// Gauss rules on Duffy triangles (not one parallelogram).
    triangles: bool,
    /// Area (progress estimate only).
    area: f64,
}

/// Exact exchange areas for unobstructed planar patches.
pub struct AnalyticKernel<'s> {
    scene: &'s Scene,
    info: Vec<PatchInfo>,
    rules: PatchRules,
    model: ErrorModel,
    occlusion: OnceLock<Occlusion>,
    /// Blockers and the policy for partly blocked pairs; `None` when nothing can block.
    shadows: Option<Shadows<'s>>,
    /// The progress estimate's prices of a partly blocked pair, when something can block.
    prices: Option<PairPrices>,
    /// Unobstructed values shared by translated pairs of gridded surfaces.
    reuse: Reuse,
    /// Exact entries whose round-off bound exceeds the method's promise.
    flags: FlagLog,
    /// The absolute goal on F of `auto` (its `--tolerance`), 0 for `analytic`: a round-off
    /// bound below it breaks no promise and is not flagged.
    abs_goal: f64,
}

thread_local! {
    /// Per-thread buffers of the obstructed branch (reset per row; results never depend on
    /// their previous content).
    static SHADOW_SCRATCH: RefCell<ShadowScratch> = RefCell::new(ShadowScratch::default());
}

impl<'s> AnalyticKernel<'s> {
    /// Prepares planes, Gauss rules and blockers for `scene`, with the per-pair relative error
    /// target `rel_tol` for the Gauss rungs; obstructed pairs are integrated exactly
    /// ([`EXACT_REL_TOL`]).
    pub fn new(scene: &'s Scene, rel_tol: f64) -> Self {
        Self::with_policy(scene, rel_tol, Policy::Exact { rel_tol: EXACT_REL_TOL })
    }

    /// As [`Self::new`], with the given policy for partly blocked pairs.
    pub fn with_policy(scene: &'s Scene, rel_tol: f64, policy: Policy) -> Self {
        let mut kernel = Self::direct(scene, rel_tol, policy);
        kernel.reuse = Reuse::new(
            scene,
            |i, j| kernel.info[i].plane == kernel.info[j].plane,
            |scratch: &mut Scratch, i, j| kernel.pair(i, j, scratch),
        );
        kernel
    }

    /// As [`Self::with_policy`], evaluating every pair itself (no translated-pair tables): the
    /// reference for the tables' tests and benchmarks.
    pub fn direct(scene: &'s Scene, rel_tol: f64, policy: Policy) -> Self {
        let polys = scene.patches.iter().map(|p| &p.polygon);
        let scale = polys.clone().map(|p| p.bounding_radius()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let extent = scene
            .patches
            .iter()
            .map(|p| p.polygon.centroid().length() + p.polygon.bounding_radius())
            .fold(scale, f64::max);
        let planes = PlaneGroups::new(polys.clone(), extent, PATCH_COPLANAR_REL * extent);
        let rules = PatchRules::new(polys);
        let info = scene
            .patches
            .iter()
            .enumerate()
            .map(|(p, patch)| {
                let poly = &patch.polygon;
                PatchInfo {
                    normal: poly.normal(),
                    offset: poly.normal().dot(poly.centroid()),
                    centroid: poly.centroid(),
                    radius: poly.bounding_radius(),
                    plane: planes.id[p],
                    inv_len: 1.0 / rules.param_len(p),
                    triangles: rules.triangulated(p),
                    area: poly.area(),
                }
            })
            .collect();
        let shadows = Shadows::new(scene, policy);
        let prices = shadows.as_ref().map(|s| {
            let (model, b) = (s.model(), s.typical_blockers());
            PairPrices { sample_ns: model.mc_ns(1.0, b), shadow_ns: model.shadow_ns(1.0, 1.0, b) }
        });
        AnalyticKernel {
            scene,
            info,
            rules,
            model: ErrorModel::new(rel_tol),
            occlusion: OnceLock::new(),
            shadows,
            prices,
            reuse: Reuse::default(),
            flags: FlagLog::default(),
            abs_goal: match policy {
                Policy::Auto { tol, .. } => tol,
                Policy::Exact { .. } => 0.0,
            },
        }
    }

    /// The table of translated pairs (for diagnostics).
    pub fn reuse(&self) -> &Reuse {
        &self.reuse
    }

    /// The blocker detector (for diagnostics and tests), built on first use.
    pub fn occlusion(&self) -> &Occlusion {
        self.occlusion.get_or_init(|| Occlusion::new(self.scene))
    }

    /// The blockers and policy of the obstructed branch, when the scene has blockers.
    pub fn shadows(&self) -> Option<&Shadows<'s>> {
        self.shadows.as_ref()
    }

    /// Progress estimate only: the blockers the classification of row i shadows from (those
    /// in front of patch i's plane, less a solid's faces turned away from it); `ids` is scratch.
    pub fn row_blockers(&self, i: usize, ids: &mut Vec<u32>) -> usize {
        let Some(shadows) = self.shadows.as_ref() else { return 0 };
        crate::viewfactor::shadow::classify::row_blockers(
            shadows.blockers(),
            &self.scene.patches[i].polygon,
            ids,
        );
        ids.len()
    }

    /// Progress estimate only: the cost (ns) of row i over the receivers `js`, each pair's
    /// `Self::pair_cost` plus the row's classification against its [`Self::row_blockers`]
    /// shadow volumes, which a row whose receivers all face away skips unless it is
    /// `always_classified` (the hierarchy classifies every row of patch pairs it hands over);
    /// `ids` is scratch.
    pub fn row_cost(
        &self,
        i: usize,
        js: impl IntoIterator<Item = usize>,
        ids: &mut Vec<u32>,
        always_classified: bool,
    ) -> f64 {
        let b = self.row_blockers(i, ids);
        let (mut pairs, mut facing) = (0.0, always_classified);
        for j in js {
            let c = self.pair_cost(i, j, b > 0);
            facing |= c > COST_ZERO_PAIR_NS;
            pairs += c;
        }
        if facing {
            b as f64 * COST_ROW_BLOCKER_NS + pairs
        } else {
            pairs
        }
    }

    /// Progress estimate only: the cost (ns) of pair (i, j) in row i, `shaded` when blockers
    /// stand in front of patch i ([`Self::row_blockers`] > 0). A pair behind a plane costs
    /// [`COST_ZERO_PAIR_NS`]; a front-facing one a clear pair plus, in a shaded row,
    /// [`COST_PARTIAL_SHARE`] of its price if partly obstructed ([`Self::partial_price`]).
    fn pair_cost(&self, i: usize, j: usize, shaded: bool) -> f64 {
        if !self.may_face(i, j) {
            return COST_ZERO_PAIR_NS;
        }
        match self.prices.filter(|_| shaded) {
            Some(prices) => COST_CLEAR_PAIR_NS + COST_PARTIAL_SHARE * self.partial_price(prices, i, j),
            None => COST_CLEAR_PAIR_NS,
        }
    }

    /// Progress estimate only: the price (ns) of pair (i, j) if partly obstructed. Under `auto`
    /// its unobstructed value u comes from the centroids (the point-to-point kernel, at most
    /// the smaller area): the pair costs the sampling that meets its goal (an integration tried
    /// first stops within that price), or the integration where sampling would need more than
    /// [`MC_MAX_SAMPLES`]. A wall patch facing a small facet has u far above the facet's goal
    /// (thousands of samples), a facet facing a far facet a few samples: u/goal sets most of
    /// the difference between rows. Under `analytic` the goal is relative: every partial pair
    /// costs alike.
    fn partial_price(&self, prices: PairPrices, i: usize, j: usize) -> f64 {
        if self.abs_goal <= 0.0 {
            return prices.shadow_ns;
        }
        let (p, q) = (&self.info[i], &self.info[j]);
        let d = q.centroid - p.centroid;
        let d2 = d.length_squared().max(f64::MIN_POSITIVE);
        let cos2 = p.normal.dot(d).max(0.0) * (-q.normal.dot(d)).max(0.0) / d2;
        let u = (p.area * q.area * cos2 / (std::f64::consts::PI * d2)).min(p.area.min(q.area));
        let goal = pair_goal(self.abs_goal, p.area, q.area);
        let n = CostModel::samples(u, goal);
        if n > MC_MAX_SAMPLES as f64 {
            (u / goal).max(1.0).sqrt() * prices.shadow_ns
        } else {
            n * prices.sample_ns
        }
    }

    /// Lowest and highest signed distance of patch `q`'s vertices from the plane of patch
    /// `p`, from the bounding sphere when it decides the sign.
    #[inline]
    fn extent(&self, p: &PatchInfo, q: usize) -> (f64, f64) {
        let b = &self.info[q];
        let d = p.normal.dot(b.centroid) - p.offset;
        if d.abs() >= b.radius {
            return (d - b.radius, d + b.radius);
        }
        self.scene.patches[q].polygon.vertices().iter().fold(
            (f64::INFINITY, f64::NEG_INFINITY),
            |(lo, hi), v| {
                let d = p.normal.dot(*v) - p.offset;
                (lo.min(d), hi.max(d))
            },
        )
    }

    /// False when one patch of (i, j) is behind the other's plane by its bounding sphere alone
    /// (a cheap, one-sided test: true may still be a zero pair).
    #[inline]
    fn may_face(&self, i: usize, j: usize) -> bool {
        let (a, b) = (&self.info[i], &self.info[j]);
        a.plane != b.plane
            && a.normal.dot(b.centroid) - a.offset + b.radius > 0.0
            && b.normal.dot(a.centroid) - b.offset + a.radius > 0.0
    }

    /// Which rung of the ladder treats the unobstructed pair (i, j), j ≠ i.
    pub fn rung(&self, i: usize, j: usize) -> Rung {
        let (a, b) = (&self.info[i], &self.info[j]);
        if a.plane == b.plane {
            return Rung::Zero;
        }
        // j seen from i's plane, and i from j's.
        let (jlo, jhi) = self.extent(a, j);
        if jhi <= 0.0 {
            return Rung::Zero;
        }
        let (ilo, ihi) = self.extent(b, i);
        if ihi <= 0.0 {
            return Rung::Zero;
        }
        if jlo >= 0.0 && ilo >= 0.0 {
            let sphere = a.centroid.distance(b.centroid) - a.radius - b.radius;
            let d = sphere.max(jlo).max(ilo);
            // Each patch's cosine factor varies over the *other* patch: ν_i from i's extent in
            // j's plane, ν_j from j's extent in i's plane.
            let mi = self.model.order(a.triangles, d * a.inv_len, ilo, ihi);
            let mj = self.model.order(b.triangles, d * b.inv_len, jlo, jhi);
            if let (Some(mi), Some(mj)) = (mi, mj) {
                return Rung::Gauss(mi, mj);
            }
        }
        Rung::Exact
    }

    /// Unobstructed A_i F_ij for one pair (j ≠ i), from the translated-pair tables when
    /// they hold it.
    #[inline]
    fn unobstructed(&self, i: usize, j: usize, reuse: &mut RowLookup, scratch: &mut Scratch) -> f64 {
        match reuse.get(j) {
            Some(s) => s,
            None => self.pair(i, j, scratch),
        }
    }

    /// Unobstructed A_i F_ij for one pair (j ≠ i), evaluated.
    fn pair(&self, i: usize, j: usize, scratch: &mut Scratch) -> f64 {
        match self.rung(i, j) {
            Rung::Zero => 0.0,
            Rung::Gauss(mi, mj) => {
                let (a, b) = (&self.info[i], &self.info[j]);
                let Scratch { rule_i, rule_j, weights } = scratch;
                let pi = self.rules.points(i, mi, rule_i);
                let pj = self.rules.points(j, mj, rule_j);
                gauss_exchange(pi, a.normal, a.offset, pj, b.normal, b.offset, weights)
            }
            Rung::Exact => {
                let (pi, pj) = (&self.scene.patches[i].polygon, &self.scene.patches[j].polygon);
                let x = polygon_polygon_with_round_off(pi, pj);
                let area = pi.area().min(pj.area());
                let promise = (ANALYTIC_REL * x.value).max(FLAG_ABS.max(self.abs_goal) * area);
                if x.round_off > promise {
                    self.flags.push(Flag {
                        from: i,
                        to: j,
                        method: MethodSet::ANALYTIC,
                        note: format!(
                            "F = {} has a round-off bound of {:.1e} relative, above the method's {ANALYTIC_REL:e} \
                             (both polygons long against their distance?)",
                            x.value / pi.area(),
                            x.round_off / x.value
                        ),
                    });
                }
                x.value
            }
        }
    }
}

impl<'s> AnalyticKernel<'s> {
    /// The entry of pair (i, j) given its shadow status; None when blocked, or zero without an
    /// error.
    #[inline]
    fn entry(
        &self,
        shadows: &Shadows<'s>,
        i: usize,
        j: usize,
        status: Status<'_>,
        (reuse, scratch): (&mut RowLookup<'_>, &mut Scratch),
        work: &mut PairWork,
    ) -> Option<RawEntry> {
        let entry = match status {
            Status::Blocked => return None,
            Status::Clear => RawEntry {
                j: j as u32,
                method: MethodSet::ANALYTIC,
                s: self.unobstructed(i, j, reuse, scratch),
                var: 0.0,
            },
            Status::Partial(partial) => {
                let u = self.unobstructed(i, j, reuse, scratch);
                if !(u > 0.0) {
                    return None;
                }
                let r = shadows.pair(PairAt::new(i, j, u, partial), work);
                RawEntry { j: j as u32, method: r.method, s: r.s, var: r.var }
            }
        };
        // A zero Monte Carlo estimate (every sample blocked) keeps its variance.
        (entry.s > 0.0 || entry.var > 0.0).then_some(entry)
    }

    /// Exchange areas A_i F_ij of patch i with the receivers `js` (ascending, any j ≠ i),
    /// exactly as [`RowKernel::row`] computes them; entries with s = 0 are left out. Blockers
    /// are classified only within the box of the receivers; a pair keeps those that meet its
    /// own box (`Near`), so its entry is the same whichever receivers share the call.
    pub fn partners(&self, i: usize, js: &[u32], out: &mut Vec<RawEntry>) {
        let mut scratch = Scratch::default();
        let mut reuse = self.reuse.row(i);
        let Some(shadows) = &self.shadows else {
            for &j in js {
                let s = self.unobstructed(i, j as usize, &mut reuse, &mut scratch);
                if s > 0.0 {
                    out.push(RawEntry { j, method: MethodSet::ANALYTIC, s, var: 0.0 });
                }
            }
            return;
        };
        let near = Near::new(self.scene, shadows, i);
        let mut kept = Vec::new();
        SHADOW_SCRATCH.with_borrow_mut(|ShadowScratch { row, work }| {
            shadows.classify_row_in(i, js, row);
            for &j in js {
                let status = near.status(j as usize, row.status(j as usize), &mut kept);
                out.extend(self.entry(shadows, i, j as usize, status, (&mut reuse, &mut scratch), work));
            }
        });
    }
}

/// The partial blockers of a row's pairs cut to those that may cut the pair's own sight lines
/// (`classify::may_cut`: its box shaft, in front of the receiver), so an entry does not depend
/// on which other receivers share the row (whose shafts limit the row's classification) nor
/// on the process that holds them.
struct Near<'a> {
    scene: &'a Scene,
    blockers: &'a Blockers,
    /// The box of the emitter.
    bi: (DVec3, DVec3),
}

impl<'a> Near<'a> {
    fn new(scene: &'a Scene, shadows: &'a Shadows<'_>, i: usize) -> Self {
        Near { scene, blockers: shadows.blockers(), bi: bounds(scene.patches[i].polygon.vertices()) }
    }

    /// `status` of pair (i, j) with its partial blockers that cannot cut its sight lines left
    /// out (into `kept`); clear when none is left.
    fn status<'k>(&self, j: usize, status: Status<'_>, kept: &'k mut Vec<u32>) -> Status<'k>
    where
        'a: 'k,
    {
        match status {
            Status::Partial(list) => {
                let pj = &self.scene.patches[j].polygon;
                let snap = self.blockers.snap();
                let shaft = Shaft::new(self.bi, bounds(pj.vertices()), snap);
                let plane = (pj.normal(), pj.normal().dot(pj.centroid()));
                kept.clear();
                kept.extend(
                    list.iter()
                        .copied()
                        .filter(|&b| may_cut(&shaft, plane, &self.blockers.get(b as usize).ring, snap)),
                );
                if kept.is_empty() {
                    Status::Clear
                } else {
                    Status::Partial(kept)
                }
            }
            Status::Clear => Status::Clear,
            Status::Blocked => Status::Blocked,
        }
    }
}

/// The rung of the ladder that evaluates a pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rung {
    /// Coplanar or back-facing: exactly 0.
    Zero,
    /// Tensor Gauss rules of these orders on patch i and patch j.
    Gauss(usize, usize),
    /// The exact double contour integral.
    Exact,
}

/// Per-row buffers: generated high-order rules and the receiver weights.
#[derive(Default)]
struct Scratch {
    rule_i: Points,
    rule_j: Points,
    weights: Vec<f64>,
}

impl RowKernel for AnalyticKernel<'_> {
    fn symmetric(&self) -> bool {
        true
    }

    fn flags(&self) -> Vec<Flag> {
        self.flags.sorted()
    }

    fn misses(&self) -> (u64, Option<crate::viewfactor::shadow::misses::Miss>) {
        self.shadows.as_ref().map_or((0, None), |s| s.misses().summary())
    }

    fn tree_hash(&self) -> u64 {
        self.shadows.as_ref().map_or(0, |s| s.blockers().tree_hash())
    }

    fn absorb(&self, flags: Vec<Flag>, misses: (u64, Option<crate::viewfactor::shadow::misses::Miss>)) {
        for f in flags {
            self.flags.push(f);
        }
        if let Some(s) = &self.shadows {
            s.misses().merge(misses.0, misses.1);
        }
    }

    fn row(&self, i: usize, out: &mut Row) -> Result<()> {
        let n = self.info.len();
        let mut scratch = Scratch::default();
        let mut reuse = self.reuse.row(i);
        out.entries.reserve(n - i - 1);
        let Some(shadows) = &self.shadows else {
            for j in i + 1..n {
                let s = self.unobstructed(i, j, &mut reuse, &mut scratch);
                if s > 0.0 {
                    out.entries.push(RawEntry { j: j as u32, method: MethodSet::ANALYTIC, s, var: 0.0 });
                }
            }
            out.pairs = (n - i - 1) as u64;
            return Ok(());
        };
        let near = Near::new(self.scene, shadows, i);
        let mut kept = Vec::new();
        SHADOW_SCRATCH.with_borrow_mut(|ShadowScratch { row, work }| {
            shadows.classify_row(i, row);
            for j in i + 1..n {
                let status = near.status(j, row.status(j), &mut kept);
                out.entries.extend(self.entry(shadows, i, j, status, (&mut reuse, &mut scratch), work));
            }
        });
        out.pairs = (n - i - 1) as u64;
        Ok(())
    }

    fn row_costs(&self) -> Option<Vec<u64>> {
        use rayon::prelude::*;
        self.shadows.as_ref()?;
        let n = self.info.len();
        let costs = (0..n)
            .into_par_iter()
            .map_init(Vec::new, |ids, i| self.row_cost(i, i + 1..n, ids, false).round() as u64)
            .collect();
        Some(costs)
    }

    fn warnings(&self) -> Vec<String> {
        let Some(shadows) = &self.shadows else { return Vec::new() };
        let (count, worst) = shadows.misses().summary();
        let Some(w) = worst else { return Vec::new() };
        // The error on F in the worse direction: over the smaller patch's area.
        let small = self.scene.patches[w.i].polygon.area().min(self.scene.patches[w.j].polygon.area());
        vec![format!(
            "{count} partly obstructed entr{} ended with an error estimate above its goal (the shadow \
             integration stopped at its depth limit, or where its error stopped falling{}); worst: F({} -> {}) or \
             its reciprocal, error estimate {:.1e} on F against a goal of {:.1e}",
            if count == 1 { "y" } else { "ies" },
            if matches!(shadows.policy(), Policy::Auto { .. }) { ", and no capped sample did better" } else { "" },
            self.scene.patch_name(w.i),
            self.scene.patch_name(w.j),
            w.error / small,
            w.goal / small
        )]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewfactor::engine::RowKernel;

    fn case(name: &str) -> Scene {
        let p = format!("{}/cases/{name}/scene.toml", env!("CARGO_MANIFEST_DIR"));
        crate::scene::load(std::path::Path::new(&p)).expect("a shipped case loads")
    }

    #[test]
    fn rows_that_face_past_a_blocker_are_estimated_dearer_than_rows_that_face_nothing() {
        // 16 bottom patches facing 16 top patches past a centred plate: the bottom rows hold
        // every obstructed pair, the top rows (receivers j > i on their own plane) none.
        let scene = case("o1_squares_centred_blocker");
        let policy = Policy::Auto { tol: 1e-4, seed: 0 };
        let kernel = AnalyticKernel::with_policy(&scene, 1e-5, policy);
        let costs = kernel.row_costs().expect("a scene with blockers has row costs");
        assert_eq!(costs.len(), 32);
        let (bottom, top): (u64, u64) = (costs[..16].iter().sum(), costs[16..].iter().sum());
        // By pair count alone the bottom rows weigh 392 / 136 = 2.9 times the top rows.
        assert!(bottom > 100 * top, "bottom rows {bottom}, top rows {top}");
        assert_eq!(costs[31], 0, "the last row has no receiver");
        // A convex enclosure has no blockers: every pair is priced alike (the pair count).
        let furnace = case("e3_cube_furnace");
        assert!(AnalyticKernel::new(&furnace, GAUSS_REL_TOL).row_costs().is_none());
    }

    /// A closed U channel 0.6 × 0.6 × 0.4 m (32 triangles, outward normals) as ASCII STL.
    fn u_channel_stl() -> String {
        let u = [
            (-0.3, -0.3),
            (0.3, -0.3),
            (0.3, 0.3),
            (0.2, 0.3),
            (0.2, -0.2),
            (-0.2, -0.2),
            (-0.2, 0.3),
            (-0.3, 0.3),
        ];
        let (z0, z1) = (-0.2, 0.2);
        let mut tris: Vec<[(f64, f64, f64); 3]> = Vec::new();
        for k in 0..u.len() {
            let (a, b) = (u[k], u[(k + 1) % u.len()]);
            let (a0, b0, b1, a1) = ((a.0, a.1, z0), (b.0, b.1, z0), (b.0, b.1, z1), (a.0, a.1, z1));
            tris.extend([[a0, b0, b1], [a0, b1, a1]]);
        }
        // The caps as three convex pieces sharing the channel's vertices (no T-junctions).
        let caps: [&[(f64, f64)]; 3] = [
            &[(-0.3, -0.3), (0.3, -0.3), (0.3, -0.2), (0.2, -0.2), (-0.2, -0.2), (-0.3, -0.2)],
            &[(-0.3, -0.2), (-0.2, -0.2), (-0.2, 0.3), (-0.3, 0.3)],
            &[(0.2, -0.2), (0.3, -0.2), (0.3, 0.3), (0.2, 0.3)],
        ];
        for c in caps {
            for k in 1..c.len() - 1 {
                let (p, q, r) = (c[0], c[k], c[k + 1]);
                tris.push([(p.0, p.1, z1), (q.0, q.1, z1), (r.0, r.1, z1)]);
                tris.push([(p.0, p.1, z0), (r.0, r.1, z0), (q.0, q.1, z0)]);
            }
        }
        let mut s = String::from("solid part\n");
        for t in tris {
            s.push_str(" facet normal 0 0 0\n  outer loop\n");
            for v in t {
                s.push_str(&format!("   vertex {} {} {}\n", v.0, v.1, v.2));
            }
            s.push_str("  endloop\n endfacet\n");
        }
        s + "endsolid part\n"
    }

    #[test]
    fn wall_rows_facing_a_concave_part_are_estimated_far_dearer_than_the_parts_rows() {
        // The channel case at small scale: a U channel in a 2 m room of 4×4 patches per wall.
        // A wall patch's pairs with the facets hold u far above a facet's goal (thousands of
        // samples or an integration each); measured one thread: 67 ms per wall row, 6–170 µs
        // per part row (validation/cad.md). Pricing every front pair at the row's blocker
        // count alone put the two within a factor of 10.
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::write(dir.path().join("part.stl"), u_channel_stl()).expect("stl written");
        let mut toml = String::from("[[model]]\nfile = \"part.stl\"\n");
        let walls = [
            ("floor", [-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
            ("ceiling", [-1.0, -1.0, 1.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]),
            ("wall_x0", [-1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]),
            ("wall_x1", [1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]),
            ("wall_y0", [-1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]),
            ("wall_y1", [-1.0, 1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]),
        ];
        for (name, o, u, v) in walls {
            toml.push_str(&format!(
                "[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o:?}, u = {u:?}, v = {v:?} }}\nsubdivide = [4, 4]\n"
            ));
        }
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, toml).expect("scene written");
        let scene = crate::scene::load(&path).expect("the scene loads");
        assert_eq!(scene.patches.len(), 96 + 32);
        let kernel = AnalyticKernel::with_policy(&scene, 1e-5, Policy::Auto { tol: 1e-4, seed: 0 });
        let costs = kernel.row_costs().expect("the part blocks");
        let mean = |r: &[u64]| r.iter().sum::<u64>() as f64 / r.len() as f64;
        let (wall, part) = (mean(&costs[..96]), mean(&costs[96..]));
        assert!(wall > 30.0 * part, "wall rows {wall:.3e}, part rows {part:.3e}");
    }

    #[test]
    fn a_row_s_receivers_below_it_get_the_entries_their_own_rows_give_it() {
        // The hierarchy evaluates a leaf pair from its smaller patch: a part facet's row with
        // the room's patches below it. Each entry against the same pair from the other side,
        // within the ladder's and the exact policy's goals on both sides (of the unobstructed
        // value). A facet emitting next to the faces it shares edges with is where the Gauss
        // rules agreed on wrong values (`shadow::adaptive`'s touching cells).
        for part in ["heat_sink", "l_bracket", "u_channel"] {
            let path =
                format!("{}/validation/reference/real_parts/{part}/scene.toml", env!("CARGO_MANIFEST_DIR"));
            let scene = crate::scene::load(std::path::Path::new(&path)).expect("the part loads");
            let n = scene.patches.len();
            let (ladder, rel) = (1e-8, 1e-6);
            let kernel = AnalyticKernel::with_policy(&scene, ladder, Policy::Exact { rel_tol: rel });
            let rows: Vec<Row> = (0..n)
                .map(|i| {
                    let mut row = Row::default();
                    kernel.row(i, &mut row).expect("the row computes");
                    row
                })
                .collect();
            let (mut compared, mut shadowed, mut off) = (0, 0, Vec::new());
            for i in 1..n {
                let below: Vec<u32> = (0..i as u32).collect();
                let mut out = Vec::new();
                kernel.partners(i, &below, &mut out);
                for (j, row) in rows.iter().enumerate().take(i) {
                    let theirs = row.entries.iter().find(|e| e.j as usize == i).map_or(0.0, |e| e.s);
                    let ours = out.iter().find(|e| e.j as usize == j).map_or(0.0, |e| e.s);
                    let u = kernel.unobstructed(i, j, &mut kernel.reuse.row(i), &mut Scratch::default());
                    if (ours - theirs).abs() > 2.0 * (ladder + rel) * u {
                        off.push((i, j, (ours - theirs) / u));
                    }
                    compared += 1;
                    shadowed +=
                        usize::from(out.iter().any(|e| e.j as usize == j && e.method == MethodSet::SHADOWED));
                }
            }
            assert!(
                compared == n * (n - 1) / 2 && shadowed > 20,
                "{part}: {compared} pairs, {shadowed} shadowed"
            );
            assert!(
                off.is_empty(),
                "{part}: {} pairs off (i, j, difference / unobstructed): {off:?}",
                off.len()
            );
        }
    }

    #[test]
    fn a_pair_s_entry_is_the_same_whichever_receivers_share_its_row() {
        // The heat sink (92 facets) in a room of 4×4 patches per wall: each emitter's
        // receivers in one call, in two pieces and one by one (the hierarchy's pieces of a
        // row, held by any process), against the full row. Blockers beside a pair's box used to
        // reach it through the row's classification box and move `auto`'s choices and the
        // integration's silhouettes.
        let dir = tempfile::tempdir().expect("temp dir");
        let stl =
            format!("{}/validation/reference/real_parts/heat_sink/part0.stl", env!("CARGO_MANIFEST_DIR"));
        let shipped = std::fs::read_to_string(stl.replace("part0.stl", "scene.toml")).expect("scene read");
        let toml = shipped
            .replace("file = \"part0.stl\"", &format!("file = {stl:?}"))
            .replace("emissivity = 0.8\n", "emissivity = 0.8\nsubdivide = [4, 4]\n");
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, toml).expect("scene written");
        let scene = crate::scene::load(&path).expect("the heat sink loads");
        assert_eq!(scene.patches.len(), 92 + 96);
        let n = scene.patches.len();
        for policy in [Policy::Auto { tol: 1e-4, seed: 7 }, Policy::Exact { rel_tol: 1e-4 }] {
            let kernel = AnalyticKernel::with_policy(&scene, 1e-5, policy);
            let mut compared = 0;
            for i in (0..n - 1).step_by(3) {
                let mut row = Row::default();
                kernel.row(i, &mut row).expect("the row computes");
                let key = |e: &RawEntry| (e.j, e.s.to_bits(), e.var.to_bits(), e.method);
                let want: Vec<_> = row.entries.iter().map(key).collect();
                let js: Vec<u32> = (i as u32 + 1..n as u32).collect();
                let (a, b) = js.split_at(js.len() / 3);
                let groups: [Vec<&[u32]>; 3] = [vec![&js[..]], vec![a, b], js.chunks(1).collect()];
                for group in groups {
                    let mut out = Vec::new();
                    for piece in &group {
                        kernel.partners(i, piece, &mut out);
                    }
                    let got: Vec<_> = out.iter().map(key).collect();
                    assert_eq!(got, want, "row {i} in {} pieces", group.len());
                }
                compared += want.len();
            }
            assert!(compared > n * n / 15, "{compared} entries compared");
        }
    }
}
