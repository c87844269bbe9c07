//! The interface every view-factor method implements: a [`RowKernel`] fills one patch row of
//! exchange areas s_ij = A_i F_ij ([`Row`] of [`RawEntry`]); the engine
//! ([`super::engine`]), the sinks and the MPI row split all speak it.
use super::MethodSet;
use crate::Result;

/// One estimated exchange area s_ij = A_i F_ij in row i.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawEntry {
    /// Column (receiving patch).
    pub j: u32,
    /// Which method produced it.
    pub method: MethodSet,
    /// A_i F_ij, m².
    pub s: f64,
    /// Variance of `s` (0 for deterministic methods), m⁴.
    pub var: f64,
}

/// One patch row as a kernel returns it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Row {
    /// Entries with s > 0, any order.
    pub entries: Vec<RawEntry>,
    /// When > 0, the entries come from this many shared samples, each landing on at most one
    /// receiver (hit counting): the variance of a union of entries then follows the
    /// multinomial rule. 0 means the entries are independent estimates.
    pub shared_samples: u32,
    /// Pairs this row evaluated (for throughput statistics).
    pub pairs: u64,
}

/// A view-factor method, one patch row at a time.
pub trait RowKernel: Sync {
    /// True when the kernel computes only j > i and reciprocity supplies the rest.
    fn symmetric(&self) -> bool;
    /// Fills row `i`.
    fn row(&self, i: usize, out: &mut Row) -> Result<()>;
    /// What the run should tell its user once every row is done (entries that missed their
    /// error goal), one line each.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
    /// Entries flagged so far (error not bounded, receiver cut), sorted by pair.
    fn flags(&self) -> Vec<super::Flag> {
        Vec::new()
    }
    /// Count and worst entry of the entries that missed their error goal (MPI runs gather them).
    fn misses(&self) -> (u64, Option<super::shadow::misses::Miss>) {
        (0, None)
    }
    /// Estimated cost of each row, in any unit, for the progress report's time left only (it
    /// never changes a number); `None`: each pair costs the same.
    fn row_costs(&self) -> Option<Vec<u64>> {
        None
    }
    /// Hash of the acceleration trees the kernel built (BVH nodes and primitive order), so
    /// that MPI ranks and shards whose trees differ are refused; 0 for a kernel without one.
    fn tree_hash(&self) -> u64 {
        0
    }
    /// Merges the flags and misses that a copy of this kernel recorded on another MPI rank, so
    /// that [`RowKernel::warnings`] and [`RowKernel::flags`] cover every row.
    fn absorb(&self, flags: Vec<super::Flag>, misses: (u64, Option<super::shadow::misses::Miss>)) {
        let _ = (flags, misses);
    }
}

/// The estimated cost of each of the `n` rows for the progress report: the kernel's when a
/// report is drawn, else (and when it has none) the pairs of the row.
pub fn row_costs(kernel: &dyn RowKernel, shown: bool, n: usize, pairs: impl Fn(usize) -> u64) -> Vec<u64> {
    shown
        .then(|| kernel.row_costs())
        .flatten()
        .filter(|c| c.len() == n)
        .unwrap_or_else(|| (0..n).map(pairs).collect())
}
