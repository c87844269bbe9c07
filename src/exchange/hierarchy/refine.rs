//! Link refinement (Hanrahan–Salzman–Aupperle 1991, with Smits–Arvo–Greenberg 1994 clusters):
//! starting from the root's self-pair, each pair of clusters (A, B) is
//! - dropped when no patch of one can see any of the other (one lies behind every plane of a
//!   parallel cluster, or the normal cones face away);
//! - split when the clusters are near ([`NEAR`]), when either is curved (not parallel), when
//!   a parallel cluster lies on more than one plane in a scene with blockers (a channel's
//!   inner and outer flange faces), when one reaches behind the other's plane, or when the
//!   link's heat-rate error bound exceeds its budget;
//! - otherwise linked: S_AB from the children-level estimate Σ_cd S(c, d), its error
//!   |S⁽²⁾ − S⁽¹⁾| against the one-level estimate plus a floor, with the second-order Taylor
//!   estimate between planar clusters (area moments as weights, remainder ∝ (ρ/r)⁴),
//!   times a visible fraction from rays through the BVH when a blocker meets the pair's
//!   hull (its box and polygon within the shaft of the clusters' boxes, Haines–Wallace, and
//!   its box within the hull of their bounding spheres; the blocker in front of both
//!   clusters' planes): n rays between uniform points, n at least [`VIS_RAYS`]. Unanimous
//!   rays leave S/(n + 2) in the bound (the rule of succession: a shadow edge or a gap none
//!   of them met), n chosen so that this fits the budget when that many rays cost less than
//!   the link's patch pairs ([`PAIR_RAYS`] each, at most [`VIS_RAYS_MAX`]), else split; a
//!   mixed result is kept with two standard errors in the bound when that fits, else split.
//!   A link that every ray found blocked has S = 0 and that S/(n + 2) as its bound: on a
//!   concave part such links hid the views of patches near a lip, 2.4 times their
//!   estimates (validation/cad.md).
//!
//! Two single patches always form a leaf pair, evaluated later by the exact kernel from the
//! smaller patch when their areas differ by more than [`SMALL_ROW_RATIO`], else from the lower
//! index.
//!
//! The budget of a link (single-surface clusters on surfaces s_A, s_B, ΔJ the range of the
//! radiosity bounds of the patches of A ∪ B) is tol · Q_ref · S_AB ΔJ / (2 max(W_sA, W_sB)) in
//! heat rate, W_s a bound on Σ S·ΔJ over the links of s ([`crate::solve::apriori`]: view caps
//! of bounding spheres), or tol · Q_ref · S_AB / (2 max(A_sA, A_sB)) (each link the same
//! relative accuracy, loosened where ΔJ is small), whichever is larger. Each rule alone sums to
//! at most tol · Q_ref / 2 over the links of any surface, so the larger stays under
//! tol · Q_ref. The first lets a link carry its share of the surface's radiosity differences:
//! a small hot part's links to a room wall are not held to the accuracy that the wall's area
//! at the part's ΔJ would ask. Scenes of many surfaces have no weights (the second rule).
use super::tree::{Node, Tree, NONE};
use crate::geometry::shaft::Shaft;
use crate::viewfactor::shadow::blockers::Blockers;
use crate::visibility::Visibility;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::ops::Range;
use std::sync::Mutex;

/// Clusters whose radii sum to more than this fraction of their distance are split (their
/// kernel varies too much for a cluster estimate; touching patches end as exact leaf pairs).
pub const NEAR: f64 = 0.5;
/// Visibility rays of a cluster link whose hull may meet a blocker: all clear or all blocked
/// is trusted (the classic hierarchical-radiosity rule); a partly visible link is kept with
/// the sampled fraction and [`VIS_SIGMAS`] standard errors when that fits its budget, else
/// split.
pub const VIS_RAYS: usize = 16;
/// Most visibility rays of one link: a link whose unanimous rays would leave more than its
/// budget unaccounted after this many (or after [`PAIR_RAYS`] per patch pair it holds, when
/// that is fewer, but never below 2 [`VIS_RAYS`]) is split.
pub const VIS_RAYS_MAX: usize = 4096;
/// Visibility rays that cost about one exact patch pair behind blockers (a ray 0.9 µs, a pair
/// 7–18 µs on the arm link's and the channel's rooms): a link casts at most this many per
/// pair it holds, since splitting it would end in those pairs.
pub const PAIR_RAYS: usize = 8;
/// Standard errors of a partly visible link's sampled fraction counted in its bound.
pub const VIS_SIGMAS: f64 = 2.0;
/// Remainder of the second-order estimate per (ρ/r)⁴ (ρ the radius sum) of the kernel's
/// largest value over the pair times the areas: at most 0.16 of S itself measured on
/// parallel, perpendicular and tilted squares, regular and jittered, ρ/r from 0.13 to 0.76,
/// and within this floor on squares that meet the other's plane (tests below); the floor
/// guards children estimates that agree by accident.
pub const SECOND_ORDER_FLOOR: f64 = 0.25;
/// Relative spread of plane offsets within which a parallel cluster counts as one plane:
/// above single-precision rounding of mesh vertices (6e-8), below any machined step.
pub const COPLANAR_TOL: f64 = 1e-6;
/// Area ratio above which a leaf pair's row is its smaller patch: the shadow volumes of its
/// blockers are built from the row's patch, and from a small one they are narrow, so fewer
/// receivers are left partly shadowed (a room wall's patch against a meshed part's triangles:
/// the arm link's 40×40 room evaluates its pairs 2.1 times faster, validation/cad.md); when
/// the areas are close the lower index is the row, as in the dense path (gridded walls keep
/// their lattice tables, which are built from the lower surface).
pub const SMALL_ROW_RATIO: f64 = 2.0;
/// Node pairs above this patch-count product are refined on two threads.
const PAR_WORK: usize = 4096;

