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
//! (`super::distributed::rows`).
//!
//! The split is estimated, then measured (as on the gathered route): a probe wave (every
//! [`partition::PROBE_STRIDE`]-th row, dealt round-robin, each row timed in thread CPU
//! seconds), an all-gather of the timings, then the mat-vec's blocks split into contiguous
//! runs by the measured cost of their other rows ([`partition::grouped`]). The probe rows are
//! sent to the ranks that hold them (one all-to-all of their packed slices, 8 bytes per
//! pair: far cheaper than computing them again). The memory check of each rank's final share
//! (its rows plus the probe rows it sends and receives) runs after the split, before the
//! block is allocated. `LAMBERT_MPI_BALANCE=estimated` keeps the estimated split (equal pair
//! counts per rank, [`held_rows`]) and no probe.
#[cfg_attr(not(feature = "mpi"), allow(unused_imports))]
use super::packed::{self, PackedTriangular};
use super::progress;
use super::row::RowKernel;
use crate::distributed::partition;
use crate::scene::Scene;
use crate::Result;
use std::ops::Range;

/// Rows of `n` that rank `rank` of `size` holds under the estimated split: a contiguous run
/// of the mat-vec's row blocks, the runs balanced by their pair counts (some ranks hold none
/// when blocks are fewer than ranks).
pub fn held_rows(n: usize, rank: usize, size: usize) -> Range<usize> {
    estimated_split(n, size)[rank.min(size.max(1) - 1)].clone()
}

/// Every rank's rows under the estimated split ([`held_rows`]).
pub fn estimated_split(n: usize, size: usize) -> Vec<Range<usize>> {
    let bounds = packed::matvec_bounds(n);
    let pairs: Vec<f64> = bounds.windows(2).map(|b| (b[0]..b[1]).map(|i| (n - i) as f64).sum()).collect();
    partition::balanced(&pairs, size).iter().map(|run| bounds[run.start]..bounds[run.end]).collect()
}

/// Every rank's rows split by measured cost: the mat-vec's blocks in contiguous runs
/// balanced by each row's pairs times the measured seconds per pair of the probes around it
/// (`probes`: row, seconds, sorted by row), probe rows not counted (they are computed
/// already). The same on every rank that gathered the same probes.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub fn measured_split(n: usize, size: usize, probes: &[(usize, f64)]) -> Vec<Range<usize>> {
    let bounds = packed::matvec_bounds(n);
    let blocks: Vec<Range<usize>> = bounds.windows(2).map(|b| b[0]..b[1]).collect();
    let est: Vec<f64> = (0..n).map(|i| (n - i) as f64).collect();
    partition::grouped(&est, probes, &blocks, size, true)
        .iter()
        .map(|run| bounds[run.start]..bounds[run.end])
        .collect()
}

/// Every rank's share of the distributed store, for the memory check: its rows, and the
/// bytes it holds in passing (probe rows it sends and receives, 8 per pair).
#[derive(Debug, Clone, PartialEq)]
pub struct RowSplit {
    /// Rows of each rank.
    pub held: Vec<Range<usize>>,
    /// Bytes of probe rows each rank sends plus those it receives.
    pub transit: Vec<u64>,
}

impl RowSplit {
    /// The estimated split of `n` rows among `size` ranks (nothing in passing).
    pub fn estimated(n: usize, size: usize) -> RowSplit {
        RowSplit { held: estimated_split(n, size), transit: vec![0; size] }
    }

    /// The split `held` after a probe wave: each rank sends its probe rows held elsewhere and
    /// receives the probe rows it holds that another rank computed.
    pub fn probed(n: usize, held: Vec<Range<usize>>) -> RowSplit {
        let size = held.len();
        let mut transit = vec![0u64; size];
        for r in 0..size {
            for i in partition::probe_rows(n, size, r) {
                if !held[r].contains(&i) {
                    let bytes = 8 * (n - i) as u64;
                    transit[r] += bytes;
                    if let Some(owner) = held.iter().position(|h| h.contains(&i)) {
                        transit[owner] += bytes;
                    }
                }
            }
        }
        RowSplit { held, transit }
    }
}

