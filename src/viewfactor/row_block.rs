//! The packed store distributed by row blocks (MPI, the `solve` route): each rank computes
//! and keeps the rows of a contiguous run of the mat-vec's row blocks
//! ([`super::packed::matvec_bounds`], a function of the patch count alone), so the store's
//! memory per rank is about 1/ranks and no row travels. What every rank then needs of the
//! other rows is O(N) and replicated: the diagonal, the raw row sums, variances and methods
//! (mirrored across the ranks in row order, `super::packed::mirror`), the pair count, and
//! every rank's flagged entries and goal misses (merged into each rank's kernel in rank
//! order, as the gathered route merges them into rank 0's). A failed row ends the run on
//! every rank with the error of the earliest failed row, the one a run without MPI reports.
//!
//! Only symmetric kernels are served (their rows write their own cells); a kernel that
//! folds s_ji into another row's cells (hemicube, single-plane) keeps the gathered route
//! (`super::distributed::rows`). The split is estimated (equal pair counts), never measured:
//! the owner of a row must compute it, and a probe wave's rows would have to travel.
#[cfg_attr(not(feature = "mpi"), allow(unused_imports))]
use super::packed::{self, PackedTriangular};
use super::progress::Progress;
use super::row::RowKernel;
use crate::scene::Scene;
use crate::Result;
use std::ops::Range;

/// Rows of `n` that rank `rank` of `size` holds: a contiguous run of the mat-vec's row
/// blocks, the runs balanced by their pair counts (some ranks hold none when blocks are
/// fewer than ranks).
pub fn held_rows(n: usize, rank: usize, size: usize) -> Range<usize> {
    let bounds = packed::matvec_bounds(n);
    let pairs: Vec<f64> = bounds.windows(2).map(|b| (b[0]..b[1]).map(|i| (n - i) as f64).sum()).collect();
    let runs = crate::distributed::partition::balanced(&pairs, size);
    let run = &runs[rank.min(runs.len() - 1)];
    bounds[run.start]..bounds[run.end]
}

/// Under MPI with several ranks and a symmetric kernel: this rank's rows (for the progress
/// count and the memory check); `None` otherwise (one process computes every row).
pub fn keeps_rows(n: usize, symmetric: bool) -> Option<Range<usize>> {
    if !symmetric || !crate::distributed::reduce::active() {
        return None;
    }
    let (rank, size) = crate::distributed::rank_size();
    Some(held_rows(n, rank, size))
}

/// Fills this rank's rows `held` of the patch-level triangle of `scene` with `kernel` (a
/// symmetric kernel, every rank calling), after the ranks agree on the geometry, trees,
/// method and `options` (a mismatch ends the run with exit code 2).
pub fn fill(
    scene: &Scene,
    kernel: &dyn RowKernel,
    options: &str,
    held: Range<usize>,
    progress: &Progress,
    costs: &[u64],
) -> Result<PackedTriangular> {
    #[cfg(feature = "mpi")]
    {
        use super::distributed::{agreement_hash, decode, encode, Share};
        use crate::distributed::{comm, reduce};
        let hash = agreement_hash(scene, options, kernel.symmetric(), kernel.tree_hash());
        comm::check_rows(hash, "scene geometry, acceleration trees, method and options");
        let n = scene.patches.len();
        let areas = scene.patches.iter().map(|p| p.polygon.area()).collect();
        let mut t = PackedTriangular::zeros_rows(n, areas, held.clone())?;
        t.distributed = true;
        let start = std::time::Instant::now();
        let failure = packed::fill_held(&mut t, kernel, progress, costs);
        // Every rank learns every failure, flag and miss (a failure ends the run everywhere).
        let share = Share {
            first: held.start,
            rows: Vec::new(),
            failure,
            flags: kernel.flags(),
            misses: kernel.misses(),
            seconds: start.elapsed().as_secs_f64(),
        };
        let rank = comm::rank_size().0;
        let mut earliest: Option<(usize, crate::Error)> = None;
        for (r, bytes) in reduce::all_gather_bytes(&encode(&share)).iter().enumerate() {
            let s = decode(bytes).ok_or_else(|| {
                crate::Error::Compute(format!("the view-factor summary from MPI rank {r} arrived damaged"))
            })?;
            if r != rank {
                kernel.absorb(s.flags, s.misses);
            }
            if let Some((i, e)) = s.failure {
                if earliest.as_ref().is_none_or(|f| i < f.0) {
                    earliest = Some((i, e));
                }
            }
        }
        if let Some((_, e)) = earliest {
            return Err(e);
        }
        // The diagonal of every row, in rank (so row) order.
        let mine: Vec<u8> = held.clone().flat_map(|i| t.row(i)[0].to_bits().to_le_bytes()).collect();
        t.diag = reduce::all_gather_bytes(&mine)
            .iter()
            .flat_map(|b| {
                b.chunks_exact(8).map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().expect("8"))))
            })
            .collect();
        packed::mirror(&mut t);
        t.warnings = kernel.warnings();
        t.flags = kernel.flags();
        Ok(t)
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = (scene, kernel, options, held, progress, costs);
        unreachable!("keeps_rows() is None without MPI")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ranks_hold_every_row_once_in_whole_blocks() {
        for n in [0usize, 1, 5, 63, 64, 200, 1000] {
            let bounds = packed::matvec_bounds(n);
            for size in 1..6 {
                let runs: Vec<Range<usize>> = (0..size).map(|r| held_rows(n, r, size)).collect();
                assert_eq!(runs[0].start, 0, "n {n}, size {size}");
                assert_eq!(runs[size - 1].end, n, "n {n}, size {size}");
                for w in runs.windows(2) {
                    assert_eq!(w[0].end, w[1].start, "n {n}, size {size}: {runs:?}");
                }
                for r in runs.iter().filter(|r| !r.is_empty()) {
                    assert!(bounds.contains(&r.start) && bounds.contains(&r.end), "{r:?} cuts a block");
                }
            }
        }
    }

    #[test]
    fn the_ranks_hold_about_equal_shares_of_the_pairs() {
        let n = 1000;
        let total = (n * (n + 1) / 2) as f64;
        for size in [2, 3, 4] {
            for r in 0..size {
                let rows = held_rows(n, r, size);
                let pairs: usize = rows.map(|i| n - i).sum();
                let share = pairs as f64 / total;
                assert!((share * size as f64 - 1.0).abs() < 0.1, "size {size}, rank {r}: {share}");
            }
        }
    }
}
