//! The obstructed branch of the analytic kernels: everything a row needs beyond the
//! unobstructed ladder.
//!
//! [`Shadows`] holds the scene's blockers and the integration rules; per row it classifies the
//! receivers ([`super::classify::classify_row`]) and per partly obstructed pair it returns
//! the obstructed exchange area under a [`Policy`]:
//! - [`Policy::Exact`] (`analytic`): shadow integration to a relative target on the
//!   unobstructed value, rules and depths [`EXACT_ADAPT`];
//! - [`Policy::Auto`] (`auto`): the cheaper of shadow integration (rules and depths
//!   [`AUTO_ADAPT`], kink cuts [`AUTO_CUTS`]) and the Monte Carlo ratio estimator, to an absolute goal per F,
//!   priced by the [`CostModel`] that [`super::calibrate`] fits on the scene's own pairs when
//!   the branch is built (see [`super::policy`]); a pair priced for integration is first
//!   probed by the sample's first points ([`super::policy::probe_pilot`]), which price
//!   sampling for the pair's own share in shadow at the tests per point the probe made:
//!   sampled where that is cheaper, else integrated within [`CAP_PRICE_SHARE`] of that price
//!   less the integration's set-up ([`super::policy::setup_units`]), and sampled past it. A
//!   pair whose worst-case sample is past [`MC_MAX_SAMPLES`] is integrated to
//!   [`OVERRUN_RATIO`] times the model's price before such a probe is drawn.
//!
//! Under both, a pair behind [`SOLID_MIN_FACES`] or more faces of one convex solid is
//! integrated as the facet sum ([`super::solid`]) instead of the shadow.
use super::adaptive::Integrator;
use super::blockers::{BlockerSource, Blockers};
use super::classify::{classify_row, RowShadows};
use super::mc_pair::{estimate, Budget, McPair, PatchSampler};
use super::misses::{Miss, MissLog};
use super::pair::{falls_away, shadowed, PairScratch, Shadowed};
use super::policy::{
    mc_ns_at, pair_goal, pilot, probe_pilot, setup_units, Choice, CostModel, Policy, AUTO_ADAPT, AUTO_CUTS,
    CAP_PRICE_SHARE, EXACT_ADAPT, MC_MAX_SAMPLES, MC_SIGMAS, OVERRUN_RATIO, SHADOW_UNIT_NS, SOLID_MIN_FACES,
};
use super::segtree::SegmentBlocker;
use super::segtree::SegmentTree;
use crate::geometry::Polygon;
use crate::scene::Scene;
use crate::viewfactor::MethodSet;

/// One obstructed entry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obstructed {
    /// A_i F_ij, m².
    pub s: f64,
    /// Variance (Monte Carlo) or 0, m⁴.
    pub var: f64,
    /// Which method produced it.
    pub method: MethodSet,
    /// Viewpoints evaluated (shadow integration) or point pairs sampled (Monte Carlo).
    pub work: u64,
    /// Cells accepted at the depth limit (shadow integration).
    pub at_max_depth: u32,
}

/// One partly obstructed pair as the branch's estimators take it: rows `i`, `j`, the
/// unobstructed exchange area `u` (m²) and the partial blockers `partial` from the row
/// classification.
#[derive(Debug, Clone, Copy)]
pub struct PairAt<'p> {
    /// Emitter patch.
    pub i: usize,
    /// Receiver patch.
    pub j: usize,
    /// Unobstructed A_i F_ij, m².
    pub u: f64,
    /// Partial blockers (ids into the scene's blockers).
    pub partial: &'p [u32],
}

impl<'p> PairAt<'p> {
    /// Pair (i, j) with unobstructed value `u` behind `partial`.
    pub fn new(i: usize, j: usize, u: f64, partial: &'p [u32]) -> Self {
        Self { i, j, u, partial }
    }
}

/// Per-thread buffers of the obstructed branch.
#[derive(Debug, Clone, Default)]
pub struct ShadowScratch {
    /// The row's classification.
    pub row: RowShadows,
    /// Buffers of the pair estimators.
    pub work: PairWork,
}

/// Buffers of [`Shadows::pair`].
#[derive(Debug, Clone, Default)]
pub struct PairWork {
    pair: PairScratch,
    tree: SegmentTree,
}

/// The scene's blockers, rules and policy.
#[derive(Debug)]
pub struct Shadows<'s> {
    scene: &'s Scene,
    blockers: Blockers,
    integrator: Integrator,
    policy: Policy,
    samplers: Vec<PatchSampler>,
    /// Every blocker ready for segment tests (Monte Carlo under `auto`).
    segments: Vec<SegmentBlocker>,
    /// Prices of the two estimators (`auto`).
    model: CostModel,
    /// Entries that missed their goal.
    misses: MissLog,
    /// Per patch: it is a face of a non-convex solid (`super::pair`'s choice of emitter).
    on_solid: Vec<bool>,
    /// Partial blockers of a typical partly obstructed pair (the calibration pairs' median; 1
    /// without them): the progress estimate prices unclassified pairs at this count.
    typical_blockers: usize,
}

impl<'s> Shadows<'s> {
    /// Collects the blockers of `scene` with the default prices; `None` when nothing can block
    /// (convex enclosures). [`Shadows::new`] ([`super::calibrate`]) measures `auto`'s prices.
    pub fn uncalibrated(scene: &'s Scene, policy: Policy) -> Option<Self> {
        let blockers = Blockers::new(scene);
        if blockers.is_empty() {
            return None;
        }
        let integrator = Integrator::new(match policy {
            Policy::Exact { .. } => EXACT_ADAPT,
            Policy::Auto { .. } => AUTO_ADAPT,
        });
        let integrator = integrator.with_solids(SOLID_MIN_FACES);
        let integrator = match policy {
            Policy::Exact { .. } => integrator,
            Policy::Auto { .. } => integrator.with_cuts(AUTO_CUTS),
        };
        let mut on_solid = vec![false; scene.patches.len()];
        for b in 0..blockers.len() {
            let bl = blockers.get(b);
            if let (BlockerSource::Patch(p), 1, None) = (bl.source, bl.closed, bl.body) {
                on_solid[p] = true;
                for &q in &bl.also {
                    on_solid[q as usize] = true;
                }
            }
        }
        let pad = blockers.pad();
        let (samplers, segments) = match policy {
            Policy::Auto { .. } => (
                scene.patches.iter().map(|p| PatchSampler::new(&p.polygon)).collect(),
                (0..blockers.len()).map(|b| SegmentBlocker::new(&blockers.get(b).ring, pad)).collect(),
            ),
            Policy::Exact { .. } => (Vec::new(), Vec::new()),
        };
        Some(Self {
            scene,
            blockers,
            integrator,
            policy,
            samplers,
            segments,
            model: CostModel::default(),
            misses: MissLog::default(),
            on_solid,
            typical_blockers: 1,
        })
    }