/// A memory check of every rank's final share (a collective; the same error on every rank).
pub type CheckShare<'a> = &'a dyn Fn(&RowSplit) -> Result<()>;

/// Under MPI with several ranks and a symmetric kernel: this rank's rows under the estimated
/// split (for the early memory check); `None` otherwise (one process computes every row).
pub fn keeps_rows(n: usize, symmetric: bool) -> Option<Range<usize>> {
    if !symmetric || !crate::distributed::reduce::active() {
        return None;
    }
    let (rank, size) = crate::distributed::rank_size();
    Some(held_rows(n, rank, size))
}

/// Fills this rank's row block of the patch-level triangle of `scene` with `kernel` (a
/// symmetric kernel, every rank calling), after the ranks agree on the geometry, trees,
/// method and `options` (a mismatch ends the run with exit code 2). The split is measured
/// (module docs) unless [`partition::BALANCE_VAR`] asks for the estimated one; `check`
/// refuses a final share that does not fit before the block is allocated.
pub fn fill(
    scene: &Scene,
    kernel: &dyn RowKernel,
    options: &str,
    mode: progress::Mode,
    costs: &[u64],
    check: CheckShare,
) -> Result<PackedTriangular> {
    #[cfg(feature = "mpi")]
    {
        mpi_fill(scene, kernel, options, mode, costs, check)
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = (scene, kernel, options, mode, costs, check);
        unreachable!("keeps_rows() is None without MPI")
    }
}

/// CPU seconds of the whole process (every thread), user and system.
#[cfg(feature = "mpi")]
fn process_cpu_seconds() -> f64 {
    let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes one rusage that we own.
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, u.as_mut_ptr()) } != 0 {
        return 0.0;
    }
    // SAFETY: zeroed, then written by a successful getrusage.
    let u = unsafe { u.assume_init() };
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

/// Probe rows computed on this rank: (row, its packed slice, its metadata, thread CPU s).
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
type Probed = Vec<(usize, Vec<f64>, packed::RowOut, f64)>;

/// Computes `rows` (a symmetric kernel) in parallel, each into its own slice, timed; the
/// earliest failure is returned beside the rows that succeeded.
#[cfg(feature = "mpi")]
fn probe(kernel: &dyn RowKernel, n: usize, rows: &[usize]) -> (Probed, Option<(usize, crate::Error)>) {
    use rayon::prelude::*;
    let outs: Vec<(usize, Vec<f64>, Result<packed::RowOut>, f64)> = rows
        .par_iter()
        .with_max_len(1)
        .map(|&i| {
            let start = super::distributed::thread_cpu_seconds();
            let mut slot = vec![0.0; n - i];
            let out = packed::fill_row(kernel, n, i, &mut slot);
            (i, slot, out, super::distributed::thread_cpu_seconds() - start)
        })
        .collect();
    let mut ok = Vec::with_capacity(outs.len());
    let mut failure = None;
    for (i, slot, out, t) in outs {
        match out {
            Ok(o) => ok.push((i, slot, o, t)),
            Err(e) if failure.is_none() => failure = Some((i, e)),
            Err(_) => {}
        }
    }
    (ok, failure)
}

/// Probe rows on the wire: row, slice, metadata (bit-exact).
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
fn encode_probed(rows: &[&(usize, Vec<f64>, packed::RowOut, f64)]) -> Vec<u8> {
    use super::distributed::{put_f64, put_u32, put_u64, put_u8};
    let mut b = Vec::new();
    for (i, slot, (def, ex, sum, var, methods, pairs), _) in rows {
        put_u64(&mut b, *i as u64);
        put_u8(&mut b, def.bits());
        put_u64(&mut b, ex.len() as u64);
        for e in ex {
            put_u32(&mut b, e.j);
            put_u8(&mut b, e.method.bits());
            put_f64(&mut b, e.var);
        }
        put_f64(&mut b, *sum);
        put_f64(&mut b, *var);
        put_u8(&mut b, methods.bits());
        put_u64(&mut b, *pairs);
        slot.iter().for_each(|&v| put_f64(&mut b, v));
    }
    b
}

