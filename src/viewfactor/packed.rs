//! The lean dense exchange store: one packed f64 upper triangle of symmetric exchange areas
//! s̄_ij = ½(s_ij + s_ji) (diagonal included), plus per row a default method and a short
//! sorted list of exceptions (entries whose method differs from the row's, or that carry a
//! variance). About N²/2 × 8 bytes; no per-entry column index, method tag or variance where a
//! row is uniform (deterministic methods have no variance).
//!
//! - [`PackedTriangular`]: the store, packed row access and the symmetric mat-vec y = S x used by
//!   closure and the solve (fixed row blocks, [`matvec_blocks`]: identical on any thread count);
//!   under MPI on the `solve` route each rank holds a contiguous run of those blocks
//!   ([`PackedTriangular::held`], filled by `super::row_block`) and the blocks' partial
//!   products are added in block order across the ranks, so the sums are those of one process;
//! - [`fill`]: runs a [`RowKernel`] straight into the triangle. Symmetric kernels (j > i only)
//!   write their row into its own packed slice in parallel; the others are computed in
//!   bounded waves and folded serially, each cell receiving s_ij then s_ji.
use super::engine::{RawEntry, Row, RowKernel, WAVE_ENTRY_BUDGET};
use super::progress::Progress;
use super::MethodSet;
use crate::scene::Scene;
use crate::{Error, Result};
use rayon::prelude::*;
use std::ops::Range;

/// One entry of a row that is not described by the row's default method alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exception {
    /// Column j ≥ i.
    pub j: u32,
    /// Method(s) behind s̄_ij.
    pub method: MethodSet,
    /// Variance of s̄_ij, m⁴.
    pub var: f64,
}

/// Packed symmetric exchange areas at patch (or surface) level.
#[derive(Debug, Clone, PartialEq)]
pub struct PackedTriangular {
    /// Order.
    pub n: usize,
    /// Row i holds s̄_ij for j = i..n, rows concatenated; length n(n+1)/2.
    pub s: Vec<f64>,
    /// Method of every positive entry of row i (upper part) not listed in `exceptions[i]`.
    pub row_method: Vec<MethodSet>,
    /// Per row, sorted by column: entries with another method or a variance.
    pub exceptions: Vec<Vec<Exception>>,
    /// Node areas A_i, m².
    pub areas: Vec<f64>,
    /// Per node: Σ_j s_ij of the raw row before any averaging, m².
    pub raw_row_sums: Vec<f64>,
    /// Per node: Σ_j var(s_ij) of the raw row, m⁴.
    pub raw_row_vars: Vec<f64>,
    /// Per node: union of the methods of the raw row.
    pub raw_row_methods: Vec<MethodSet>,
    /// max |s_ij − s_ji| over the raw pairs (0 for symmetric kernels), m².
    pub raw_asymmetry: f64,
    /// Patch pairs evaluated.
    pub pairs: u64,
    /// What the method reported about its own accuracy (entries above their error goal).
    pub warnings: Vec<String>,
    /// Patch pairs whose entry the method could not bound (reported on stderr).
    pub flags: Vec<super::Flag>,
    /// Rows held in `s`: every row in one process; under MPI on the `solve` route, this rank's
    /// row block (`row_method` and `exceptions` are set on these rows only).
    pub held: Range<usize>,
    /// True when other MPI ranks hold the other rows: the sums over the store are collectives.
    pub distributed: bool,
    /// s̄_ii of every node when `distributed` (kept in step with `s`), else empty.
    pub diag: Vec<f64>,
}

/// Fewest row blocks of the symmetric mat-vec: a count fixed by n alone, so sums never depend
/// on threads or ranks.
pub const MATVEC_BLOCKS: usize = 64;
/// Patches per row block above [`MATVEC_BLOCKS`] blocks: beyond 131,072 patches more than 64
/// ranks can each hold a block (the single-process sums there change order, nothing below).
const PATCHES_PER_BLOCK: usize = 2048;
/// Most row blocks (1M patches: 488).
const MAX_MATVEC_BLOCKS: usize = 4096;

