//! Adaptive integration of the shaded integrand over the emitter: ∫_E g dA, with g from
//! [`super::viewpoint::ShadowGeometry::shaded`].
//!
//! g is continuous but has kinks wherever a shadow edge crosses a receiver edge, so raising a
//! fixed order converges slowly; the emitter is split instead (View3D's `ViewRP`/`ViewTP`):
//! - the emitter is first cut along the planes where g has kinks, first and second order
//!   ([`split_cells`]), so each root cell holds a smooth g;
//! - each cell (parallelogram, quadrilateral or triangle) is integrated with two rules of the
//!   degrees of the Gauss products of orders [`AdaptParams::low`] and [`AdaptParams::high`]
//!   per direction, |high − low| being its error estimate (on a triangle the higher one is a
//!   symmetric rule of the same degree in fewer points, [`triangle_rule`]); globally adaptive:
//!   the cell with the largest estimate splits into four until the estimates sum to the
//!   tolerance;
//! - no cell larger than the emitter's area over 4^[`AdaptParams::min_depth`] is accepted on
//!   its own rules (root cells already cut smaller are not split again);
//! - **blockers are re-classified per cell** with the exact penumbra/umbra planes
//!   ([`super::volume`]): a blocker clear of the cell's penumbra is dropped, one whose umbra
//!   holds the whole receiver makes g equal to the unobstructed integrand on that cell, and a
//!   cell with no blocker left contributes exactly 0;
//! - **no blocker goes unseen**: a cell in whose penumbra a blocker still lies, but from none
//!   of whose quadrature points that blocker's shadow reached the receiver, carries as its error
//!   estimate at least its unobstructed integral (0 ≤ g ≤ the unobstructed integrand, so a
//!   shadow the points missed is bounded by it) even when the two rules agree. This is what
//!   View3D lacks (it misses small blockers near edges, research/view3d.md §4 gunter2): such a
//!   cell is split while its bound matters to the tolerance, and the split stops as soon as
//!   the smaller cells' penumbrae clear the receiver or the shadow is sampled, or at
//!   [`AdaptParams::max_depth`]. A cell whose whole unobstructed share is far below the
//!   tolerance (a sliver receiver) is not split for it.
//! - **a cell a blocker touches** (a face standing on the emitter's edge or corner, as next
//!   to a facet of a solid) is held to the sum of its four children, with |parent − Σ
//!   children| in its error: g is not smooth at the touching point, and the two rules on
//!   such a cell can agree on a wrong value ([`Touch`]).
use super::classify::clip_front;
use super::viewpoint::{Scratch, ShadowGeometry, VIEWPOINT_WORK};
use super::volume::{Class, ShadowVolume};
use crate::geometry::convex::{ear_indices, is_convex_local};
use crate::geometry::frame::Frame;
use crate::geometry::groups::Groups;
use crate::geometry::planes::{plane_of, Plane};
use crate::geometry::quadrature::gauss_legendre;
use crate::geometry::tolerance::{EDGE_PARALLEL_ANGLE, EVENT_LEVEL_REL, PARALLELOGRAM_REL};
use glam::{DVec2, DVec3};

/// One emitter cell in the receiver frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    /// The parallelogram o + s·u + t·v, s, t ∈ [0, 1].
    Para {
        /// Corner.
        o: DVec3,
        /// First edge.
        u: DVec3,
        /// Second edge.
        v: DVec3,
    },
    /// A triangle.
    Tri([DVec3; 3]),
    /// A convex planar quadrilateral (counter-clockwise), mapped bilinearly from [0, 1]².
    Quad([DVec3; 4]),
}

impl Cell {
    /// Area, m².
    pub fn area(&self) -> f64 {
        match *self {
            Cell::Para { u, v, .. } => u.cross(v).length(),
            Cell::Tri([a, b, c]) => 0.5 * (b - a).cross(c - a).length(),
            Cell::Quad([a, b, c, d]) => 0.5 * (c - a).cross(d - b).length(),
        }
    }
    /// The four congruent children.
    pub fn children(&self) -> [Cell; 4] {
        match *self {
            Cell::Para { o, u, v } => {
                let (u, v) = (0.5 * u, 0.5 * v);
                [
                    Cell::Para { o, u, v },
                    Cell::Para { o: o + u, u, v },
                    Cell::Para { o: o + v, u, v },
                    Cell::Para { o: o + u + v, u, v },
                ]
            }
            Cell::Tri([a, b, c]) => {
                let (ab, bc, ca) = (0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a));
                [
                    Cell::Tri([a, ab, ca]),
                    Cell::Tri([ab, b, bc]),
                    Cell::Tri([ca, bc, c]),
                    Cell::Tri([ab, bc, ca]),
                ]
            }
            Cell::Quad([a, b, c, d]) => {
                let (ab, bc, cd, da) = (0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + d), 0.5 * (d + a));
                let m = 0.25 * (a + b + c + d);
                [
                    Cell::Quad([a, ab, m, da]),
                    Cell::Quad([ab, b, bc, m]),
                    Cell::Quad([m, bc, c, cd]),
                    Cell::Quad([da, m, cd, d]),
                ]
            }
        }
    }
    /// Vertices (3 or 4) into `out`.
    pub fn ring(&self, out: &mut Vec<DVec3>) {
        let (corners, m) = self.corners();
        out.clear();
        out.extend_from_slice(&corners[..m]);
    }
    /// Vertices in order: the first 3 or 4 of the array, and how many.
    fn corners(&self) -> ([DVec3; 4], usize) {
        match *self {
            Cell::Para { o, u, v } => ([o, o + u, o + u + v, o + v], 4),
            Cell::Tri([a, b, c]) => ([a, b, c, c], 3),
            Cell::Quad(q) => (q, 4),
        }
    }
}

/// Gauss–Legendre nodes and weights on [0, 1], and for a higher rule on a triangle the
/// symmetric rule of the collapsed n×n product's degree where one is tabulated
/// ([`triangle_rule`]).
#[derive(Debug, Clone)]
struct Rule {
    x: Vec<f64>,
    w: Vec<f64>,
    /// Barycentric points and weights (summing to 1) of the triangle rule; empty for the
    /// collapsed product (every lower rule).
    tri: Vec<([f64; 3], f64)>,
}

impl Rule {
    /// The products of order n (the lower rule of a pair).
    fn new(n: usize) -> Self {
        let (x, w) = gauss_legendre(n);
        Self { x, w, tri: Vec::new() }
    }
    /// The higher rule of a pair: the products, with the symmetric rule on triangles where
    /// one is tabulated.
    fn higher(n: usize) -> Self {
        Self { tri: triangle_rule(n), ..Self::new(n) }
    }
    /// Points the rule takes on `cell`.
    fn points(&self, cell: &Cell) -> usize {
        match cell {
            Cell::Tri(_) if !self.tri.is_empty() => self.tri.len(),
            _ => self.x.len() * self.x.len(),
        }
    }
    /// Calls `f(point, weight)` over the tensor rule on a parallelogram or quadrilateral, the
    /// symmetric (where tabulated) or collapsed rule on a triangle; weights sum to the cell's
    /// area.
    #[inline]
    fn each(&self, cell: &Cell, mut f: impl FnMut(DVec3, f64)) {
        let area = cell.area();
        match *cell {
            Cell::Para { o, u, v } => {
                for (xi, wi) in self.x.iter().zip(&self.w) {
                    for (xj, wj) in self.x.iter().zip(&self.w) {
                        f(o + *xi * u + *xj * v, area * wi * wj);
                    }
                }
            }
            Cell::Tri([a, b, c]) if !self.tri.is_empty() => {
                for &([l0, l1, l2], w) in &self.tri {
                    f(l0 * a + l1 * b + l2 * c, area * w);
                }
            }
            Cell::Tri([a, b, c]) => {
                for (xi, wi) in self.x.iter().zip(&self.w) {
                    for (xj, wj) in self.x.iter().zip(&self.w) {
                        let t = xj * (1.0 - xi);
                        f(a + *xi * (b - a) + t * (c - a), 2.0 * area * wi * wj * (1.0 - xi));
                    }
                }
            }
            Cell::Quad([a, b, c, d]) => {
                // x(s, t) = (1−s)(1−t)a + s(1−t)b + s·t·c + (1−s)t·d, weight |x_s × x_t|.
                for (&xs, ws) in self.x.iter().zip(&self.w) {
                    for (&xt, wt) in self.x.iter().zip(&self.w) {
                        let p = (1.0 - xs) * ((1.0 - xt) * a + xt * d) + xs * ((1.0 - xt) * b + xt * c);
                        let ds = (1.0 - xt) * (b - a) + xt * (c - d);
                        let dt = (1.0 - xs) * (d - a) + xs * (c - b);
                        f(p, ds.cross(dt).length() * ws * wt);
                    }
                }
            }
        }
    }
}