/// Writes the probe rows of [`encode_probed`]'s bytes into `t` (rows it holds); false when
/// the bytes are damaged or name a row not held here.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
fn place_probed(t: &mut PackedTriangular, bytes: &[u8]) -> bool {
    use super::distributed::Reader;
    use super::MethodSet;
    fn one(r: &mut Reader<'_>, t: &mut PackedTriangular) -> Option<()> {
        let i = usize::try_from(r.u64()?).ok().filter(|i| t.held.contains(i))?;
        let def = MethodSet(r.u8()?);
        let count = usize::try_from(r.u64()?).ok()?;
        let mut ex = Vec::with_capacity(count.min(t.n));
        for _ in 0..count {
            ex.push(packed::Exception { j: r.u32()?, method: MethodSet(r.u8()?), var: r.f64()? });
        }
        let (sum, var, methods, pairs) = (r.f64()?, r.f64()?, MethodSet(r.u8()?), r.u64()?);
        for v in t.row_mut(i) {
            *v = r.f64()?;
        }
        packed::set_row_meta(t, i, (def, ex, sum, var, methods, pairs));
        Some(())
    }
    let mut r = Reader(bytes);
    while !r.0.is_empty() {
        if one(&mut r, t).is_none() {
            return false;
        }
    }
    true
}

#[cfg(feature = "mpi")]
fn mpi_fill(
    scene: &Scene,
    kernel: &dyn RowKernel,
    options: &str,
    mode: progress::Mode,
    costs: &[u64],
    check: CheckShare,
) -> Result<PackedTriangular> {
    use super::distributed::{agreement_hash, decode, encode, put_f64, put_u64, Reader, Share};
    use crate::distributed::{comm, reduce};
    let hash = agreement_hash(scene, options, kernel.symmetric(), kernel.tree_hash());
    comm::check_rows(hash, "scene geometry, acceleration trees, method and options");
    let n = scene.patches.len();
    let (rank, size) = comm::rank_size();
    let measured = partition::measured();
    let (wall, cpu) = (std::time::Instant::now(), process_cpu_seconds());
    // Estimated first: the probe wave, timed row by row, its timings shared.
    let (probed, mut failure) =
        if measured { probe(kernel, n, &partition::probe_rows(n, size, rank)) } else { (Vec::new(), None) };
    let probe_seconds = wall.elapsed().as_secs_f64();
    let split = if measured {
        let mut b = Vec::with_capacity(16 * probed.len());
        for (i, _, _, t) in &probed {
            put_u64(&mut b, *i as u64);
            put_f64(&mut b, *t);
        }
        let mut probes: Vec<(usize, f64)> = Vec::new();
        for bytes in reduce::all_gather_bytes(&b) {
            let mut r = Reader(&bytes);
            while let (Some(i), Some(t)) = (r.u64(), r.f64()) {
                probes.push((i as usize, t));
            }
        }
        probes.sort_by_key(|p| p.0);
        // Then measured: the blocks split by the measured cost of their other rows.
        RowSplit::probed(n, measured_split(n, size, &probes))
    } else {
        RowSplit::estimated(n, size)
    };
    check(&split)?;
    let held = split.held[rank].clone();
    let areas = scene.patches.iter().map(|p| p.polygon.area()).collect();
    let mut t = PackedTriangular::zeros_rows(n, areas, held.clone())?;
    t.distributed = true;
    // The probe rows to the ranks that hold them (this rank's own straight into its block).
    let bytes_before = reduce::bytes_sent();
    let exchange_start = std::time::Instant::now();
    let mut to: Vec<Vec<u8>> = vec![Vec::new(); size];
    let mut own = Vec::new();
    for (d, h) in split.held.iter().enumerate() {
        let rows: Vec<_> = probed.iter().filter(|p| h.contains(&p.0)).collect();
        if d == rank {
            own = encode_probed(&rows);
        } else {
            to[d] = encode_probed(&rows);
        }
    }
    drop(probed);
    let mut got = reduce::all_to_all_bytes(to);
    got[rank] = own;
    for (r, bytes) in got.iter().enumerate() {
        if !place_probed(&mut t, bytes) {
            return Err(crate::Error::Compute(format!("the probe rows from MPI rank {r} arrived damaged")));
        }
    }
    drop(got);
    let exchange = (exchange_start.elapsed().as_secs_f64(), reduce::bytes_sent() - bytes_before);
    // The other held rows, computed here.
    let is_probe = |i: usize| measured && i.is_multiple_of(partition::PROBE_STRIDE);
    let pairs = held.clone().filter(|&i| !is_probe(i)).map(|i| (n - i) as u64).sum();
    let cost = held.clone().filter(|&i| !is_probe(i)).map(|i| costs.get(i).copied().unwrap_or(0)).sum();
    let progress = progress::Progress::start_costed(pairs, "pairs", mode, cost);
    let late = packed::fill_held(&mut t, kernel, &progress, costs, &is_probe);
    progress.finish();
    if late.as_ref().is_some_and(|l| failure.as_ref().is_none_or(|f| l.0 < f.0)) {
        failure = late;
    }
    let seconds = wall.elapsed().as_secs_f64();
    let cpu = process_cpu_seconds() - cpu;
    // Every rank learns every failure, flag and miss (a failure ends the run everywhere).
    let share = Share {
        first: held.start,
        rows: Vec::new(),
        failure,
        flags: kernel.flags(),
        misses: kernel.misses(),
        seconds,
    };
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
    report_split(measured, seconds, cpu, probe_seconds, exchange);
    // The diagonal of every row, in rank (so row) order.
    let mine: Vec<u8> = held.clone().flat_map(|i| t.row(i)[0].to_bits().to_le_bytes()).collect();
    t.diag = reduce::all_gather_bytes(&mine)
        .iter()
        .flat_map(|b| b.chunks_exact(8).map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().expect("8")))))
        .collect();
    packed::mirror(&mut t);
    t.warnings = kernel.warnings();
    t.flags = kernel.flags();
    Ok(t)
}

