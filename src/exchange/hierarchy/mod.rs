//! Clustered, hierarchical exchange for large scenes (Hanrahan–Salzman–Aupperle 1991;
//! Smits–Arvo–Greenberg 1994 and Sillion 1995 clustering): no N×N object anywhere.
//!
//! - [`tree`]: the cluster tree over the patches (orientation, then space);
//! - [`refine`]: links between clusters refined until each link's heat-rate error bound fits
//!   its share of `tol` × the largest heat rate; near and touching pairs end as patch pairs
//!   (radiosity ranges and heat-rate scale come from the solve as a [`Budget`]);
//! - this file: [`Hierarchy`] — the exact values of the patch pairs (the `analytic`/`auto`
//!   kernel, shadows included), the symmetric operator S = Σ_links s_AB a_A b_Bᵀ (+ its
//!   transpose) applied by pull (area-weighted means up the tree), one pass over the links and
//!   push (area shares down the tree); the enforcement hooks of [`Operator`] (the leak check
//!   on surface rows against the links' bounds, closure or capped scales g kept as a vector,
//!   S → G S G, the ambient of open scenes); and the heat-rate error estimate of a solution:
//!   each link's bound on its total, the first-order error of its sharing by area, signed
//!   ([`Hierarchy::sharing_shift`]), and the patch pairs' independent errors.
//!
//! Reciprocity holds by construction: each link is one symmetric rank-one block. Memory is
//! O(N + links).
//!
//! Under MPI ([`part`]) the refinement is cut into fixed tasks and chunks (from the tree alone);
//! each rank refines, evaluates and keeps only its chunks' links and patch pairs, and every sum
//! over them (the operator's product, row sums, error estimates) is a local sum plus a
//! combination in a fixed order, bit-identical to one process. The tree, the vectors over
//! patches and nodes, and the sampled pairs' variances are replicated.
use super::enforce::{DETERMINISTIC_LEAK_TOL, LEAK_SIGMAS};
use super::leak::LeakRow;
use super::operator::Operator;
use crate::error::InputError;
use crate::scene::Scene;
use crate::viewfactor::analytic::kernel::{AnalyticKernel, GAUSS_REL_TOL};
use crate::viewfactor::engine::{RawEntry, RowKernel};
use crate::viewfactor::progress::{self, Progress};
use crate::viewfactor::{auto, Method, MethodSet};
use crate::visibility::Visibility;
use crate::{Error, Result};
use glam::DVec3;
use rayon::prelude::*;
use std::time::{Duration, Instant};

pub mod part;
pub mod rays;
pub mod refine;
pub mod tree;

pub use part::Share;
use part::{Held, Split};
pub use refine::Link;
use tree::Tree;

/// A closed scene's row may fall short of 1 by this many times its links' error bound (plus
/// [`DETERMINISTIC_LEAK_TOL`]) before it counts as a leak.
pub const LEAK_ERR_SIGMAS: f64 = 3.0;

/// `auto`'s goal on each F of the exact patch pairs, as a share of the heat-rate tolerance
/// (at most [`PAIR_TOLERANCE_MAX`]). Their errors are independent of each other's and
/// count in the estimate as standard errors (the sampled ones' own, the integrated ones' goal),
/// summed per surface in quadrature ([`crate::solve::dense::surface_spread`]).
pub const PAIR_TOLERANCE_SHARE: f64 = 0.1;
/// The loosest goal on each F of an exact patch pair.
pub const PAIR_TOLERANCE_MAX: f64 = 1e-2;

/// Default relative heat-rate tolerance of the hierarchical path: a bound on each surface's
/// heat-rate error relative to the largest heat rate (measured errors are 20–100× smaller,
/// validation/scale.md).
pub const DEFAULT_HEAT_RATE_TOLERANCE: f64 = 1e-2;

/// True for the mark of an integrated pair in the hierarchy's list of independent errors (a
/// negative variance: its goal squared).
fn integrated(v: f64) -> bool {
    v < 0.0
}

/// What the build measured.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Tree nodes.
    pub nodes: usize,
    /// Cluster links.
    pub links: usize,
    /// Patch pairs evaluated by the exact kernel.
    pub leaf_pairs: usize,
    /// Visibility rays cast for cluster links.
    pub rays: u64,
    /// Bytes of the tree, links and adjacency this process holds.
    pub bytes: usize,
    /// What each MPI rank holds, in rank order (one entry without MPI).
    pub shares: Vec<Share>,
    /// Wall time of the refinement.
    pub refine: Duration,
    /// Wall time of the patch pairs.
    pub pairs: Duration,
}

/// Patch pairs evaluated by one build, looked up by a later one (same scene, same tree).
#[derive(Debug, Clone)]
pub struct PairCache {
    leaf_of: Vec<u32>,
    pairs: Vec<(u32, u32, f64)>,
    sampled: Vec<(u32, u32, f64)>,
    /// The build's chunks: a later build keeps each row on the same rank.
    split: Split,
}

impl PairCache {
    /// Exchange area and its variance of patch pair (i, j) (row i, as the build chose it), when
    /// it was evaluated as a pair with a nonzero value.
    fn get(&self, i: u32, j: u32) -> Option<(f64, f64)> {
        let key = (self.leaf_of[i as usize], self.leaf_of[j as usize]);
        let k = self.pairs.binary_search_by_key(&key, |p| (p.0, p.1)).ok()?;
        let var =
            self.sampled.binary_search_by_key(&(i, j), |p| (p.0, p.1)).map_or(0.0, |m| self.sampled[m].2);
        Some((self.pairs[k].2, var))
    }
}

/// The link hierarchy of a scene: a symmetric exchange operator over its patches.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    tree: Tree,
    /// Patch areas (patch order).
    areas: Vec<f64>,
    /// Cluster links with their error bounds, sorted by (a, b): this process's chunks.
    links: Vec<Link>,
    /// Exact patch pairs as (leaf node, leaf node, s), sorted within each chunk: this
    /// process's chunks.
    pairs: Vec<(u32, u32, f64)>,
    /// The chunks and which of them this process holds.
    split: Split,
    held: Held,
    /// Patch pairs with independent errors (`auto`), (i, j, v): sampled ones with v the
    /// variance of s_ij (m⁴), integrated ones with v = −goal² ([`integrated`]): their goal on
    /// s_ij counts as a standard error in the heat-rate estimate, not in the leak check.
    sampled: Vec<(u32, u32, f64)>,
    /// Scales g of enforcement (S → G S G), patch order.
    g: Option<Vec<f64>>,
    /// Patch names.
    pub names: Vec<String>,
    /// Each patch's surface (the leak check's rows).
    surface: Vec<u32>,
    /// Surface names.
    surface_names: Vec<String>,
    /// S_i,amb of open scenes, after enforcement.
    pub ambient: Option<Vec<f64>>,
    /// Build statistics.
    pub stats: Stats,
}

