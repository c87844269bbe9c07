//! How the refinement of a [`super::Hierarchy`] is cut into fixed tasks and chunks and shared
//! between MPI ranks, and the sums over its links and pairs in a fixed order.
//!
//! - The top of the refinement's recursion is cut into tasks ([`refine::tasks`]: pairs of
//!   nodes, taken on geometric decisions alone), so the tasks depend on the tree only — not on
//!   the tolerance, the radiosity bounds or the rank count — and together they give the whole
//!   refinement. Each task's cost is estimated ([`refine::estimate`]).
//! - The tasks, in order, are grouped into [`chunk_count`] chunks of near equal estimated cost
//!   (a function of the patch count, never of the rank count). Each rank holds a contiguous run
//!   of chunks balanced by their estimated cost ([`Split`]); it refines only its chunks' tasks
//!   and keeps the links and patch pairs it refined, so no rank ever holds the whole lists and
//!   their memory falls as 1/ranks.
//! - The split is estimated, then measured ([`Split::measure`]): every
//!   [`partition::PROBE_STRIDE`]-th task, dealt round-robin, is refined as a probe and its
//!   links and patch pairs counted (the estimate cannot see the budget, which refines pairs
//!   between surfaces of different radiosity much further); the counts are all-gathered and
//!   the chunks re-split by each task's estimate times the measured entries per estimated
//!   unit around it ([`partition::grouped`]). Only the split moves: the chunks and their
//!   sums stay as they were, so outputs do not change. `LAMBERT_MPI_BALANCE=estimated` keeps
//!   the estimated split. Within a chunk the links are sorted by node pair and the
//!   patch pairs by patch pair, rows evaluated per chunk, so every chunk holds the same entries
//!   in the same order on any rank count. A two-pass solve keeps the first pass's split, so its
//!   cached pairs are on the rank that refines them again.
//! - Every sum over links or pairs adds in chunk order, on any rank count: each rank adds its
//!   own chunks' terms to the running sum of the ranks before it
//!   ([`crate::distributed::reduce::ordered_sum`]), so outputs are byte-identical to a run
//!   without MPI.
//!
//! Without MPI (or on one rank) one process holds every chunk and nothing is sent.
use super::refine::{self, Task};
use crate::distributed::{partition, reduce};
use rayon::prelude::*;
use std::ops::Range;

/// Fewest chunks of a split: the single-process product adds one buffer per chunk (spread
/// over rayon's threads), and 16 keeps that as fast as before on scenes of 10⁴ patches.
pub const MIN_CHUNKS: usize = 16;
/// Patches per chunk above [`MIN_CHUNKS`] chunks: 64 ranks hold a share from 131,072
/// patches on (smaller scenes gain nothing from more ranks).
pub const PATCHES_PER_CHUNK: usize = 2048;
/// Most chunks of a split (1M patches: 488 chunks).
pub const MAX_CHUNKS: usize = 1024;
/// Tasks per chunk aimed at when the recursion is cut: enough that chunks balance to a few
/// per cent by their tasks' estimates.
pub const TASKS_PER_CHUNK: usize = 16;

/// Chunks of the refinement of `n` patches (depends on `n` alone: sums add in the same order
/// on any rank count).
pub fn chunk_count(n: usize) -> usize {
    (n / PATCHES_PER_CHUNK).clamp(MIN_CHUNKS, MAX_CHUNKS)
}

/// The tasks and chunks of one build and which chunks each rank holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Split {
    /// The refinement's tasks, in order.
    pub tasks: Vec<Task>,
    /// Tasks of each chunk: contiguous, in order.
    pub chunks: Vec<Range<usize>>,
    /// Estimated cost of each chunk.
    pub costs: Vec<f64>,
    /// Estimated cost of each task.
    pub estimates: Vec<f64>,
    /// Measured cost (links and patch pairs refined) of each chunk, when measured.
    pub measured: Option<Vec<f64>>,
    /// Tree nodes each chunk's links and pairs touch: sorted, disjoint runs of node ids.
    pub touched: Vec<Vec<Range<u32>>>,
    /// Chunks held by each rank: contiguous, in rank order.
    pub ranks: Vec<Range<usize>>,
}

impl Split {
    /// Cuts the refinement of `ctx` into tasks and chunks and shares them among `size` ranks
    /// by estimated cost.
    pub fn new(ctx: &refine::Context, size: usize) -> Split {
        let n = ctx.tree.nodes[0].len();
        let count = chunk_count(n);
        let pairs = n as f64 * (n as f64 - 1.0) / 2.0;
        let tasks = refine::tasks(ctx, pairs / (count * TASKS_PER_CHUNK) as f64);
        let estimates: Vec<f64> = tasks.par_iter().map(|t| refine::estimate(ctx, *t)).collect();
        Split::from_tasks(ctx.tree, tasks, &estimates, count, size)
    }