/// Under [`crate::distributed::STATS_VAR`]: rank 0 prints each rank's view-factor wall and
/// CPU seconds, its probe wave and probe-row exchange, and the CPU max/mean (a collective).
#[cfg(feature = "mpi")]
fn report_split(measured: bool, seconds: f64, cpu: f64, probe: f64, exchange: (f64, u64)) {
    use crate::distributed::reduce;
    if std::env::var_os(crate::distributed::STATS_VAR).is_none() {
        return;
    }
    let mine: Vec<u8> = [seconds, cpu, probe, exchange.0, exchange.1 as f64]
        .iter()
        .flat_map(|v| v.to_bits().to_le_bytes())
        .collect();
    let all: Vec<Vec<f64>> = reduce::all_gather_bytes(&mine)
        .iter()
        .map(|b| {
            b.chunks_exact(8).map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().expect("8")))).collect()
        })
        .collect();
    if !crate::distributed::writes_outputs() {
        return;
    }
    for (r, v) in all.iter().enumerate() {
        eprintln!(
            "lambert: mpi: dense view factors, rank {r}: {:.3} s wall, {:.3} CPU s ({:.3} s probing, probe rows \
             exchanged in {:.3} s, {:.0} bytes sent)",
            v[0], v[1], v[2], v[3], v[4]
        );
    }
    let cpus: Vec<f64> = all.iter().map(|v| v[1]).collect();
    let mean = cpus.iter().sum::<f64>() / cpus.len() as f64;
    let max = cpus.iter().copied().fold(0.0, f64::max);
    let split = if measured { "measured" } else { "estimated" };
    eprintln!(
        "lambert: mpi: dense {split} split, view-factor CPU seconds max/mean {:.2}",
        max / mean.max(1e-12)
    );
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
    fn the_measured_split_keeps_whole_blocks_and_moves_rows_off_the_dear_ranks() {
        let n = 1000;
        let bounds = packed::matvec_bounds(n);
        // Rows 500.. cost 20 times as much per pair as rows ..500 (shadowed patches).
        let rate = |i: usize| if i >= 500 { 20e-6 } else { 1e-6 };
        let probes: Vec<(usize, f64)> =
            (0..n).step_by(partition::PROBE_STRIDE).map(|i| (i, rate(i) * (n - i) as f64)).collect();
        for size in [2, 3, 4] {
            let m = measured_split(n, size, &probes);
            let e = estimated_split(n, size);
            assert_eq!((m[0].start, m[size - 1].end), (0, n), "{m:?}");
            assert!(m.windows(2).all(|w| w[0].end == w[1].start), "{m:?}");
            assert!(m.iter().all(|r| bounds.contains(&r.start) && bounds.contains(&r.end)), "{m:?}");
            // The last rank holds the dear rows: fewer of them than the pair count gives it.
            assert!(m[size - 1].len() < e[size - 1].len(), "size {size}: {m:?} against {e:?}");
            let cost = |r: &Range<usize>| -> f64 {
                r.clone().filter(|i| i % partition::PROBE_STRIDE != 0).map(|i| rate(i) * (n - i) as f64).sum()
            };
            let costs: Vec<f64> = m.iter().map(cost).collect();
            let mean = costs.iter().sum::<f64>() / size as f64;
            let max = costs.iter().copied().fold(0.0, f64::max);
            assert!(max / mean < 1.1, "size {size}: measured costs {costs:?}");
        }
        // Without probes the estimate decides (probe rows not counted: about the same split).
        let m = measured_split(n, 2, &[]);
        assert!(m[0].end.abs_diff(estimated_split(n, 2)[0].end) <= 40, "{m:?}");
    }

    #[test]
    fn probe_rows_survive_the_wire_and_damaged_bytes_are_refused() {
        use super::super::MethodSet;
        let n = 6;
        let ex = vec![packed::Exception { j: 3, method: MethodSet::SHADOWED, var: 2.5e-9 }];
        let a = (
            2,
            vec![0.0, 0.25, -1e-300, 0.5],
            (MethodSet::ANALYTIC, ex, 0.75, 2.5e-9, MethodSet::ANALYTIC, 4),
            0.1,
        );
        let b =
            (4, vec![0.0, 0.125], (MethodSet::ANALYTIC, Vec::new(), 0.125, 0.0, MethodSet::ANALYTIC, 2), 0.2);
        let bytes = encode_probed(&[&a, &b]);
        let mut t = PackedTriangular::zeros_rows(n, vec![1.0; n], 2..6).unwrap();
        assert!(place_probed(&mut t, &bytes));
        assert_eq!((t.row(2), t.row(4)), (&a.1[..], &b.1[..]));
        assert_eq!(
            (t.exceptions[2].clone(), t.raw_row_sums[2], t.raw_row_vars[2]),
            (a.2 .1.clone(), 0.75, 2.5e-9)
        );
        assert_eq!((t.row_method[4], t.raw_row_sums[4], t.pairs), (MethodSet::ANALYTIC, 0.125, 6));
        for cut in [1, 9, bytes.len() - 1] {
            let mut t = PackedTriangular::zeros_rows(n, vec![1.0; n], 2..6).unwrap();
            assert!(!place_probed(&mut t, &bytes[..cut]), "bytes cut at {cut} were placed");
        }
        // A row this rank does not hold is refused, not written elsewhere.
        let mut t = PackedTriangular::zeros_rows(n, vec![1.0; n], 3..6).unwrap();
        assert!(!place_probed(&mut t, &bytes));
    }

    #[test]
    fn probe_rows_in_passing_are_counted_on_both_ends() {
        let n = 64;
        let held = vec![0..20, 20..64];
        let s = RowSplit::probed(n, held.clone());
        // Probes 0, 8, …, 56 dealt to ranks 0, 1, 0, 1, …: rank 0 computes 0, 16 (its own),
        // 32 and 48 (sent to rank 1); rank 1 computes 8 (sent to rank 0), 24, 40 and 56.
        let bytes = |rows: &[usize]| rows.iter().map(|&i| 8 * (n - i) as u64).sum::<u64>();
        let r0 = bytes(&[32, 48]) + bytes(&[8]);
        let r1 = bytes(&[8]) + bytes(&[32, 48]);
        assert_eq!(s.transit, vec![r0, r1], "{s:?}");
        assert_eq!(RowSplit::estimated(n, 2).transit, vec![0, 0]);
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