/// What the links are refined against, from the solve's boundary conditions (the exchange
/// layer reads none): each patch's radiosity range and the heat-rate scale of the tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct Budget {
    /// Each patch's radiosity range (lo, hi), W/m².
    pub radiosity: Vec<(f64, f64)>,
    /// The largest heat rate to expect, W: `tol` is relative to it.
    pub heat_rate_scale: f64,
    /// Per surface, a bound on Σ S·ΔJ over its links (W): a link's share of the heat-rate
    /// budget is its S·ΔJ over the larger of its two surfaces' weights. `None`: its S over the
    /// larger of its surfaces' areas (every link of a surface at the widest ΔJ).
    pub surface_weight: Option<Vec<f64>>,
}

impl Hierarchy {
    /// Builds the links of `scene` for the relative heat-rate tolerance `tol` of `budget`, with
    /// the patch pairs from the `analytic` or `auto` kernel of `vf`.
    pub fn build(scene: &Scene, vf: &crate::viewfactor::Params, tol: f64, budget: &Budget) -> Result<Self> {
        Self::build_bounded(scene, vf, tol, budget, None)
    }

    /// As [`Hierarchy::build`]: a link's budget is weighed against the radiosity range of its
    /// two clusters.
    /// Patch pairs that `known` (from an earlier build of the same scene and kernel) holds
    /// are taken from it (and it is freed once they are).
    pub fn build_bounded(
        scene: &Scene,
        vf: &crate::viewfactor::Params,
        tol: f64,
        budget: &Budget,
        known: Option<PairCache>,
    ) -> Result<Self> {
        if scene.patches.is_empty() {
            return Err(InputError::file(&scene.source, "the scene has no patches").into());
        }
        let kernel = match vf.method {
            Method::Analytic => AnalyticKernel::new(scene, GAUSS_REL_TOL),
            Method::Auto => auto::kernel(scene, vf),
            m => {
                return Err(Error::Usage(format!(
                    "the hierarchical store evaluates its near pairs with `auto` or `analytic`, not `{m}`"
                )))
            }
        };
        let start = Instant::now();
        let tree = Tree::new(scene);
        let blockers = kernel.shadows().map(|s| s.blockers());
        // The rays only ask whether something separates two patch points: occluders with every
        // patch on one side of their plane (a convex room's walls) are left out of their tree.
        let vis = blockers.map(|b| Visibility::occluding_only(scene, b.splits_patches(scene)));
        let radiosity = tree.ranges(|p| budget.radiosity[p]);
        let mut acc = 0.0;
        let prefix = tree
            .order
            .iter()
            .map(|&p| {
                acc += tree.geom[p as usize].area;
                acc
            })
            .collect();
        let ctx = refine::Context {
            scene,
            tree: &tree,
            blockers,
            vis: vis.as_ref(),
            radiosity,
            tol,
            q_ref: budget.heat_rate_scale,
            weight: budget.surface_weight.clone(),
            area: tree.nodes[0].area,
            prefix,
            seed: vf.seed,
        };
        // This process's chunks (all of them without MPI); a second pass keeps the first's.
        let (rank, size) =
            if crate::distributed::reduce::active() { crate::distributed::rank_size() } else { (0, 1) };
        if size > 1 {
            agree(scene, vf, tol, &tree, kernel.tree_hash());
        }
        let mut probe_seconds = None;
        let split = match known.as_ref() {
            Some(k) if k.split.ranks.len() == size => k.split.clone(),
            _ => {
                let mut split = Split::new(&ctx, size);
                // Estimated first, then measured: a probe of the tasks re-splits the chunks.
                if size > 1 && crate::distributed::partition::measured() {
                    probe_seconds = Some(split.measure(&ctx, rank, size));
                }
                split
            }
        };
        let chunks = split.ranks[rank].clone();
        // Refine this rank's chunks only, chunk by chunk: each chunk's links sorted by node
        // pair, its patch pairs by patch pair.
        let (mut links, mut pairs, mut rays) = (Vec::new(), Vec::new(), 0u64);
        let (mut link_bounds, mut leaf_bounds) = (vec![0], vec![0]);
        let mode = progress::Mode::for_stderr(vf.progress);
        let my_tasks = split.chunks[chunks.clone()].iter().map(|c| c.len() as u64).sum();
        let units = |e: f64| e.max(1.0).round() as u64;
        let my_cost =
            split.chunks[chunks.clone()].iter().flat_map(|c| &split.estimates[c.clone()]).map(|&e| units(e));
        let refining = Progress::start_costed(my_tasks, "refinement tasks", mode, my_cost.sum());
        for c in chunks.clone() {
            let estimates = &split.estimates[split.chunks[c].clone()];
            let done = |k: usize| refining.add_costed(1, units(estimates[k]));
            let mut r = refine::refine_tasks_counted(&ctx, split.tasks_of(c), &done);
            // Exact growth: large blocks grow in place (no doubling of the rank's lists).
            links.reserve_exact(r.links.len());
            pairs.reserve_exact(r.leaves.len());
            links.append(&mut r.links);
            pairs.append(&mut r.leaves);
            rays += r.rays;
            link_bounds.push(links.len());
            leaf_bounds.push(pairs.len());
        }
        refining.finish();
        let refined = links.len() + pairs.len();
        let t_refine = start.elapsed();
        let start = Instant::now();
        // Patch pairs by row: a row's pieces in every chunk this process holds are evaluated
        // together (one blocker classification per row), each piece's values written into the
        // refinement's list in place (no second list of pairs).
        let mut pieces: Vec<Piece> = Vec::new();
        let mut rest = &mut pairs[..];
        for w in leaf_bounds.windows(2) {
            let (mut chunk, tail) = rest.split_at_mut(w[1] - w[0]);
            rest = tail;
            while !chunk.is_empty() {
                let i = chunk[0].0;
                let len = chunk.iter().position(|p| p.0 != i).unwrap_or(chunk.len());
                let (row, more) = chunk.split_at_mut(len);
                pieces.push(row);
                chunk = more;
            }
        }
        // Stable: a row's pieces stay in chunk order.
        pieces.sort_by_key(|piece| piece[0].0);
        let mut rows: Vec<Vec<Piece>> = Vec::new();
        for piece in pieces {
            match rows.last_mut() {
                Some(row) if row[0][0].0 == piece[0].0 => row.push(piece),
                _ => rows.push(vec![piece]),
            }
        }
        let receivers = |row: &[Piece]| -> Vec<u32> {
            let mut js: Vec<u32> = row.iter().flat_map(|piece| piece.iter().map(|p| p.1)).collect();
            js.sort_unstable();
            js
        };
        let row_len = |row: &[Piece]| row.iter().map(|piece| piece.len() as u64).sum::<u64>();
        // Each row's pairs weighed by the kernel's estimate for each (drawn runs only).
        let row_cost: Vec<u64> = if vf.progress {
            rows.par_iter()
                .map_init(Vec::new, |ids, row| {
                    let js = receivers(row).into_iter().map(|j| j as usize);
                    kernel.row_cost(row[0][0].0 as usize, js, ids, true).round() as u64
                })
                .collect()
        } else {
            rows.iter().map(|row| row_len(row)).collect()
        };
        let n_pairs = rows.iter().map(|r| row_len(r)).sum();
        let pairing = Progress::start_costed(n_pairs, "patch pairs", mode, row_cost.iter().sum());
        // Each row's variances go straight into one list, sorted once at the end (its keys are
        // unique, so the order rows finish in leaves no trace): a wave's rows collected
        // first and copied in at its end held both at once, the run's peak (2.6 GB where the
        // store is 1.2 GB at 30k patches). Room for every pair is reserved: pages never
        // written are never resident, and the list never moves (where the system refuses that
        // much address space it grows as needed).
        let mut sampled: Vec<(u32, u32, f64)> = Vec::new();
        let _ = sampled.try_reserve_exact(n_pairs as usize);
        let shared = std::sync::Mutex::new(sampled);
        // `auto`'s goal on each F of an integrated pair (s within goal · min(A_i, A_j)).
        let goal = if vf.method == Method::Auto { vf.tolerance } else { 0.0 };
        let mut first = 0;
        for wave in rows.chunks_mut(PAIR_WAVE) {
            let costs = &row_cost[first..first + wave.len()];
            first += wave.len();
            wave.par_iter_mut().zip(costs).for_each_init(Vec::new, |var, (row, &cost)| {
                let i = row[0][0].0;
                let all = receivers(row);
                let mut out = Vec::with_capacity(all.len());
                let mut js: Vec<u32> = Vec::with_capacity(all.len());
                for &j in &all {
                    match known.as_ref().and_then(|c| c.get(i, j)) {
                        Some((s, var)) if integrated(var) => {
                            out.push(RawEntry { j, method: MethodSet::SHADOWED, s, var: 0.0 })
                        }
                        Some((s, var)) => out.push(RawEntry { j, method: MethodSet::ANALYTIC, s, var }),
                        None => js.push(j),
                    }
                }
                // Far pairs whose whole exchange is within a few goals go by rays
                // ([`rays`]), before the row's blocker classification.
                if let (Some(vis), true) = (vis.as_ref(), goal > 0.0) {
                    js.retain(|&j| match rays::estimate(scene, &tree, vis, (i, j), goal, vf.seed) {
                        Some((s, var)) => {
                            out.push(RawEntry { j, method: MethodSet::MC_AREA, s, var });
                            false
                        }
                        None => true,
                    });
                }
                kernel.partners(i as usize, &js, &mut out);
                out.sort_unstable_by_key(|e| e.j);
                var.clear();
                for p in row.iter_mut().flat_map(|piece| piece.iter_mut()) {
                    let Ok(k) = out.binary_search_by_key(&p.1, |e| e.j) else { continue };
                    p.2 = out[k].s;
                    if out[k].var > 0.0 {
                        var.push((i, p.1, out[k].var));
                    } else if goal > 0.0 && out[k].method == MethodSet::SHADOWED {
                        let area = tree.geom[i as usize].area.min(tree.geom[p.1 as usize].area);
                        var.push((i, p.1, -(goal * area).powi(2)));
                    }
                }
                shared.lock().unwrap_or_else(|e| e.into_inner()).extend_from_slice(var);
                pairing.add_costed(row_len(row), cost);
            });
        }
        pairing.finish();
        let mut sampled = shared.into_inner().unwrap_or_else(|e| e.into_inner());
        sampled.shrink_to_fit();
        drop((rows, known));
        // Chunk by chunk: pairs that exchange nothing are dropped, patch order goes to leaf
        // nodes, and each chunk is sorted.
        let mut kept = 0;
        let mut pair_bounds = vec![0];
        for w in leaf_bounds.windows(2) {
            for r in w[0]..w[1] {
                if pairs[r].2 != 0.0 {
                    pairs[kept] = pairs[r];
                    kept += 1;
                }
            }
            pair_bounds.push(kept);
        }
        pairs.truncate(kept);
        let leaf_of = &tree.leaf_of;
        pairs.par_iter_mut().for_each(|p| *p = (leaf_of[p.0 as usize], leaf_of[p.1 as usize], p.2));
        for w in pair_bounds.windows(2) {
            pairs[w[0]..w[1]].par_sort_unstable_by_key(|p| (p.0, p.1));
        }
        pairs.shrink_to_fit();
        links.shrink_to_fit();
        let t_pairs = start.elapsed();
        let n_nodes = tree.nodes.len();
        let touched = split.touched[chunks.clone()].to_vec();
        let held = Held { distributed: size > 1, chunks, links: link_bounds, pairs: pair_bounds, touched };
        // The sampled pairs' variances are replicated: every rank's, sorted.
        if held.distributed {
            sampled = held.all_gather(&part::encode(&sampled)).iter().flat_map(|b| part::decode(b)).collect();
        }
        sampled.par_sort_unstable_by_key(|p| (p.0, p.1));
        let bytes = std::mem::size_of_val(&links[..])
            + std::mem::size_of_val(&pairs[..])
            + std::mem::size_of_val(&sampled[..])
            + n_nodes * std::mem::size_of::<tree::Node>();
        let shares = held.shares(Share { links: links.len(), pairs: pairs.len(), bytes, refined });
        let (total_links, rays) = (held.total(links.len()), held.total(rays as usize) as u64);
        let leaf_pairs = held.total(leaf_bounds[leaf_bounds.len() - 1]);
        let stats_asked = std::env::var_os(crate::distributed::STATS_VAR).is_some();
        // Each rank's seconds of probing (a collective, so on every rank).
        let probes = if stats_asked {
            held.all_gather(&probe_seconds.unwrap_or(0.0).to_le_bytes())
        } else {
            Vec::new()
        };
        if crate::distributed::writes_outputs() && stats_asked {
            let spans: u64 = split.touched.iter().flatten().map(|s| u64::from(s.end - s.start)).sum();
            eprintln!(
                "lambert: mpi: hierarchy: {} tasks in {} chunks touching {:.2} × the {n_nodes} nodes",
                split.tasks.len(),
                split.chunks.len(),
                spans as f64 / n_nodes as f64
            );
            if let Some(m) = &split.measured {
                let whole = m.iter().sum::<f64>().max(1.0);
                for (r, p) in probes.iter().enumerate() {
                    eprintln!(
                        "lambert: mpi: hierarchy rank {r}: measured split, measured cost {:.3} of the whole, probe {:.3} s",
                        m[split.ranks[r].clone()].iter().sum::<f64>() / whole,
                        f64::from_le_bytes(p[..8].try_into().expect("8 bytes"))
                    );
                }
            }
            for (r, s) in shares.iter().enumerate() {
                let cost: f64 = split.costs[split.ranks[r].clone()].iter().sum();
                eprintln!(
                    "lambert: mpi: hierarchy rank {r}: chunks {:?}, estimated cost {:.3} of the whole, {} links, {} patch pairs, {} refined, {:.1} MB",
                    split.ranks[r],
                    cost / split.costs.iter().sum::<f64>().max(1.0),
                    s.links,
                    s.pairs,
                    s.refined,
                    s.bytes as f64 / 1e6
                );
            }
        }
        let stats = Stats {
            nodes: n_nodes,
            links: total_links,
            leaf_pairs,
            rays,
            bytes,
            shares,
            refine: t_refine,
            pairs: t_pairs,
        };
        let areas = tree.geom.iter().map(|g| g.area).collect();
        let names = (0..scene.patches.len()).map(|p| scene.patch_name(p)).collect();
        let surface = scene.patches.iter().map(|p| p.surface as u32).collect();
        let surface_names = scene.surfaces.iter().map(|s| s.name.clone()).collect();
        Ok(Hierarchy {
            tree,
            areas,
            links,
            pairs,
            split,
            held,
            sampled,
            g: None,
            names,
            surface,
            surface_names,
            ambient: None,
            stats,
        })
    }