/// One cluster link: exchange area s between nodes a and b (a ≠ b), with its error bound.
/// Both are stored in single precision (16 bytes a link): the rounding of `s` is added to
/// the bound, which is rounded up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    /// Node.
    pub a: u32,
    /// Node.
    pub b: u32,
    /// Exchange area S_AB, m².
    pub s: f32,
    /// Estimated bound on |S_AB − exact|, m²; for a link that every visibility ray found
    /// blocked (s = 0), the exchange area those rays may have missed.
    pub err: f32,
}

impl Link {
    /// The link (a, b) with exchange area `s` and error bound `err` (m²), rounded to storage.
    pub fn new(a: u32, b: u32, s: f64, err: f64) -> Link {
        let s32 = s as f32;
        let bound = err + (s - f64::from(s32)).abs();
        let mut err32 = bound as f32;
        if f64::from(err32) < bound {
            err32 = err32.next_up();
        }
        Link { a, b, s: s32, err: err32 }
    }

    /// Exchange area S_AB, m².
    pub fn s(&self) -> f64 {
        f64::from(self.s)
    }

    /// Error bound of S_AB, m².
    pub fn err(&self) -> f64 {
        f64::from(self.err)
    }
}

/// What refinement produced.
#[derive(Debug, Default)]
pub struct Refined {
    /// Cluster links.
    pub links: Vec<Link>,
    /// Patch pairs (i, j, s) for the exact kernel, i the row (`row_first`), s = 0 until it
    /// fills them in place.
    pub leaves: Vec<(u32, u32, f64)>,
    /// Visibility rays cast.
    pub rays: u64,
}

impl Refined {
    fn append(&mut self, o: &mut Refined) {
        self.links.append(&mut o.links);
        self.leaves.append(&mut o.leaves);
        self.rays += o.rays;
        o.rays = 0;
    }
}

/// Where the parallel tasks of a refinement put their links and pairs: each task appends its
/// own short lists once, so the results grow in one list each (never held twice, as
/// concatenating per-task lists would); sorting afterwards fixes their order.
#[derive(Default)]
struct Sink(Mutex<Refined>);

impl Sink {
    fn put(&self, mut piece: Refined) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).append(&mut piece);
    }
}

/// Everything the refinement reads.
pub struct Context<'a> {
    /// The scene.
    pub scene: &'a crate::scene::Scene,
    /// The clusters.
    pub tree: &'a Tree,
    /// Blockers of the scene (None: nothing can block).
    pub blockers: Option<&'a Blockers>,
    /// Ray queries (present with `blockers`).
    pub vis: Option<&'a Visibility>,
    /// Per node: bounds (lo, hi) of the radiosity of its patches, W/m².
    pub radiosity: Vec<(f64, f64)>,
    /// Relative heat-rate tolerance.
    pub tol: f64,
    /// Heat-rate scale the tolerance refers to (largest |Q_s|), W.
    pub q_ref: f64,
    /// Per surface, the bound on Σ S·ΔJ over its links (W) that weighs each link's budget
    /// ([`super::Budget::surface_weight`]).
    pub weight: Option<Vec<f64>>,
    /// Total patch area, m².
    pub area: f64,
    /// Cumulative patch areas in tree order (for area sampling of rays).
    pub prefix: Vec<f64>,
    /// Seed of the visibility rays.
    pub seed: u64,
}

/// Refines the whole scene: links sorted by (a, b), patch pairs by (i, j), so the result
/// does not depend on the order the parallel tasks finished in.
pub fn refine(ctx: &Context) -> Refined {
    refine_tasks(ctx, &[Task::Within(0)])
}

/// One subtree of the refinement's recursion: the pairs within a node, or the pairs between
/// two nodes. The tasks of [`tasks`] partition every patch pair of the scene, so refining each
/// gives, together, the links and pairs of [`refine`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Task {
    /// Every pair within node k.
    Within(u32),
    /// Every pair between nodes a and b.
    Between(u32, u32),
}

impl Task {
    /// Patch pairs the task covers (patch-count product).
    pub fn size(&self, tree: &Tree) -> f64 {
        let len = |k: u32| tree.nodes[k as usize].len() as f64;
        match *self {
            Task::Within(k) => len(k) * (len(k) - 1.0) / 2.0,
            Task::Between(a, b) => len(a) * len(b),
        }
    }

    /// The tree nodes whose sums the task's links and pairs touch: one or two runs of node
    /// ids (a subtree is a contiguous run, 2 len − 1 nodes from its root, in preorder).
    pub fn nodes(&self, tree: &Tree) -> [Range<u32>; 2] {
        let sub = |k: u32| k..k + 2 * tree.nodes[k as usize].len() as u32 - 1;
        match *self {
            Task::Within(k) => [sub(k), 0..0],
            Task::Between(a, b) => [sub(a), sub(b)],
        }
    }
}

/// The top of the recursion cut into tasks of at most `max_size` patch pairs each (or single
/// pairs of nodes whose fate the budget decides), in the recursion's order. Only geometric
/// decisions are taken on the way down (`geometric`), so the list depends on the tree alone:
/// not on the tolerance, the radiosity bounds or the rank count.
pub fn tasks(ctx: &Context, max_size: f64) -> Vec<Task> {
    let mut out = Vec::new();
    expand(ctx, Task::Within(0), max_size.max(1.0), &mut out);
    out
}