/// Row blocks of the mat-vec of order `n` (a function of `n` alone).
pub fn matvec_blocks(n: usize) -> usize {
    (n / PATCHES_PER_BLOCK).clamp(MATVEC_BLOCKS, MAX_MATVEC_BLOCKS)
}

/// Row bounds of the mat-vec's blocks for order `n`: blocks of about equal area.
pub fn matvec_bounds(n: usize) -> Vec<usize> {
    block_bounds(n, matvec_blocks(n))
}

impl PackedTriangular {
    /// An all-zero triangle of order `n`, refusing sizes whose length overflows.
    pub fn zeros(n: usize, areas: Vec<f64>) -> Result<Self> {
        Self::zeros_rows(n, areas, 0..n)
    }

    /// An all-zero block `held` of the rows of a triangle of order `n`.
    pub fn zeros_rows(n: usize, areas: Vec<f64>, held: Range<usize>) -> Result<Self> {
        let overflow = || Error::Compute(format!("{n} nodes overflow the packed store"));
        packed_len(n).ok_or_else(overflow)?;
        let len = row_offset(n, held.end) - row_offset(n, held.start);
        Ok(Self {
            n,
            s: vec![0.0; len],
            row_method: vec![MethodSet::default(); n],
            exceptions: vec![Vec::new(); n],
            areas,
            raw_row_sums: vec![0.0; n],
            raw_row_vars: vec![0.0; n],
            raw_row_methods: vec![MethodSet::default(); n],
            raw_asymmetry: 0.0,
            pairs: 0,
            warnings: Vec::new(),
            flags: Vec::new(),
            held,
            distributed: false,
            diag: Vec::new(),
        })
    }

    /// Start of row i (a held row) in the packed store.
    #[inline]
    pub fn offset(&self, i: usize) -> usize {
        debug_assert!(self.held.contains(&i) || i == self.held.end, "row {i} is not held here");
        row_offset(self.n, i) - row_offset(self.n, self.held.start)
    }

    /// s̄_ii, wherever row i is held.
    pub fn self_term(&self, i: usize) -> f64 {
        if self.distributed {
            self.diag[i]
        } else {
            self.row(i)[0]
        }
    }

    /// Row i (columns i..n).
    pub fn row(&self, i: usize) -> &[f64] {
        let o = self.offset(i);
        &self.s[o..o + self.n - i]
    }

    /// Held row i (columns i..n), to write.
    pub fn row_mut(&mut self, i: usize) -> &mut [f64] {
        let o = self.offset(i);
        let len = self.n - i;
        &mut self.s[o..o + len]
    }

