//! Receiver tallies for one patch row: weights summed per receiver, per replicate, turned into
//! exchange areas s_ij = A_i·F_ij with a variance.
//!
//! - one replicate (random sampling): s = A·Σw/N, Var = A²(Σw²/N − (Σw/N)²)/N; for 0/1 weights
//!   this is the binomial A²F(1−F)/N;
//! - R replicates (randomised QMC): s = mean of the replicate estimates, Var = their sample
//!   variance / R. Replicate estimates of different receivers are correlated (they share the
//!   rays), so the variance of an output cell (a surface J at surface level) is computed from
//!   the replicate spread of the whole cell, Σ_{j∈J} s_j per replicate, and then attributed to
//!   the cell's entries in proportion to s_ij: the sink's sum of entry variances is then the
//!   cell's variance. At patch level every cell is one entry.
//!
//! Storage: a `TallyPool` hands out per-thread buffers. A flat table per receiver patch
//! (its slot and output cell, 8 bytes, so one cache miss per new receiver) points into a dense list of the receivers this row hit;
//! likewise for output cells. Closing a replicate or a row costs only the receivers actually
//! hit, and buffers go back to the pool with every slot cleared.
use super::super::engine::{RawEntry, Row};
use super::super::MethodSet;
use std::hash::Hasher;
use std::sync::Mutex;

/// Slot-table value of a receiver (or cell) not yet hit in this row.
const EMPTY: u32 = u32::MAX;

/// Per-receiver (or per-cell) sums.
#[derive(Debug, Clone, Copy, Default)]
struct Acc {
    /// Σw in the current replicate.
    w: f64,
    /// Σw² in the current replicate (single-replicate variance).
    w2: f64,
    /// Σ of replicate estimates.
    est: f64,
    /// Σ of squared replicate estimates.
    est2: f64,
}

/// Buffers of one tally; between rows every slot is [`EMPTY`] and every list empty.
#[derive(Debug, Default)]
struct Buffers {
    /// Per receiver patch: [index into `acc` or [`EMPTY`], output cell].
    slot: Vec<[u32; 2]>,
    /// Sums of the receivers hit in this row, in first-hit order.
    acc: Vec<Acc>,
    /// Receiver patch and output-cell slot of each `acc` entry.
    recv: Vec<(u32, u32)>,
    /// `acc` entries touched in the current replicate, in first-hit order.
    touched: Vec<u32>,
    /// Per output cell: index into `cells`, or [`EMPTY`].
    cell_slot: Vec<u32>,
    /// Sums of the cells hit in this row, and their cell ids.
    cells: Vec<Acc>,
    cell_ids: Vec<u32>,
    /// Scratch: (receiver << 32 | `acc` index), sorted by receiver.
    order: Vec<u64>,
}

/// Reusable tally buffers shared by the rows of one run (one set per concurrent row).
#[derive(Debug)]
pub(crate) struct TallyPool<'a> {
    /// Output cell of each receiver patch.
    cell_of: &'a [u32],
    n_cells: usize,
    free: Mutex<Vec<Buffers>>,
}

impl<'a> TallyPool<'a> {
    /// A pool for receivers `0..cell_of.len()` mapped to output cells by `cell_of`.
    pub fn new(cell_of: &'a [u32]) -> Self {
        let n_cells = cell_of.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
        Self { cell_of, n_cells, free: Mutex::new(Vec::new()) }
    }