fn expand(ctx: &Context, t: Task, max_size: f64, out: &mut Vec<Task>) {
    match t {
        Task::Within(k) => {
            let node = &ctx.tree.nodes[k as usize];
            if node.is_leaf() {
                return;
            }
            if t.size(ctx.tree) <= max_size {
                out.push(t);
                return;
            }
            let [l, r] = node.kids;
            expand(ctx, Task::Within(l), max_size, out);
            expand(ctx, Task::Within(r), max_size, out);
            expand(ctx, Task::Between(l, r), max_size, out);
        }
        Task::Between(a, b) => {
            if t.size(ctx.tree) <= max_size {
                out.push(t);
                return;
            }
            match geometric(ctx, a, b) {
                Ok(Decision::Split(x, o)) => {
                    let [c, d] = ctx.tree.nodes[x as usize].kids;
                    expand(ctx, Task::Between(c, o), max_size, out);
                    expand(ctx, Task::Between(d, o), max_size, out);
                }
                Ok(Decision::Zero) => {}
                _ => out.push(t),
            }
        }
    }
}

/// Estimated cost of a task: the outcomes of its recursion taken on geometric decisions alone
/// (patch pairs of near clusters, plus one for each pair of far clusters whose budget would
/// decide), a lower bound of its links and pairs that needs neither rays nor the budget.
pub fn estimate(ctx: &Context, t: Task) -> f64 {
    fn count(ctx: &Context, t: Task) -> u64 {
        match t {
            Task::Within(k) => {
                let node = &ctx.tree.nodes[k as usize];
                if node.is_leaf() {
                    return 0;
                }
                let [l, r] = node.kids;
                count(ctx, Task::Within(l)) + count(ctx, Task::Within(r)) + count(ctx, Task::Between(l, r))
            }
            Task::Between(a, b) => match geometric(ctx, a, b) {
                Ok(Decision::Split(x, o)) => {
                    let [c, d] = ctx.tree.nodes[x as usize].kids;
                    count(ctx, Task::Between(c, o)) + count(ctx, Task::Between(d, o))
                }
                Ok(Decision::Zero) => 0,
                Ok(_) => 1,
                // Far clusters: their budget splits them into links and pairs about as many as
                // their patches (hierarchical radiosity's linear link count).
                Err(_) => (ctx.tree.nodes[a as usize].len() + ctx.tree.nodes[b as usize].len()) as u64,
            },
        }
    }
    count(ctx, t) as f64
}

/// Refines `tasks` (in parallel): their links sorted by (a, b), patch pairs by (i, j), so the
/// result does not depend on the order the parallel tasks finished in.
pub fn refine_tasks(ctx: &Context, tasks: &[Task]) -> Refined {
    refine_tasks_counted(ctx, tasks, &|_| {})
}

/// As [`refine_tasks`], calling `done(k)` as task `tasks[k]` finishes (for the progress
/// report; the result does not depend on it).
pub fn refine_tasks_counted(ctx: &Context, tasks: &[Task], done: &(dyn Fn(usize) + Sync)) -> Refined {
    let sink = Sink::default();
    tasks.par_iter().enumerate().for_each(|(k, t)| {
        match *t {
            Task::Within(k) => self_pair(ctx, k, &sink),
            Task::Between(a, b) => pair(ctx, a, b, None, &sink),
        }
        done(k);
    });
    let mut out = sink.0.into_inner().unwrap_or_else(|e| e.into_inner());
    out.links.par_sort_unstable_by_key(|l| (l.a, l.b));
    out.leaves.par_sort_unstable_by_key(|p| (p.0, p.1));
    out
}

/// All pairs within node k.
fn self_pair(ctx: &Context, k: u32, sink: &Sink) {
    let node = &ctx.tree.nodes[k as usize];
    if node.is_leaf() {
        return;
    }
    let [l, r] = node.kids;
    if node.len() > 64 {
        rayon::join(
            || rayon::join(|| self_pair(ctx, l, sink), || self_pair(ctx, r, sink)),
            || pair(ctx, l, r, None, sink),
        );
    } else {
        let mut out = Refined::default();
        self_pair_into(ctx, k, &mut out);
        sink.put(out);
    }
}

/// All pairs within node k, serially.
fn self_pair_into(ctx: &Context, k: u32, out: &mut Refined) {
    let node = &ctx.tree.nodes[k as usize];
    if node.is_leaf() {
        return;
    }
    let [l, r] = node.kids;
    self_pair_into(ctx, l, out);
    self_pair_into(ctx, r, out);
    pair_into(ctx, l, r, None, out);
}

/// Pairs between nodes a and b, in parallel while the work is large; `hint` as in
/// [`pair_into`].
fn pair(ctx: &Context, a: u32, b: u32, hint: Option<u32>, sink: &Sink) {
    let (na, nb) = (&ctx.tree.nodes[a as usize], &ctx.tree.nodes[b as usize]);
    if na.len() * nb.len() < PAR_WORK {
        let mut out = Refined::default();
        pair_into(ctx, a, b, hint, &mut out);
        sink.put(out);
        return;
    }
    let mut hint = hint;
    match assess(ctx, a, b, &mut hint) {
        Decision::Split(x, other) => {
            let [c, d] = ctx.tree.nodes[x as usize].kids;
            rayon::join(|| pair(ctx, c, other, hint, sink), || pair(ctx, d, other, hint, sink));
        }
        decision => {
            let mut out = Refined::default();
            record(decision, a, b, ctx, &mut out);
            sink.put(out);
        }
    }
}

/// Pairs between nodes a and b, serially. `hint`: a blocker found in the hull of a parent
/// pair, tried first by the pair's own blocker search (which it only shortens).
fn pair_into(ctx: &Context, a: u32, b: u32, hint: Option<u32>, out: &mut Refined) {
    let mut hint = hint;
    match assess(ctx, a, b, &mut hint) {
        Decision::Split(x, other) => {
            let [c, d] = ctx.tree.nodes[x as usize].kids;
            pair_into(ctx, c, other, hint, out);
            pair_into(ctx, d, other, hint, out);
        }
        decision => record(decision, a, b, ctx, out),
    }
}