/// Symmetric triangle rules with positive weights and interior points (Dunavant 1985), exact
/// to degree 2n − 2 like the collapsed n×n Gauss product they replace as the higher rule, in
/// fewer points (n = 3, 5: 6 and 16 against 9 and 25); empty for other n. The lower rule stays
/// the collapsed product: with the 12-point degree-6 rule as the lower one too, the pair's
/// difference stood below the error more often (heat sink with one patch per wall, `analytic`:
/// 10 pairs off by more than their estimate against 5, worst 1.1e-7 of u against 8.2e-8); with
/// two point sets this unlike, it is as often right as with the products'. Each orbit is
/// (weight, a, b): the centroid when a = b = ⅓, three points (1 − 2a, a, a) when b = a, else
/// the six permutations of (a, b, 1 − a − b). Constants refined to double precision against the
/// moment equations (`tests::symmetric_rules_are_exact_to_their_degree`).
fn triangle_rule(n: usize) -> Vec<([f64; 3], f64)> {
    const THIRD: f64 = 1.0 / 3.0;
    let orbits: &[(f64, f64, f64)] = match n {
        3 => &[
            (0.223_381_589_678_011_47, 0.445_948_490_915_964_9, 0.445_948_490_915_964_9),
            (0.109_951_743_655_321_87, 0.091_576_213_509_770_74, 0.091_576_213_509_770_74),
        ],
        5 => &[
            (0.144_315_607_677_787_17, THIRD, THIRD),
            (0.095_091_634_267_284_62, 0.459_292_588_292_723_2, 0.459_292_588_292_723_2),
            (0.103_217_370_534_718_24, 0.170_569_307_751_760_2, 0.170_569_307_751_760_2),
            (0.032_458_497_623_198_08, 0.050_547_228_317_030_98, 0.050_547_228_317_030_98),
            (0.027_230_314_174_434_993, 0.008_394_777_409_957_605, 0.263_112_829_634_638_1),
        ],
        _ => &[],
    };
    let mut out = Vec::new();
    for &(w, a, b) in orbits {
        let c = 1.0 - a - b;
        if a == THIRD && b == THIRD {
            out.push(([a, a, a], w));
        } else if a == b {
            out.extend([([c, a, a], w), ([a, c, a], w), ([a, a, c], w)]);
        } else {
            out.extend([[a, b, c], [a, c, b], [b, a, c], [b, c, a], [c, a, b], [c, b, a]].map(|p| (p, w)));
        }
    }
    out
}

/// Controls of the adaptive integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptParams {
    /// Gauss order per direction of the lower rule.
    pub low: usize,
    /// Gauss order per direction of the higher rule (the value kept).
    pub high: usize,
    /// No accepted cell is larger than the emitter over 4^min_depth (each quarter-split of
    /// the whole emitter counts one).
    pub min_depth: u32,
    /// No cell is split more than this many times.
    pub max_depth: u32,
}

/// What the integration did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AdaptInfo {
    /// ∫_E g dA, m².
    pub shaded: f64,
    /// Σ over accepted cells of |high − low|: the error estimate, m².
    pub error: f64,
    /// Viewpoint evaluations.
    pub evals: u64,
    /// Counted work: the viewpoints' [`super::viewpoint::Coverage::work`] plus one per
    /// blocker re-classified for a cell (the unit in which `auto` prices integration).
    pub work: u64,
    /// Cells accepted.
    pub cells: u32,
    /// Cells accepted only because they reached the maximum depth.
    pub at_max_depth: u32,
    /// Root cells after the split along kink planes.
    pub roots: u32,
    /// True when refinement stopped because the error estimate had stopped falling
    /// ([`STALL_MIN_WORK`]); the result then carries its error, above the tolerance.
    pub stalled: bool,
    /// True when refinement stopped at the work cap short of the tolerance: the result is
    /// incomplete (root cells may be missing) and its error does not bound it.
    pub capped: bool,
}

/// Share of the cap a capped integration spends on its root cells before it judges, from the
/// work of the roots done, whether all of them fit ([`past_cap`]).
pub const CAP_PROJECT_SHARE: u64 = 8;

/// True when `work` spent on the first `done` of `roots` root cells, at least
/// 1/[`CAP_PROJECT_SHARE`] of `max_work`, projects past `max_work` over all the roots: the
/// integration stops there instead of at the cap (never without a cap). The projection comes
/// before any refinement, so it undercounts: a wall pair behind a meshed part spent its whole
/// cap on 60–80 roots and was then sampled all the same (validation/cad.md).
fn past_cap(work: u64, done: usize, roots: usize, max_work: u64) -> bool {
    max_work < u64::MAX
        && done > 0
        && work.saturating_mul(CAP_PROJECT_SHARE) >= max_work
        && u128::from(work) * roots as u128 > u128::from(max_work) * done as u128
}

/// Work after which the integration checks, at every [`STALL_WORK_RATIO`]-fold increase of
/// its work, that its error estimate fell by [`STALL_ERROR_RATIO`] or more. Adaptive
/// refinement of a piecewise smooth integrand (kinks and jumps along lines included) cuts the
/// error at least in proportion to the work; an estimate that stays put is held up by cells
/// at the depth limit or round-off, and more work would not lower it (a mis-rotated wall
/// crossing the room kept one pair at 4e-6 through 1e8 work, 24 s). Far above the work of
/// any pair in the validation suite or the real-parts scenes.
pub const STALL_MIN_WORK: u64 = 1_000_000;
/// See [`STALL_MIN_WORK`].
pub const STALL_WORK_RATIO: u64 = 4;
/// See [`STALL_MIN_WORK`].
pub const STALL_ERROR_RATIO: f64 = 0.5;

/// Reusable state of the integrator.
#[derive(Debug, Clone, Default)]
pub struct AdaptScratch {
    /// Per-viewpoint buffers.
    pub shadow: Scratch,
    heap: std::collections::BinaryHeap<(Key, std::cmp::Reverse<usize>)>,
    leaves: Vec<Leaf>,
    pool: Vec<u32>,
    ring: Vec<DVec3>,
    volume: ShadowVolume,
    shaft: Vec<Plane>,
}

/// A heap key: an error, ordered as a total order on f64.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Key(f64);
impl Eq for Key {}
impl PartialOrd for Key {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Key {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

/// An evaluated cell.
#[derive(Debug, Clone, Copy)]
struct Leaf {
    item: Item,
    hi: f64,
    err: f64,
}

#[derive(Debug, Clone, Copy)]
struct Item {
    cell: Cell,
    depth: u32,
    /// Active blockers: pool[start..start + len].
    start: usize,
    len: usize,
    /// The receiver lies in some blocker's umbra: g is the unobstructed integrand.
    full: bool,
    /// Cells below the root re-classify their blockers.
    classify: bool,
}

/// The adaptive integrator with its Gauss tables.
#[derive(Debug, Clone)]
pub struct Integrator {
    params: AdaptParams,
    low: Rule,
    high: Rule,
    solid_min: Option<usize>,
    cuts: Cuts,
}

/// How many of the kink planes cut the emitter into root cells ([`split_cells`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cuts {
    /// Most root pieces; the planes past the cap are left to the adaptivity.
    pub max_pieces: usize,
    /// Cut along the blockers' own planes after the edge and event planes instead of before
    /// (no effect with `edges_only`, which takes none of them).
    pub faces_last: bool,
    /// Cut along the receiver-edge planes only (a shadow edge sliding along a receiver edge),
    /// leaving the blockers' planes and the second-order events to the adaptivity.
    pub edges_only: bool,
}

impl Cuts {
    /// Every kink plane first, up to `MAX_PIECES` pieces, the blockers' planes first
    /// (`analytic`: each root smooth).
    pub const ALL: Self = Self::up_to(MAX_PIECES, false);

    /// Every kind of kink plane, up to `max_pieces` pieces, the blockers' planes last when
    /// `faces_last`.
    pub const fn up_to(max_pieces: usize, faces_last: bool) -> Self {
        Self { max_pieces, faces_last, edges_only: false }
    }