    /// The patch pairs alone (this process's), for a later build of the same scene and kernel;
    /// the links and indexes are freed.
    pub fn into_pairs(self) -> PairCache {
        let mut pairs = self.pairs;
        pairs.par_sort_unstable_by_key(|p| (p.0, p.1));
        PairCache { leaf_of: self.tree.leaf_of, pairs, sampled: self.sampled, split: self.split }
    }

    /// Area-weighted means of `x` (patch order) over every node.
    fn pull(&self, x: &[f64]) -> Vec<f64> {
        let nodes = &self.tree.nodes;
        let mut m = vec![0.0; nodes.len()];
        for k in (0..nodes.len()).rev() {
            let n = &nodes[k];
            m[k] = if n.is_leaf() {
                x[self.tree.order[n.lo as usize] as usize]
            } else {
                let [l, r] = n.kids;
                let (nl, nr) = (&nodes[l as usize], &nodes[r as usize]);
                (nl.area * m[l as usize] + nr.area * m[r as usize]) / n.area
            };
        }
        m
    }

    /// Distributes per-node amounts `z` to the patches by area share: y_i = A_i Σ_{N∋i} z_N/A_N.
    fn push(&self, z: &[f64]) -> Vec<f64> {
        let nodes = &self.tree.nodes;
        let mut w = vec![0.0; nodes.len()];
        w[0] = z[0] / nodes[0].area;
        let mut y = vec![0.0; self.areas.len()];
        for k in 0..nodes.len() {
            let n = &nodes[k];
            if n.is_leaf() {
                let p = self.tree.order[n.lo as usize] as usize;
                y[p] = self.areas[p] * w[k];
            } else {
                for c in n.kids {
                    w[c as usize] = w[k] + z[c as usize] / nodes[c as usize].area;
                }
            }
        }
        y
    }