fn record(decision: Decision, a: u32, b: u32, ctx: &Context, out: &mut Refined) {
    match decision {
        Decision::Zero => {}
        Decision::Leaves => {
            let (i, j) = (ctx.tree.patches(a)[0], ctx.tree.patches(b)[0]);
            out.leaves.push(row_first(ctx, i, j));
        }
        Decision::Link { s, err, rays } => {
            out.rays += rays;
            out.links.push(Link::new(a, b, s, err));
        }
        Decision::Split(..) => unreachable!("split pairs are recursed"),
    }
}

/// Leaf pair (i, j) as (row, receiver, 0): the smaller patch is the row when the other is
/// more than [`SMALL_ROW_RATIO`] times its area, else the lower index.
fn row_first(ctx: &Context, i: u32, j: u32) -> (u32, u32, f64) {
    let (ai, aj) = (ctx.tree.geom[i as usize].area, ctx.tree.geom[j as usize].area);
    if aj * SMALL_ROW_RATIO < ai || ai * SMALL_ROW_RATIO < aj {
        if ai < aj {
            (i, j, 0.0)
        } else {
            (j, i, 0.0)
        }
    } else {
        (i.min(j), i.max(j), 0.0)
    }
}

/// The fate of a node pair.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Decision {
    /// Nothing exchanged.
    Zero,
    /// Two patches: the exact kernel.
    Leaves,
    /// One cluster link.
    Link { s: f64, err: f64, rays: u64 },
    /// Split the first node (a child pairs with the second).
    Split(u32, u32),
}

/// Split the larger of a and b (by radius), or the one that is not a leaf.
fn split(ctx: &Context, a: u32, b: u32) -> Decision {
    let (na, nb) = (&ctx.tree.nodes[a as usize], &ctx.tree.nodes[b as usize]);
    if nb.is_leaf() || (!na.is_leaf() && na.radius >= nb.radius) {
        Decision::Split(a, b)
    } else {
        Decision::Split(b, a)
    }
}

/// Split whichever of a and b is `unfit` (the larger when both are): a cluster that spans
/// several surfaces, or a curved one.
fn split_unfit(a: u32, b: u32, na: &Node, nb: &Node, unfit: impl Fn(&Node) -> bool) -> Decision {
    if unfit(na) && (!unfit(nb) || na.radius >= nb.radius) {
        Decision::Split(a, b)
    } else {
        Decision::Split(b, a)
    }
}

/// True when every point of `b` lies behind (or on) every plane of the parallel cluster `a`:
/// then no patch of a sees b.
fn behind(a: &Node, b: &Node, snap: f64) -> bool {
    match a.planes {
        Some((lo, _)) => b.support(a.axis) <= lo + snap,
        None => false,
    }
}

fn assess(ctx: &Context, a: u32, b: u32, hint: &mut Option<u32>) -> Decision {
    match geometric(ctx, a, b) {
        Ok(decision) => decision,
        Err(far) => budgeted(ctx, a, b, far, hint),
    }
}

/// What the budget part of [`assess`] reads of a pair that geometry alone did not decide.
#[derive(Debug, Clone, Copy)]
struct Far {
    dist: f64,
    rho: f64,
}

/// The part of [`assess`] that reads only the tree (no radiosity bounds, tolerance or rays):
/// `Ok` when geometry decides the pair, `Err` when its budget must. The top of the recursion is
/// cut into tasks with it ([`tasks`]), so the tasks do not depend on the budget.
fn geometric(ctx: &Context, a: u32, b: u32) -> Result<Decision, Far> {
    let (na, nb) = (&ctx.tree.nodes[a as usize], &ctx.tree.nodes[b as usize]);
    let snap = snap(na, nb);
    if behind(na, nb, snap) || behind(nb, na, snap) {
        return Ok(Decision::Zero);
    }
    if na.is_leaf() && nb.is_leaf() {
        return Ok(Decision::Leaves);
    }
    // A link shares its exchange by area within each cluster: across surfaces that share
    // would be wrong to first order, so only single-surface clusters are linked.
    if na.surface == NONE || nb.surface == NONE {
        return Ok(split_unfit(a, b, na, nb, |n| n.surface == NONE));
    }
    let d = nb.centroid - na.centroid;
    let dist = d.length();
    let rho = na.radius + nb.radius;
    if !(rho < NEAR * dist) {
        return Ok(split(ctx, a, b));
    }
    let dir = d / dist;
    // Every sight line is within `delta` of dir: a pair whose normal cones face away from
    // every sight line exchanges nothing.
    let delta = (rho / dist).asin();
    let facing = |n: &Node, dir: DVec3| {
        n.axis.dot(dir).clamp(-1.0, 1.0).acos() - n.cone_cos.clamp(-1.0, 1.0).acos() - delta
    };
    if facing(na, dir) >= FRAC_PI_2 || facing(nb, -dir) >= FRAC_PI_2 {
        return Ok(Decision::Zero);
    }
    // A curved cluster is split down to planar ones: links of curved clusters (the vector-area
    // estimate, shared by area over patches facing many ways) left 0.2–0.3 W of a meshed
    // part's heat rate outside the bounds that count pair errors per surface (the channel and
    // the arm link in rooms, validation/cad.md).
    if na.planes.is_none() || nb.planes.is_none() {
        return Ok(split_unfit(a, b, na, nb, |n| n.planes.is_none()));
    }
    // A parallel cluster on several planes (a channel's inner and outer flange faces face the
    // same way) is seen past blockers patch by patch: the rays of its link, drawn by area,
    // can all miss its small patches behind a flange, so it is split down to single planes.
    if ctx.blockers.is_some() && (stepped(na) || stepped(nb)) {
        return Ok(split_unfit(a, b, na, nb, stepped));
    }
    // Every point of each in front of (or on) the other's plane: the kernel is the unclipped
    // polynomial over |r|⁴ on the whole pair, so the Taylor estimate holds up to grazing sight
    // lines (the normal cones alone would split those to single patches along every edge
    // where two surfaces meet).
    if !(in_front(na, nb, snap) && in_front(nb, na, snap)) {
        return Ok(split(ctx, a, b));
    }
    Err(Far { dist, rho })
}