    /// The receiver-edge planes only, up to `max_pieces` pieces.
    pub const fn receiver_edges(max_pieces: usize) -> Self {
        Self { max_pieces, faces_last: false, edges_only: true }
    }
}

impl Integrator {
    /// Builds the rules.
    pub fn new(params: AdaptParams) -> Self {
        Self {
            params,
            low: Rule::new(params.low.max(1)),
            high: Rule::higher(params.high.max(1)),
            solid_min: None,
            cuts: Cuts::ALL,
        }
    }
    /// Which kink planes cut the emitter into root cells.
    pub fn with_cuts(mut self, cuts: Cuts) -> Self {
        self.cuts = Cuts { max_pieces: cuts.max_pieces.max(1), ..cuts };
        self
    }
    /// Pairs whose partial blockers are all faces of one convex solid of at least `min_faces`
    /// faces take the facet sum ([`super::solid`]) instead of the shadow integration.
    pub fn with_solids(mut self, min_faces: usize) -> Self {
        self.solid_min = Some(min_faces);
        self
    }
    /// The fewest faces of one convex solid that take the facet sum, if it is used.
    pub fn solid_min(&self) -> Option<usize> {
        self.solid_min
    }

    /// ∫_E g dA over the emitter of `geo` with every kept blocker active, to the absolute
    /// tolerance `tol` (m²).
    #[cfg(test)]
    pub fn shaded(&self, geo: &ShadowGeometry, tol: f64, s: &mut AdaptScratch) -> AdaptInfo {
        self.shaded_within(geo, tol, u64::MAX, s)
    }

    /// As [`Self::shaded`], refining no further once [`AdaptInfo::work`] reaches `max_work`
    /// (the result is then short of the tolerance: for pricing, never for an entry).
    pub fn shaded_within(
        &self,
        geo: &ShadowGeometry,
        tol: f64,
        max_work: u64,
        s: &mut AdaptScratch,
    ) -> AdaptInfo {
        let mut info = AdaptInfo::default();
        let roots = split_cells(geo, self.cuts);
        let total_area: f64 = roots.iter().map(Cell::area).sum();
        info.roots = roots.len() as u32;
        if !(total_area > 0.0) || geo.blockers().is_empty() {
            return info;
        }
        s.pool.clear();
        s.pool.extend(0..geo.blockers().len() as u32);
        s.heap.clear();
        s.leaves.clear();
        let n = s.pool.len();
        let several = roots.len() > 1;
        let groups = fold_groups(geo);
        let touch = Touch::new(geo);
        // A cell larger than this is split whatever its rules say (the 1e-9 keeps the exact
        // quarters of the emitter below it).
        let forced_area = total_area * 0.25f64.powi(self.params.min_depth as i32) * (1.0 + 1e-9);
        // Open leaves: error (∞ while a split is forced), ordered largest first.
        let (mut open_err, mut forced) = (0.0, 0usize);
        let push = |item: Item, this: &Self, s: &mut AdaptScratch, info: &mut AdaptInfo| {
            let mut item = item;
            if item.classify && !item.full {
                info.work += item.len as u64;
                this.reclassify(geo, &mut item, s);
                if !item.full && item.len == 0 {
                    info.cells += 1;
                    return (0.0, 0);
                }
            }
            // A cap that comes within a cell's rules ends the integration there, capped.
            let Some((lo, mut hi, (seen, away))) = this.evaluate(geo, &item, max_work, info, s) else {
                return (0.0, 0);
            };
            let mut rules = (hi - lo).abs();
            if !item.full && item.depth < this.params.max_depth && touch.meets(&item, &s.pool) {
                // A blocker touches the cell: its rules can agree on a wrong value, so the
                // cell is held to its children's sum (see [`Touch`]).
                let (mut sum, mut spread) = (0.0, 0.0);
                for cell in item.cell.children() {
                    let Some((lo, hi, _)) = this.evaluate(geo, &Item { cell, ..item }, max_work, info, s)
                    else {
                        return (0.0, 0);
                    };
                    sum += hi;
                    spread += (hi - lo).abs();
                }
                rules = spread + (hi - sum).abs();
                hi = sum;
            }
            let all_seen = item.full || item.len >= 64 || {
                // Every active blocker was turned away from some rule point, or it or a
                // blocker folded onto it cast a shadow here. A face turned away vouches for
                // itself only: counted for its body, it once let a board whose faces' shadows
                // all fell between the rule points pass as seen.
                let active = &s.pool[item.start..item.start + item.len];
                let mut hit = 0u64;
                for (bit, &b) in active.iter().enumerate() {
                    if seen >> bit & 1 == 1 {
                        hit |= 1 << (groups[b as usize] % 64);
                    }
                }
                active
                    .iter()
                    .enumerate()
                    .all(|(bit, &b)| away >> bit & 1 == 1 || hit >> (groups[b as usize] % 64) & 1 == 1)
            };
            let must_split = item.cell.area() > forced_area && item.depth < this.params.max_depth;
            // A blocker no rule point saw may still shade part of the cell: 0 ≤ g ≤ the
            // unobstructed integrand, so the cell's unobstructed integral bounds that error.
            let err = if all_seen {
                rules
            } else {
                let (bound, evals) = this.unshaded_integral(geo, &item.cell);
                info.evals += evals;
                info.work += evals * VIEWPOINT_WORK;
                rules.max(bound)
            };
            let key = if must_split { f64::INFINITY } else { err };
            let k = s.leaves.len();
            s.leaves.push(Leaf { item, hi, err });
            s.heap.push((Key(key), std::cmp::Reverse(k)));
            if must_split {
                (0.0, 1)
            } else {
                (err, 0)
            }
        };
        let n_roots = roots.len();
        for (k, cell) in roots.into_iter().enumerate() {
            if info.work >= max_work || past_cap(info.work, k, n_roots, max_work) {
                info.capped = true;
                break;
            }
            let (e, f) = push(
                Item { cell, depth: 0, start: 0, len: n, full: false, classify: several },
                self,
                s,
                &mut info,
            );
            open_err += e;
            forced += f;
        }
        // Refine the worst leaf until the open error meets the tolerance (global adaptivity:
        // effort goes where the error is, not where a per-cell share is tightest), or until
        // the error stops falling (see [`STALL_MIN_WORK`]).
        let mut check = (STALL_MIN_WORK, f64::INFINITY);
        while (forced > 0 || open_err > tol) && info.work < max_work {
            if forced == 0 && info.work >= check.0 {
                let estimate = open_err + info.error;
                if estimate > STALL_ERROR_RATIO * check.1 {
                    info.stalled = true;
                    break;
                }
                check = (info.work.saturating_mul(STALL_WORK_RATIO), estimate);
            }
            let Some((Key(key), std::cmp::Reverse(k))) = s.heap.pop() else { break };
            let leaf = s.leaves[k];
            if key.is_infinite() {
                forced -= 1;
            } else {
                open_err -= leaf.err;
            }
            if leaf.item.depth >= self.params.max_depth {
                info.shaded += leaf.hi;
                info.error += leaf.err;
                info.cells += 1;
                info.at_max_depth += 1;
                continue;
            }
            for child in leaf.item.cell.children() {
                let item = Item { cell: child, depth: leaf.item.depth + 1, classify: true, ..leaf.item };
                let (e, f) = push(item, self, s, &mut info);
                open_err += e;
                forced += f;
            }
        }
        info.capped |= info.work >= max_work && (forced > 0 || open_err > tol);
        for (_, std::cmp::Reverse(k)) in s.heap.drain() {
            let leaf = &s.leaves[k];
            info.shaded += leaf.hi;
            info.error += leaf.err;
            info.cells += 1;
        }
        info
    }

    /// Drops blockers clear of the cell's penumbra, and faces of a solid turned away from the
    /// whole cell; marks the cell full when the receiver is in some blocker's umbra. The
    /// surviving list is copied to the end of the pool.
    fn reclassify(&self, geo: &ShadowGeometry, item: &mut Item, s: &mut AdaptScratch) {
        item.cell.ring(&mut s.ring);
        let snap = geo.snap();
        s.shaft.clear();
        if item.len >= SHAFT_MIN_BLOCKERS {
            shaft_planes(&s.ring, geo.receiver_hull(), snap, &mut s.shaft);
        }
        let start = s.pool.len();
        for k in item.start..item.start + item.len {
            let b = s.pool[k];
            if geo.turned_away(b as usize, &s.ring) {
                // A solid's face turned away from the whole cell casts no shadow from it.
                continue;
            }
            let blocker = &geo.blockers()[b as usize];
            if s.shaft.iter().any(|p| blocker.iter().all(|&x| p.distance(x) > snap)) {
                // Outside the hull of the cell and the receiver, which holds every segment
                // between them: clear, without building its volume.
                continue;
            }
            match s.volume.build_classify_exact(&s.ring, blocker, geo.snap(), geo.receiver_ring()) {
                None | Some(Class::Clear) => {}
                Some(Class::Full) => {
                    item.full = true;
                    s.pool.truncate(start);
                    item.start = start;
                    item.len = 0;
                    return;
                }
                Some(Class::Partial) => s.pool.push(b),
            }
        }
        item.start = start;
        item.len = s.pool.len() - start;
    }