    /// An empty tally for `reps` replicates.
    pub fn tally(&self, reps: u32) -> Tally<'_> {
        let buf = self.lock().pop().unwrap_or_else(|| Buffers {
            slot: self.cell_of.iter().map(|&c| [EMPTY, c]).collect(),
            cell_slot: vec![EMPTY; self.n_cells],
            ..Buffers::default()
        });
        Tally { pool: self, buf, reps, single_w2: reps == 1 }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<Buffers>> {
        // The guarded Vec is only pushed and popped: a poisoned lock still holds clean buffers.
        self.free.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Sums for one row, indexed by receiver patch.
#[derive(Debug)]
pub(crate) struct Tally<'p> {
    pool: &'p TallyPool<'p>,
    buf: Buffers,
    reps: u32,
    single_w2: bool,
}

impl Tally<'_> {
    /// Adds weight `w` to receiver `j` in the current replicate.
    #[inline]
    pub fn add(&mut self, j: u32, w: f64) {
        if w <= 0.0 {
            return;
        }
        let [mut k, cell] = self.buf.slot[j as usize];
        if k == EMPTY {
            // Cells matter only for replicate spreads.
            let c = if self.single_w2 { EMPTY } else { self.cell_slot(cell) };
            let b = &mut self.buf;
            k = b.acc.len() as u32;
            b.slot[j as usize][0] = k;
            b.acc.push(Acc::default());
            b.recv.push((j, c));
        }
        let b = &mut self.buf;
        let a = &mut b.acc[k as usize];
        if a.w == 0.0 {
            b.touched.push(k);
        }
        a.w += w;
        a.w2 += w * w;
    }

    /// Slot of output cell `c`, created on first use.
    fn cell_slot(&mut self, c: u32) -> u32 {
        let b = &mut self.buf;
        let c = c as usize;
        if b.cell_slot[c] == EMPTY {
            b.cell_slot[c] = b.cells.len() as u32;
            b.cells.push(Acc::default());
            b.cell_ids.push(c as u32);
        }
        b.cell_slot[c]
    }

    /// Closes a replicate of `n` samples whose estimates scale by `scale` (the row's A_i).
    pub fn end_replicate(&mut self, n: u32, scale: f64) {
        let Buffers { acc, recv, cells, touched, .. } = &mut self.buf;
        for &k in touched.iter() {
            let a = &mut acc[k as usize];
            let e = scale * a.w / n.max(1) as f64;
            a.est += e;
            a.est2 += e * e;
            if !self.single_w2 {
                cells[recv[k as usize].1 as usize].w += a.w;
                a.w2 = 0.0;
            }
            a.w = 0.0;
        }
        touched.clear();
        if !self.single_w2 {
            for c in cells.iter_mut() {
                let e = scale * c.w / n.max(1) as f64;
                c.est += e;
                c.est2 += e * e;
                c.w = 0.0;
            }
        }
    }

    /// Writes the entries (sorted by receiver) into `out`. `n` is the row's total sample count.
    pub fn finish(mut self, method: MethodSet, n: u32, scale: f64, out: &mut Row) {
        let reps = self.reps as f64;
        let nf = n.max(1) as f64;
        // Replicate variance of the mean of R estimates with sums Σe and Σe².
        let spread = |a: &Acc| {
            let mean = a.est / reps;
            (mean, ((a.est2 - reps * mean * mean) / (reps * (reps - 1.0))).max(0.0))
        };
        let Buffers { slot, acc, recv, touched, cell_slot, cells, cell_ids, order } = &mut self.buf;
        order.clear();
        order.extend(recv.iter().enumerate().map(|(k, &(j, _))| (j as u64) << 32 | k as u64));
        order.sort_unstable();
        out.entries.clear();
        out.entries.extend(order.iter().map(|&o| o as u32).filter(|&k| acc[k as usize].est > 0.0).map(|k| {
            let a = &acc[k as usize];
            let (j, c) = recv[k as usize];
            let (s, var) = if self.single_w2 {
                let mean = a.est;
                let m2 = scale * scale * a.w2 / nf;
                (mean, ((m2 - mean * mean) / nf).max(0.0))
            } else {
                let (s, _) = spread(a);
                let (cell_s, cell_var) = spread(&cells[c as usize]);
                (s, cell_var * s / cell_s)
            };
            RawEntry { j, method, s, var }
        }));
        out.shared_samples = if self.single_w2 { n } else { 0 };
        // Clear what this row touched and hand the buffers back.
        for &(j, _) in recv.iter() {
            slot[j as usize][0] = EMPTY;
        }
        for &c in cell_ids.iter() {
            cell_slot[c as usize] = EMPTY;
        }
        recv.clear();
        acc.clear();
        touched.clear();
        cells.clear();
        cell_ids.clear();
        let buf = std::mem::take(&mut self.buf);
        self.pool.lock().push(buf);
    }
}