/// Length below which two clusters' points count as on a plane: round-off of their size
/// and place.
fn snap(na: &Node, nb: &Node) -> f64 {
    1e-9 * (na.radius + nb.radius + na.centroid.abs().max_element() + nb.centroid.abs().max_element())
}

/// The part of [`assess`] that weighs a pair's estimate against its budget.
fn budgeted(ctx: &Context, a: u32, b: u32, far: Far, hint: &mut Option<u32>) -> Decision {
    let (na, nb) = (&ctx.tree.nodes[a as usize], &ctx.tree.nodes[b as usize]);
    let Far { dist, rho } = far;
    // The second-order estimate, whose remainder is fourth order in ρ/r (bounded with the
    // kernel's largest value over the pair, which grazing sight lines make larger than its
    // value at the centroids).
    let floor = SECOND_ORDER_FLOOR * (rho / dist).powi(4) * kernel_max(na, nb, rho);
    let one = second_order(na, nb);
    let two = children(ctx, na).flat_map(|c| children(ctx, nb).map(move |d| second_order(c, d))).sum::<f64>();
    let geo = (two - one).abs() + floor;
    let dj = {
        let (ra, rb) = (ctx.radiosity[a as usize], ctx.radiosity[b as usize]);
        ra.1.max(rb.1) - ra.0.min(rb.0)
    };
    // Two shares of tol·Q_ref/2 each over a surface's links: by S against its area, and by S·ΔJ
    // against the surface's weight (the bound on its links' Σ S·ΔJ). The larger of the two
    // keeps the sum within tol·Q_ref.
    let by_area = ctx.tol * ctx.q_ref * two / (2.0 * na.min_surface_area.max(nb.min_surface_area));
    let weight = ctx.weight.as_ref().map_or(0.0, |w| w[na.surface as usize].max(w[nb.surface as usize]));
    let budget =
        if weight > 0.0 { by_area.max(ctx.tol * ctx.q_ref * two * dj / (2.0 * weight)) } else { by_area };
    if geo * dj > budget {
        return split(ctx, a, b);
    }
    let Some((v, vis_err, rays)) = visibility(ctx, a, b, two, dj, budget - geo * dj, hint) else {
        return split(ctx, a, b);
    };
    // A link that every ray found blocked is stored with s = 0 and its `err` is the exchange
    // area the rays may have missed; `visibility` cast enough rays for it to fit the budget.
    let err = if v == 0.0 { vis_err } else { geo * v + vis_err };
    Decision::Link { s: two * v, err, rays }
}

/// The node's children, or the node itself for a leaf.
fn children<'t>(ctx: &'t Context, n: &'t Node) -> impl Iterator<Item = &'t Node> + Clone {
    let k = n.kids;
    let leaf = n.is_leaf();
    let nodes = &ctx.tree.nodes;
    std::iter::once(n)
        .filter(move |_| leaf)
        .chain(k.into_iter().filter(move |_| !leaf).map(move |c| &nodes[c as usize]))
}

/// Gradient ∇K(r) of the kernel K(r) = (n_a·r)(−n_b·r)/(π|r|⁴) of two planar clusters at
/// r = c_b − c_a (m⁻³): to first order a patch pair (i in a, j in b) exchanges
/// A_i A_j (K + ∇K·(x_j − c_b − x_i + c_a)), which the link's sharing by area leaves out.
pub(crate) fn kernel_gradient(a: &Node, b: &Node) -> DVec3 {
    let r = b.centroid - a.centroid;
    let rr = r.length_squared();
    let (ca, cb) = (a.axis.dot(r), -b.axis.dot(r));
    (a.axis * cb - b.axis * ca) / (PI * rr * rr) - r * (4.0 * ca * cb / (PI * rr * rr * rr))
}

/// Second-order estimate of S_AB between two planar clusters that face each other: the
/// kernel K(r) = (n_a·r)(−n_b·r)/(π|r|⁴) expanded about the centroids (r = c_b − c_a), the
/// first-order terms vanishing about centroids, S ≈ A_a A_b K + ½ tr(∇²K (A_b M_a + A_a M_b))
/// with M the second moments of area. Its remainder is below [`SECOND_ORDER_FLOOR`] (ρ/r)⁴ S
/// (tests: parallel, perpendicular and tilted squares against closed forms).
pub(crate) fn second_order(a: &Node, b: &Node) -> f64 {
    let r = b.centroid - a.centroid;
    let (na, nb) = (a.axis, b.axis);
    let rr = r.length_squared();
    let (ca, cb) = (na.dot(r), -nb.dot(r));
    let g = ca * cb;
    let h = 1.0 / (PI * rr * rr);
    // ∇g, ∇h; ∇²g = −(n_a n_bᵀ + n_b n_aᵀ), ∇²h = (−4 I/|r|⁶ + 24 r rᵀ/|r|⁸)/π.
    let dg = na * cb - nb * ca;
    let dh = r * (-4.0 / (PI * rr * rr * rr));
    let w = a.second_moment * b.area + b.second_moment * a.area;
    let trace_w = w.x_axis.x + w.y_axis.y + w.z_axis.z;
    let tr = -2.0 * h * na.dot(w * nb)
        + 2.0 * dg.dot(w * dh)
        + g * (-4.0 * trace_w / (PI * rr * rr * rr) + 24.0 * r.dot(w * r) / (PI * rr * rr * rr * rr));
    a.area * b.area * g * h + 0.5 * tr
}