    /// Per node k: Σ over its links and pairs (k, o, s) of s · m_o. Each chunk's entries are
    /// spread (both directions) into its own buffer, and the buffers are added in chunk order
    /// (across ranks under MPI): the same sums on any thread or rank count, and no index of the
    /// entries by their second end. A chunk's buffer spans its first to its last touched node,
    /// zeroed lazily by the allocator, and only its touched runs are added (adding the zeros
    /// elsewhere would change no sum: a sum that starts from +0 never becomes −0).
    fn gather(&self, m: &[f64]) -> Vec<f64> {
        let nodes = self.tree.nodes.len();
        let (lb, pb, touched) = (&self.held.links, &self.held.pairs, &self.held.touched);
        let bounds = |c: usize| {
            let t = &touched[c];
            t.first().map_or(0..0, |f| f.start as usize..t[t.len() - 1].end as usize)
        };
        let bufs: Vec<Vec<f64>> = (0..lb.len() - 1)
            .into_par_iter()
            .map(|c| {
                let span = bounds(c);
                let lo = span.start;
                let mut y = vec![0.0; span.len()];
                for l in &self.links[lb[c]..lb[c + 1]] {
                    let (a, b, s) = (l.a as usize, l.b as usize, l.s());
                    y[a - lo] += s * m[b];
                    y[b - lo] += s * m[a];
                }
                for &(a, b, s) in &self.pairs[pb[c]..pb[c + 1]] {
                    let (a, b) = (a as usize, b as usize);
                    y[a - lo] += s * m[b];
                    y[b - lo] += s * m[a];
                }
                y
            })
            .collect();
        self.held.sum(nodes, |y| {
            for (c, b) in bufs.iter().enumerate() {
                let lo = bounds(c).start;
                for run in &touched[c] {
                    let run = run.start as usize..run.end as usize;
                    let (y, b) = (&mut y[run.clone()], &b[run.start - lo..run.end - lo]);
                    if run.len() >= PAR_ADD {
                        y.par_iter_mut().zip(b).for_each(|(y, b)| *y += b);
                    } else {
                        y.iter_mut().zip(b).for_each(|(y, b)| *y += b);
                    }
                }
            }
        })
    }

    /// Per-patch bound on the row-sum error Σ_j |δs_ij| from the cluster links, m².
    pub fn row_errors(&self) -> Vec<f64> {
        self.row_sum_of(|l| if l.s > 0.0 { l.err() } else { 0.0 })
    }

    /// Per-patch exchange area that links found blocked by every ray may still have (the
    /// rays trusted when unanimous can miss a gap), m²: the leak check allows it.
    pub fn row_unsure(&self) -> Vec<f64> {
        self.row_sum_of(|l| if l.s > 0.0 { 0.0 } else { l.err() })
    }