    /// Replaces the prices `auto` chooses by (the calibration's fit).
    pub(super) fn set_model(&mut self, model: CostModel) {
        self.model = model;
    }

    /// Sets the typical count of partial blockers per pair (the calibration's median).
    pub(super) fn set_typical_blockers(&mut self, b: usize) {
        self.typical_blockers = b;
    }

    /// Partial blockers of a typical partly obstructed pair (progress estimate only).
    pub fn typical_blockers(&self) -> usize {
        self.typical_blockers
    }

    /// The scene.
    pub fn scene(&self) -> &'s Scene {
        self.scene
    }
    /// How partly obstructed pairs are computed.
    pub fn policy(&self) -> Policy {
        self.policy
    }
    /// The prices `auto` chooses by.
    pub fn model(&self) -> &CostModel {
        &self.model
    }

    /// The blockers.
    pub fn blockers(&self) -> &Blockers {
        &self.blockers
    }

    /// Classifies the receivers j > i of row `i` into `row`.
    pub fn classify_row(&self, i: usize, row: &mut RowShadows) {
        classify_row(self.scene, &self.blockers, i, i + 1, row);
    }

    /// As [`Self::classify_row`] for the `receivers` only (any j ≠ i, above or below it).
    pub fn classify_row_in(&self, i: usize, receivers: &[u32], row: &mut RowShadows) {
        super::classify::classify_row_in(self.scene, &self.blockers, i, 0, Some(receivers), row);
    }

    /// Obstructed A_i F_ij for the partly obstructed pair `p` (its unobstructed value and partial
    /// blockers from the row classification). Under `auto` the goal is
    /// [`pair_goal`] (both F_ij and F_ji); Monte Carlo that cannot reach it within
    /// [`MC_MAX_SAMPLES`] is replaced by the shadow integration, and an integration that ends
    /// above it by the capped sample where that reports the smaller error (`settle`). An
    /// entry whose error estimate still exceeds its goal is recorded in [`Self::misses`].
    pub fn pair(&self, p: PairAt, s: &mut PairWork) -> Obstructed {
        let (i, j, u, partial) = (p.i, p.j, p.u, p.partial);
        match self.policy {
            Policy::Exact { rel_tol } => {
                let goal = rel_tol * u;
                let r = self.integrate(p, goal, u64::MAX, s);
                if r.error > goal {
                    self.misses.record(Miss { i, j, error: r.error, goal });
                }
                settle(&r, None, 0)
            }
            Policy::Auto { tol, seed } => {
                let (ai, aj) = (self.scene.patches[i].polygon.area(), self.scene.patches[j].polygon.area());
                let goal = pair_goal(tol, ai, aj);
                // The entry from an integration `r`, and from the sample `m` where one was
                // drawn (`spent`: work besides theirs): see [`settle`]. An integration that
                // ended above its goal (depth limit, or its error stopped falling) is checked
                // against a capped sample drawn for it.
                let finish = |r: Shadowed, m: Option<McPair>, spent: u64, s: &mut PairWork| {
                    let m = m.or_else(|| {
                        (r.error > goal).then(|| self.sample(p, (MC_MAX_SAMPLES, goal), seed, s))
                    });
                    let entry = settle(&r, m.as_ref(), spent);
                    let error = if entry.method == MethodSet::MC_AREA {
                        MC_SIGMAS * entry.var.sqrt()
                    } else {
                        r.error
                    };
                    if error > goal {
                        self.misses.record(Miss { i, j, error, goal });
                    }
                    entry
                };
                let sampled = |n: u32, spent: u64, s: &mut PairWork| {
                    let m = self.sample(p, (n, goal), seed, s);
                    if MC_SIGMAS * m.var.sqrt() > goal {
                        // The sample cap was reached first: the entry is integrated.
                        let r = self.integrate(p, goal, u64::MAX, s);
                        return finish(r, Some(m), spent, s);
                    }
                    Obstructed {
                        s: m.s,
                        var: m.var,
                        method: MethodSet::MC_AREA,
                        work: m.samples as u64 + spent,
                        at_max_depth: 0,
                    }
                };
                match self.model.choose(u, goal, partial.len()) {
                    Choice::Shadowed => {
                        let n = CostModel::samples(u, goal);
                        if n > MC_MAX_SAMPLES as f64 {
                            // No sample is priced for its worst case: integrated, but only
                            // to `OVERRUN_RATIO` times the model's price before a probe of
                            // the largest sample is drawn (a receiver beside a sliver
                            // neighbour refines to the depth limit and finds no shadow).
                            let over = OVERRUN_RATIO * self.model.shadow_ns(u, goal, partial.len());
                            let r = self.integrate(p, goal, (over / SHADOW_UNIT_NS) as u64, s);
                            if !r.info.capped {
                                return finish(r, None, 0, s);
                            }
                            let (probe, need, _) = self.probe(p, (MC_MAX_SAMPLES, goal), seed, s);
                            let spent = r.info.evals + u64::from(probe.samples);
                            if need.is_some() {
                                return sampled(MC_MAX_SAMPLES, spent, s);
                            }
                            let r = self.integrate(p, goal, u64::MAX, s);
                            return finish(r, None, spent, s);
                        }
                        let n = n as u32;
                        if self.falls_away(p, s) {
                            // No blocker is left once clipped to the pair: integrated before
                            // its first viewpoint, no probe needed.
                            let r = self.integrate(p, goal, u64::MAX, s);
                            return finish(r, None, 0, s);
                        }
                        // The worst-case count prices the sample for a ratio of ½; a
                        // probe (the sample's first points, `probe_pilot`) prices it for
                        // this pair's share in shadow (a wall pair behind a part is mostly
                        // seen: a tenth of the worst case or less). See [`probe_samples`].
                        let (probe, _, price) = self.probe(p, (n, goal), seed, s);
                        let spent = u64::from(probe.samples);
                        if price < self.model.shadow_ns(u, goal, partial.len()) {
                            return sampled(n, spent, s);
                        }
                        // The model's price of the integration can be far off (a wall pair
                        // behind a whole meshed part costs hundreds of times the price fitted
                        // on the part's own pairs): integrate within sampling's price, and
                        // sample where that was not enough (within a share of it: a capped
                        // integration is thrown away). The integration's set-up (the
                        // kink cuts, before its first root cell and uncounted in its work)
                        // comes out of that price first; where it takes all of it, the pair
                        // is sampled.
                        let cap = if price.is_finite() {
                            let setup = setup_units(partial.len());
                            match ((CAP_PRICE_SHARE * price / SHADOW_UNIT_NS).ceil() as u64)
                                .checked_sub(setup)
                            {
                                Some(cap) if cap > 0 => cap,
                                _ => return sampled(n, spent, s),
                            }
                        } else {
                            u64::MAX
                        };
                        let r = self.integrate(p, goal, cap, s);
                        // A finished result is kept even past the cap (the facet sum behind
                        // a convex solid runs to its end whatever the cap).
                        if !r.info.capped {
                            return finish(r, None, spent, s);
                        }
                        sampled(n, r.info.evals + spent, s)
                    }
                    Choice::MonteCarlo(n) => sampled(n, 0, s),
                }
            }
        }
    }

    /// Entries whose error estimate ended above their goal (see `super::misses`).
    pub fn misses(&self) -> &MissLog {
        &self.misses
    }

    /// Shadow integration of pair (i, j) to the absolute goal `goal`, refining no further past
    /// `max_work` work units.
    pub fn integrate(&self, p: PairAt<'_>, goal: f64, max_work: u64, s: &mut PairWork) -> Shadowed {
        let (pi, pj) = self.polygons(p);
        let on_solid = self.on_solid[p.i];
        shadowed(
            pi,
            pj,
            p.u,
            &self.blockers,
            p.partial,
            &self.integrator,
            goal,
            max_work,
            on_solid,
            &mut s.pair,
        )
    }

    /// The emitter's and the receiver's polygons of pair `p`.
    fn polygons(&self, p: PairAt<'_>) -> (&Polygon, &Polygon) {
        (&self.scene.patches[p.i].polygon, &self.scene.patches[p.j].polygon)
    }

    /// True when none of pair (i, j)'s partial blockers is left once clipped to the pair
    /// ([`falls_away`]): its integration ends before its first viewpoint.
    fn falls_away(&self, p: PairAt<'_>, s: &mut PairWork) -> bool {
        let (pi, pj) = self.polygons(p);
        falls_away(pi, pj, &self.blockers, p.partial, self.on_solid[p.i], &mut s.pair)
    }

    /// The Monte Carlo ratio estimate of pair (i, j) from `n` samples first, doubling until its
    /// standard error meets `goal`/[`MC_SIGMAS`] (`auto` only).
    pub fn sample(&self, p: PairAt<'_>, (n, goal): (u32, f64), seed: u64, s: &mut PairWork) -> McPair {
        self.sample_within(p, (pilot(n), MC_MAX_SAMPLES, goal), seed, s)
    }

    /// The probe of pair (i, j) for a sample whose worst case is `n` points: its first
    /// [`probe_pilot`] points, the count the doubling would reach ([`probe_samples`]), and that
    /// sample's price at the probe's own tests per point (the fitted count can be several times
    /// that for a pair behind a whole meshed part); infinite where no count is reached.
    fn probe(
        &self,
        p: PairAt<'_>,
        (n, goal): (u32, f64),
        seed: u64,
        s: &mut PairWork,
    ) -> (McPair, Option<u32>, f64) {
        let first = probe_pilot(n);
        let probe = self.sample_within(p, (first, first, goal), seed, s);
        let need = probe_samples(&probe, goal, first);
        let tests = probe.tests as f64 / f64::from(probe.samples.max(1));
        let price = need.map_or(f64::INFINITY, |m| mc_ns_at(f64::from(m), tests));
        (probe, need, price)
    }

    /// [`Self::sample`] from `first` points, doubling up to `max`.
    fn sample_within(
        &self,
        p: PairAt<'_>,
        (first, max, goal): (u32, u32, f64),
        seed: u64,
        s: &mut PairWork,
    ) -> McPair {
        let (pi, pj) = self.polygons(p);
        estimate(
            &self.samplers[p.i],
            pi.normal(),
            &self.samplers[p.j],
            pj.normal(),
            p.u,
            (&self.segments, p.partial),
            Budget { first, max, sigma: goal / MC_SIGMAS },
            seed,
            (p.i, p.j),
            &mut s.tree,
        )
    }
}

