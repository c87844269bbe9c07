//! The row engine: every method is a [`RowKernel`] that fills one patch row of exchange areas
//! s_ij = A_i F_ij; the engine runs rows in parallel waves and feeds them, in patch order, to a
//! sink. Order-fixed reduction makes results identical on any thread count.
use super::progress::{self, Progress};
use super::sink::{Level, Sink, ViewFactors};
use super::Params;
use crate::scene::Scene;
use crate::Result;
use rayon::prelude::*;
use std::time::Instant;

pub use super::row::{row_costs, RawEntry, Row, RowKernel};

/// Entries buffered per wave, bounding memory while keeping every core busy.
pub(super) const WAVE_ENTRY_BUDGET: usize = 2_000_000;

/// Runs `kernel` over every patch row and aggregates at `level`.
pub fn run(scene: &Scene, kernel: &dyn RowKernel, params: &Params, level: Level) -> Result<ViewFactors> {
    let start = Instant::now();
    // Under mpirun: every rank computes a block of rows, rank 0 folds them all (others exit).
    let gathered =
        super::shard::split_rows(scene, kernel, &format!("sparse {level:?} {}", params.agreement()))?;
    let kernel: &dyn RowKernel = match &gathered {
        Some(g) => g,
        None => kernel,
    };
    let n = scene.patches.len();
    let mut sink = Sink::new(scene, level, kernel.symmetric());
    let threads = rayon::current_num_threads().max(1);
    // Not `clamp`: beyond 1,024 threads (RAYON_NUM_THREADS) its lower bound would pass the upper.
    let wave = (WAVE_ENTRY_BUDGET / n.max(1)).max(4 * threads).min(4096);
    // Pairs per row: the kernel's half of a symmetric matrix, or the whole row.
    let symmetric = kernel.symmetric();
    let row_pairs = |i: usize| if symmetric { (n - i) as u64 } else { n as u64 };
    let total = (0..n).map(row_pairs).sum();
    let costs = row_costs(kernel, params.progress, n, row_pairs);
    let mode = progress::Mode::for_stderr(params.progress);
    let progress = Progress::start_costed(total, "pairs", mode, costs.iter().sum());
    // Pipeline: while the pool computes wave k + 1, this thread folds wave k into the sink
    // (the sink is serial; folding between waves would leave the other cores idle).
    let compute = |lo: usize, hi: usize| -> Vec<Result<Row>> {
        (lo..hi)
            .into_par_iter()
            .with_max_len(1)
            .map(|i| {
                let mut row = Row::default();
                let out = kernel.row(i, &mut row).map(|_| row);
                progress.add_costed(row_pairs(i), costs[i]);
                out
            })
            .collect()
    };
    let fold = |sink: &mut Sink, lo: usize, rows: Vec<Result<Row>>| -> Result<()> {
        for (k, row) in rows.into_iter().enumerate() {
            sink.accept(lo + k, &row?);
        }
        Ok(())
    };
    let mut pending: Option<(usize, Vec<Result<Row>>)> = None;
    let mut lo = 0;
    while lo < n {
        let hi = (lo + wave).min(n);
        let (rows, folded) = rayon::join(
            || compute(lo, hi),
            || pending.take().map_or(Ok(()), |(start, rows)| fold(&mut sink, start, rows)),
        );
        folded?;
        pending = Some((lo, rows));
        lo = hi;
    }
    if let Some((start, rows)) = pending {
        fold(&mut sink, start, rows)?;
    }
    progress.finish();
    let mut vf = sink.finish(start.elapsed());
    vf.warnings = kernel.warnings();
    vf.flags = kernel.flags();
    Ok(vf)
}
