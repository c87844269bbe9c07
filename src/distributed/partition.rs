//! Contiguous row blocks balanced by an estimated cost per row: rank k gets rows
//! `blocks[k]`, in order, so that gathering the blocks in rank order gives the rows in row order.

use std::ops::Range;

/// Splits rows `0..costs.len()` into `parts` contiguous blocks of nearly equal total cost:
/// block k ends at the first row where the running cost reaches (k + 1)/parts of the total.
/// Every row belongs to exactly one block; blocks may be empty when rows are fewer than parts.
pub fn balanced(costs: &[f64], parts: usize) -> Vec<Range<usize>> {
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

#[cfg(test)]
mod tests {
    use super::*;

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
