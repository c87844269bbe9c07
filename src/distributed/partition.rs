//! Row splits between ranks: estimated first, then measured.
//!
//! - [`balanced`]: contiguous row blocks balanced by an estimated cost per row (pairs per
//!   row); rank k gets rows `blocks[k]`. Shards (`--shard`, no communication) use this split.
//! - [`probe_rows`], [`rebalanced`]: an MPI run first computes a probe wave, every
//!   [`PROBE_STRIDE`]-th row dealt round-robin to the ranks (so each rank's probe holds the
//!   same mix of cheap and dear rows), timing each row; the ranks share the timings, and the
//!   remaining rows are split into contiguous runs balanced by the *measured* seconds per
//!   estimated unit around each row. Rows are independent, so which rank computes a row
//!   never changes a number.

use std::ops::Range;

/// Every this-many-th row is probed: 1/8 of the rows is enough to sample the cost along the
/// row order (neighbouring patches cost alike), and the probe wave itself is balanced.
pub const PROBE_STRIDE: usize = 8;
/// Probed rows on each side whose timings are pooled into the rate around a row: one row's
/// time is noisy (a thread preempted), a few neighbours' sum is not.
pub const RATE_WINDOW: usize = 2;
/// Environment variable: `estimated` keeps the estimated split under MPI (no probe wave), for
/// comparison; anything else or unset balances by measured cost.
pub const BALANCE_VAR: &str = "LAMBERT_MPI_BALANCE";

/// Splits rows `0..costs.len()` into `parts` contiguous blocks of nearly equal total cost:
/// block k ends at the first row where the running cost reaches (k + 1)/parts of the total;
/// where one dear row makes that leave a block heavier than the best split could, the blocks
/// of the least possible largest cost instead (`least_largest`). Every row belongs to
/// exactly one block; blocks may be empty when rows are fewer than parts.
pub fn balanced(costs: &[f64], parts: usize) -> Vec<Range<usize>> {
    let by_running = running(costs, parts);
    let largest = |blocks: &[Range<usize>]| {
        blocks.iter().map(|b| costs[b.clone()].iter().map(|c| c.max(0.0)).sum::<f64>()).fold(0.0, f64::max)
    };
    let best = least_largest(costs, parts);
    if largest(&by_running) > largest(&best) * (1.0 + MINIMAX_GAIN) {
        best
    } else {
        by_running
    }
}

/// Excess of the running-cost split's largest block over the least-largest one's above which
/// [`balanced`] takes the least-largest split (which fills blocks front first).
const MINIMAX_GAIN: f64 = 0.02;