    /// Per patch: Σ over the links of its clusters of `f(link)`, shared by area.
    fn row_sum_of(&self, f: impl Fn(&Link) -> f64) -> Vec<f64> {
        let z = self.held.sum(self.tree.nodes.len(), |z| {
            for l in &self.links {
                z[l.a as usize] += f(l);
                z[l.b as usize] += f(l);
            }
        });
        self.push(&z)
    }

    /// Per-patch variance of the row sum from the sampled patch pairs, m⁴.
    pub fn row_variances(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.areas.len()];
        for &(i, j, var) in self.sampled.iter().filter(|p| !integrated(p.2)) {
            v[i as usize] += var;
            v[j as usize] += var;
        }
        v
    }

    /// Per-patch heat-rate error estimate (W) of radiosities `j` before enforcement: each
    /// cluster link's error bound (for a link that every ray found blocked, the exchange the
    /// rays may have missed) times the radiosity range over its two clusters, shared by
    /// area, and the sampled pairs' standard errors; in an open scene (ambient emissive power
    /// `e_amb`) also the row's error times |J_i − E_amb|, as the ambient takes what the links
    /// miss. The enforcement's own move is [`Hierarchy::enforcement_shift`], the links' sharing
    /// by area [`Hierarchy::sharing_shift`]: both signed, as they cancel in part.
    pub fn heat_rate_errors(&self, j: &[f64], e_amb: Option<f64>) -> Vec<f64> {
        let (mut e, pairs) = self.heat_rate_error_parts(j, e_amb);
        for (e, s) in e.iter_mut().zip(pairs) {
            *e += s;
        }
        e
    }

    /// [`Hierarchy::heat_rate_errors`] in its two parts: the links' bounds (with the rows'
    /// errors against the ambient of an open scene), and per patch [`LEAK_ERR_SIGMAS`]
    /// standard errors of Σ_j s_ij (J_i − J_j) over its sampled pairs (and its integrated ones,
    /// each goal a standard error). The second is a per-patch view of independent errors; a
    /// surface's total is [`crate::solve::dense::surface_spread`] of
    /// [`Hierarchy::independent_pairs`].
    pub fn heat_rate_error_parts(&self, j: &[f64], e_amb: Option<f64>) -> (Vec<f64>, Vec<f64>) {
        let nodes = &self.tree.nodes;
        let range = self.tree.ranges(|p| (j[p], j[p]));
        let n = self.areas.len();
        let gmax = self.g.as_ref().map_or(1.0, |g| g.iter().copied().fold(1.0, f64::max));
        let z = self.held.sum(nodes.len(), |z| {
            for l in &self.links {
                let (ra, rb) = (range[l.a as usize], range[l.b as usize]);
                let dq = l.err() * gmax * gmax * (ra.1.max(rb.1) - ra.0.min(rb.0));
                z[l.a as usize] += dq;
                z[l.b as usize] += dq;
            }
        });
        let mut e = self.push(&z);
        // Pairs: LEAK_ERR_SIGMAS standard errors of Σ_j s_ij (J_i − J_j).
        let mut var = vec![0.0; n];
        for &(a, b, v) in &self.sampled {
            let d = (j[a as usize] - j[b as usize]).powi(2) * v.abs();
            var[a as usize] += d;
            var[b as usize] += d;
        }
        let sampled = var.iter().map(|v| LEAK_ERR_SIGMAS * gmax * gmax * v.sqrt()).collect();
        if let Some(ea) = e_amb {
            let rows = self.row_errors();
            for i in 0..n {
                e[i] += rows[i] * gmax * gmax * (j[i] - ea).abs();
            }
        }
        (e, sampled)
    }

    /// The sampled patch pairs (i, j, variance of the enforced s_ij, m⁴), each pair once, and
    /// the integrated ones with their goal as a standard error: errors independent of each
    /// other's (read in place: on a big part they number millions).
    pub fn independent_pairs(&self) -> impl Iterator<Item = (u32, u32, f64)> + Clone + '_ {
        let g = move |k: u32| self.g.as_ref().map_or(1.0, |g| g[k as usize]);
        self.sampled.iter().map(move |&(a, b, v)| (a, b, v.abs() * (g(a) * g(b)).powi(2)))
    }

    /// The enforcement's change of each patch's net exchange Σ_j s_ij (J_j − J_i) at
    /// radiosities `j` (W, signed; zero without enforcement scales): a correction of the same
    /// order as the link errors, counted in the error estimate.
    pub fn enforcement_shift(&self, j: &[f64]) -> Vec<f64> {
        let n = self.areas.len();
        if self.g.is_none() {
            return vec![0.0; n];
        }
        let ones = vec![1.0; n];
        let (sj, s1) = (self.matvec_scaled(None, j), self.matvec_scaled(None, &ones));
        let (rj, r1) = (self.apply(None, None, j), self.apply(None, None, &ones));
        (0..n).map(|i| (sj[i] - rj[i]) - j[i] * (s1[i] - r1[i])).collect()
    }

    /// The first-order error of the links' sharing by area, as each patch's change of net
    /// exchange Σ_j δs_ij (J_j − J_i) at radiosities `j` (W, signed; δs the shared value less
    /// the exact one, the ambient taking the row's change in an open scene of emissive power
    /// `e_amb`). A link's total is within its bound, but its share of a patch is off to first
    /// order in ρ/r, by −A_i A_j ∇K·(x_j − c_b − x_i + c_a) per pair between planar
    /// clusters (`refine::kernel_gradient`); over a surface that cancels only where J and the
    /// heat rates' sensitivity are uniform over the clusters, so it is carried through the
    /// inter-reflections with its sign, as the enforcement's move. Links of curved clusters
    /// are left out.
    pub fn sharing_shift(&self, j: &[f64], e_amb: Option<f64>) -> Vec<f64> {
        let nodes = &self.tree.nodes;
        let mean = self.pull(j);
        // First moment Σ A_i (x_i − c) J_i of each node about its centroid.
        let mut moment = vec![DVec3::ZERO; nodes.len()];
        for k in (0..nodes.len()).rev() {
            let n = &nodes[k];
            if !n.is_leaf() {
                moment[k] = n.kids.iter().fold(DVec3::ZERO, |m, &c| {
                    let c = c as usize;
                    m + moment[c] + (nodes[c].centroid - n.centroid) * (nodes[c].area * mean[c])
                });
            }
        }
        // Per node, over its links (o the other end, G the gradient seen from this end):
        // patch i gets A_i (α + β·(x_i − c) − J_i γ·(x_i − c)), α = −G·m_o, β = G A_o J̄_o,
        // γ = G A_o.
        // α, β, γ packed by node (7 values each), summed in link order across ranks.
        let packed = self.held.sum(7 * nodes.len(), |z| {
            for l in self.links.iter().filter(|l| l.s > 0.0) {
                let (a, b) = (l.a as usize, l.b as usize);
                let (na, nb) = (&nodes[a], &nodes[b]);
                if na.planes.is_none() || nb.planes.is_none() {
                    continue;
                }
                // A partly visible link's rays scaled its value, and so its variation.
                let one = if self.stats.rays > 0 { refine::second_order(na, nb) } else { 0.0 };
                let v = if one > 0.0 { (l.s() / one).min(1.0) } else { 1.0 };
                let g = refine::kernel_gradient(na, nb) * v;
                for (x, o, g) in [(a, b, g), (b, a, -g)] {
                    let (db, dg) = (g * (nodes[o].area * mean[o]), g * nodes[o].area);
                    let z = &mut z[7 * x..7 * x + 7];
                    z[0] -= g.dot(moment[o]);
                    for (k, d) in [db.x, db.y, db.z, dg.x, dg.y, dg.z].into_iter().enumerate() {
                        z[1 + k] += d;
                    }
                }
            }
        });
        let alpha: Vec<f64> = packed.chunks_exact(7).map(|z| z[0]).collect();
        let beta: Vec<DVec3> = packed.chunks_exact(7).map(|z| DVec3::new(z[1], z[2], z[3])).collect();
        let gamma: Vec<DVec3> = packed.chunks_exact(7).map(|z| DVec3::new(z[4], z[5], z[6])).collect();
        // Down the tree, each sum of affine terms re-centred on the node: s + v·(x − c) and
        // t + u·(x − c); a leaf's centroid is its patch's.
        let mut acc = vec![(0.0, DVec3::ZERO, 0.0, DVec3::ZERO); nodes.len()];
        acc[0] = (alpha[0], beta[0], 0.0, gamma[0]);
        let mut out = vec![0.0; self.areas.len()];
        for k in 0..nodes.len() {
            let n = &nodes[k];
            let (s, v, t, u) = acc[k];
            if n.is_leaf() {
                let p = self.tree.order[n.lo as usize] as usize;
                // Open: the ambient takes the row change A_i t, so J_i gives way to E_amb.
                out[p] = self.areas[p] * (s - e_amb.unwrap_or(j[p]) * t);
            } else {
                for c in n.kids {
                    let c = c as usize;
                    let d = nodes[c].centroid - n.centroid;
                    acc[c] = (s + v.dot(d) + alpha[c], v + beta[c], t + u.dot(d), u + gamma[c]);
                }
            }
        }
        out
    }

    /// y = W G S G W x with enforcement scales `g` (None: the raw links).
    fn apply(&self, g: Option<&[f64]>, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
        let scale = |i: usize| w.map_or(1.0, |w| w[i]) * g.map_or(1.0, |g| g[i]);
        let xs: Vec<f64> = x.par_iter().enumerate().map(|(i, x)| x * scale(i)).collect();
        let m = self.pull(&xs);
        let z = self.gather(&m);
        let mut y = self.push(&z);
        y.par_iter_mut().enumerate().for_each(|(i, y)| *y *= scale(i));
        y
    }

    /// The leak check's rows: surface rows, not patch rows (a link shares its value by area
    /// within a cluster, which moves exchange between patches of one surface but never between
    /// surfaces). Per surface: its raw row sum (m²), the links' error bound, the exchange area
    /// that unanimous rays may have missed, the sampled pairs' variance and the area, from the
    /// patches' raw row sums `sums`.
    fn surface_rows(&self, sums: &[f64]) -> Vec<[f64; 5]> {
        let (errs, vars, unsure) = (self.row_errors(), self.row_variances(), self.row_unsure());
        let mut out = vec![[0.0; 5]; self.surface_names.len()];
        for (i, &k) in self.surface.iter().enumerate() {
            let r = &mut out[k as usize];
            for (x, v) in r.iter_mut().zip([sums[i], errs[i], unsure[i], vars[i], self.areas[i]]) {
                *x += v;
            }
        }
        out
    }

    /// Cluster links with their error bounds (this process's chunks under MPI).
    pub fn links(&self) -> &[Link] {
        &self.links
    }
}