/// `auto`'s entry from a finished shadow integration `r` and, where one was drawn, a sample
/// `m` (`spent`: work besides theirs): the integration where its error estimate is no larger
/// than the sample's ([`MC_SIGMAS`] standard errors), else the sample. A sliver behind a
/// meshed part can end its integration at the depth limit hundreds of times above its goal,
/// where a capped sample still reports its standard error honestly.
fn settle(r: &Shadowed, m: Option<&McPair>, spent: u64) -> Obstructed {
    let work = spent + r.info.evals + m.map_or(0, |m| u64::from(m.samples));
    match m {
        Some(m) if MC_SIGMAS * m.var.sqrt() < r.error => {
            Obstructed { s: m.s, var: m.var, method: MethodSet::MC_AREA, work, at_max_depth: 0 }
        }
        _ => Obstructed {
            s: r.s,
            var: 0.0,
            method: MethodSet::SHADOWED,
            work,
            at_max_depth: r.info.at_max_depth,
        },
    }
}

/// Points a sample that starts at `first` draws to meet `goal`, as the probe `probe` (its first
/// draw) predicts: its variance falls as 1/n, and it doubles from `first`; `None` when even
/// [`MC_MAX_SAMPLES`] would not meet the goal. A probe that missed a thin shadow predicts too
/// few, and the sample then doubles further on its own measure: the price errs, the entry does
/// not.
fn probe_samples(probe: &McPair, goal: f64, first: u32) -> Option<u32> {
    let sigma = goal / MC_SIGMAS;
    let want = f64::from(probe.samples.max(1)) * probe.var / (sigma * sigma);
    if !(want <= f64::from(MC_MAX_SAMPLES)) {
        return None;
    }
    let mut n = first.max(1);
    while f64::from(n) < want {
        n = n.saturating_mul(2).min(MC_MAX_SAMPLES);
    }
    Some(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Polygon;
    use crate::viewfactor::exact::pair::polygon_polygon;
    use crate::viewfactor::shadow::adaptive::AdaptInfo;
    use crate::viewfactor::shadow::classify::Status;
    use crate::viewfactor::shadow::policy::{PowerLaw, AUTO_RULES, EXACT_REL_TOL};
    use glam::DVec3;

    fn sq(z: f64, x0: f64, y0: f64, s: f64, up: bool) -> Polygon {
        Polygon::new(crate::geometry::fixtures::square(z, x0, y0, s, up)).unwrap()
    }

    /// A_0 F_01 through classification and the obstructed branch, as a kernel would.
    fn exchange(scene: &Scene, policy: Policy) -> (f64, MethodSet) {
        let shadows = Shadows::new(scene, policy).expect("the blocker is found");
        let (mut s, partial, u) = pair_01(&shadows);
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        assert!(r.s <= u);
        (r.s, r.method)
    }

    /// Pair 0–1 classified as a row does and integrated to `EXACT_REL_TOL`: (result, u).
    fn integrate_01(shadows: &Shadows) -> (Shadowed, f64) {
        let (mut s, partial, u) = pair_01(shadows);
        (shadows.integrate(PairAt::new(0, 1, u, &partial), EXACT_REL_TOL * u, u64::MAX, &mut s.work), u)
    }

    /// Row 0 classified as a row does: the buffers, pair 0–1's partial blockers and its
    /// unobstructed A_0 F_01.
    fn pair_01(shadows: &Shadows) -> (ShadowScratch, Vec<u32>, f64) {
        let scene = shadows.scene();
        let mut s = ShadowScratch::default();
        shadows.classify_row(0, &mut s.row);
        let u = polygon_polygon(&scene.patches[0].polygon, &scene.patches[1].polygon);
        let Status::Partial(partial) = s.row.status(1) else { panic!("pair 0-1 is partly obstructed") };
        let partial = partial.to_vec();
        (s, partial, u)
    }

    /// The blockers that are faces of obstructions (not patch outlines).
    fn obstruction_faces<'a>(shadows: &'a Shadows) -> Vec<&'a super::super::blockers::Blocker> {
        (0..shadows.blockers().len())
            .map(|b| shadows.blockers().get(b))
            .filter(|b| matches!(b.source, super::super::blockers::BlockerSource::Obstruction { .. }))
            .collect()
    }

    /// The box [lo, hi] as 12 triangles, normals out (or in), two per face.
    fn block(lo: DVec3, hi: DVec3, inward: bool) -> Vec<Polygon> {
        let c = |i: usize| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2]);
        // Faces as corner indices, counter-clockwise seen from outside.
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .map(|t| {
                let mut v: Vec<DVec3> = t.iter().map(|&i| c(i)).collect();
                if inward {
                    v.reverse();
                }
                Polygon::new(v).unwrap()
            })
            .collect()
    }

    /// A floor triangle and a wall triangle of the 572-triangle irregular box (o7), past its
    /// float32 block: F from the generator's independent exact-shadow integration
    /// (`cases/_generator`, `converged` at h = 0.005, order 8; 3e-21 between refinements).
    const BOX_PAIR_REFERENCE: f64 = 1.664_604_037_651_87e-6;

    fn box_pair_scene(block_faces: Vec<Polygon>) -> Scene {
        let f = |v: [f64; 3]| DVec3::from_array(v);
        let tri = |v: [[f64; 3]; 3]| Polygon::new(v.iter().map(|&x| f(x)).collect()).unwrap();
        let e = tri([
            [0.860933780670166, 0.892845630645752, 0.0],
            [1.0, 0.8608298897743225, 0.0],
            [0.8680282235145569, 1.012006163597107, 0.0],
        ]);
        let r = tri([
            [0.0, 0.5754350423812866, 0.2608218491077423],
            [0.0, 0.5746476650238037, 0.4067416191101074],
            [0.0, 0.413876473903656, 0.3967311382293701],
        ]);
        // A ceiling above the block, so every block face has patches on both sides.
        let ceiling = Polygon::new(vec![
            DVec3::new(0.0, 0.0, 0.7),
            DVec3::new(0.0, 1.3, 0.7),
            DVec3::new(1.0, 1.3, 0.7),
            DVec3::new(1.0, 0.0, 0.7),
        ])
        .unwrap();
        Scene::builder()
            .surface("floor", vec![e], 0.9, None)
            .surface("wall", vec![r], 0.9, None)
            .surface("ceiling", vec![ceiling], 0.9, None)
            .obstruction("block", block_faces)
            .build()
    }

    fn f32_block() -> (DVec3, DVec3) {
        let f = |x: f32| f64::from(x);
        (DVec3::new(f(0.35), f(0.45), f(0.2)), DVec3::new(f(0.65), f(0.85), f(0.5)))
    }

    #[test]
    fn an_integration_above_its_goal_gives_way_to_a_sample_that_reports_less() {
        let info = AdaptInfo { evals: 500, at_max_depth: 3, ..AdaptInfo::default() };
        let r = Shadowed { s: 0.30, error: 0.05, info, swapped: false };
        // A sample at 2 standard errors of 0.02 against an integration's 0.05: the sample.
        let m = McPair { s: 0.27, var: 1e-4, samples: 4096, tests: 0 };
        let e = settle(&r, Some(&m), 7);
        assert_eq!((e.s, e.var, e.method, e.work, e.at_max_depth), (0.27, 1e-4, MethodSet::MC_AREA, 4603, 0));
        // At 2 standard errors of 0.06 the integration stays; without a sample too.
        let wide = McPair { var: 9e-4, ..m };
        for e in [settle(&r, Some(&wide), 0), settle(&r, None, 0)] {
            assert_eq!((e.s, e.var, e.method, e.at_max_depth), (0.30, 0.0, MethodSet::SHADOWED, 3));
        }
    }

    #[test]
    fn a_goal_out_of_reach_is_flagged_and_keeps_the_better_estimate() {
        // The blocked box pair at a goal of 1e-17 × the triangle's area: the integration ends
        // above it; the capped sample drawn for it reports more, so the integration is kept,
        // and the entry is recorded once as a miss.
        let (lo, hi) = f32_block();
        let scene = box_pair_scene(block(lo, hi, false));
        let shadows = Shadows::new(&scene, Policy::Auto { tol: 1e-17, seed: 1 }).unwrap();
        let (mut s, partial, u) = pair_01(&shadows);
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        let (count, worst) = shadows.misses().summary();
        assert_eq!(r.method, MethodSet::SHADOWED);
        assert!((r.s - BOX_PAIR_REFERENCE).abs() < 1e-9 * u, "{} vs {BOX_PAIR_REFERENCE}", r.s);
        assert_eq!(count, 1);
        let worst = worst.unwrap();
        assert!(worst.error > worst.goal && (worst.i, worst.j) == (0, 1), "{worst:?}");
        // The sample was drawn: its points count in the entry's work beyond the integration's.
        let alone = shadows.integrate(PairAt::new(0, 1, u, &partial), worst.goal, u64::MAX, &mut s.work);
        assert!(
            r.work >= alone.info.evals + u64::from(MC_MAX_SAMPLES) / 16,
            "{} vs {}",
            r.work,
            alone.info.evals
        );
    }

    #[test]
    fn a_closed_block_of_triangles_matches_the_independent_reference() {
        let (lo, hi) = f32_block();
        // Out- and inward-facing closed meshes (faces turned away skipped, convex hull of the
        // faces' shadows), and the same triangles with one flipped (no closed body: every
        // face's shadow subtracted).
        let mut flipped = block(lo, hi, false);
        flipped[3] = Polygon::new(flipped[3].vertices().iter().rev().copied().collect()).unwrap();
        // Each face's two triangles are one blocker, but for the flipped one and its partner.
        for (what, faces, closed, count) in [
            ("outward", block(lo, hi, false), 1, 6),
            ("inward", block(lo, hi, true), -1, 6),
            ("one face flipped", flipped, 0, 7),
        ] {
            let scene = box_pair_scene(faces);
            let shadows = Shadows::new(&scene, Policy::Exact { rel_tol: EXACT_REL_TOL }).unwrap();
            assert_eq!(shadows.blockers().len(), count, "{what}");
            assert!((0..count).all(|b| shadows.blockers().get(b).closed == closed), "{what}");
            assert_eq!(shadows.blockers().get(0).body.is_some(), closed != 0, "{what}");
            let (r, u) = integrate_01(&shadows);
            let err = (r.s - BOX_PAIR_REFERENCE).abs() / u;
            assert!(err < EXACT_REL_TOL, "{what}: {} vs {BOX_PAIR_REFERENCE}: {err:.2e} of u", r.s);
            assert!(r.info.at_max_depth == 0 && r.info.evals < 2_000, "{what}: {:?}", r.info);
        }
    }

    /// The generator's geodesic sphere (`cases/_generator/gltf.py` `icosphere`, the same
    /// operations in the same order) with its vertices rounded to float32 as glTF stores them.
    fn f32_icosphere(radius: f64, subdivisions: u32) -> Vec<Polygon> {
        let unit = |a: [f64; 3]| {
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            [a[0] / n, a[1] / n, a[2] / n]
        };
        let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
        let t = (1.0 + 5f64.sqrt()) / 2.0;
        let v = [
            [-1.0, t, 0.0],
            [1.0, t, 0.0],
            [-1.0, -t, 0.0],
            [1.0, -t, 0.0],
            [0.0, -1.0, t],
            [0.0, 1.0, t],
            [0.0, -1.0, -t],
            [0.0, 1.0, -t],
            [t, 0.0, -1.0],
            [t, 0.0, 1.0],
            [-t, 0.0, -1.0],
            [-t, 0.0, 1.0],
        ]
        .map(unit);
        let f = [
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        let mut tris: Vec<[[f64; 3]; 3]> = f.iter().map(|t| t.map(|k| v[k])).collect();
        for _ in 0..subdivisions {
            tris = tris
                .iter()
                .flat_map(|&[a, b, c]| {
                    let (ab, bc, ca) = (unit(add(a, b)), unit(add(b, c)), unit(add(c, a)));
                    [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
                })
                .collect();
        }
        let f32v = |p: [f64; 3]| DVec3::from_array(p.map(|x| f64::from((x * radius) as f32)));
        tris.iter().map(|t| Polygon::new(t.iter().map(|&p| f32v(p)).collect()).unwrap()).collect()
    }

    /// sphere_room's floor patch 0 and ceiling patch 103 past the 1,280-facet sphere: A·F from
    /// the generator's exact-shadow integration (`converged` at h = 1/32, order 8), and the
    /// difference from its coarser level (h = 1/16, order 6).
    const SPHERE_PAIR_REFERENCE: (f64, f64) = (2.604_355_888_979e-4, 4.06e-11);

    #[test]
    fn a_facetted_sphere_pair_matches_the_independent_reference() {
        let sphere = f32_icosphere(0.6, 3);
        assert_eq!(sphere.len(), 1280);
        let square =
            |v: [[f64; 3]; 4]| Polygon::new(v.iter().map(|&x| DVec3::from_array(x)).collect()).unwrap();
        // The four side walls facing in, so every face of the sphere has patches on both sides.
        let (m, p) = (-2.0, 2.0);
        let walls = vec![
            square([[m, m, m], [m, p, m], [m, p, p], [m, m, p]]),
            square([[p, m, p], [p, p, p], [p, p, m], [p, m, m]]),
            square([[m, m, m], [m, m, p], [p, m, p], [p, m, m]]),
            square([[p, p, m], [p, p, p], [m, p, p], [m, p, m]]),
        ];
        let scene = Scene::builder()
            .surface(
                "floor",
                vec![square([
                    [-2.0, -2.0, -2.0],
                    [-1.5, -2.0, -2.0],
                    [-1.5, -1.5, -2.0],
                    [-2.0, -1.5, -2.0],
                ])],
                0.9,
                None,
            )
            .surface(
                "ceiling",
                vec![square([[0.0, 1.5, 2.0], [0.0, 2.0, 2.0], [0.5, 2.0, 2.0], [0.5, 1.5, 2.0]])],
                0.9,
                None,
            )
            .surface("walls", walls, 0.9, None)
            .obstruction("sphere", sphere)
            .build();
        let shadows = Shadows::new(&scene, Policy::Exact { rel_tol: EXACT_REL_TOL }).unwrap();
        let faces = obstruction_faces(&shadows);
        assert!(faces.len() == 1280 && faces.iter().all(|b| b.closed == 1 && b.body.is_some()));
        let (r, u) = integrate_01(&shadows);
        let (reference, convergence) = SPHERE_PAIR_REFERENCE;
        // The facet sum: every root cell a smooth piece of one face, accepted as it is.
        assert!(r.info.cells == r.info.roots && r.info.evals < 10_000, "{:?}", r.info);
        assert!(
            (r.s - reference).abs() <= 2.0 * convergence,
            "{} vs {reference}: {:.2e} of u",
            r.s,
            (r.s - reference).abs() / u
        );
    }

    #[test]
    fn an_enclosure_meshed_with_inward_normals_hides_what_is_outside() {
        // A closed unit box of 12 triangles facing in (six square blockers), a small plate inside it facing up, a
        // plate outside beside it in the plane y = 0.5 (which cuts the box, so the inside
        // plate is the emitter: viewpoints inside the body), and a floor below so every face
        // of the box has patches on both sides. No sight line gets out.
        let sq = |z: f64, x0: f64, s: f64, up: bool| {
            Polygon::new(crate::geometry::fixtures::square(z, x0, x0, s, up)).unwrap()
        };
        let beside = Polygon::new(vec![
            DVec3::new(2.0, 0.5, 0.6),
            DVec3::new(3.0, 0.5, 0.6),
            DVec3::new(3.0, 0.5, 1.6),
            DVec3::new(2.0, 0.5, 1.6),
        ])
        .unwrap();
        let scene = Scene::builder()
            .surface("inside", vec![sq(0.5, 0.4, 0.2, true)], 0.9, None)
            .surface("beside", vec![beside], 0.9, None)
            .surface("floor", vec![sq(-1.0, -1.0, 3.0, true)], 0.9, None)
            .obstruction("enclosure", block(DVec3::ZERO, DVec3::ONE, true))
            .build();
        let shadows = Shadows::new(&scene, Policy::Exact { rel_tol: EXACT_REL_TOL }).unwrap();
        let faces = obstruction_faces(&shadows);
        assert!(faces.len() == 6 && faces.iter().all(|b| b.closed == -1 && b.body.is_some()));
        // One square face now intercepts every segment: the row's classification says so.
        let mut s = ShadowScratch::default();
        shadows.classify_row(0, &mut s.row);
        assert!(matches!(s.row.status(1), Status::Blocked));
        // The integration from viewpoints inside the body, every face handed over as partial.
        let u = polygon_polygon(&scene.patches[0].polygon, &scene.patches[1].polygon);
        assert!(u > 1e-6, "the plates face each other: {u}");
        let all: Vec<u32> = (0..shadows.blockers().len() as u32)
            .filter(|&b| {
                matches!(
                    shadows.blockers().get(b as usize).source,
                    super::super::blockers::BlockerSource::Obstruction { .. }
                )
            })
            .collect();
        let r = shadows.integrate(PairAt::new(0, 1, u, &all), EXACT_REL_TOL * u, u64::MAX, &mut s.work);
        assert!(!r.swapped, "the inside plate emits");
        assert!(r.s <= 1e-12 * u, "A·F = {} of {u} escapes the enclosure", r.s);
    }

    #[test]
    fn plates_with_centred_and_corner_blockers() {
        for (blocker, exact) in [
            (sq(0.5, 0.25, 0.25, 0.5, true), 0.099_506_294_6),
            (sq(0.5, 0.0, 0.0, 0.5, false), 0.149_868_671_8),
        ] {
            let scene = Scene::builder()
                .surface("bottom", vec![sq(0.0, 0.0, 0.0, 1.0, true)], 0.9, None)
                .surface("top", vec![sq(1.0, 0.0, 0.0, 1.0, false)], 0.9, None)
                .obstruction("plate", vec![blocker])
                .build();
            let (s, method) = exchange(&scene, Policy::Exact { rel_tol: EXACT_REL_TOL });
            assert!((s - exact).abs() < 1e-9, "analytic {s} vs {exact}");
            assert_eq!(method, MethodSet::SHADOWED);
            let (s, _) = exchange(&scene, Policy::Auto { tol: 1e-4, seed: 1 });
            assert!((s - exact).abs() < 1e-4, "auto {s} vs {exact}");
        }
    }

    /// Unit squares 1 apart (patches 0 and 1), a 0.1² plate midway: about 1 % of their exchange
    /// is blocked.
    fn mostly_visible_pair() -> Scene {
        unit_squares_behind("plate", vec![sq(0.5, 0.45, 0.45, 0.1, true)])
    }

    /// Unit squares 1 apart facing each other (patches 0 and 1), with the obstruction `faces`.
    fn unit_squares_behind(name: &str, faces: Vec<Polygon>) -> Scene {
        Scene::builder()
            .surface("bottom", vec![sq(0.0, 0.0, 0.0, 1.0, true)], 0.9, None)
            .surface("top", vec![sq(1.0, 0.0, 0.0, 1.0, false)], 0.9, None)
            .obstruction(name, faces)
            .build()
    }

    #[test]
    fn a_probe_predicts_the_doubling_count_or_none_past_the_cap() {
        let sigma = 1e-3;
        let goal = MC_SIGMAS * sigma;
        let probe = |samples: u32, var: f64| McPair { s: 0.5, var, samples, tests: 0 };
        // Already within the goal: the first draw is the whole sample.
        assert_eq!(probe_samples(&probe(256, 0.9 * sigma * sigma), goal, 256), Some(256));
        // Five times the variance wanted: 5 × 256 points, reached by doubling to 2,048.
        assert_eq!(probe_samples(&probe(256, 5.0 * sigma * sigma), goal, 256), Some(2048));
        // More than the cap can bring within the goal: no sample price.
        let over = 2.0 * f64::from(MC_MAX_SAMPLES) / 256.0;
        assert_eq!(probe_samples(&probe(256, over * sigma * sigma), goal, 256), None);
        assert_eq!(probe_samples(&probe(256, f64::NAN), goal, 256), None);
    }

    #[test]
    fn a_probe_sends_a_mostly_visible_pair_to_its_sample_where_the_worst_case_would_integrate() {
        // Unit squares 1 apart, a 0.1² plate midway (about 1 % blocked), a goal of u/64: the
        // worst case is 4,096 samples, the pair's share in shadow a few hundred.
        let scene = mostly_visible_pair();
        let exact = Shadows::new(&scene, Policy::Exact { rel_tol: EXACT_REL_TOL }).expect("a blocker");
        let (reference, u) = integrate_01(&exact);
        let goal = u / 64.0;
        let n = CostModel::samples(u, goal);
        assert_eq!(n, 4096.0);
        let mut shadows =
            Shadows::uncalibrated(&scene, Policy::Auto { tol: goal, seed: 3 }).expect("a blocker");
        let (mut s, partial, _) = pair_01(&shadows);
        let b = partial.len();
        // Integration priced at half the worst case's sample: above the probe's price.
        let mc = shadows.model().mc;
        let price = |c: f64| CostModel { shadow: PowerLaw { c, exp: 0.0 }, mc };
        let between = 0.5 * shadows.model().mc_ns(n, b) / ((u / goal).sqrt() * SHADOW_UNIT_NS);
        shadows.set_model(price(between));
        assert_eq!(shadows.model().choose(u, goal, b), Choice::Shadowed, "the worst case integrates");
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        assert_eq!(r.method, MethodSet::MC_AREA, "{r:?}");
        assert!(r.work <= 1280, "probe and sample drew {} points", r.work);
        assert!(
            MC_SIGMAS * r.var.sqrt() <= goal && (r.s - reference.s).abs() <= goal,
            "{r:?} vs {reference:?}"
        );
        // Integration priced below the informed sample but costing more than a quarter of it
        // (`CAP_PRICE_SHARE`): cut there and sampled.
        shadows.set_model(price(1.0));
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        assert_eq!(r.method, MethodSet::MC_AREA, "{r:?}");
        assert!(
            MC_SIGMAS * r.var.sqrt() <= goal && (r.s - reference.s).abs() <= goal,
            "{r:?} vs {reference:?}"
        );
        // Integration priced below the informed sample, at a goal of u/256 (a sample of
        // several thousand points, whose quarter pays for the integration): integrated,
        // within the goal.
        let goal = u / 256.0;
        let mut shadows =
            Shadows::uncalibrated(&scene, Policy::Auto { tol: goal, seed: 3 }).expect("a blocker");
        shadows.set_model(price(1.0));
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        assert_eq!(r.method, MethodSet::SHADOWED, "{r:?}");
        assert!((r.s - reference.s).abs() <= goal, "{r:?} vs {reference:?}");
    }

    /// Unit squares 1 apart with a 10 × 10 grid of 0.03² plates midway between them (100
    /// blockers, walked in the sample's box tree; a few per cent of the exchange blocked).
    fn pair_behind_a_grid() -> Scene {
        let plates = (0..100)
            .map(|k| sq(0.5, 0.2 + 0.06 * f64::from(k % 10), 0.2 + 0.06 * f64::from(k / 10), 0.03, true))
            .collect();
        unit_squares_behind("grid", plates)
    }

    #[test]
    fn a_probe_prices_its_sample_at_its_own_tests_per_point() {
        // 100 partial blockers: the prior prices a sample at 1 + b tests (a scan), the box tree
        // makes a handful. Integration priced between the two: the pair is sampled.
        let scene = pair_behind_a_grid();
        let exact = Shadows::new(&scene, Policy::Exact { rel_tol: 1e-5 }).expect("blockers");
        let (mut s, partial, u) = pair_01(&exact);
        let reference = exact.integrate(PairAt::new(0, 1, u, &partial), 1e-5 * u, u64::MAX, &mut s.work);
        assert!(reference.error <= 1e-5 * u, "{reference:?}");
        let goal = u / 64.0;
        let n = CostModel::samples(u, goal);
        let mut shadows =
            Shadows::uncalibrated(&scene, Policy::Auto { tol: goal, seed: 5 }).expect("blockers");
        let b = partial.len();
        assert_eq!(b, 100);
        let (probe, need, measured) =
            shadows.probe(PairAt::new(0, 1, u, &partial), (n as u32, goal), 5, &mut s.work);
        let tests = probe.tests as f64 / f64::from(probe.samples);
        assert!(
            4.0 * tests < shadows.model().mc.at(b),
            "{tests} tests a point against the prior's {}",
            shadows.model().mc.at(b)
        );
        let need = need.expect("a sample count");
        let prior = shadows.model().mc_ns(f64::from(need), b);
        let c = (measured * prior).sqrt() / ((u / goal).sqrt() * SHADOW_UNIT_NS);
        shadows.set_model(CostModel { shadow: PowerLaw { c, exp: 0.0 }, mc: shadows.model().mc });
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        assert_eq!(r.method, MethodSet::MC_AREA, "{r:?}");
        assert!(u64::from(need) + u64::from(probe.samples) >= r.work, "no integration drawn: {r:?}");
        assert!(
            MC_SIGMAS * r.var.sqrt() <= goal && (r.s - reference.s).abs() <= goal,
            "{r:?} vs {reference:?}"
        );
    }

    #[test]
    fn a_sample_priced_below_the_integration_s_set_up_is_drawn_without_integrating() {
        // A goal of u/8: a sample of ~100 points, priced below the set-up of an integration
        // past 100 blockers; the integration itself is priced lower still by the model.
        let scene = pair_behind_a_grid();
        let u = polygon_polygon(&scene.patches[0].polygon, &scene.patches[1].polygon);
        // Unit squares: the pair's goal is the tolerance.
        let goal = u / 8.0;
        let mut shadows =
            Shadows::uncalibrated(&scene, Policy::Auto { tol: goal, seed: 2 }).expect("blockers");
        let (mut s, partial, _) = pair_01(&shadows);
        let n = CostModel::samples(u, goal);
        let (probe, _, price) =
            shadows.probe(PairAt::new(0, 1, u, &partial), (n as u32, goal), 2, &mut s.work);
        assert!(price / SHADOW_UNIT_NS < setup_units(partial.len()) as f64, "{price} ns");
        let mc = shadows.model().mc;
        shadows.set_model(CostModel { shadow: PowerLaw { c: 1e-3, exp: 0.0 }, mc });
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        let m = shadows.sample(PairAt::new(0, 1, u, &partial), (n as u32, goal), 2, &mut s.work);
        assert_eq!(r.method, MethodSet::MC_AREA, "{r:?}");
        assert_eq!(r.work, u64::from(probe.samples + m.samples), "the probe and the sample only: {r:?}");
    }

    #[test]
    fn an_unpriced_pair_s_integration_far_past_its_price_gives_way_to_a_probe() {
        // A goal of u/512: the worst-case sample is 2^18 points, past the cap, so no sample is
        // priced; the pair (about 1 % blocked) needs a few thousand.
        let scene = mostly_visible_pair();
        let exact = Shadows::new(&scene, Policy::Exact { rel_tol: EXACT_REL_TOL }).expect("a blocker");
        let (reference, u) = integrate_01(&exact);
        let goal = u / 512.0;
        assert!(CostModel::samples(u, goal) > f64::from(MC_MAX_SAMPLES));
        let mut shadows =
            Shadows::uncalibrated(&scene, Policy::Auto { tol: goal, seed: 4 }).expect("a blocker");
        let (mut s, partial, _) = pair_01(&shadows);
        let full = shadows.integrate(PairAt::new(0, 1, u, &partial), goal, u64::MAX, &mut s.work);
        let mc = shadows.model().mc;
        let price = |c: f64| CostModel { shadow: PowerLaw { c, exp: 0.0 }, mc };
        // Priced at a thousandth of its work: cut at 64 times that, then probed and sampled.
        let c = full.info.work as f64 / 1000.0 / (u / goal).sqrt();
        shadows.set_model(price(c));
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        assert_eq!(r.method, MethodSet::MC_AREA, "{r:?}");
        assert!(
            MC_SIGMAS * r.var.sqrt() <= goal && (r.s - reference.s).abs() <= goal,
            "{r:?} vs {reference:?}"
        );
        // Priced at its work: integrated as before.
        shadows.set_model(price(2.0 * c * 1000.0));
        let r = shadows.pair(PairAt::new(0, 1, u, &partial), &mut s.work);
        assert_eq!(r.method, MethodSet::SHADOWED, "{r:?}");
        assert!((r.s - reference.s).abs() <= goal, "{r:?} vs {reference:?}");
    }

    #[test]
    fn a_capped_integration_stops_at_its_cap_or_once_its_roots_project_past_it() {
        let scene = pair_behind_a_grid();
        // A goal of u/64: the root cells (80, along the plates' kinks) are most of the work.
        let shadows = Shadows::uncalibrated(&scene, Policy::Auto { tol: 1e-6, seed: 0 }).expect("blockers");
        let (mut s, partial, u) = pair_01(&shadows);
        let goal = u / 64.0;
        let full = shadows.integrate(PairAt::new(0, 1, u, &partial), goal, u64::MAX, &mut s.work);
        assert!(!full.info.capped && full.info.roots > 8, "{:?}", full.info);
        let cap = full.info.work / 2;
        let capped = shadows.integrate(PairAt::new(0, 1, u, &partial), goal, cap, &mut s.work);
        assert!(capped.info.capped, "{:?}", capped.info);
        // Without the projection the roots run on until the cap itself.
        assert!(2 * capped.info.work < cap, "{} of a cap of {cap}", capped.info.work);
        // Caps that fall inside a root cell's rules (2×2 and 3×3 points, 13 a cell): the
        // integration stops at the viewpoint that reached the cap, not at the cell's end.
        let per_cell = (AUTO_RULES.0 * AUTO_RULES.0 + AUTO_RULES.1 * AUTO_RULES.1) as u64;
        let mid_cell = (0..40)
            .map(|k| 150 + 50 * k)
            .filter(|&cap| {
                let r = shadows.integrate(PairAt::new(0, 1, u, &partial), goal, cap, &mut s.work);
                assert!(r.info.capped, "{:?} for a cap of {cap}", r.info);
                !r.info.evals.is_multiple_of(per_cell)
            })
            .count();
        assert!(mid_cell > 10, "the rules of a cell ran to their end for {} of 40 caps", 40 - mid_cell);
    }

    #[test]
    fn a_mostly_visible_pair_stops_sampling_early_and_keeps_an_honest_error() {
        // Unit squares 1 apart, a 0.1² plate midway: about 1 % of the exchange is blocked.
        let scene = mostly_visible_pair();
        let exact = Shadows::new(&scene, Policy::Exact { rel_tol: EXACT_REL_TOL }).expect("a blocker");
        let (reference, u) = integrate_01(&exact);
        let blocked = 1.0 - reference.s / u;
        assert!(blocked > 0.002 && blocked < 0.05, "blocked share {blocked}");
        // A goal of u/256: the worst case (a ratio of ½) needs 2¹⁶ samples.
        let goal = u / 256.0;
        let shadows = Shadows::new(&scene, Policy::Auto { tol: goal, seed: 0 }).expect("a blocker");
        let n = CostModel::samples(u, goal) as u32;
        assert_eq!(n, MC_MAX_SAMPLES);
        let (mut s, partial, _) = pair_01(&shadows);
        let (mut far, mut drawn) = (0, 0u64);
        for seed in 0..200 {
            let m = shadows.sample(PairAt::new(0, 1, u, &partial), (n, goal), seed, &mut s.work);
            assert!(MC_SIGMAS * m.var.sqrt() <= goal, "seed {seed}: ± {} for a goal of {goal}", m.var.sqrt());
            far += usize::from((m.s - reference.s).abs() > 3.0 * m.var.sqrt());
            drawn += u64::from(m.samples);
        }
        // r(1 − r) ≈ 0.01 of the worst case's ¼: the doubling from the pilot stops far short.
        assert!(drawn <= 200 * u64::from(n) / 4, "{drawn} samples drawn, {} on average", drawn / 200);
        // Honest standard errors put about 0.3 % beyond three (at most 1 % allowed).
        assert!(far <= 2, "{far} of 200 estimates beyond 3 standard errors");
    }
}