    /// s̄_ij for any i, j.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (a, b) = if i <= j { (i, j) } else { (j, i) };
        self.s[self.offset(a) + b - a]
    }

    /// Method(s) and variance of s̄_ij (default method and 0 unless listed as an exception).
    pub fn meta(&self, i: usize, j: usize) -> (MethodSet, f64) {
        let (a, b) = if i <= j { (i, j) } else { (j, i) };
        let ex = &self.exceptions[a];
        match ex.binary_search_by_key(&(b as u32), |e| e.j) {
            Ok(k) => (ex[k].method, ex[k].var),
            Err(_) => (self.row_method[a], 0.0),
        }
    }

    /// Mutable held rows, one slice per row, in order (the first is row `held.start`).
    pub fn rows_mut(&mut self) -> Vec<&mut [f64]> {
        let mut out = Vec::with_capacity(self.held.len());
        let mut rest: &mut [f64] = &mut self.s;
        for i in self.held.clone() {
            let (row, tail) = std::mem::take(&mut rest).split_at_mut(self.n - i);
            out.push(row);
            rest = tail;
        }
        out
    }

    /// Multiplies s̄_ij by g_i g_j in place (the diagonal copy too).
    pub fn scale(&mut self, g: &[f64]) {
        let lo = self.held.start;
        let rows = self.rows_mut();
        rows.into_par_iter().enumerate().for_each(|(k, row)| {
            let i = lo + k;
            for (s, gj) in row.iter_mut().zip(&g[i..]) {
                *s *= g[i] * gj;
            }
        });
        // The same product as the row's first cell: s̄_ii g_i g_i.
        self.diag.iter_mut().zip(g).for_each(|(d, gi)| *d *= gi * gi);
    }

    /// max |s̄_ij| and the count of negative entries over the whole store (a collective when
    /// `distributed`).
    pub fn max_abs_and_negatives(&self) -> (f64, usize) {
        let (m, k) = self
            .s
            .par_iter()
            .fold(|| (0.0, 0), |(m, k), &x| (f64::max(m, x.abs()), k + usize::from(x < 0.0)))
            .reduce(|| (0.0, 0), |a, b| (a.0.max(b.0), a.1 + b.1));
        if !self.distributed {
            return (m, k);
        }
        let all = crate::distributed::reduce::all_gather_bytes(
            &[m.to_le_bytes(), (k as u64).to_le_bytes()].concat(),
        );
        all.iter().fold((0.0, 0), |(m, k), b| {
            let word = |o: usize| u64::from_le_bytes(b[o..o + 8].try_into().expect("16 bytes a rank"));
            (f64::max(m, f64::from_bits(word(0))), k + word(8) as usize)
        })
    }

    /// y = W S W x with W = diag(w) (w = None: y = S x), the full symmetric product from the
    /// upper triangle. Deterministic: fixed row blocks ([`matvec_bounds`]), partial column sums
    /// added in block order; under MPI each rank adds its blocks to the running sum of the
    /// ranks before it ([`crate::distributed::reduce::ordered_sum`]), the same additions.
    pub fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
        let n = self.n;
        let wx: Vec<f64> = match w {
            Some(w) => x.iter().zip(w).map(|(x, w)| x * w).collect(),
            None => x.to_vec(),
        };
        let bounds = matvec_bounds(n);
        let held = &self.held;
        let blocks: Vec<(usize, usize)> = bounds
            .windows(2)
            .map(|b| (b[0], b[1]))
            .filter(|&(lo, hi)| lo >= held.start && hi <= held.end)
            .collect();
        // Each block: its own rows' y_i (row part) and a partial column vector for j ≥ lo.
        let parts: Vec<(usize, Vec<f64>)> = blocks
            .par_iter()
            .map(|&(lo, hi)| {
                let mut col = vec![0.0; n - lo];
                for i in lo..hi {
                    let row = self.row(i);
                    let xi = wx[i];
                    let acc = row_dot_axpy(row, &wx[i..], xi, &mut col[i - lo..]);
                    // The diagonal was added to both: keep it once.
                    col[i - lo] += acc - row[0] * xi;
                }
                (lo, col)
            })
            .collect();
        let add = |y: &mut [f64]| {
            for (lo, col) in parts {
                for (k, c) in col.into_iter().enumerate() {
                    y[lo + k] += c;
                }
            }
        };
        let mut y = if self.distributed {
            // Every rank must add its blocks: a product off the main thread would silently
            // miss the other ranks' rows.
            assert!(
                crate::distributed::reduce::active(),
                "a distributed store's product outside the MPI collectives"
            );
            crate::distributed::reduce::ordered_sum(n, add)
        } else {
            let mut y = vec![0.0; n];
            add(&mut y);
            y
        };
        if let Some(w) = w {
            y.iter_mut().zip(w).for_each(|(y, w)| *y *= w);
        }
        y
    }

    /// Σ_j s̄_ij per node.
    pub fn row_sums(&self) -> Vec<f64> {
        self.matvec_scaled(None, &vec![1.0; self.n])
    }

    /// Bytes held by the store (triangle plus exceptions).
    pub fn bytes(&self) -> usize {
        self.s.len() * 8 + self.exceptions.iter().map(|e| e.capacity()).sum::<usize>() * 16
    }
}