impl Operator for Hierarchy {
    fn len(&self) -> usize {
        self.areas.len()
    }
    fn areas(&self) -> &[f64] {
        &self.areas
    }
    fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
        self.apply(self.g.as_deref(), w, x)
    }
    fn self_term(&self, _i: usize) -> f64 {
        0.0
    }
    fn names(&self) -> &[String] {
        &self.names
    }
    fn ambient(&self) -> Option<&[f64]> {
        self.ambient.as_deref()
    }
    fn set_ambient(&mut self, ambient: Vec<f64>) {
        self.ambient = Some(ambient);
    }
    /// Composes the scales with those already applied (S → G S G is kept as the vector g).
    fn scale(&mut self, g: &[f64]) {
        self.g = Some(match self.g.take() {
            Some(old) => old.iter().zip(g).map(|(a, b)| a * b).collect(),
            None => g.to_vec(),
        });
    }
    fn negatives(&self) -> usize {
        self.held.total(
            self.links.iter().filter(|l| l.s < 0.0).count() + self.pairs.iter().filter(|p| p.2 < 0.0).count(),
        )
    }
    /// Surface rows: the links by their bounds ([`LEAK_ERR_SIGMAS`] of them, at least
    /// [`DETERMINISTIC_LEAK_TOL`]) plus what unanimous rays may have missed, the sampled pairs by
    /// [`LEAK_SIGMAS`] standard errors (as the dense store's check).
    fn leak_budget(&self, raw: &[f64]) -> Vec<(f64, f64)> {
        self.surface_rows(raw)
            .iter()
            .map(|&[sum, err, unsure, var, area]| {
                if area <= 0.0 {
                    return (1.0, 0.0);
                }
                let allowed = DETERMINISTIC_LEAK_TOL.max(LEAK_ERR_SIGMAS * err / area)
                    + unsure / area
                    + LEAK_SIGMAS * var.sqrt() / area;
                (sum / area, allowed)
            })
            .collect()
    }
    fn leak_row_name(&self, k: usize) -> String {
        self.surface_names[k].clone()
    }
    fn leak_rows(&self, leaks: &[(usize, f64)]) -> Vec<LeakRow> {
        let var = self.row_variances();
        let mut sampled = vec![false; self.surface_names.len()];
        for (i, &k) in self.surface.iter().enumerate() {
            sampled[k as usize] |= var[i] > 0.0;
        }
        leaks
            .iter()
            .map(|&(k, p)| LeakRow {
                name: self.surface_names[k].clone(),
                row_sum: p,
                sampled: usize::from(sampled[k]),
                entries: usize::from(p > 0.0),
                worst: None,
            })
            .collect()
    }
    fn couplings(&self, f: &mut dyn FnMut(usize, usize)) {
        if !self.held.distributed {
            self.local_couplings(f);
            return;
        }
        // Under MPI: every rank's groups joined on every rank, as one process's couplings.
        let all_gather = |mine: &[u8]| self.held.all_gather(mine);
        super::ranks::gathered_couplings(self.areas.len(), |g| self.local_couplings(g), all_gather, f);
    }
}