/// Hasher for small integer keys (patch ids): one multiply, no DoS concern here.
#[derive(Default)]
pub(crate) struct IdHasher(u64);

impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u32(&mut self, x: u32) {
        self.0 = (x as u64 ^ self.0).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_replicate_gives_the_binomial_variance() {
        // 30 hits on receiver 4 out of 100 samples, area 2: s = 0.6, Var = 4·0.3·0.7/100.
        let cells: Vec<u32> = (0..8).collect();
        let pool = TallyPool::new(&cells);
        let mut t = pool.tally(1);
        for _ in 0..30 {
            t.add(4, 1.0);
        }
        t.end_replicate(100, 2.0);
        let mut row = Row::default();
        t.finish(MethodSet::MC_COSINE, 100, 2.0, &mut row);
        assert_eq!(row.shared_samples, 100);
        let e = row.entries[0];
        assert!((e.s - 0.6).abs() < 1e-15 && (e.var - 4.0 * 0.3 * 0.7 / 100.0).abs() < 1e-15, "{e:?}");
    }

    #[test]
    fn replicates_give_the_spread_of_their_estimates() {
        // Replicate estimates 1·(k/10) for k = 1..4 hits out of 10: mean 0.25.
        let cells: Vec<u32> = (0..8).collect();
        let pool = TallyPool::new(&cells);
        let mut t = pool.tally(4);
        for k in 1..=4 {
            for _ in 0..k {
                t.add(1, 1.0);
            }
            t.end_replicate(10, 1.0);
        }
        let mut row = Row::default();
        t.finish(MethodSet::MC_COSINE, 40, 1.0, &mut row);
        let est = [0.1, 0.2, 0.3, 0.4];
        let var = est.iter().map(|e: &f64| (e - 0.25).powi(2)).sum::<f64>() / 3.0 / 4.0;
        let e = row.entries[0];
        assert_eq!(row.shared_samples, 0);
        assert!((e.s - 0.25).abs() < 1e-15 && (e.var - var).abs() < 1e-15, "{e:?} vs {var}");
    }

    #[test]
    fn a_cell_that_catches_every_sample_has_no_variance() {
        // Receivers 1 and 2 form one cell; each replicate splits its 10 samples differently.
        let cells = [0, 5, 5];
        let pool = TallyPool::new(&cells);
        let mut t = pool.tally(3);
        for k in 1..=3 {
            for s in 0..10 {
                t.add(if s < k { 1 } else { 2 }, 1.0);
            }
            t.end_replicate(10, 1.0);
        }
        let mut row = Row::default();
        t.finish(MethodSet::MC_COSINE, 30, 1.0, &mut row);
        let (s, var): (f64, f64) = row.entries.iter().fold((0.0, 0.0), |a, e| (a.0 + e.s, a.1 + e.var));
        assert!((s - 1.0).abs() < 1e-15 && var < 1e-30, "cell sum {s}, variance {var}");
    }

    #[test]
    fn pooled_buffers_come_back_clean() {
        // The same two rows through one pool (buffers reused) and through fresh pools.
        let cells = [0, 1, 1, 2];
        let run = |pool: &TallyPool, shift: u32| {
            let mut t = pool.tally(2);
            for r in 0..2 {
                for s in 0..7 {
                    t.add((s + r + shift) % 4, 0.5 + s as f64);
                }
                t.end_replicate(7, 3.0);
            }
            let mut row = Row::default();
            t.finish(MethodSet::MC_UNIFORM, 14, 3.0, &mut row);
            row
        };
        let shared = TallyPool::new(&cells);
        let (a1, a2) = (run(&shared, 0), run(&shared, 1));
        let (b1, b2) = (run(&TallyPool::new(&cells), 0), run(&TallyPool::new(&cells), 1));
        assert_eq!(a1, b1);
        assert_eq!(a2, b2);
        assert_ne!(a1, a2);
    }
}