/// Lanes of the row kernel: independent partial sums let the compiler vectorise.
const LANES: usize = 8;

/// Σ_k s_k x_k while c_k += s_k·xi, in one pass over the row (partial sums in [`LANES`]
/// fixed lanes, added in a fixed order).
#[inline]
fn row_dot_axpy(s: &[f64], x: &[f64], xi: f64, c: &mut [f64]) -> f64 {
    let m = s.len();
    let (x, c) = (&x[..m], &mut c[..m]);
    let mut acc = [0.0; LANES];
    let full = m / LANES * LANES;
    for ((sc, xc), cc) in s[..full]
        .chunks_exact(LANES)
        .zip(x[..full].chunks_exact(LANES))
        .zip(c[..full].chunks_exact_mut(LANES))
    {
        for l in 0..LANES {
            acc[l] += sc[l] * xc[l];
            cc[l] += sc[l] * xi;
        }
    }
    let mut tail = 0.0;
    for k in full..m {
        tail += s[k] * x[k];
        c[k] += s[k] * xi;
    }
    let half = [acc[0] + acc[4], acc[1] + acc[5], acc[2] + acc[6], acc[3] + acc[7]];
    (half[0] + half[2]) + (half[1] + half[3]) + tail
}

/// n(n+1)/2, or None on overflow.
pub fn packed_len(n: usize) -> Option<usize> {
    n.checked_mul(n.checked_add(1)?).map(|x| x / 2)
}

/// Start of row i of an order-n packed upper triangle.
#[inline]
fn row_offset(n: usize, i: usize) -> usize {
    i * n - i * (i.saturating_sub(1)) / 2
}

/// Row bounds splitting the triangle into `k` blocks of about equal area (fixed for a given n).
fn block_bounds(n: usize, k: usize) -> Vec<usize> {
    let total = n * (n + 1) / 2;
    let mut out = vec![0];
    let mut acc = 0;
    let mut next = 1;
    for i in 0..n {
        acc += n - i;
        if acc * k >= next * total && i + 1 < n {
            out.push(i + 1);
            while acc * k >= next * total {
                next += 1;
            }
        }
    }
    out.push(n);
    out.dedup();
    out
}

/// Splits a row's entries into the default method (the most frequent) and exceptions.
fn row_meta(entries: &[RawEntry], i: usize) -> (MethodSet, Vec<Exception>) {
    let mut counts: Vec<(MethodSet, usize)> = Vec::new();
    for e in entries.iter().filter(|e| e.var == 0.0) {
        match counts.iter_mut().find(|c| c.0 == e.method) {
            Some(c) => c.1 += 1,
            None => counts.push((e.method, 1)),
        }
    }
    let default = counts.iter().max_by_key(|c| c.1).map_or(MethodSet::default(), |c| c.0);
    let mut ex: Vec<Exception> = entries
        .iter()
        .filter(|e| e.j as usize >= i && (e.method != default || e.var != 0.0))
        .map(|e| Exception { j: e.j, method: e.method, var: e.var })
        .collect();
    ex.sort_by_key(|e| e.j);
    (default, ex)
}

/// Fills the patch-level triangle of `scene` with `kernel`; `wave` bounds the rows buffered
/// per wave for non-symmetric kernels; `progress` counts the pairs of every finished row and
/// its estimated cost (`costs`, one per row).
pub fn fill(
    scene: &Scene,
    kernel: &dyn RowKernel,
    progress: &Progress,
    costs: &[u64],
) -> Result<PackedTriangular> {
    let n = scene.patches.len();
    let mut t = PackedTriangular::zeros(n, scene.patches.iter().map(|p| p.polygon.area()).collect())?;
    if kernel.symmetric() {
        fill_symmetric(&mut t, kernel, progress, costs)?;
    } else {
        fill_folded(&mut t, kernel, progress, costs)?;
    }
    t.warnings = kernel.warnings();
    t.flags = kernel.flags();
    Ok(t)
}