    /// The higher rule's ∫ of the unobstructed integrand over `cell` (which bounds ∫ g there),
    /// and its evaluations.
    fn unshaded_integral(&self, geo: &ShadowGeometry, cell: &Cell) -> (f64, u64) {
        let mut sum = 0.0;
        let mut evals = 0;
        self.high.each(cell, |p, w| {
            evals += 1;
            sum += w * geo.unshaded(p);
        });
        (sum, evals)
    }

    /// Both rules on one cell: (low, high, (seen, turned-away) masks), their evaluations and
    /// work added to `info`; `None`, with `info` marked capped, when its work reached
    /// `max_work` before the last rule point (the rest are not evaluated).
    fn evaluate(
        &self,
        geo: &ShadowGeometry,
        item: &Item,
        max_work: u64,
        info: &mut AdaptInfo,
        s: &mut AdaptScratch,
    ) -> Option<(f64, f64, (u64, u64))> {
        let budget = max_work.saturating_sub(info.work);
        let active = &s.pool[item.start..item.start + item.len];
        let shadow = &mut s.shadow;
        let (mut seen, mut away) = (0u64, 0u64);
        let mut evals = 0u64;
        let mut work = 0u64;
        let mut cut = false;
        let mut sums = [0.0; 2];
        for (k, rule) in [&self.low, &self.high].into_iter().enumerate() {
            rule.each(&item.cell, |p, w| {
                if work >= budget {
                    cut = true;
                    return;
                }
                evals += 1;
                let g = if item.full {
                    work += VIEWPOINT_WORK;
                    geo.unshaded(p)
                } else {
                    let (g, cov) = geo.shaded(p, active, shadow);
                    seen |= cov.seen;
                    away |= cov.away;
                    work += cov.work;
                    g
                };
                sums[k] += w * g;
            });
        }
        info.evals += evals;
        info.work += work;
        info.capped |= cut;
        (!cut).then_some((sums[0], sums[1], (seen, away)))
    }
}

/// The points where blockers touch the emitter's plane (within the snap): the faces next to
/// an emitter on a solid's surface, which share its edges or corners. From a viewpoint near
/// such a point the blocker's shadow swings through every direction, so g is not smooth
/// there, and the two Gauss rules on a cell that touches it can agree on a wrong value: a
/// heat-sink channel floor's 4×4 and 5×5 rules agreed to 5e-10 m² where the cell was 3.4e-9
/// off, and the pair ended 3.6 times its estimate. Such a cell is held to its children's sum,
/// with |parent − Σ children| in its error (two levels instead of two rules).
struct Touch {
    /// The emitter's frame (its normal the frame's n).
    frame: Frame,
    /// Per kept blocker, its touching segments in the frame's plane (a lone point as a
    /// zero-length one).
    sets: Vec<Vec<(DVec2, DVec2)>>,
    snap: f64,
}

impl Touch {
    fn new(geo: &ShadowGeometry) -> Self {
        let snap = geo.snap();
        let frame = Frame::new(geo.emitter()[0], geo.emitter_normal());
        let flat = |x: DVec3| frame.in_plane(x);
        let sets = geo
            .blockers()
            .iter()
            .map(|b| {
                let m = b.len();
                let h: Vec<f64> = b.iter().map(|&v| frame.point(v).z).collect();
                let mut out = Vec::new();
                for k in 0..m {
                    let (v, w, hv, hw) = (b[k], b[(k + 1) % m], h[k], h[(k + 1) % m]);
                    if hv.abs() <= snap && hw.abs() <= snap {
                        out.push((flat(v), flat(w)));
                    } else if hv.abs() <= snap {
                        out.push((flat(v), flat(v)));
                    } else if (hv < 0.0) != (hw < 0.0) && hw.abs() > snap {
                        let x = flat(v + (w - v) * (hv / (hv - hw)));
                        out.push((x, x));
                    }
                }
                out
            })
            .collect();
        Self { frame, sets, snap }
    }

    /// True when an active blocker of `item` touches its cell (within the snap).
    fn meets(&self, item: &Item, pool: &[u32]) -> bool {
        let active = &pool[item.start..item.start + item.len];
        if active.iter().all(|&b| self.sets[b as usize].is_empty()) {
            return false;
        }
        let (corners, m) = item.cell.corners();
        let flat = corners.map(|x| self.frame.in_plane(x));
        let ring = &flat[..m];
        let near = |p: DVec2, q: DVec2| {
            segment_meets_ring(p, q, ring)
                || (0..m).any(|k| segment_distance(p, q, ring[k], ring[(k + 1) % m]) <= self.snap)
        };
        active.iter().any(|&b| self.sets[b as usize].iter().any(|&(p, q)| near(p, q)))
    }
}

/// Distance between segments [a, b] and [c, d] that do not cross (2-D).
fn segment_distance(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    let to = |p: DVec2, a: DVec2, b: DVec2| {
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 {
            ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + ab * t - p).length()
    };
    to(a, c, d).min(to(b, c, d)).min(to(c, a, b)).min(to(d, a, b))
}

/// Fewest active blockers for which a cell's reclassification first builds its shaft planes
/// ([`shaft_planes`], about 24 candidate planes): below, the shadow volumes of the few blockers
/// cost less than the planes.
const SHAFT_MIN_BLOCKERS: usize = 8;

/// The side planes of the shaft conv(cell ∪ receiver) (every segment from the cell to the
/// receiver lies in it), oriented with the shaft behind them (within `snap`): the planes through
/// an edge of one polygon and a vertex of the other that leave every vertex on one side.
fn shaft_planes(cell: &[DVec3], receiver: &[DVec2], snap: f64, out: &mut Vec<Plane>) {
    out.clear();
    let r = |k: usize| receiver[k % receiver.len()].extend(0.0);
    let all = || cell.iter().copied().chain((0..receiver.len()).map(r));
    let mut keep = |a: DVec3, b: DVec3, v: DVec3| {
        let Some(p) = Plane::through(a, b, v, 1e-300) else { return };
        let (lo, hi) = all().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            let d = p.distance(x);
            (lo.min(d), hi.max(d))
        });
        if hi <= snap {
            out.push(p);
        } else if lo >= -snap {
            out.push(p.flipped());
        }
    };
    for k in 0..cell.len() {
        let (a, b) = (cell[k], cell[(k + 1) % cell.len()]);
        for m in 0..receiver.len() {
            keep(a, b, r(m));
        }
    }
    for m in 0..receiver.len() {
        let (a, b) = (r(m), r(m + 1));
        for &v in cell {
            keep(a, b, v);
        }
    }
}

/// What [`Integrator::integrate_smooth`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Smooth {
    /// The integral.
    pub value: f64,
    /// Σ over accepted cells of |high − low|.
    pub error: f64,
    /// Integrand evaluations.
    pub evals: u64,
    /// Cells accepted.
    pub cells: u32,
    /// Cells accepted only because they reached the maximum depth.
    pub at_max_depth: u32,
}

impl Integrator {
    /// ∫ f over the cells `roots` (on each of which f is smooth), globally adaptive with the
    /// rule pair until the error estimates sum to `tol`; no blockers, no forced splits.
    pub fn integrate_smooth(&self, roots: &[Cell], tol: f64, mut f: impl FnMut(DVec3) -> f64) -> Smooth {
        let mut out = Smooth::default();
        let mut heap: std::collections::BinaryHeap<(Key, std::cmp::Reverse<usize>)> = Default::default();
        let mut leaves: Vec<(Cell, u32, f64, f64)> = Vec::new();
        let mut open = 0.0;
        let mut eval = |cell: &Cell, depth: u32, out: &mut Smooth| {
            let mut sums = [0.0; 2];
            for (k, rule) in [&self.low, &self.high].into_iter().enumerate() {
                rule.each(cell, |p, w| sums[k] += w * f(p));
                out.evals += rule.points(cell) as u64;
            }
            (*cell, depth, sums[1], (sums[1] - sums[0]).abs())
        };
        for cell in roots {
            let leaf = eval(cell, 0, &mut out);
            open += leaf.3;
            heap.push((Key(leaf.3), std::cmp::Reverse(leaves.len())));
            leaves.push(leaf);
        }
        while open > tol {
            let Some((_, std::cmp::Reverse(k))) = heap.pop() else { break };
            let (cell, depth, hi, err) = leaves[k];
            open -= err;
            if depth >= self.params.max_depth {
                out.value += hi;
                out.error += err;
                out.cells += 1;
                out.at_max_depth += 1;
                continue;
            }
            for child in cell.children() {
                let leaf = eval(&child, depth + 1, &mut out);
                open += leaf.3;
                heap.push((Key(leaf.3), std::cmp::Reverse(leaves.len())));
                leaves.push(leaf);
            }
        }
        for (_, std::cmp::Reverse(k)) in heap.drain() {
            out.value += leaves[k].2;
            out.error += leaves[k].3;
            out.cells += 1;
        }
        out
    }
}