    /// Groups `tasks` (with their estimated costs) into `count` chunks, shared among `size`
    /// ranks.
    pub fn from_tasks(
        tree: &super::tree::Tree,
        tasks: Vec<Task>,
        estimates: &[f64],
        count: usize,
        size: usize,
    ) -> Split {
        let chunks = partition::balanced(estimates, count);
        let costs: Vec<f64> = chunks.iter().map(|c| estimates[c.clone()].iter().sum()).collect();
        let touched = chunks
            .iter()
            .map(|c| {
                let mut runs: Vec<Range<u32>> =
                    tasks[c.clone()].iter().flat_map(|t| t.nodes(tree)).filter(|r| !r.is_empty()).collect();
                runs.sort_by_key(|r| r.start);
                let mut merged: Vec<Range<u32>> = Vec::with_capacity(runs.len());
                for r in runs {
                    match merged.last_mut() {
                        Some(m) if r.start <= m.end => m.end = m.end.max(r.end),
                        _ => merged.push(r),
                    }
                }
                merged
            })
            .collect();
        let ranks = partition::balanced(&costs, size);
        Split { tasks, chunks, costs, estimates: estimates.to_vec(), measured: None, touched, ranks }
    }

    /// Re-splits the chunks among `size` ranks by measured cost (every rank calling, a
    /// collective): this rank (`rank`) refines its probe tasks, counting each one's links and
    /// patch pairs, the counts are all-gathered, and every rank computes the same split from
    /// them. Returns this rank's seconds of probing.
    pub fn measure(&mut self, ctx: &refine::Context, rank: usize, size: usize) -> f64 {
        let start = std::time::Instant::now();
        let mine: Vec<u8> = partition::probe_rows(self.tasks.len(), size, rank)
            .par_iter()
            .map(|&k| {
                let r = refine::refine_tasks(ctx, &self.tasks[k..k + 1]);
                (k, (r.links.len() + r.leaves.len()) as f64)
            })
            .collect::<Vec<_>>()
            .iter()
            .flat_map(|&(k, c)| [(k as u64).to_le_bytes(), c.to_bits().to_le_bytes()].concat())
            .collect();
        let seconds = start.elapsed().as_secs_f64();
        let mut probes: Vec<(usize, f64)> = reduce::all_gather_bytes(&mine)
            .iter()
            .flat_map(|b| {
                b.chunks_exact(16)
                    .map(|c| {
                        let w = |o: usize| u64::from_le_bytes(c[o..o + 8].try_into().expect("8 bytes"));
                        (w(0) as usize, f64::from_bits(w(8)))
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        probes.sort_by_key(|p| p.0);
        self.rebalance(&probes, size);
        seconds
    }

    /// Splits the chunks among `size` ranks by the measured costs `probes` (task, cost; sorted
    /// by task) of some tasks ([`partition::grouped`]).
    pub fn rebalance(&mut self, probes: &[(usize, f64)], size: usize) {
        self.ranks = partition::grouped(&self.estimates, probes, &self.chunks, size, false);
        let cost = partition::measured_costs(&self.estimates, probes);
        self.measured = Some(self.chunks.iter().map(|c| cost[c.clone()].iter().sum()).collect());
    }

    /// The tasks of chunk `c`.
    pub fn tasks_of(&self, c: usize) -> &[Task] {
        &self.tasks[self.chunks[c].clone()]
    }
}

/// This process's share: its chunks and where each starts in its own link and pair lists.
#[derive(Debug, Clone, PartialEq)]
pub struct Held {
    /// True when the other chunks are on other ranks (every sum is then collective).
    pub distributed: bool,
    /// Chunks held.
    pub chunks: Range<usize>,
    /// Start of each held chunk in this rank's links, and their end.
    pub links: Vec<usize>,
    /// Start of each held chunk in this rank's pairs, and their end.
    pub pairs: Vec<usize>,
    /// Tree nodes each held chunk touches (sorted, disjoint runs).
    pub touched: Vec<Vec<Range<u32>>>,
}

impl Held {
    /// The sum over every rank of `len` values, each rank adding its terms with `add` in chunk
    /// order (see the module docs); `add` alone in a single process.
    pub fn sum(&self, len: usize, add: impl FnOnce(&mut [f64])) -> Vec<f64> {
        if self.distributed {
            reduce::ordered_sum(len, add)
        } else {
            let mut y = vec![0.0; len];
            add(&mut y);
            y
        }
    }

    /// The total over ranks of a count.
    pub fn total(&self, count: usize) -> usize {
        if self.distributed {
            reduce::all_gather_u64(count as u64).iter().sum::<u64>() as usize
        } else {
            count
        }
    }

    /// Every rank's bytes in rank order (`[mine]` in a single process).
    pub fn all_gather(&self, mine: &[u8]) -> Vec<Vec<u8>> {
        if self.distributed {
            reduce::all_gather_bytes(mine)
        } else {
            vec![mine.to_vec()]
        }
    }

    /// Every rank's (links, patch pairs, bytes) in rank order.
    pub fn shares(&self, mine: Share) -> Vec<Share> {
        let bytes: Vec<u8> = [mine.links, mine.pairs, mine.bytes, mine.refined]
            .iter()
            .flat_map(|v| (*v as u64).to_le_bytes())
            .collect();
        self.all_gather(&bytes)
            .iter()
            .map(|b| {
                let v =
                    |k: usize| u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("32 bytes")) as usize;
                Share { links: v(0), pairs: v(1), bytes: v(2), refined: v(3) }
            })
            .collect()
    }
}

/// What one rank holds of a hierarchy.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Share {
    /// Cluster links.
    pub links: usize,
    /// Patch pairs with a nonzero exchange area.
    pub pairs: usize,
    /// Bytes of its links, pairs, sampled pairs' variances and the tree.
    pub bytes: usize,
    /// Links and patch pairs (zero ones included) its refinement produced: the most it held
    /// at once (no rank receives another's).
    pub refined: usize,
}

/// Patch pairs as 16 bytes each (for the all-gather of the sampled pairs).
pub fn encode(v: &[(u32, u32, f64)]) -> Vec<u8> {
    let mut out = Vec::with_capacity(16 * v.len());
    for &(a, b, x) in v {
        out.extend_from_slice(&a.to_le_bytes());
        out.extend_from_slice(&b.to_le_bytes());
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

/// The inverse of [`encode`].
pub fn decode(bytes: &[u8]) -> Vec<(u32, u32, f64)> {
    bytes
        .chunks_exact(16)
        .map(|c| {
            let u = |k: usize| u32::from_le_bytes(c[k..k + 4].try_into().expect("4 bytes"));
            (u(0), u(4), f64::from_le_bytes(c[8..16].try_into().expect("8 bytes")))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chunk_count_grows_with_the_patches_alone() {
        assert_eq!(chunk_count(10), MIN_CHUNKS);
        assert_eq!(chunk_count(15_000), MIN_CHUNKS);
        assert_eq!(chunk_count(100_000), 48);
        assert!(chunk_count(131_072) >= 64);
        assert_eq!(chunk_count(1 << 30), MAX_CHUNKS);
    }

    #[test]
    fn measured_counts_move_chunks_and_keep_them_whole() {
        // 16 chunks of 8 tasks of equal estimates; the tasks of chunks 0..4 refine ten times
        // as many entries as the estimate says (pairs between hot and cold surfaces).
        let chunks: Vec<Range<usize>> = (0..16).map(|c| 8 * c..8 * c + 8).collect();
        let mut split = Split {
            tasks: Vec::new(),
            chunks: chunks.clone(),
            costs: vec![8.0; 16],
            estimates: vec![1.0; 128],
            measured: None,
            touched: Vec::new(),
            ranks: partition::balanced(&[8.0; 16], 2),
        };
        assert_eq!(split.ranks, vec![0..8, 8..16]);
        let count = |k: usize| if k < 32 { 10.0 } else { 1.0 };
        let probes: Vec<(usize, f64)> =
            (0..128).step_by(partition::PROBE_STRIDE).map(|k| (k, count(k))).collect();
        split.rebalance(&probes, 2);
        // The rates pool 5 probes (one a chunk), so chunks 2..6 blend: measured cost 416 in
        // all (80, 80, 65.6, 51.2, 36.8, 22.4, then 8 a chunk); the first rank's half ends
        // after chunk 2 or 3.
        assert_eq!((split.ranks[0].start, split.ranks[1].end), (0, 16));
        assert_eq!(split.ranks[0].end, split.ranks[1].start);
        assert!((2..=3).contains(&split.ranks[0].end), "{:?}", split.ranks);
        let m = split.measured.as_ref().expect("measured costs");
        assert!((m.iter().sum::<f64>() - 416.0).abs() < 1e-9, "{m:?}");
        assert_eq!((m[0], m[15]), (80.0, 8.0));
    }

    #[test]
    fn pairs_survive_the_byte_round_trip() {
        let v = vec![(1, 2, 0.5), (u32::MAX, 0, -1e-300)];
        assert_eq!(decode(&encode(&v)), v);
    }

    #[test]
    fn one_process_sums_are_its_own() {
        let h =
            Held { distributed: false, chunks: 0..MIN_CHUNKS, links: vec![], pairs: vec![], touched: vec![] };
        assert_eq!(h.sum(3, |y| y[1] += 2.0), vec![0.0, 2.0, 0.0]);
        assert_eq!(h.total(7), 7);
    }
}