/// True when the patches of the parallel cluster `n` lie on more than one plane (offsets
/// apart by more than [`COPLANAR_TOL`] of the node's size and place).
fn stepped(n: &Node) -> bool {
    n.planes.is_some_and(|(lo, hi)| hi - lo > COPLANAR_TOL * (n.radius + n.centroid.abs().max_element()))
}

/// True when every point of node `b`'s box lies on the front side of (or on) the plane of
/// the parallel cluster `a`, to `snap`.
fn in_front(a: &Node, b: &Node, snap: f64) -> bool {
    match a.planes {
        Some((_, hi)) => -b.support(-a.axis) >= hi - snap,
        None => false,
    }
}

/// Upper bound of A_a A_b K(x, y) over the points of two planar clusters with radius sum ρ
/// (ρ < |r|): each cosine factor n·r grows by at most ρ, the distance shrinks by at most ρ.
pub(crate) fn kernel_max(a: &Node, b: &Node, rho: f64) -> f64 {
    let r = b.centroid - a.centroid;
    let d = r.length();
    let (ca, cb) = (a.axis.dot(r).max(0.0) + rho, (-b.axis.dot(r)).max(0.0) + rho);
    a.area * b.area * ca * cb / (PI * (d - rho).powi(4))
}

thread_local! {
    /// The blocker this thread's last link search found (`u32::MAX`: none), the search's
    /// second hint: the pairs a thread assesses one after another are neighbours, and a pair
    /// split before any search passes no hint of its own to its children.
    static LAST_BLOCKER: std::cell::Cell<u32> = const { std::cell::Cell::new(u32::MAX) };
}