/// Splits the planar convex `ring` along every plane that crosses its interior (by more than
/// `snap`), into at most `max` pieces (planes past the cap are left to the adaptivity).
pub fn cut_along(ring: &[DVec3], planes: &[Plane], snap: f64, max: usize) -> Vec<Vec<DVec3>> {
    let mut pieces: Vec<Vec<DVec3>> = vec![ring.to_vec()];
    let mut half = Vec::new();
    for p in planes {
        if pieces.len() >= max {
            break;
        }
        let mut next = Vec::with_capacity(pieces.len() + 1);
        for piece in pieces {
            let (lo, hi) = piece.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                let d = p.distance(v);
                (l.min(d), h.max(d))
            });
            if lo < -snap && hi > snap {
                for side in [*p, p.flipped()] {
                    clip_front(&piece, side.n, -side.d, snap, &mut half);
                    if half.len() >= 3 {
                        next.push(half.clone());
                    }
                }
            } else {
                next.push(piece);
            }
        }
        pieces = next;
    }
    pieces
}

/// Most emitter pieces after splitting along kink planes (a meshed curved body has more
/// events than are worth cutting; the adaptivity takes the rest).
const MAX_PIECES: usize = 256;

/// Root cells of the emitter, split first along the planes where g has kinks:
/// - a blocker's plane: the blocker turns from front to back as the viewpoint crosses it, which
///   changes which shadow edges exist;
/// - the plane through a receiver edge and a parallel blocker edge: there the shadow edge
///   slides onto the receiver edge, and the shaded area's slope jumps;
/// - the second-order events (`event_planes`): a blocker vertex's shadow crossing a receiver
///   edge, a blocker edge's shadow crossing a receiver vertex, where g is C¹ but its second
///   derivatives jump. Left to the adaptivity these cost thousands of viewpoints per pair
///   (a cell cut by such a line converges as h⁴) and can stall at the depth limit.
///
/// Only edges that can bound the blockers' joint shadow count (`silhouette_edges`): an edge
/// two faces of one mesh share is skipped when, from the whole emitter, they fold away on the
/// same side. Within each piece g is then smooth (up to `cuts.max_pieces` pieces).
///
/// With [`Cuts::faces_last`] the blockers' planes come after the others: a facet turning
/// edge-on starts its shadow from zero width, so its kink scales with the facet, while a
/// shadow edge sliding along a receiver edge kinks g along a whole line.
pub fn split_cells(geo: &ShadowGeometry, cuts: Cuts) -> Vec<Cell> {
    let snap = geo.snap();
    // The blockers' own planes (none when cutting along the receiver edges only).
    let mut planes: Vec<Plane> = if cuts.edges_only {
        Vec::new()
    } else {
        geo.blockers().iter().filter_map(|b| plane_of(b)).collect()
    };
    let faces = planes.len();
    let recv = geo.receiver_edges();
    let silhouette = silhouette_edges(geo);
    for (b, sil) in geo.blockers().iter().zip(&silhouette) {
        for k in 0..b.len() {
            if !sil[k] {
                continue;
            }
            let (a, c) = (b[k], b[(k + 1) % b.len()]);
            let db = (c - a).normalize_or_zero();
            for &(q0, q1) in &recv {
                let dr = (q1 - q0).normalize_or_zero();
                if db.cross(dr).length() < EDGE_PARALLEL_ANGLE {
                    if let Some(p) = Plane::through(q0, q1, a, snap * (q1 - q0).length()) {
                        planes.push(p);
                    }
                }
            }
        }
    }
    if !cuts.edges_only {
        event_planes(geo, &silhouette, &mut planes);
        if cuts.faces_last {
            planes.rotate_left(faces);
        }
    }
    let pieces = cut_along(geo.emitter(), &planes, snap, cuts.max_pieces);
    pieces.iter().flat_map(|piece| emitter_cells(piece, geo.emitter_normal())).collect()
}

/// Appends the planes of the second-order events that happen over the emitter: a blocker
/// vertex whose shadow crosses a receiver edge, and a receiver vertex that a blocker edge's
/// shadow crosses. Across them g is C¹ with a jump in its second derivatives.
fn event_planes(geo: &ShadowGeometry, silhouette: &[Vec<bool>], planes: &mut Vec<Plane>) {
    let snap = geo.snap();
    let e = geo.emitter();
    let n_e = geo.emitter_normal();
    let d_e = n_e.dot(e[0]);
    let height = |x: DVec3| n_e.dot(x) - d_e;
    let (e1, _) = n_e.any_orthonormal_pair();
    let e2 = n_e.cross(e1);
    let flat = |x: DVec3| glam::DVec2::new(x.dot(e1), x.dot(e2));
    let ring: Vec<glam::DVec2> = e.iter().map(|&x| flat(x)).collect();
    let recv = geo.receiver_edges();
    // The event's trace on the emitter plane, in 2-D: the sight lines through point c and
    // segment [a, b], extended to the plane. `through`: c is a blocker vertex between the
    // plane and a receiver edge [a, b] (only the part of [a, b] farther from the plane than c
    // casts a trace); otherwise c is a receiver vertex and [a, b] a blocker edge, of which the
    // part nearer the plane than c counts.
    let trace = |c: DVec3, a: DVec3, b: DVec3, through: bool| -> Option<(glam::DVec2, glam::DVec2)> {
        let (hc, ha, hb) = (height(c), height(a), height(b));
        let delta = EVENT_LEVEL_REL * (a - b).length().max(snap);
        // For `through` (c = blocker vertex, segment on the receiver) the segment must be
        // above c; otherwise (c = receiver vertex, segment on the blocker) below it.
        let (fa, fb) = if through { (ha - hc, hb - hc) } else { (hc - ha, hc - hb) };
        if fa <= delta && fb <= delta {
            return None;
        }
        let cut = |x: DVec3, y: DVec3, fx: f64, fy: f64| {
            if fx > delta {
                x
            } else {
                x + (y - x) * ((delta - fx) / (fy - fx))
            }
        };
        let (a2, b2) = (cut(a, b, fa, fb), cut(b, a, fb, fa));
        let proj = |x: DVec3| {
            let (apex, other) = if through { (x, c) } else { (c, x) };
            let (ha, ho) = (height(apex), height(other));
            flat(apex + (other - apex) * (ha / (ha - ho)))
        };
        Some((proj(a2), proj(b2)))
    };
    let mut push = |a: DVec3, b: DVec3, c: DVec3, seg: Option<(glam::DVec2, glam::DVec2)>| {
        if let Some((p, q)) = seg {
            if segment_meets_ring(p, q, &ring) {
                if let Some(pl) = Plane::through(a, b, c, snap * (b - a).length()) {
                    planes.push(pl);
                }
            }
        }
    };
    // A corner shared by several faces gives the same planes once per face: taken once.
    let mut corners: Vec<DVec3> = Vec::new();
    for (b, sil) in geo.blockers().iter().zip(silhouette) {
        let m = b.len();
        for k in 0..m {
            let (v, w) = (b[k], b[(k + 1) % m]);
            if (sil[k] || sil[(k + m - 1) % m]) && !corners.contains(&v) {
                corners.push(v);
                for &(q0, q1) in &recv {
                    push(q0, q1, v, trace(v, q0, q1, true));
                }
            }
            if sil[k] {
                for &(q0, _) in &recv {
                    push(v, w, q0, trace(q0, v, w, false));
                }
            }
        }
    }
}

/// Per kept blocker, the smallest index of the blockers folded onto it through shared edges
/// (one mesh body or sheet): the unit that must be seen from a cell's quadrature points.
fn fold_groups(geo: &ShadowGeometry) -> Vec<u32> {
    let n = geo.blockers().len();
    let mut groups = Groups::new(n);
    for k in 0..n {
        for e in 0..geo.blockers()[k].len() {
            if let Some(m) = geo.neighbour(k, e) {
                groups.join(k, m as usize);
            }
        }
    }
    (0..n).map(|k| groups.root(k) as u32).collect()
}