/// The contiguous split into at most `parts` blocks whose largest cost is least (within
/// 1e-12 of the total): bisection on that cost, each candidate tried by filling blocks in
/// order up to it. Blocks past the rows are empty.
fn least_largest(costs: &[f64], parts: usize) -> Vec<Range<usize>> {
    let parts = parts.max(1);
    let c = |i: usize| costs[i].max(0.0);
    let fill = |cap: f64| -> Option<Vec<Range<usize>>> {
        let mut blocks = Vec::with_capacity(parts);
        let mut row = 0;
        for _ in 0..parts {
            let lo = row;
            let mut run = 0.0;
            while row < costs.len() && run + c(row) <= cap {
                run += c(row);
                row += 1;
            }
            blocks.push(lo..row);
        }
        (row == costs.len()).then_some(blocks)
    };
    let total: f64 = (0..costs.len()).map(c).sum();
    let (mut lo, mut hi) = ((0..costs.len()).map(c).fold(total / parts as f64, f64::max), total);
    for _ in 0..200 {
        if hi - lo <= 1e-12 * total {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if fill(mid).is_some() {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    fill(hi).unwrap_or_else(|| running(costs, parts))
}

/// [`balanced`]'s running-cost split.
fn running(costs: &[f64], parts: usize) -> Vec<Range<usize>> {
    let parts = parts.max(1);
    let n = costs.len();
    let total: f64 = costs.iter().map(|c| c.max(0.0)).sum();
    let mut blocks = Vec::with_capacity(parts);
    let (mut lo, mut row, mut run) = (0, 0, 0.0);
    for k in 1..=parts {
        if k == parts {
            blocks.push(lo..n);
            break;
        }
        let goal = total * k as f64 / parts as f64;
        while row < n && run + costs[row].max(0.0) * 0.5 < goal {
            run += costs[row].max(0.0);
            row += 1;
        }
        blocks.push(lo..row);
        lo = row;
    }
    blocks
}

/// The probe rows of `part` of `parts`: rows 0, S, 2S, … (S = [`PROBE_STRIDE`]) dealt
/// round-robin, probe k to part k mod parts.
pub fn probe_rows(n: usize, parts: usize, part: usize) -> Vec<usize> {
    (0..n)
        .step_by(PROBE_STRIDE)
        .enumerate()
        .filter(|(k, _)| k % parts.max(1) == part)
        .map(|(_, i)| i)
        .collect()
}

/// Splits the rows that are not probe rows into `parts` contiguous runs (in row order) of
/// nearly equal measured cost: each row's estimated cost times the seconds per estimated
/// unit of the probes around it (`probes`: row, seconds; sorted by row; [`RATE_WINDOW`]
/// probes pooled on each side). Without probes the estimate alone decides.
pub fn rebalanced(estimated: &[f64], probes: &[(usize, f64)], parts: usize) -> Vec<Vec<usize>> {
    let rest: Vec<usize> = (0..estimated.len()).filter(|i| i % PROBE_STRIDE != 0).collect();
    let measured = measured_costs(estimated, probes);
    let costs: Vec<f64> = rest.iter().map(|&i| measured[i]).collect();
    balanced(&costs, parts).into_iter().map(|r| rest[r].to_vec()).collect()
}

/// Splits `groups` (contiguous ranges of the items `0..estimated.len()`, in order: the fixed
/// blocks whose sums must stay whole on one rank) into `parts` contiguous runs of groups of
/// nearly equal measured cost: each item's estimated cost times the measured cost per
/// estimated unit of the probes around it, as [`rebalanced`]. With `probes_kept` the probe
/// items (every [`PROBE_STRIDE`]-th) count nothing: their results travel to the group's
/// owner, so only the other items are computed after the split. A function of its
/// arguments alone: ranks that gathered the same probes compute the same split.
pub fn grouped(
    estimated: &[f64],
    probes: &[(usize, f64)],
    groups: &[Range<usize>],
    parts: usize,
    probes_kept: bool,
) -> Vec<Range<usize>> {
    let measured = measured_costs(estimated, probes);
    let costs: Vec<f64> = groups
        .iter()
        .map(|g| g.clone().filter(|i| !probes_kept || i % PROBE_STRIDE != 0).map(|i| measured[i]).sum())
        .collect();
    balanced(&costs, parts)
}

/// Each item's estimated cost times the measured cost per estimated unit of the nearest probe
/// at or before it (the first probe for items before it); the estimate alone without probes.
pub fn measured_costs(estimated: &[f64], probes: &[(usize, f64)]) -> Vec<f64> {
    let rates = probe_rates(estimated, probes);
    (0..estimated.len())
        .map(|i| {
            let k = probes.partition_point(|p| p.0 <= i).saturating_sub(1);
            estimated[i] * rates.get(k).copied().unwrap_or(1.0)
        })
        .collect()
}

/// True unless [`BALANCE_VAR`] asks for the estimated split.
pub fn measured() -> bool {
    std::env::var(BALANCE_VAR).map_or(true, |v| v != "estimated")
}

/// Seconds per estimated unit around each probe (pooled over [`RATE_WINDOW`] neighbours).
fn probe_rates(estimated: &[f64], probes: &[(usize, f64)]) -> Vec<f64> {
    (0..probes.len())
        .map(|k| {
            let window = &probes[k.saturating_sub(RATE_WINDOW)..(k + RATE_WINDOW + 1).min(probes.len())];
            let secs: f64 = window.iter().map(|p| p.1.max(0.0)).sum();
            let units: f64 = window.iter().map(|p| estimated[p.0].max(0.0)).sum();
            if units > 0.0 && secs > 0.0 {
                secs / units
            } else {
                1.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    #[test]
    fn the_largest_block_is_within_two_percent_of_the_least_any_split_allows() {
        // Random chunk costs with a dear chunk or two (the refined entries of a room's
        // hierarchy chunks), 2–4 parts, against every contiguous split; the running split
        // alone misses that bound in some of them (counted below).
        let mut rng = Pcg64Mcg::seed_from_u64(0x2545_f491_4f6c_dd1d);
        let mut next = || rng.random::<f64>();
        let mut moved = 0;
        for case in 0..400 {
            let n = 5 + case % 14;
            let mut costs: Vec<f64> = (0..n).map(|_| 1.0 + next()).collect();
            for _ in 0..1 + case % 2 {
                let k = (next() * n as f64) as usize % n;
                costs[k] *= 2.0 + 4.0 * next();
            }
            let parts = 2 + case % 3;
            let sum = |r: Range<usize>| costs[r].iter().sum::<f64>();
            let largest = |blocks: &[Range<usize>]| blocks.iter().map(|b| sum(b.clone())).fold(0.0, f64::max);
            let least = least_of_all(&costs, parts);
            let blocks = balanced(&costs, parts);
            assert_eq!(blocks.len(), parts);
            assert_eq!((blocks[0].start, blocks[parts - 1].end), (0, n));
            assert!(blocks.windows(2).all(|w| w[0].end == w[1].start), "{blocks:?}");
            assert!(
                largest(&blocks) <= least * (1.0 + MINIMAX_GAIN) + 1e-12,
                "{costs:?} {parts}: {blocks:?}"
            );
            moved += usize::from(largest(&running(&costs, parts)) > least * (1.0 + MINIMAX_GAIN));
        }
        assert!(moved > 20, "the running split was off in {moved} cases only");
    }

    /// The least largest block over every contiguous split of `costs` into `parts`.
    fn least_of_all(costs: &[f64], parts: usize) -> f64 {
        if parts == 1 {
            return costs.iter().sum();
        }
        (0..=costs.len())
            .map(|a| costs[..a].iter().sum::<f64>().max(least_of_all(&costs[a..], parts - 1)))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn the_probe_rows_are_dealt_round_robin_and_cover_every_stride() {
        let n = 100;
        let all: Vec<Vec<usize>> = (0..3).map(|p| probe_rows(n, 3, p)).collect();
        assert_eq!(all[0][..2], [0, 3 * PROBE_STRIDE]);
        assert_eq!(all[1][0], PROBE_STRIDE);
        let mut joined: Vec<usize> = all.concat();
        joined.sort_unstable();
        assert_eq!(joined, (0..n).step_by(PROBE_STRIDE).collect::<Vec<_>>());
    }

    #[test]
    fn measured_costs_move_rows_away_from_the_dear_end() {
        // Equal estimates, but rows 0..500 cost 9 times as much as rows 500..1000 (small,
        // shadowed patches): the estimated split gives two equal halves, the measured split
        // gives the first rank half the cost, 4375/2/9 ≈ 243 of the 875 remaining rows.
        let n = 1000;
        let est = vec![1.0; n];
        let probes: Vec<(usize, f64)> =
            (0..n).step_by(PROBE_STRIDE).map(|i| (i, if i < 500 { 9e-3 } else { 1e-3 })).collect();
        let runs = rebalanced(&est, &probes, 2);
        let rest = n - n.div_ceil(PROBE_STRIDE);
        assert_eq!(runs[0].len() + runs[1].len(), rest);
        assert!(runs[0].iter().all(|i| i % PROBE_STRIDE != 0));
        assert!(runs[0].windows(2).all(|w| w[0] < w[1]) && runs[0].last() < runs[1].first());
        let cost = |r: &[usize]| r.iter().map(|&i| if i < 500 { 9.0 } else { 1.0 }).sum::<f64>();
        let (a, b) = (cost(&runs[0]), cost(&runs[1]));
        assert!((a / b - 1.0).abs() < 0.03, "measured halves cost {a} and {b}");
        assert!(runs[0].len().abs_diff(243) <= 3, "{} rows against {}", runs[0].len(), runs[1].len());
    }

    #[test]
    fn grouped_runs_keep_groups_whole_and_follow_the_measured_cost() {
        // 64 groups of 16 items, equal estimates; the first quarter's items cost 9 times as
        // much: by the estimate two halves of 32 groups, measured the first rank takes fewer.
        let n = 1024;
        let est = vec![1.0; n];
        let groups: Vec<Range<usize>> = (0..64).map(|g| 16 * g..16 * g + 16).collect();
        let dear = |i: usize| if i < 256 { 9e-3 } else { 1e-3 };
        let probes: Vec<(usize, f64)> = (0..n).step_by(PROBE_STRIDE).map(|i| (i, dear(i))).collect();
        assert_eq!(grouped(&est, &[], &groups, 2, false), vec![0..32, 32..64]);
        for kept in [false, true] {
            let runs = grouped(&est, &probes, &groups, 2, kept);
            assert_eq!((runs[0].start, runs[0].end, runs[1].end), (0, runs[1].start, 64), "{runs:?}");
            // Cost 9·256 + 768 = 3072 in all: the first run ends near item 171 (group 10 or 11).
            assert!((10..=11).contains(&runs[0].end), "kept {kept}: {runs:?}");
            let cost = |r: &Range<usize>| -> f64 {
                groups[r.clone()].iter().flat_map(|g| g.clone()).map(dear).sum()
            };
            assert!((cost(&runs[0]) / cost(&runs[1]) - 1.0).abs() < 0.1, "kept {kept}: {runs:?}");
        }
    }

    #[test]
    fn without_timings_the_estimate_splits_the_rest() {
        let est: Vec<f64> = (0..64).map(|i| (64 - i) as f64).collect();
        let runs = rebalanced(&est, &[], 2);
        let cost = |r: &[usize]| r.iter().map(|&i| est[i]).sum::<f64>();
        assert!((cost(&runs[0]) - cost(&runs[1])).abs() <= 64.0);
    }

    fn cost(costs: &[f64], r: &Range<usize>) -> f64 {
        costs[r.clone()].iter().sum()
    }

    #[test]
    fn blocks_cover_every_row_once_in_order() {
        for n in [0, 1, 2, 5, 97] {
            for parts in 1..6 {
                let costs: Vec<f64> = (0..n).map(|i| (n - i) as f64).collect();
                let b = balanced(&costs, parts);
                assert_eq!(b.len(), parts);
                assert_eq!(b[0].start, 0);
                assert_eq!(b[parts - 1].end, n);
                for w in b.windows(2) {
                    assert_eq!(w[0].end, w[1].start);
                }
            }
        }
    }

    #[test]
    fn a_triangle_of_costs_gets_longer_blocks_at_its_cheap_end() {
        // Symmetric kernels: row i costs n - i pairs.
        let n = 1000;
        let costs: Vec<f64> = (0..n).map(|i| (n - i) as f64).collect();
        let b = balanced(&costs, 4);
        let total: f64 = costs.iter().sum();
        for r in &b {
            let share = cost(&costs, r) / total;
            assert!((share - 0.25).abs() < 0.01, "{r:?} holds {share} of the cost");
        }
        assert!(b[0].len() < b[3].len(), "{b:?}");
    }

    #[test]
    fn uniform_costs_give_equal_blocks() {
        let b = balanced(&[1.0; 12], 3);
        assert_eq!(b, vec![0..4, 4..8, 8..12]);
    }
}
