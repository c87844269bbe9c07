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
use super::super::engine::{RawEntry, Row};
use super::super::MethodSet;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Per-receiver sums.
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

type IdMap<V> = HashMap<u32, V, BuildHasherDefault<IdHasher>>;

/// Sums for one row, keyed by receiver patch.
#[derive(Debug)]
pub(crate) struct Tally<'a> {
    acc: IdMap<Acc>,
    /// Output cell of each receiver patch, and the per-cell replicate sums.
    cell_of: &'a [u32],
    cells: IdMap<Acc>,
    /// Receivers touched in the current replicate.
    touched: Vec<u32>,
    reps: u32,
    single_w2: bool,
}

impl<'a> Tally<'a> {
    /// A tally for `reps` replicates; `cell_of` maps receiver patches to output cells.
    pub fn new(reps: u32, cell_of: &'a [u32]) -> Self {
        Self {
            acc: IdMap::default(),
            cell_of,
            cells: IdMap::default(),
            touched: Vec::new(),
            reps,
            single_w2: reps == 1,
        }
    }

    /// Adds weight `w` to receiver `j` in the current replicate.
    #[inline]
    pub fn add(&mut self, j: u32, w: f64) {
        if w <= 0.0 {
            return;
        }
        let a = self.acc.entry(j).or_default();
        if a.w == 0.0 {
            self.touched.push(j);
        }
        a.w += w;
        a.w2 += w * w;
    }

    /// Closes a replicate of `n` samples whose estimates scale by `scale` (the row's A_i).
    pub fn end_replicate(&mut self, n: u32, scale: f64) {
        for &j in &self.touched {
            let a = self.acc.get_mut(&j).expect("touched receivers are present");
            let e = scale * a.w / n.max(1) as f64;
            a.est += e;
            a.est2 += e * e;
            if !self.single_w2 {
                self.cells.entry(self.cell_of[j as usize]).or_default().w += a.w;
                a.w2 = 0.0;
            }
            a.w = 0.0;
        }
        self.touched.clear();
        for c in self.cells.values_mut() {
            let e = scale * c.w / n.max(1) as f64;
            c.est += e;
            c.est2 += e * e;
            c.w = 0.0;
        }
    }

    /// Writes the entries (sorted by receiver) into `out`. `n` is the row's total sample count.
    pub fn finish(self, method: MethodSet, n: u32, scale: f64, out: &mut Row) {
        let reps = self.reps as f64;
        let nf = n.max(1) as f64;
        // Replicate variance of the mean of R estimates with sums Σe and Σe².
        let spread = |a: &Acc| {
            let mean = a.est / reps;
            (mean, ((a.est2 - reps * mean * mean) / (reps * (reps - 1.0))).max(0.0))
        };
        let cells = &self.cells;
        let cell_of = self.cell_of;
        let mut entries: Vec<RawEntry> = self
            .acc
            .into_iter()
            .filter(|(_, a)| a.est > 0.0)
            .map(|(j, a)| {
                let (s, var) = if self.single_w2 {
                    let mean = a.est;
                    let m2 = scale * scale * a.w2 / nf;
                    (mean, ((m2 - mean * mean) / nf).max(0.0))
                } else {
                    let (s, _) = spread(&a);
                    let (cell_s, cell_var) = spread(&cells[&cell_of[j as usize]]);
                    (s, cell_var * s / cell_s)
                };
                RawEntry { j, method, s, var }
            })
            .collect();
        entries.sort_unstable_by_key(|e| e.j);
        out.entries = entries;
        out.shared_samples = if self.single_w2 { n } else { 0 };
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
        let mut t = Tally::new(1, &cells);
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
        let mut t = Tally::new(4, &cells);
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
        let mut t = Tally::new(3, &cells);
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
}
