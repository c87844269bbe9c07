//! How a [`super::Hierarchy`]'s links and patch pairs are cut into [`CHUNKS`] fixed chunks and
//! shared between MPI ranks, and the sums over them in a fixed order.
//!
//! - The links (sorted by node pair) are cut at equal counts; the patch pairs by patch row, at
//!   the row starts nearest equal pair counts ([`Split`]), so that a row is evaluated whole, by
//!   one rank, as in a single process. A two-pass solve keeps the first pass's rows per chunk
//!   and ranks, so its cached pairs are found where the single process finds them.
//! - Each rank holds a contiguous run of chunks ([`Held`]), balanced by the pairs per chunk
//!   (the estimated cost: the pairs' exact view factors are the build's dearest part); it keeps
//!   only those chunks' links and pairs, so their memory falls as 1/ranks.
//! - Every sum over links or pairs adds in chunk order, on any rank count: each rank adds its
//!   own chunks' terms to the running sum of the ranks before it
//!   ([`crate::distributed::reduce::ordered_sum`]), so outputs are byte-identical to a run
//!   without MPI.
//!
//! Without MPI (or on one rank) one process holds every chunk and nothing is sent.
use crate::distributed::{partition, reduce};
use std::ops::Range;

/// Fixed chunks of the links and of the patch pairs (fixed, so that sums do not depend on the
/// thread or rank count; at most this many ranks hold a share, further ranks idle).
pub const CHUNKS: usize = 16;

/// The chunks of one build: where the pair rows are cut and which chunks each rank holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Split {
    /// First patch row of each chunk's pairs; [`CHUNKS`] + 1 entries, the last the patch count.
    pub rows: Vec<u32>,
    /// Chunks held by each rank: contiguous, in rank order.
    pub ranks: Vec<Range<usize>>,
}

impl Split {
    /// Chunks of `leaves` (patch pairs sorted by row, of `n` patches) cut at row starts near
    /// equal pair counts, shared among `size` ranks by their pair counts.
    pub fn new(leaves: &[(u32, u32, f64)], n: usize, size: usize) -> Split {
        let len = leaves.len();
        let rows: Vec<u32> = (0..=CHUNKS)
            .map(|c| {
                let pos = len * c / CHUNKS;
                match c {
                    0 => 0,
                    _ if pos >= len => n as u32,
                    _ => leaves[pos].0,
                }
            })
            .collect();
        let at = |row: u32| leaves.partition_point(|p| p.0 < row);
        let costs: Vec<f64> = (0..CHUNKS).map(|c| (at(rows[c + 1]) - at(rows[c])) as f64).collect();
        Split { rows, ranks: partition::balanced(&costs, size) }
    }

    /// The rows of chunks `chunks`.
    pub fn rows_of(&self, chunks: &Range<usize>) -> Range<u32> {
        self.rows[chunks.start]..self.rows[chunks.end]
    }
}

/// The range of chunk `c` in a list of `len` links.
pub fn link_range(len: usize, c: usize) -> Range<usize> {
    len * c / CHUNKS..len * (c + 1) / CHUNKS
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
        let bytes: Vec<u8> =
            [mine.links, mine.pairs, mine.bytes].iter().flat_map(|v| (*v as u64).to_le_bytes()).collect();
        self.all_gather(&bytes)
            .iter()
            .map(|b| {
                let v =
                    |k: usize| u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("24 bytes")) as usize;
                Share { links: v(0), pairs: v(1), bytes: v(2) }
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
    fn chunks_start_at_row_starts_and_cover_every_pair() {
        // Row i holds 10 - i pairs (i < j): a triangle, cut only where a row starts.
        let n = 10;
        let leaves: Vec<(u32, u32, f64)> =
            (0..n).flat_map(|i| (i + 1..n).map(move |j| (i as u32, j as u32, 0.0))).collect();
        for size in 1..5 {
            let s = Split::new(&leaves, n, size);
            assert_eq!(s.rows.len(), CHUNKS + 1);
            assert_eq!((s.rows[0], s.rows[CHUNKS]), (0, n as u32));
            assert!(s.rows.windows(2).all(|w| w[0] <= w[1]), "{:?}", s.rows);
            assert_eq!(s.ranks.len(), size);
            assert_eq!((s.ranks[0].start, s.ranks[size - 1].end), (0, CHUNKS));
            assert!(s.ranks.windows(2).all(|w| w[0].end == w[1].start));
        }
    }

    #[test]
    fn ranks_get_near_equal_pair_counts() {
        let n = 2000;
        let leaves: Vec<(u32, u32, f64)> =
            (0..n).flat_map(|i| (i + 1..n).step_by(7).map(move |j| (i as u32, j as u32, 0.0))).collect();
        let s = Split::new(&leaves, n, 4);
        for r in &s.ranks {
            let rows = s.rows_of(r);
            let count = leaves.iter().filter(|p| rows.contains(&p.0)).count();
            let share = count as f64 / leaves.len() as f64;
            assert!((share - 0.25).abs() < 0.02, "{r:?} holds {share} of the pairs");
        }
    }

    #[test]
    fn pairs_survive_the_byte_round_trip() {
        let v = vec![(1, 2, 0.5), (u32::MAX, 0, -1e-300)];
        assert_eq!(decode(&encode(&v)), v);
    }

    #[test]
    fn one_process_sums_are_its_own() {
        let h = Held { distributed: false, chunks: 0..CHUNKS, links: vec![], pairs: vec![] };
        assert_eq!(h.sum(3, |y| y[1] += 2.0), vec![0.0, 2.0, 0.0]);
        assert_eq!(h.total(7), 7);
    }
}
