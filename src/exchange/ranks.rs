//! The packed store's sums that cross MPI ranks when it is held in row blocks
//! (`super::rowblock`), below the store and its builder: the coupled groups of the anchoring
//! check, and the leaking rows named in a refusal. Without MPI, or on a whole store, each is
//! the single-process sum.
use super::leak::LeakRow;
use crate::distributed::reduce;
pub(crate) use crate::geometry::groups::Groups;
use crate::viewfactor::packed::PackedTriangular;

/// Calls `f(i, j)` for pairs that couple i and j, enough to join every group of coupled
/// patches: the held rows' couplings, and under MPI every rank's groups as each patch's
/// group label (its smallest patch), all-gathered (a collective).
pub fn couplings(t: &PackedTriangular, f: &mut dyn FnMut(usize, usize)) {
    let held = |f: &mut dyn FnMut(usize, usize)| {
        for i in t.held.clone() {
            for (k, &s) in t.row(i).iter().enumerate().skip(1) {
                if s != 0.0 {
                    f(i, i + k);
                }
            }
        }
    };
    if !t.distributed {
        held(f);
        return;
    }
    gathered_couplings(t.n, held, reduce::all_gather_bytes, f);
}

/// The couplings of a store held in parts across ranks: `local` calls its argument on this
/// rank's coupled pairs; each patch's group label (its smallest member) is all-gathered by
/// `all_gather`, and `f(u, label)` joins every patch to its group on every rank, so that the
/// groups are those of one process's couplings (a collective).
pub(crate) fn gathered_couplings(
    n: usize,
    local: impl FnOnce(&mut dyn FnMut(usize, usize)),
    all_gather: impl FnOnce(&[u8]) -> Vec<Vec<u8>>,
    f: &mut dyn FnMut(usize, usize),
) {
    let mut groups = Groups::new(n);
    local(&mut |u, v| groups.join(u, v));
    let labels: Vec<u8> = (0..n).flat_map(|u| (groups.root(u) as u32).to_le_bytes()).collect();
    for bytes in all_gather(&labels) {
        for (u, c) in bytes.chunks_exact(4).enumerate() {
            let root = u32::from_le_bytes(c.try_into().expect("4 bytes")) as usize;
            if root != u {
                f(u, root);
            }
        }
    }
}

/// The leaking rows `(row, row sum)` of the packed store, whose sampled entries are its
/// exceptions with a variance (one pass over them).
pub fn rows_from_triangle(t: &PackedTriangular, names: &[String], leaks: &[(usize, f64)]) -> Vec<LeakRow> {
    let mut slot = vec![usize::MAX; t.n];
    let mut rows: Vec<LeakRow> = leaks
        .iter()
        .enumerate()
        .map(|(k, &(i, sum))| {
            slot[i] = k;
            LeakRow::new(&names[i], sum)
        })
        .collect();
    for (a, list) in t.exceptions.iter().enumerate() {
        for e in list.iter().filter(|e| e.var > 0.0) {
            let (b, s, sd) = (e.j as usize, t.get(a, e.j as usize), e.var.sqrt());
            if slot[a] != usize::MAX {
                rows[slot[a]].add(&names[b], s / t.areas[a], sd / t.areas[a]);
            }
            if b != a && slot[b] != usize::MAX {
                rows[slot[b]].add(&names[a], s / t.areas[b], sd / t.areas[b]);
            }
        }
    }
    // Under MPI each rank saw its own rows' entries only.
    merge_leak_rows(t, rows)
}

/// The leaking rows of a distributed store: each rank's partial rows (from its held rows'
/// exceptions) merged in rank order, so in row order as one process adds them (a
/// collective); `rows` unchanged when the store is whole.
pub fn merge_leak_rows(t: &PackedTriangular, rows: Vec<LeakRow>) -> Vec<LeakRow> {
    if !t.distributed {
        return rows;
    }
    let mine: Vec<u8> = rows.iter().flat_map(LeakRow::partial_bytes).collect();
    let mut out: Vec<LeakRow> = rows.iter().map(LeakRow::emptied).collect();
    for bytes in reduce::all_gather_bytes(&mine) {
        let mut rest: &[u8] = &bytes;
        for r in &mut out {
            match r.merge_bytes(rest) {
                Some(tail) => rest = tail,
                None => return rows,
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::leak::{rows_from_exchange, rows_from_viewfactors};
    use super::super::Exchange;
    use super::*;
    use crate::viewfactor::ViewFactors;

    /// Three patches of area 2; entries 0–1 sampled (σ of s̄ = 0.02), 1–2 exact.
    fn stores() -> (ViewFactors, PackedTriangular) {
        use crate::viewfactor::packed::Exception;
        use crate::viewfactor::{Entry, Level, MethodSet};
        let names: Vec<String> = ["a#0", "a#1", "b#0"].iter().map(|s| s.to_string()).collect();
        let e = |to: u32, factor: f64, std_error: f64| Entry {
            to,
            factor,
            std_error,
            method: MethodSet::ANALYTIC,
        };
        let vf = ViewFactors {
            level: Level::Patch,
            names: names.clone(),
            areas: vec![2.0; 3],
            rows: vec![vec![e(1, 0.3, 0.01)], vec![e(0, 0.3, 0.01), e(2, 0.5, 0.0)], vec![e(1, 0.5, 0.0)]],
            patch_row_sums: vec![0.3, 0.8, 0.5],
            patch_samples: vec![0; 3],
            pairs: 3,
            wall: std::time::Duration::ZERO,
            flags: Vec::new(),
            warnings: Vec::new(),
        };
        let mut t = PackedTriangular::zeros(3, vec![2.0; 3]).unwrap();
        let (k01, k12) = (t.offset(0) + 1, t.offset(1) + 1);
        t.s[k01] = 0.6;
        t.s[k12] = 1.0;
        t.exceptions[0].push(Exception { j: 1, method: MethodSet::SHADOWED, var: 0.02f64.powi(2) });
        (vf, t)
    }

    #[test]
    fn every_store_gives_the_same_sampled_entries() {
        let (vf, t) = stores();
        let leaks = [(0, 0.3), (1, 0.8), (2, 0.5)];
        let from_vf = rows_from_viewfactors(&vf, &leaks);
        let from_ex = rows_from_exchange(&Exchange::from_viewfactors(&vf), &leaks);
        let from_t = rows_from_triangle(&t, &vf.names, &leaks);
        for rows in [&from_vf, &from_ex, &from_t] {
            assert_eq!(rows.iter().map(|r| r.sampled).collect::<Vec<_>>(), [1, 1, 0], "{rows:?}");
            let w = rows[1].worst.as_ref().unwrap();
            assert_eq!(w.to, "a#0");
            assert!((w.factor - 0.3).abs() < 1e-15 && (w.std_error - 0.01).abs() < 1e-15, "{w:?}");
            assert!(rows[2].worst.is_none());
        }
    }
}