/// Per kept blocker and edge: false when the edge is shared with another kept blocker and,
/// from every point of the emitter, the two fold away on the same side of it (so the edge
/// never bounds their joint shadow and casts no kink).
fn silhouette_edges(geo: &ShadowGeometry) -> Vec<Vec<bool>> {
    let snap = geo.snap();
    let e = geo.emitter();
    let blockers = geo.blockers();
    let centre = |r: &[DVec3]| r.iter().copied().sum::<DVec3>() / r.len() as f64;
    let (mut one, mut both) = (Vec::new(), Vec::new());
    blockers
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let m = b.len();
            let c = centre(b);
            (0..m)
                .map(|j| {
                    let Some(other) = geo.neighbour(k, j) else { return true };
                    let (v, w) = (b[j], b[(j + 1) % m]);
                    let n1 = (w - v).cross(c - v).normalize_or_zero();
                    let n2 = (w - v).cross(centre(&blockers[other as usize]) - v).normalize_or_zero();
                    if n1 == DVec3::ZERO || n2 == DVec3::ZERO {
                        return true;
                    }
                    // Seen from x, the two faces lie on the same side of the edge when
                    // (n1·(x − v))(n2·(x − v)) > 0: the edge is on their silhouette.
                    [1.0, -1.0].into_iter().any(|sign: f64| {
                        let beyond = |n: DVec3| move |x: DVec3| sign * n.dot(x - v) - snap;
                        crate::geometry::clip::clip_ring(e, beyond(n1), 0.0, &mut one);
                        crate::geometry::clip::clip_ring(&one, beyond(n2), 0.0, &mut both);
                        !both.is_empty()
                    })
                })
                .collect()
        })
        .collect()
}

/// True when segment [p, q] meets the polygon `ring` (2-D).
pub(super) fn segment_meets_ring(p: glam::DVec2, q: glam::DVec2, ring: &[glam::DVec2]) -> bool {
    let m = ring.len();
    let inside = |x: glam::DVec2| {
        let mut w = false;
        for k in 0..m {
            let (a, b) = (ring[k], ring[(k + 1) % m]);
            if (a.y > x.y) != (b.y > x.y) && x.x < a.x + (x.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                w = !w;
            }
        }
        w
    };
    if inside(p) || inside(q) {
        return true;
    }
    let cross = |o: glam::DVec2, a: glam::DVec2, b: glam::DVec2| (a - o).perp_dot(b - o);
    (0..m).any(|k| {
        let (a, b) = (ring[k], ring[(k + 1) % m]);
        let (d1, d2) = (cross(p, q, a), cross(p, q, b));
        let (d3, d4) = (cross(a, b, p), cross(a, b, q));
        d1 * d2 <= 0.0 && d3 * d4 <= 0.0
    })
}