impl Hierarchy {
    /// Coupled patch pairs of this process's links and pairs (every pair in one process).
    fn local_couplings(&self, f: &mut dyn FnMut(usize, usize)) {
        let ends = self.links.iter().map(|l| (l.a, l.b, l.s())).chain(self.pairs.iter().copied());
        for (a, b, s) in ends {
            if s != 0.0 {
                let (pa, pb) = (self.tree.patches(a), self.tree.patches(b));
                for &p in pa {
                    f(p as usize, pb[0] as usize);
                }
                for &q in pb {
                    f(pa[0] as usize, q as usize);
                }
            }
        }
    }
}

/// Under MPI: every rank must refine the same tree of the same scene with the same settings
/// (`kernel_trees`: the hash of the kernel's blocker trees), else the run ends with exit code 2.
fn agree(scene: &Scene, vf: &crate::viewfactor::Params, tol: f64, tree: &Tree, kernel_trees: u64) {
    use std::hash::Hasher;
    let mut h = fnv::FnvHasher::default();
    h.write_u64(kernel_trees);
    for n in &tree.nodes {
        for v in [n.lo, n.hi, n.kids[0], n.kids[1]] {
            h.write_u32(v);
        }
        h.write_u64(n.area.to_bits());
    }
    for &p in &tree.order {
        h.write_u32(p);
    }
    let options = format!("hierarchy, heat-rate tolerance {:016x}, {}", tol.to_bits(), vf.agreement());
    let hash = crate::viewfactor::distributed::agreement_hash(scene, &options, true, h.finish());
    crate::distributed::agree(hash, "scene geometry, cluster tree, method and options");
}

/// Runs of a chunk's buffer at least this long are added on rayon's threads (shorter ones
/// cost less than a parallel split).
const PAR_ADD: usize = 1 << 14;

/// A run of one row's patch pairs (i, j, s) in one chunk, evaluated in place.
type Piece<'a> = &'a mut [(u32, u32, f64)];

/// Rows of exact patch pairs evaluated per wave (bounds the memory of their raw entries).
const PAIR_WAVE: usize = 1 << 14;

#[cfg(test)]
mod tests {
    use super::*;