/// Per-row outcome of the parallel fill: (default method, exceptions, Σ s, Σ var, methods,
/// pairs).
pub(super) type RowOut = (MethodSet, Vec<Exception>, f64, f64, MethodSet, u64);

fn fill_symmetric(
    t: &mut PackedTriangular,
    kernel: &dyn RowKernel,
    progress: &Progress,
    costs: &[u64],
) -> Result<()> {
    if let Some((_, e)) = fill_held(t, kernel, progress, costs, &|_| false) {
        return Err(e);
    }
    mirror(t);
    Ok(())
}

/// Computes row i of order `n` with a symmetric kernel into `slot` (its packed slice, s̄_ij
/// for j = i..n), returning its metadata.
pub(super) fn fill_row(kernel: &dyn RowKernel, n: usize, i: usize, slot: &mut [f64]) -> Result<RowOut> {
    // The store is fresh from the kernel: writing first maps each page once, where
    // `+=` would map the shared zero page and fault again (a TLB flush on every core).
    slot.fill(0.0);
    let mut row = Row::default();
    kernel.row(i, &mut row)?;
    let (mut sum, mut var, mut methods) = (0.0, 0.0, MethodSet::default());
    for e in &row.entries {
        let j = e.j as usize;
        if j < i || j >= n {
            return Err(Error::Compute(format!("symmetric kernel returned column {j} in row {i}")));
        }
        slot[j - i] += e.s;
        sum += e.s;
        var += e.var;
        methods = methods.union(e.method);
    }
    let (def, ex) = row_meta(&row.entries, i);
    Ok((def, ex, sum, var, methods, row.pairs))
}

/// Sets the metadata of held row i from [`fill_row`]'s outcome.
pub(super) fn set_row_meta(t: &mut PackedTriangular, i: usize, out: RowOut) {
    let (def, ex, sum, var, methods, pairs) = out;
    t.row_method[i] = def;
    t.exceptions[i] = ex;
    t.raw_row_sums[i] = sum;
    t.raw_row_vars[i] = var;
    t.raw_row_methods[i] = methods;
    t.pairs += pairs;
}

/// Fills the held rows of `t` with a symmetric kernel, but those `skip` names (filled
/// elsewhere), and sets their raw row sums, variances, methods and pairs; returns the first
/// held row that failed (later rows are left unset).
pub(super) fn fill_held(
    t: &mut PackedTriangular,
    kernel: &dyn RowKernel,
    progress: &Progress,
    costs: &[u64],
    skip: &(dyn Fn(usize) -> bool + Sync),
) -> Option<(usize, Error)> {
    let (n, lo) = (t.n, t.held.start);
    let rows = t.rows_mut();
    let outs: Vec<Option<Result<RowOut>>> = rows
        .into_par_iter()
        .with_max_len(1)
        .enumerate()
        .map(|(k, slot)| {
            let i = lo + k;
            if skip(i) {
                return None;
            }
            let out = fill_row(kernel, n, i, slot);
            if out.is_ok() {
                progress.add_costed((n - i) as u64, costs.get(i).copied().unwrap_or(0));
            }
            Some(out)
        })
        .collect();
    for (k, o) in outs.into_iter().enumerate() {
        match o {
            None => {}
            Some(Ok(out)) => set_row_meta(t, lo + k, out),
            Some(Err(e)) => return Some((lo + k, e)),
        }
    }
    None
}