/// Splits a planar emitter ring into root cells: one parallelogram when it is one, else
/// quadrilaterals and a triangle fanned from one vertex when convex, triangles by ear clipping
/// otherwise.
pub fn emitter_cells(ring: &[DVec3], normal: DVec3) -> Vec<Cell> {
    let m = ring.len();
    if m == 4 {
        let (a, b, c, d) = (ring[0], ring[1], ring[2], ring[3]);
        let scale = (c - a).length() + (d - b).length();
        if ((a + c) - (b + d)).length() <= PARALLELOGRAM_REL * scale {
            return vec![Cell::Para { o: a, u: b - a, v: d - a }];
        }
    }
    let (e1, _) = normal.any_orthonormal_pair();
    let e2 = normal.cross(e1);
    let flat: Vec<glam::DVec2> = ring.iter().map(|v| glam::DVec2::new(v.dot(e1), v.dot(e2))).collect();
    if is_convex_local(&flat) {
        // Quadrilaterals fanned from vertex 0, a triangle last when m is odd: half the cells of
        // a triangle fan.
        return (1..m - 1)
            .step_by(2)
            .map(|k| match ring.get(k + 2) {
                Some(&d) => Cell::Quad([ring[0], ring[k], ring[k + 1], d]),
                None => Cell::Tri([ring[0], ring[k], ring[k + 1]]),
            })
            .collect();
    }
    ear_indices(&flat).into_iter().map(|[i, j, k]| Cell::Tri([ring[i], ring[j], ring[k]])).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_project_past_the_cap_only_after_a_share_of_it_and_never_without_one() {
        // 10 of 40 roots done on 300 units: 1,200 projected.
        assert!(past_cap(300, 10, 40, 1_000));
        assert!(!past_cap(300, 10, 40, 1_300), "within the cap");
        assert!(!past_cap(100, 10, 40, 1_000), "less than an eighth of the cap spent");
        assert!(!past_cap(300, 0, 40, 1_000), "no root done");
        assert!(!past_cap(u64::MAX / 2, 1, usize::MAX, u64::MAX), "an uncapped integration");
    }

    /// C-11, unit squares at gap 1 (docs/literature.md V1).
    const PARALLEL_UNIT: f64 = 0.199_824_895_698;

    use crate::geometry::fixtures::square as sq;

    #[test]
    fn the_shaft_holds_every_segment_and_leaves_out_what_is_beside_it() {
        let cell = [
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(1.0, 1.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
        ];
        let receiver = [DVec2::new(0.2, 0.2), DVec2::new(0.4, 0.2), DVec2::new(0.3, 0.4)];
        let mut planes = Vec::new();
        shaft_planes(&cell, &receiver, 1e-12, &mut planes);
        assert!(!planes.is_empty());
        // Points on segments from the cell to the receiver are inside every plane.
        for (x, y) in [(cell[0], receiver[0]), (cell[2], receiver[1]), (cell[3], receiver[2])] {
            for t in [0.0, 0.3, 0.7, 1.0] {
                let p = x + t * (y.extend(0.0) - x);
                assert!(planes.iter().all(|q| q.distance(p) <= 1e-12), "{p}");
            }
        }
        let outside = |b: &[DVec3]| planes.iter().any(|q| b.iter().all(|&x| q.distance(x) > 1e-12));
        // A plate beside the shaft is outside one plane; one across it is not.
        let beside = [DVec3::new(2.0, 0.0, 1.0), DVec3::new(3.0, 0.0, 1.0), DVec3::new(2.5, 1.0, 1.0)];
        let across = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.5, 1.0, 1.0)];
        assert!(outside(&beside));
        assert!(!outside(&across));
    }

    /// Unit squares at gap 1 (emitter z = 0 facing up, receiver z = 1 facing down) past `blocker`.
    fn unit_pair(blocker: &[DVec3]) -> ShadowGeometry {
        let e = sq(0.0, 0.0, 0.0, 1.0, true);
        let r = sq(1.0, 0.0, 0.0, 1.0, false);
        ShadowGeometry::new(&e, DVec3::Z, &r, -DVec3::Z, &[blocker]).unwrap()
    }

    fn shaded(blocker: &[DVec3], tol: f64, min_depth: u32) -> AdaptInfo {
        let geo = unit_pair(blocker);
        let it = Integrator::new(AdaptParams { low: 3, high: 4, min_depth, max_depth: 10 });
        it.shaded(&geo, tol, &mut AdaptScratch::default())
    }

    /// Largest error of a tabulated rule on a monomial it should integrate exactly.
    const RULE_EXACT: f64 = 1e-15;

    #[test]
    fn symmetric_rules_are_exact_to_their_degree() {
        let fact = |k: u32| (1..=k).map(f64::from).product::<f64>();
        for (n, points) in [(3, 6), (5, 16)] {
            let rule = triangle_rule(n);
            assert_eq!(rule.len(), points, "n = {n}");
            assert!(rule.iter().all(|&(l, w)| w > 0.0 && l.iter().all(|&c| c > 0.0 && c < 1.0)));
            let deg = 2 * n as u32 - 2;
            for a in 0..=deg {
                for b in 0..=deg - a {
                    // ∫ x^a y^b over the unit right triangle, over its area ½.
                    let exact = 2.0 * fact(a) * fact(b) / fact(a + b + 2);
                    let sum: f64 =
                        rule.iter().map(|&([_, x, y], w)| w * x.powi(a as i32) * y.powi(b as i32)).sum();
                    assert!((sum - exact).abs() < RULE_EXACT, "n = {n}, x^{a} y^{b}: {sum} vs {exact}");
                }
            }
        }
        assert!([1, 2, 4, 6].iter().all(|&n| triangle_rule(n).is_empty()), "the product elsewhere");
        // On cells, both kinds of rule sum to the cell's area and the points counted are taken.
        let cells = [
            Cell::Tri([DVec3::ZERO, DVec3::new(2.0, 0.1, 0.0), DVec3::new(0.3, 1.5, 0.0)]),
            Cell::Quad([
                DVec3::ZERO,
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(1.7, 1.4, 0.0),
                DVec3::new(-0.2, 1.0, 0.0),
            ]),
            Cell::Para { o: DVec3::ZERO, u: DVec3::new(1.0, 0.5, 0.0), v: DVec3::new(0.0, 2.0, 0.0) },
        ];
        for rule in (2..=6).flat_map(|n| [Rule::new(n), Rule::higher(n)]) {
            let n = rule.x.len();
            for c in &cells {
                let (mut area, mut count) = (0.0, 0);
                rule.each(c, |_, w| {
                    area += w;
                    count += 1;
                });
                assert!((area - c.area()).abs() < 1e-14 * c.area(), "n = {n}, {c:?}");
                assert_eq!(count, rule.points(c), "n = {n}, {c:?}");
            }
        }
    }

    #[test]
    fn quadrilateral_cells_integrate_polynomials_and_split_into_their_area() {
        let q = Cell::Quad([
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.2, 1.0),
            DVec3::new(1.7, 1.5, 1.0),
            DVec3::new(-0.3, 1.0, 1.0),
        ]);
        let tri_fan = [
            Cell::Tri([DVec3::new(0.0, 0.0, 1.0), DVec3::new(2.0, 0.2, 1.0), DVec3::new(1.7, 1.5, 1.0)]),
            Cell::Tri([DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.7, 1.5, 1.0), DVec3::new(-0.3, 1.0, 1.0)]),
        ];
        // x²y + y³ over the quadrilateral, by its own rule and by the two triangles'.
        let f = |p: DVec3| p.x * p.x * p.y + p.y.powi(3);
        let rule = Rule::new(5);
        let integrate = |c: &Cell| {
            let mut s = 0.0;
            rule.each(c, |p, w| s += w * f(p));
            s
        };
        let by_tris: f64 = tri_fan.iter().map(integrate).sum();
        assert!((integrate(&q) - by_tris).abs() < 1e-13, "{} vs {by_tris}", integrate(&q));
        let area: f64 = tri_fan.iter().map(Cell::area).sum();
        assert!((q.area() - area).abs() < 1e-14);
        assert!((q.children().iter().map(Cell::area).sum::<f64>() - area).abs() < 1e-14);
        let children: f64 = q.children().iter().map(integrate).sum();
        assert!((children - by_tris).abs() < 1e-13);
        // A convex pentagon: two cells, a quadrilateral and a triangle.
        let ring: Vec<DVec3> = (0..5)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 5.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let cells = emitter_cells(&ring, DVec3::Z);
        assert!(matches!(cells[..], [Cell::Quad(_), Cell::Tri(_)]), "{cells:?}");
    }

    #[test]
    fn a_fold_edge_counts_only_where_it_can_be_a_silhouette() {
        // Two faces of one mesh: a square in z = 1 split along its diagonal (coplanar: the
        // diagonal never bounds their shadow), and a fold about the edge y = 0 of a roof.
        let e = sq(0.0, 0.0, 0.0, 1.0, true);
        let r = sq(2.0, 0.0, 0.0, 1.0, false);
        let (a, b, c, d) = (
            DVec3::new(0.2, 0.2, 1.0),
            DVec3::new(0.8, 0.2, 1.0),
            DVec3::new(0.8, 0.8, 1.0),
            DVec3::new(0.2, 0.8, 1.0),
        );
        let t1 = vec![a, b, c];
        let t2 = vec![a, c, d];
        let mut geo = ShadowGeometry::new(&e, DVec3::Z, &r, -DVec3::Z, &[&t1, &t2]).unwrap();
        // Edge 2 of t1 (c → a) is edge 0 of t2 (a → c).
        geo.set_neighbours(&[vec![None, None, Some(1)], vec![Some(0), None, None]], &[(0, None), (0, None)]);
        let sil = silhouette_edges(&geo);
        assert_eq!(sil, vec![vec![true, true, false], vec![false, true, true]]);
        // A roof: ridge along x at y = 0.5, z = 1.2, faces down to eaves at z = 1. The emitter
        // (z = 0) lies below both faces' planes: from every point of it the faces fall on
        // either side of the ridge, which never outlines their shadow.
        let (p0, p1) = (DVec3::new(0.2, 0.5, 1.2), DVec3::new(0.8, 0.5, 1.2));
        let roof = |eave: f64, dy: f64| {
            let f1 = vec![DVec3::new(0.2, 0.5 - dy, eave), DVec3::new(0.8, 0.5 - dy, eave), p1, p0];
            let f2 = vec![p0, p1, DVec3::new(0.8, 0.5 + dy, eave), DVec3::new(0.2, 0.5 + dy, eave)];
            let mut geo = ShadowGeometry::new(&e, DVec3::Z, &r, -DVec3::Z, &[&f1, &f2]).unwrap();
            geo.set_neighbours(
                &[vec![None, None, Some(1), None], vec![Some(0), None, None, None]],
                &[(0, None), (0, None)],
            );
            silhouette_edges(&geo)
        };
        assert_eq!(roof(1.0, 0.2), vec![vec![true, true, false, true], vec![false, true, true, true]]);
        // A steep, narrow roof (eaves at z = 0.5, 0.01 from the ridge): emitter points beside
        // it are outside one face's plane and inside the other's, where the ridge is the
        // outline.
        assert_eq!(roof(0.5, 0.01), vec![vec![true; 4]; 2]);
    }

    #[test]
    fn unobstructed_integrand_integrates_to_c11() {
        let e = sq(0.0, 0.0, 0.0, 1.0, true);
        let r = sq(1.0, 0.0, 0.0, 1.0, false);
        let geo = ShadowGeometry::new(&e, DVec3::Z, &r, -DVec3::Z, &[]).unwrap();
        let rule = Rule::new(8);
        let mut s = 0.0;
        for cell in emitter_cells(geo.emitter(), geo.emitter_normal()) {
            rule.each(&cell, |p, w| s += w * geo.unshaded(p));
        }
        assert!((s - PARALLEL_UNIT).abs() < 1e-10, "{s}");
    }

    #[test]
    fn corner_blocker_matches_view3d_square_obstruction() {
        // View3D's square-obstruction example: exact 0.1498686718 (research/view3d.md §5).
        let info = shaded(&sq(0.5, 0.0, 0.0, 0.5, true), 1e-10, 1);
        let f = PARALLEL_UNIT - info.shaded;
        assert!((f - 0.149_868_671_8).abs() < 1e-9, "F = {f}, {info:?}");
    }

    #[test]
    fn centred_blocker_matches_the_reference() {
        let info = shaded(&sq(0.5, 0.25, 0.25, 0.5, true), 1e-11, 1);
        let f = PARALLEL_UNIT - info.shaded;
        assert!((f - 0.099_506_294_6).abs() < 1e-9, "F = {f}, {info:?}");
    }

    #[test]
    fn the_minimum_depth_bounds_cell_area_not_the_splits_of_cut_roots() {
        // The centred plate's kink planes cut the emitter into its four quarters: at a loose
        // tolerance each is accepted on its own rules (a forced split per root made 16 cells),
        // while an emitter left in one root (cuts capped at one piece) is still split in four.
        let geo = unit_pair(&sq(0.5, 0.25, 0.25, 0.5, true));
        let it = Integrator::new(AdaptParams { low: 2, high: 3, min_depth: 1, max_depth: 8 });
        let mut s = AdaptScratch::default();
        let cut = it.shaded(&geo, 1.0, &mut s);
        let largest = split_cells(&geo, Cuts::ALL).iter().map(Cell::area).fold(0.0, f64::max);
        assert!(cut.roots == 4 && (largest - 0.25).abs() < 1e-12, "{cut:?}, largest root {largest}");
        assert_eq!(cut.cells, cut.roots, "{cut:?}");
        let one = it.with_cuts(Cuts::up_to(1, true)).shaded(&geo, 1.0, &mut s);
        assert_eq!((one.roots, one.cells), (1, 4), "{one:?}");
        // Both within the loose goal of the exact value (C-11 minus the centred plate).
        for info in [cut, one] {
            assert!((PARALLEL_UNIT - info.shaded - 0.099_506_294_6).abs() < 1e-3, "{info:?}");
        }
    }

    /// A plate tilted about x (its plane z = y − 0.1 crosses the emitter of [`unit_pair`]), its
    /// edges along x parallel to the receiver's.
    const TILTED_PLATE: [DVec3; 4] = [
        DVec3::new(0.3, 0.3, 0.2),
        DVec3::new(0.7, 0.3, 0.2),
        DVec3::new(0.7, 0.7, 0.6),
        DVec3::new(0.3, 0.7, 0.6),
    ];

    /// True when some cell lies on both sides of `plane`.
    fn some_cell_crosses(cells: &[Cell], plane: &Plane) -> bool {
        let mut ring = Vec::new();
        cells.iter().any(|c| {
            c.ring(&mut ring);
            ring.iter().any(|&v| plane.distance(v) < -1e-9) && ring.iter().any(|&v| plane.distance(v) > 1e-9)
        })
    }

    #[test]
    fn faces_last_keeps_the_receiver_edge_planes_under_a_cap() {
        // Capped at two pieces, the blockers' planes first cut along the plate's plane; faces
        // last cut along a plane through a receiver edge instead.
        let geo = unit_pair(&TILTED_PLATE);
        let plane = plane_of(&geo.blockers()[0]).unwrap();
        let first = split_cells(&geo, Cuts::up_to(2, false));
        let last = split_cells(&geo, Cuts::up_to(2, true));
        assert!(!some_cell_crosses(&first, &plane), "{first:?}");
        assert!(some_cell_crosses(&last, &plane), "{last:?}");
    }

    #[test]
    fn edges_only_cuts_along_the_receiver_edge_planes_and_no_other() {
        // The plate's own plane and its events cross the emitter, and its edges along x are
        // parallel to the receiver's. Edges only: cut (more than one root), never along the
        // plate's plane.
        let geo = unit_pair(&TILTED_PLATE);
        let plane = plane_of(&geo.blockers()[0]).unwrap();
        let edges = Cuts::receiver_edges(MAX_PIECES);
        let cells = split_cells(&geo, edges);
        assert!(split_cells(&geo, Cuts::ALL).len() > cells.len(), "every plane cuts more");
        assert!(cells.len() > emitter_cells(geo.emitter(), DVec3::Z).len(), "{cells:?}");
        assert!(some_cell_crosses(&cells, &plane), "a cell along the plate's plane: {cells:?}");
        // Turned 45° about z, no edge is parallel to the receiver's: one root, as uncut.
        let c = DVec3::new(0.5, 0.5, 0.0);
        let turned: Vec<DVec3> = TILTED_PLATE
            .iter()
            .map(|&v| {
                let d = v - c;
                c + DVec3::new((d.x - d.y) / 2f64.sqrt(), (d.x + d.y) / 2f64.sqrt(), d.z)
            })
            .collect();
        let geo = unit_pair(&turned);
        assert_eq!(split_cells(&geo, edges).len(), emitter_cells(geo.emitter(), DVec3::Z).len());
        assert!(split_cells(&geo, Cuts::ALL).len() > 1);
    }

    #[test]
    fn cells_a_blocker_touches_carry_their_error() {
        // A heat sink's channel floor (half of it, the emitter, y = y0) between fins that stand
        // on its edge and its corner, seen by the room's wall across the channel's end (z = 0,
        // in the receiver's frame): from viewpoints near a fin's foot its shadow swings
        // through every direction. The 4×4 and 5×5 rules agreed on a cell at that corner
        // where the cell was 7 times its estimate off, and the pair 3.6 times. Each goal's
        // result within its own estimate of a deep reference.
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let (near, far, y0, y1) = (0.366_667, 0.633_333, -0.066_667, 0.1);
        let (left, right) = (-0.109_333, -0.045_333);
        let e = [p(right, y0, near), p(left, y0, near), p(left, y0, far)];
        let r = [p(-0.5, y0, 0.0), p(0.5, y0, 0.0), p(0.5, 0.5, 0.0), p(-0.5, 0.5, 0.0)];
        // Fin sides facing +x (left of the floor) and −x (right of it).
        let facing_right = |x: f64| vec![p(x, y1, far), p(x, y0, far), p(x, y0, near), p(x, y1, near)];
        let facing_left = |x: f64| vec![p(x, y0, far), p(x, y1, far), p(x, y1, near), p(x, y0, near)];
        let fins = [
            facing_right(-0.186_667),
            facing_right(left),
            facing_left(right),
            facing_left(0.032),
            facing_left(0.109_333),
        ];
        let rings: Vec<&[DVec3]> = fins.iter().map(|f| f.as_slice()).collect();
        let mut geo = ShadowGeometry::new(&e, DVec3::Y, &r, DVec3::Z, &rings).unwrap();
        geo.set_neighbours(&vec![vec![None; 4]; 5], &[(1, None); 5]);
        let mut s = AdaptScratch::default();
        let deep = Integrator::new(AdaptParams { low: 4, high: 5, min_depth: 5, max_depth: 10 });
        let reference = deep.shaded(&geo, 1e-16, &mut s);
        assert!(reference.shaded > 1e-4 && reference.error < 1e-14, "{reference:?}");
        let it = Integrator::new(AdaptParams { low: 4, high: 5, min_depth: 0, max_depth: 8 });
        for goal in [1e-8, 3e-9, 1.4e-9, 1e-9, 1e-10, 1e-11] {
            let info = it.shaded(&geo, goal, &mut s);
            let off = (info.shaded - reference.shaded).abs() - reference.error;
            assert!(off <= info.error && info.error <= goal, "goal {goal:e}: off {off:.3e}, {info:?}");
        }
    }

    #[test]
    fn a_small_blocker_near_an_edge_is_not_missed() {
        // A 0.2 × 0.1 plate 0.03 above the emitter, straddling its edge y = 1: no point of the
        // 3×3 or 4×4 Gauss rules on the whole emitter sees its shadow on the receiver, so a
        // fixed rule pair (View3D without minO) agrees with itself on "unobstructed".
        let e = sq(0.0, 0.0, 0.0, 1.0, true);
        let r = sq(1.0, 0.0, 0.0, 1.0, false);
        let b = vec![
            DVec3::new(0.4, 0.95, 0.03),
            DVec3::new(0.6, 0.95, 0.03),
            DVec3::new(0.6, 1.05, 0.03),
            DVec3::new(0.4, 1.05, 0.03),
        ];
        let geo = ShadowGeometry::new(&e, DVec3::Z, &r, -DVec3::Z, &[&b]).unwrap();
        let mut s = AdaptScratch::default();
        let whole = Cell::Para { o: DVec3::ZERO, u: DVec3::X, v: DVec3::Y };
        let naive = |n: usize, s: &mut AdaptScratch| {
            let mut v = 0.0;
            Rule::new(n).each(&whole, |p, w| v += w * geo.shaded(p, &[0], &mut s.shadow).0);
            v
        };
        let (n3, n4) = (naive(3, &mut s), naive(4, &mut s));
        // Reference: every emitter cell split at least five times (1024 cells and more).
        let deep = Integrator::new(AdaptParams { low: 3, high: 4, min_depth: 5, max_depth: 10 });
        let deep_info = deep.shaded(&geo, 1e-13, &mut s);
        let reference = deep_info.shaded;
        assert!(reference > 1e-4, "the plate shades {reference}");
        assert!(
            (n3 - n4).abs() < 1e-12 && (n4 - reference).abs() > 0.5 * reference,
            "naive {n3} {n4} vs {reference}"
        );
        // The adaptive integration with its blocker checks finds it without a deep minimum.
        let info = Integrator::new(AdaptParams { low: 3, high: 4, min_depth: 0, max_depth: 10 })
            .shaded(&geo, 1e-10, &mut s);
        assert!((info.shaded - reference).abs() < 1e-9, "{info:?} vs {reference}");
        assert!(
            info.evals < deep_info.evals / 4,
            "adapts: {} vs {} evaluations",
            info.evals,
            deep_info.evals
        );
        // The emitter as one root cell (no kink cuts) at looser tolerances: each result stays
        // within its tolerance; where no rule point sees the plate, the cell's unobstructed
        // integral is its error estimate (it covers the missed shadow), and no cell is split
        // for a bound the tolerance does not need.
        for tol in [1e-3, 1.0] {
            let loose = Integrator::new(AdaptParams { low: 3, high: 4, min_depth: 0, max_depth: 10 })
                .with_cuts(Cuts::up_to(1, true))
                .shaded(&geo, tol, &mut s);
            let off = (loose.shaded - reference).abs();
            assert!(off <= tol && loose.error <= tol, "tol {tol}: {loose:?} vs {reference}");
            if tol > PARALLEL_UNIT {
                assert_eq!((loose.cells, loose.evals), (1, 9 + 16 + 16), "{loose:?}");
                assert!(loose.error >= off && loose.error > 0.5 * PARALLEL_UNIT, "{loose:?}");
            }
        }
    }
}