    /// Radiosities of a long box (1 × 1 × 3 m, 4 × 4 patches a face): a ramp along its length
    /// and a ripple across, so that clusters see J vary.
    fn long_box() -> (Scene, Vec<f64>) {
        let face = |name: &str, o: [f64; 3], u: [f64; 3], v: [f64; 3]| {
            format!(
                "[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o:?}, u = {u:?}, v = {v:?} }}\n\
                 subdivide = [4, 4]\nemissivity = 0.5\ntemperature = 300.0\n\n"
            )
        };
        let text = [
            face("floor", [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            face("ceiling", [0.0, 0.0, 3.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
            face("x0", [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]),
            face("x1", [1.0, 0.0, 0.0], [0.0, 0.0, 3.0], [0.0, 1.0, 0.0]),
            face("y0", [0.0, 0.0, 0.0], [0.0, 0.0, 3.0], [1.0, 0.0, 0.0]),
            face("y1", [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 3.0]),
        ]
        .concat();
        let scene = crate::scene::toml_scene::from_str(std::path::Path::new("box.toml"), &text).unwrap();
        let j = scene
            .patches
            .iter()
            .map(|p| {
                let c = p.polygon.centroid();
                400.0 + 100.0 * c.z + 30.0 * (7.0 * c.x + 3.0 * c.y).sin()
            })
            .collect();
        (scene, j)
    }

    #[test]
    fn the_build_reports_its_refinement_tasks_then_its_patch_pairs_to_the_end() {
        use crate::viewfactor::progress::{watching, Watch};
        let (scene, _) = long_box();
        let vf = crate::viewfactor::Params { method: Method::Analytic, ..Default::default() };
        let watch = std::sync::Arc::new(Watch::default());
        let h = watching(&watch, || {
            Hierarchy::build(&scene, &vf, 3e-2, &crate::solve::clustered::budget(&scene))
        })
        .unwrap();
        let r = watch.read();
        // Two stages: the refinement's tasks, then the patch pairs, counted to their total.
        assert_eq!(r.stages, 2, "{r:?}");
        assert_eq!(r.what, "patch pairs", "{r:?}");
        assert!(h.stats.leaf_pairs > 0);
        assert_eq!((r.done, r.total), (h.stats.leaf_pairs as u64, h.stats.leaf_pairs as u64), "{r:?}");
    }

    #[test]
    fn sharing_shift_sums_the_first_order_error_of_every_patch_pair() {
        let (scene, j) = long_box();
        let vf = crate::viewfactor::Params { method: Method::Analytic, ..Default::default() };
        let h = Hierarchy::build(&scene, &vf, 3e-2, &crate::solve::clustered::budget(&scene)).unwrap();
        assert!(h.links.len() > 50, "{} links", h.links.len());
        let e_amb = 350.0;
        // Pair by pair: δs = −A_i A_j ∇K·(x_j − c_b − x_i + c_a), net exchange δs (J_j − J_i),
        // or δs (J_j − E_amb) when the ambient takes the row's change.
        let (nodes, geom) = (&h.tree.nodes, &h.tree.geom);
        let (mut closed, mut open) = (vec![0.0; j.len()], vec![0.0; j.len()]);
        for l in &h.links {
            let (na, nb) = (&nodes[l.a as usize], &nodes[l.b as usize]);
            let g = refine::kernel_gradient(na, nb);
            for &p in h.tree.patches(l.a) {
                for &q in h.tree.patches(l.b) {
                    let (p, q) = (p as usize, q as usize);
                    let u = (geom[q].centroid - nb.centroid) - (geom[p].centroid - na.centroid);
                    let ds = -geom[p].area * geom[q].area * g.dot(u);
                    closed[p] += ds * (j[q] - j[p]);
                    closed[q] += ds * (j[p] - j[q]);
                    open[p] += ds * (j[q] - e_amb);
                    open[q] += ds * (j[p] - e_amb);
                }
            }
        }
        let scale = closed.iter().map(|x| x.abs()).fold(0.0, f64::max);
        assert!(scale > 0.0);
        for (want, got) in [(&closed, h.sharing_shift(&j, None)), (&open, h.sharing_shift(&j, Some(e_amb)))] {
            for (p, (w, g)) in want.iter().zip(&got).enumerate() {
                assert!((w - g).abs() <= SHIFT_TOL * scale, "patch {p}: {g} against {w} pair by pair");
            }
        }
    }

    /// The refinement context of `scene` at tolerance `tol` (no blockers).
    fn context<'a>(scene: &'a Scene, tree: &'a Tree, tol: f64) -> refine::Context<'a> {
        let budget = crate::solve::clustered::budget(scene);
        refine::Context {
            scene,
            tree,
            blockers: None,
            vis: None,
            radiosity: tree.ranges(|p| budget.radiosity[p]),
            tol,
            q_ref: budget.heat_rate_scale,
            weight: budget.surface_weight.clone(),
            area: tree.nodes[0].area,
            prefix: Vec::new(),
            seed: 0,
        }
    }

    #[test]
    fn a_leaf_pair_of_unequal_patches_is_evaluated_from_the_smaller() {
        // The heat sink's facets in a room of one patch per wall: a wall–facet pair's row is
        // the facet (narrow shadow volumes), pairs of like areas keep the lower index first.
        let path =
            format!("{}/validation/reference/real_parts/heat_sink/scene.toml", env!("CARGO_MANIFEST_DIR"));
        let scene = crate::scene::load(std::path::Path::new(&path)).expect("the heat sink loads");
        let tree = Tree::new(&scene);
        let whole = refine::refine(&context(&scene, &tree, 1e-3));
        let area = |p: u32| scene.patches[p as usize].polygon.area();
        let mut flipped = 0;
        for &(i, j, _) in &whole.leaves {
            let (ai, aj) = (area(i), area(j));
            if ai * refine::SMALL_ROW_RATIO < aj || aj * refine::SMALL_ROW_RATIO < ai {
                assert!(ai < aj, "pair ({i}, {j}): row area {ai:.3e} against {aj:.3e}");
                flipped += usize::from(i > j);
            } else {
                assert!(i < j, "pair ({i}, {j}) of like areas {ai:.3e}, {aj:.3e}");
            }
        }
        assert!(flipped > 100 && whole.leaves.len() > 500, "{flipped} of {} pairs", whole.leaves.len());
    }

    #[test]
    fn the_tasks_together_refine_the_whole_scene_at_any_tolerance() {
        let (scene, _) = long_box();
        let tree = Tree::new(&scene);
        let mut counts = Vec::new();
        for max_size in [1.0, 8.0, 40.0, 300.0] {
            // The tasks depend on the tree alone: the same at every tolerance.
            let tasks = refine::tasks(&context(&scene, &tree, 1e-1), max_size);
            assert_eq!(tasks, refine::tasks(&context(&scene, &tree, 1e-3), max_size));
            assert!(tasks
                .iter()
                .all(|t| t.size(&tree) <= max_size || matches!(t, refine::Task::Between(..))));
            counts.push(tasks.len());
            for tol in [1e-1, 1e-3] {
                let ctx = context(&scene, &tree, tol);
                let whole = refine::refine(&ctx);
                assert!(whole.links.len() > 20 && whole.leaves.len() > 100, "tol {tol}");
                let (mut links, mut leaves) = (Vec::new(), Vec::new());
                let mut estimate = 0.0;
                for t in &tasks {
                    let r = refine::refine_tasks(&ctx, std::slice::from_ref(t));
                    links.extend(r.links);
                    leaves.extend(r.leaves);
                    estimate += refine::estimate(&ctx, *t);
                }
                links.sort_by_key(|l| (l.a, l.b));
                leaves.sort_by_key(|p| (p.0, p.1));
                assert_eq!(links, whole.links, "max size {max_size}, tol {tol}");
                assert_eq!(leaves, whole.leaves, "max size {max_size}, tol {tol}");
                // The estimate (near pairs, far clusters by their patches) is within a small
                // factor of the links and pairs, whatever the tolerance.
                let made = (links.len() + leaves.len()) as f64;
                assert!(
                    estimate > 0.25 * made && estimate < 4.0 * made,
                    "{estimate} against {made}, tol {tol}"
                );
            }
        }
        assert!(counts.windows(2).all(|w| w[0] > w[1]), "{counts:?}");
    }

    #[test]
    fn ranks_hold_contiguous_runs_of_chunks_that_cover_every_task() {
        let (scene, _) = long_box();
        let tree = Tree::new(&scene);
        let ctx = context(&scene, &tree, 1e-2);
        let one = Split::new(&ctx, 1);
        assert_eq!(one.chunks.len(), part::chunk_count(scene.patches.len()));
        assert!(one.tasks.len() >= 4 * one.chunks.len(), "{} tasks", one.tasks.len());
        assert_eq!((one.chunks[0].start, one.chunks.last().unwrap().end), (0, one.tasks.len()));
        assert!(one.chunks.windows(2).all(|w| w[0].end == w[1].start));
        for (c, runs) in one.touched.iter().enumerate() {
            assert!(runs.windows(2).all(|w| w[0].end < w[1].start), "{runs:?}");
            for t in one.tasks_of(c) {
                for r in t.nodes(&tree).into_iter().filter(|r| !r.is_empty()) {
                    assert!(r.end as usize <= tree.nodes.len());
                    assert!(
                        runs.iter().any(|u| u.start <= r.start && r.end <= u.end),
                        "{r:?} not in {runs:?}"
                    );
                }
            }
        }
        let total: f64 = one.costs.iter().sum();
        for size in 2..5 {
            let s = Split::new(&ctx, size);
            // The same tasks and chunks on any rank count; only their owners differ.
            assert_eq!((&s.tasks, &s.chunks, &s.costs), (&one.tasks, &one.chunks, &one.costs));
            assert_eq!(s.ranks.len(), size);
            assert_eq!((s.ranks[0].start, s.ranks[size - 1].end), (0, one.chunks.len()));
            assert!(s.ranks.windows(2).all(|w| w[0].end == w[1].start));
            for r in &s.ranks {
                let share = s.costs[r.clone()].iter().sum::<f64>() / total;
                assert!((share * size as f64 - 1.0).abs() < 0.35, "{size} ranks: {r:?} holds {share}");
            }
        }
    }

    /// The tree sums against the pair-by-pair ones: round-off.
    const SHIFT_TOL: f64 = 1e-12;
}