/// Mirrors s_ji = s_ij of a symmetric kernel's rows into the column sums, variances and
/// methods of the raw rows (collectives when `t.distributed`: every rank calls it).
pub(super) fn mirror(t: &mut PackedTriangular) {
    let n = t.n;
    t.raw_row_sums = t.matvec_scaled(None, &vec![1.0; n]);
    let held = t.held.clone();
    let mut extra_var = vec![0.0; n];
    if t.distributed {
        use crate::distributed::reduce;
        // The held rows' own variances, then their mirrored ones, added in row order across
        // the ranks (as one process adds them).
        let (vars, ex) = (&t.raw_row_vars, &t.exceptions);
        let both = reduce::ordered_sum(2 * n, |v| {
            for i in held.clone() {
                v[i] += vars[i];
                for e in ex[i].iter().filter(|e| e.j as usize != i) {
                    v[n + e.j as usize] += e.var;
                }
            }
        });
        t.raw_row_vars.copy_from_slice(&both[..n]);
        extra_var.copy_from_slice(&both[n..]);
        let mine = t.raw_row_methods[held.clone()].iter().fold(MethodSet::default(), |a, &m| a.union(m));
        for bits in reduce::all_gather_u64(u64::from(mine.bits())) {
            let m = MethodSet(bits as u8);
            t.raw_row_methods.iter_mut().for_each(|r| *r = r.union(m));
        }
        t.pairs = reduce::all_gather_u64(t.pairs).iter().sum();
    } else {
        for (i, ex) in t.exceptions.iter().enumerate() {
            for e in ex.iter().filter(|e| e.j as usize != i) {
                extra_var[e.j as usize] += e.var;
            }
        }
    }
    // The mirrored half's methods are not tracked per entry: every row also takes every
    // method the kernel used (the leak threshold only asks whether a row is single-plane).
    let all = t.raw_row_methods.iter().fold(MethodSet::default(), |a, &m| a.union(m));
    for m in &mut t.raw_row_methods {
        *m = m.union(all);
    }
    for (v, e) in t.raw_row_vars.iter_mut().zip(extra_var) {
        *v += e;
    }
}

/// Cells per task when the store's pages are mapped up front (2 MB).
const PREFAULT_CHUNK: usize = 1 << 18;

fn fill_folded(
    t: &mut PackedTriangular,
    kernel: &dyn RowKernel,
    progress: &Progress,
    costs: &[u64],
) -> Result<()> {
    let n = t.n;
    let threads = rayon::current_num_threads().max(1);
    // Not `clamp`: beyond 1,024 threads (RAYON_NUM_THREADS) its lower bound would pass the upper.
    let wave = (WAVE_ENTRY_BUDGET / n.max(1)).max(4 * threads).min(4096);
    // Per row r: exceptions collected unsorted, merged at the end.
    let mut pending: Vec<Vec<Exception>> = vec![Vec::new(); n];
    let mut seen = vec![false; n];
    // The serial fold reads cells before writing them: map every page of the fresh store by
    // a parallel write first (a read would map the zero page and fault again on the write).
    t.s.par_chunks_mut(PREFAULT_CHUNK).for_each(|c| c.fill(0.0));
    let mut lo = 0;
    while lo < n {
        let hi = (lo + wave).min(n);
        let rows: Vec<Result<Row>> = (lo..hi)
            .into_par_iter()
            .with_max_len(1)
            .map(|i| {
                let mut row = Row::default();
                let out = kernel.row(i, &mut row).map(|_| row);
                progress.add_costed(n as u64, costs.get(i).copied().unwrap_or(0));
                out
            })
            .collect();
        for (k, row) in rows.into_iter().enumerate() {
            let i = lo + k;
            let row = row?;
            fold_row(t, i, &row, &mut pending, &mut seen)?;
        }
        lo = hi;
    }
    for (r, mut ex) in pending.into_iter().enumerate() {
        ex.sort_by_key(|e| e.j);
        // Merge the two halves of a pair: methods unite, variances already quartered.
        let mut merged: Vec<Exception> = Vec::with_capacity(ex.len());
        for e in ex {
            match merged.last_mut() {
                Some(m) if m.j == e.j => {
                    m.method = m.method.union(e.method);
                    m.var += e.var;
                }
                _ => merged.push(e),
            }
        }
        // A pair listed only for its method must still differ from the row default.
        let def = t.row_method[r];
        merged.retain(|e| e.method != def || e.var != 0.0);
        merged.shrink_to_fit();
        t.exceptions[r] = merged;
    }
    Ok(())
}