/// Visible fraction of link (a, b) with estimate `s`, its error in m² and the rays cast;
/// `None` when the rays disagree and their sampling error would not fit `room` (split).
/// The blocker search tries `hint` first (then the thread's last found blocker, then their
/// neighbourhoods in the tree) and leaves in `hint` the blocker it found.
fn visibility(
    ctx: &Context,
    a: u32,
    b: u32,
    s: f64,
    dj: f64,
    room: f64,
    hint: &mut Option<u32>,
) -> Option<(f64, f64, u64)> {
    let (Some(blockers), Some(vis)) = (ctx.blockers, ctx.vis) else { return Some((1.0, 0.0, 0)) };
    let (na, nb) = (&ctx.tree.nodes[a as usize], &ctx.tree.nodes[b as usize]);
    // Does any blocker meet the hull of A ∪ B (its box within the union box, and within the
    // cone of balls from A's to B's bounding sphere, the hull of the two spheres) in front of
    // both clusters' planes? A blocker on or behind a cluster's plane (the cluster's own face,
    // a convex body's neighbouring facets) cannot cut a sight line that leaves it.
    let (p, q, ra, rb) = (na.centroid, nb.centroid, na.radius, nb.radius);
    let seg = q - p;
    let len = seg.length();
    let dir = seg / len;
    let snap = snap(na, nb);
    let shaft = Shaft::new((na.lo_box, na.hi_box), (nb.lo_box, nb.hi_box), snap);
    let ahead = |n: &Node, ring: &[DVec3]| match n.planes {
        Some((lo, _)) => ring.iter().any(|v| n.axis.dot(*v) > lo + snap),
        None => true,
    };
    let last = LAST_BLOCKER.get();
    let hints = match *hint {
        Some(h) if h != last => [h, last],
        _ => [last, u32::MAX],
    };
    let met = blockers.blocker_accepted(
        &hints,
        |lo, hi| {
            let (c, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            shaft.meets_box(lo, hi) && cone_reaches(c - p, dir, len, ra, rb, h.length())
        },
        |blocker| shaft.meets_points(&blocker.ring) && ahead(na, &blocker.ring) && ahead(nb, &blocker.ring),
    );
    let Some(found) = met else { return Some((1.0, 0.0, 0)) };
    *hint = Some(found);
    LAST_BLOCKER.set(found);
    // Unanimous rays leave s/(n + 2) unaccounted (the rule of succession: a shadow edge, or a
    // gap, that none of n rays met): n is what makes that fit the room, cast only while the
    // rays cost less than the patch pairs a split would end in, else split.
    let need = if s * dj > 0.0 { (s * dj / room).ceil() - 2.0 } else { 0.0 };
    let cap = (PAIR_RAYS * na.len() * nb.len()).clamp(2 * VIS_RAYS, VIS_RAYS_MAX);
    if !(need <= cap as f64) {
        return None;
    }
    let n = (need as usize).max(VIS_RAYS);
    let mut rng =
        Pcg64Mcg::seed_from_u64(ctx.seed ^ ((a as u64) << 32 | b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    // A partly visible link is kept only if even the widest sampling error fits its budget.
    let partial_fits = VIS_SIGMAS * s * 0.5 / (n as f64).sqrt() * dj <= room;
    let mut clear = 0usize;
    for cast in 1..=n {
        let (i, pi) = sample(ctx, na, &mut rng);
        let (j, pj) = sample(ctx, nb, &mut rng);
        if !vis.occluded(pi, pj, i, j) {
            clear += 1;
        }
        if !partial_fits && clear != 0 && clear != cast {
            return None;
        }
    }
    let v = clear as f64 / n as f64;
    let err = if clear == 0 || clear == n {
        s / (n + 2) as f64
    } else {
        VIS_SIGMAS * s * (v * (1.0 - v) / n as f64).sqrt()
    };
    Some((v, err, n as u64))
}

/// True when the ball of radius `h` about p + w meets the hull of the balls of radius `ra`
/// about p and `rb` about p + len·dir (|rb − ra| < len): the hull is the union of the balls of
/// radius (1 − t) ra + t rb about p + t len·dir, t in [0, 1], and the gap
/// |w − t len·dir| − (1 − t) ra − t rb is convex in t, least where its slope vanishes.
fn cone_reaches(w: DVec3, dir: DVec3, len: f64, ra: f64, rb: f64, h: f64) -> bool {
    let u = w.dot(dir);
    let rho = (w - u * dir).length();
    let d = rb - ra;
    let x = -d * rho / (len * len - d * d).max(f64::MIN_POSITIVE).sqrt();
    let t = ((u - x) / len).clamp(0.0, 1.0);
    (w - t * len * dir).length() - (1.0 - t) * ra - t * rb <= h
}

/// A point drawn uniformly by area over the patches of node n, and its patch.
fn sample(ctx: &Context, n: &Node, rng: &mut Pcg64Mcg) -> (usize, DVec3) {
    let (lo, hi) = (n.lo as usize, n.hi as usize);
    let base = if lo == 0 { 0.0 } else { ctx.prefix[lo - 1] };
    let u = base + rng.random::<f64>() * (ctx.prefix[hi - 1] - base);
    let k = lo + ctx.prefix[lo..hi].partition_point(|&c| c < u).min(hi - lo - 1);
    let p = ctx.tree.order[k] as usize;
    (p, fan_point(ctx.scene.patches[p].polygon.vertices(), rng))
}

/// A point drawn uniformly by area over the convex polygon `v`: a fan triangle by area, then a
/// uniform point in it.
pub(crate) fn fan_point(v: &[DVec3], rng: &mut Pcg64Mcg) -> DVec3 {
    let area = |t: usize| (v[t] - v[0]).cross(v[t + 1] - v[0]).length();
    let total: f64 = (1..v.len() - 1).map(area).sum();
    let mut x = rng.random::<f64>() * total;
    let mut t = 1;
    while t + 2 < v.len() && x > area(t) {
        x -= area(t);
        t += 1;
    }
    let (mut a, mut b) = (rng.random::<f64>(), rng.random::<f64>());
    if a + b > 1.0 {
        (a, b) = (1.0 - a, 1.0 - b);
    }
    v[0] + a * (v[t] - v[0]) + b * (v[t + 1] - v[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polygon::{outer, Polygon};
    use crate::viewfactor::closed_form::{parallel_rectangles_exchange, perpendicular_rectangles_exchange};
    use glam::DMat3;

    /// A planar cluster node over `polys` (all with one normal), as the tree summarises it.
    fn node(polys: &[Polygon]) -> Node {
        let area: f64 = polys.iter().map(|p| p.area()).sum();
        let centroid = polys.iter().map(|p| p.area() * p.centroid()).sum::<DVec3>() / area;
        let second_moment = polys.iter().fold(DMat3::ZERO, |m, p| {
            let d = p.centroid() - centroid;
            m + p.second_moment() + outer(d) * p.area()
        });
        let radius =
            polys.iter().flat_map(|p| p.vertices().iter().map(|v| v.distance(centroid))).fold(0.0, f64::max);
        let axis = polys[0].normal();
        let offsets = polys.iter().map(|p| axis.dot(p.centroid()));
        let (lo, hi) = offsets.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), o| (l.min(o), h.max(o)));
        Node {
            lo: 0,
            hi: polys.len() as u32,
            kids: [NONE, NONE],
            area,
            centroid,
            second_moment,
            radius,
            lo_box: polys.iter().flat_map(|p| p.vertices()).fold(DVec3::INFINITY, |m, &v| m.min(v)),
            hi_box: polys.iter().flat_map(|p| p.vertices()).fold(DVec3::NEG_INFINITY, |m, &v| m.max(v)),
            vector_area: area * axis,
            axis,
            cone_cos: 1.0,
            planes: Some((lo, hi)),
            min_surface_area: area,
            surface: 0,
        }
    }

    /// The rectangle [x0, x1] × [y0, y1] of a coordinate plane as two triangles: `at` maps
    /// plane coordinates to space, in counter-clockwise order about the wanted normal.
    fn rect(x: [f64; 2], y: [f64; 2], at: impl Fn(f64, f64) -> DVec3) -> Vec<Polygon> {
        let (a, b, c, d) = (at(x[0], y[0]), at(x[1], y[0]), at(x[1], y[1]), at(x[0], y[1]));
        vec![Polygon::new(vec![a, b, c]).unwrap(), Polygon::new(vec![a, c, d]).unwrap()]
    }

    /// One-point estimate (V_a·d̂)(−V_b·d̂)/(π r²) between two clusters that face each other.
    fn projected(a: &Node, b: &Node) -> f64 {
        let d = b.centroid - a.centroid;
        let r2 = d.length_squared();
        let dir = d / r2.sqrt();
        (a.vector_area.dot(dir).max(0.0) * (-b.vector_area.dot(dir)).max(0.0)) / (PI * r2)
    }

    /// Errors relative to `exact` of the second-order and vector-area estimates, and the
    /// second-order floor relative to `exact`.
    fn errors(a: &[Polygon], b: &[Polygon], exact: f64) -> (f64, f64, f64) {
        let (na, nb) = (node(a), node(b));
        let rho = na.radius + nb.radius;
        let floor = SECOND_ORDER_FLOOR
            * (rho / na.centroid.distance(nb.centroid)).powi(4)
            * kernel_max(&na, &nb, rho);
        ((second_order(&na, &nb) - exact) / exact, (projected(&na, &nb) - exact) / exact, floor / exact)
    }

    #[test]
    fn the_cone_of_balls_test_agrees_with_a_scan_along_the_segment() {
        // The ball (p + w, h) meets the hull of the balls (0, ra) and (len·dir, rb) exactly
        // when some ball on the segment, of interpolated radius, meets it.
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let mut both = [0usize; 2];
        for _ in 0..20_000 {
            let mut r = || rng.random::<f64>();
            let dir = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            let len = 0.5 + 2.0 * r();
            let (ra, rb) = (0.5 * len * r() * 0.9, 0.5 * len * r() * 0.9);
            let w = DVec3::new(4.0 * r() - 2.0, 4.0 * r() - 2.0, 4.0 * r() - 2.0);
            let h = 0.3 * r();
            let gap = (0..=20_000)
                .map(|k| {
                    let t = k as f64 / 20_000.0;
                    (w - t * len * dir).length() - (1.0 - t) * ra - t * rb - h
                })
                .fold(f64::INFINITY, f64::min);
            let reaches = cone_reaches(w, dir, len, ra, rb, h);
            // The scan's step leaves at most 3 len / 20,000 of slack either way.
            if gap.abs() > 1e-3 * len {
                assert_eq!(
                    reaches,
                    gap <= 0.0,
                    "w {w:?} dir {dir:?} len {len} ra {ra} rb {rb} h {h}: gap {gap}"
                );
            }
            both[usize::from(reaches)] += 1;
        }
        assert!(both[0] > 500 && both[1] > 500, "{both:?}");
    }

    #[test]
    fn a_parallel_cluster_on_two_planes_is_stepped_and_rounding_is_not() {
        let near = rect([0.0, 1.0], [0.0, 1.0], |x, y| DVec3::new(x, y, 0.0));
        let mut two = near.clone();
        two.extend(rect([2.0, 3.0], [0.0, 1.0], |x, y| DVec3::new(x, y, 0.01)));
        assert!(stepped(&node(&two)));
        // Single-precision vertices of one plane: offsets apart by rounding only.
        let mut rounded = near.clone();
        rounded.extend(rect([2.0, 3.0], [0.0, 1.0], |x, y| DVec3::new(x, y, f64::from(1e-7f32) * 1.5)));
        assert!(!stepped(&node(&rounded)));
        assert!(!stepped(&node(&near)));
    }

    #[test]
    fn second_order_estimate_stays_within_its_floor() {
        for d in [1.5, 2.0, 3.0, 4.0, 6.0, 10.0] {
            // Parallel unit squares, offset sideways (C-13 corner sum).
            let floor_sq = rect([0.0, 1.0], [0.0, 1.0], |x, y| DVec3::new(x, y, 0.0));
            let ceiling = rect([0.3, 1.3], [0.2, 1.2], |x, y| DVec3::new(y, x, d));
            let exact = parallel_rectangles_exchange([0.0, 1.0], [0.0, 1.0], [0.2, 1.2], [0.3, 1.3], d);
            let (e2, e1, floor) = errors(&floor_sq, &ceiling, exact);
            assert!(e2.abs() <= floor, "parallel d={d}: {e2:e} above {floor:e}");
            // The vector-area estimate is second order: ten times worse wherever links are
            // made (ρ/r < NEAR, d ≥ 3 here).
            if d >= 3.0 {
                assert!(e1.abs() > 10.0 * e2.abs(), "parallel d={d}: {e1:e} vs {e2:e}");
            }
            // Perpendicular unit squares away from their planes' common line (C-14 algebra).
            let (a, b) = (0.7 * d, 0.7 * d);
            let floor_p = rect([a, a + 1.0], [0.0, 1.0], |x, y| DVec3::new(x, y, 0.0));
            let wall = rect([0.2, 1.2], [b, b + 1.0], |y, z| DVec3::new(0.0, y, z));
            let exact = perpendicular_rectangles_exchange([a, a + 1.0], [b, b + 1.0], [0.0, 1.0], [0.2, 1.2]);
            let (e2, _, floor) = errors(&floor_p, &wall, exact);
            assert!(e2.abs() <= floor, "perpendicular d={d}: {e2:e} above {floor:e}");
            // Grazing: the wall square stands on the floor's plane, d away from the floor square.
            let standing = rect([0.2, 1.2], [0.0, 1.0], |y, z| DVec3::new(0.0, y, z));
            let exact = perpendicular_rectangles_exchange([d, d + 1.0], [0.0, 1.0], [0.0, 1.0], [0.2, 1.2]);
            let floor_g = rect([d, d + 1.0], [0.0, 1.0], |x, y| DVec3::new(x, y, 0.0));
            let (e2, _, floor) = errors(&floor_g, &standing, exact);
            assert!(e2.abs() <= floor, "grazing d={d}: {e2:e} above {floor:e}");
            assert!(in_front(&node(&floor_g), &node(&standing), 1e-12));
            assert!(in_front(&node(&standing), &node(&floor_g), 1e-12));
        }
        // A square below the other's plane is not in front of it.
        let below = rect([0.0, 1.0], [0.0, 1.0], |x, y| DVec3::new(x, y, -0.5));
        let wall = rect([0.2, 1.2], [-1.0, 0.0], |y, z| DVec3::new(-2.0, y, z));
        assert!(!in_front(&node(&below), &node(&wall), 1e-12));
    }
}
