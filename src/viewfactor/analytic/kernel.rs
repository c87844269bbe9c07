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
use crate::geometry::tolerance::PATCH_COPLANAR_REL;
use crate::scene::Scene;
use crate::viewfactor::accuracy::ANALYTIC_REL;
use crate::viewfactor::engine::{RawEntry, Row, RowKernel};
use crate::viewfactor::exact::pair::polygon_polygon_with_round_off;
use crate::viewfactor::flags::{Flag, FlagLog};
use crate::viewfactor::shadow::branch::PairWork;
use crate::viewfactor::shadow::classify::Status;
use crate::viewfactor::shadow::detect::Occlusion;
use crate::viewfactor::shadow::policy::{Policy, EXACT_REL_TOL, SHADOW_UNIT_NS};
use crate::viewfactor::shadow::{ShadowScratch, Shadows};
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
/// the row is classified), each priced by the scene's shadow [`CostModel`] at the row's
/// blocker count.
///
/// [`CostModel`]: crate::viewfactor::shadow::policy::CostModel
const COST_PARTIAL_SHARE: f64 = 0.5;

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
                }
            })
            .collect();
        AnalyticKernel {
            scene,
            info,
            rules,
            model: ErrorModel::new(rel_tol),
            occlusion: OnceLock::new(),
            shadows: Shadows::new(scene, policy),
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

    /// Progress estimate only: the cost (ns) of one front-facing pair of row `i`, a clear
    /// pair plus [`COST_PARTIAL_SHARE`] of the shadow price at the count of blockers in front
    /// of patch i's plane (the classification's first filter); `ids` is scratch.
    pub fn facing_pair_cost(&self, i: usize, ids: &mut Vec<u32>) -> f64 {
        let Some(shadows) = self.shadows.as_ref() else { return COST_CLEAR_PAIR_NS };
        let (model, snap) = (shadows.model(), shadows.blockers().snap());
        let p = &self.info[i];
        ids.clear();
        shadows.blockers().blockers_where(
            |lo, hi| p.normal.dot(0.5 * (lo + hi)) + p.normal.abs().dot(0.5 * (hi - lo)) - p.offset > snap,
            ids,
        );
        let partial = match ids.len() {
            0 => 0.0,
            b => COST_PARTIAL_SHARE * model.shadow.at(b) * SHADOW_UNIT_NS,
        };
        COST_CLEAR_PAIR_NS + partial
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
                let r = shadows.pair(i, j, u, partial, work);
                RawEntry { j: j as u32, method: r.method, s: r.s, var: r.var }
            }
        };
        // A zero Monte Carlo estimate (every sample blocked) keeps its variance.
        (entry.s > 0.0 || entry.var > 0.0).then_some(entry)
    }

    /// Exchange areas A_i F_ij of patch i with the receivers `js` (ascending, all > i),
    /// exactly as [`RowKernel::row`] computes them; entries with s = 0 are left out. Blockers
    /// are classified only within the box of the receivers.
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
        let region =
            js.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |r, &j| {
                self.scene.patches[j as usize]
                    .polygon
                    .vertices()
                    .iter()
                    .fold(r, |(lo, hi), &v| (lo.min(v), hi.max(v)))
            });
        SHADOW_SCRATCH.with_borrow_mut(|ShadowScratch { row, work }| {
            shadows.classify_row_in(i, region, row);
            for &j in js {
                out.extend(self.entry(
                    shadows,
                    i,
                    j as usize,
                    row.status(j as usize),
                    (&mut reuse, &mut scratch),
                    work,
                ));
            }
        });
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
        SHADOW_SCRATCH.with_borrow_mut(|ShadowScratch { row, work }| {
            shadows.classify_row(i, row);
            for j in i + 1..n {
                out.entries.extend(self.entry(
                    shadows,
                    i,
                    j,
                    row.status(j),
                    (&mut reuse, &mut scratch),
                    work,
                ));
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
            .map_init(Vec::new, |ids, i| {
                let front = (i + 1..n).filter(|&j| self.may_face(i, j)).count() as f64;
                let back = (n - i - 1) as f64 - front;
                back * COST_ZERO_PAIR_NS + front * self.facing_pair_cost(i, ids)
            })
            .map(|c| c.round() as u64)
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
             integration stopped at its depth limit, or where its error stopped falling); worst: F({} -> {}) or its reciprocal, error \
             estimate {:.1e} on F against a goal of {:.1e}",
            if count == 1 { "y" } else { "ies" },
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
}