/// Folds raw row i: cell (i, j > i) takes s_ij; cell (j, i) for j < i, which holds s_ji,
/// becomes ½(s_ji + s_ij) as in the sparse symmetrisation; untouched cells of column i halve.
fn fold_row(
    t: &mut PackedTriangular,
    i: usize,
    row: &Row,
    pending: &mut [Vec<Exception>],
    seen: &mut [bool],
) -> Result<()> {
    let n = t.n;
    let (mut sum, mut var, mut methods) = (0.0, 0.0, MethodSet::default());
    let (def, _) = row_meta(&row.entries, i);
    t.row_method[i] = def;
    t.pairs += row.pairs;
    // The row default for method exceptions of the folded pair is the upper row's default.
    for e in &row.entries {
        let j = e.j as usize;
        if j >= n {
            return Err(Error::Compute(format!("kernel returned column {j} in row {i}")));
        }
        sum += e.s;
        var += e.var;
        methods = methods.union(e.method);
        if j >= i {
            let o = t.offset(i) + j - i;
            t.s[o] += e.s;
        } else {
            let o = t.offset(j) + i - j;
            let first = t.s[o];
            t.raw_asymmetry = t.raw_asymmetry.max((first - e.s).abs());
            t.s[o] = 0.5 * (first + e.s);
            seen[j] = true;
        }
        let (r, c) = if j >= i { (i, j) } else { (j, i) };
        if j == i {
            continue;
        }
        if e.method != t.row_method[r] || e.var != 0.0 {
            pending[r].push(Exception { j: c as u32, method: e.method, var: 0.25 * e.var });
        }
    }
    // Pairs (j < i) that row i did not report: s̄ = ½ s_ji.
    for (j, seen) in seen[..i].iter_mut().enumerate() {
        if *seen {
            *seen = false;
        } else {
            let o = t.offset(j) + i - j;
            let first = t.s[o];
            if first != 0.0 {
                t.raw_asymmetry = t.raw_asymmetry.max(first.abs());
                t.s[o] = 0.5 * first;
            }
        }
    }
    t.raw_row_sums[i] = sum;
    t.raw_row_vars[i] = var;
    t.raw_row_methods[i] = methods;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_offsets_and_blocks_cover_the_triangle() {
        for n in [1usize, 2, 3, 7, 100] {
            let mut next = 0;
            for i in 0..n {
                assert_eq!(row_offset(n, i), next);
                next += n - i;
            }
            assert_eq!(next, packed_len(n).unwrap());
            let b = block_bounds(n, MATVEC_BLOCKS);
            assert_eq!((b[0], *b.last().unwrap()), (0, n));
            assert!(b.windows(2).all(|w| w[0] < w[1]));
        }
    }

    #[test]
    fn matvec_equals_the_full_symmetric_product() {
        let n = 37;
        let mut t = PackedTriangular::zeros(n, vec![1.0; n]).unwrap();
        let full =
            |i: usize, j: usize| ((i * 7 + j * 7 + i * j) % 11) as f64 * 0.1 + if i == j { 3.0 } else { 0.0 };
        for i in 0..n {
            for j in i..n {
                let o = t.offset(i) + j - i;
                t.s[o] = full(i, j);
            }
        }
        let x: Vec<f64> = (0..n).map(|k| 1.0 + (k % 5) as f64).collect();
        let w: Vec<f64> = (0..n).map(|k| 0.5 + (k % 3) as f64).collect();
        let y = t.matvec_scaled(Some(&w), &x);
        for i in 0..n {
            let want: f64 = (0..n).map(|j| w[i] * full(i.min(j), i.max(j)) * w[j] * x[j]).sum();
            assert!((y[i] - want).abs() <= 1e-12 * want.abs(), "row {i}: {} vs {want}", y[i]);
        }
    }
}
