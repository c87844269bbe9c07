//! The exchange operator that enforcement and the solves work on, whatever stores it: the
//! sparse patch pairs ([`Exchange`], sprs CSR), the packed triangle of the dense path
//! (`PackedTriangular`, whole or, under MPI, one row block per rank: `super::rowblock`) or the link hierarchy of the clustered path. Everything they need is a
//! scaled mat-vec W S W x, the areas, the diagonal s_ii, the row sums and (for the anchoring
//! diagnostic only) the coupled pairs. The systems built on it (closure Newton steps, the
//! net-radiation K = D − S) reach faer's conjugate gradients as a
//! `super::linalg::Linear` over [`Operator::matvec_scaled`].
use super::Exchange;
use crate::viewfactor::packed::PackedTriangular;
use rayon::prelude::*;

/// A symmetric operator of exchange areas S (m²) over n patches.
pub trait Operator: Sync {
    /// Patch count.
    fn len(&self) -> usize;
    /// True when there are no patches.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Patch areas A_i, m².
    fn areas(&self) -> &[f64];
    /// y = W S W x with W = diag(w) (w = None: y = S x).
    fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64>;
    /// s_ii.
    fn self_term(&self, i: usize) -> f64;
    /// The diagonal s_ii of every node.
    fn diagonal(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.self_term(i)).collect()
    }
    /// Σ_j S_ij per node (ambient excluded).
    fn row_sums(&self) -> Vec<f64> {
        self.matvec_scaled(None, &vec![1.0; self.len()])
    }
    /// Calls `f(i, j)` for pairs that couple i and j (s_ij ≠ 0), enough to join every group of
    /// coupled patches; used only to name an unanchored group.
    fn couplings(&self, f: &mut dyn FnMut(usize, usize));
}

impl Operator for PackedTriangular {
    fn len(&self) -> usize {
        self.n
    }
    fn areas(&self) -> &[f64] {
        &self.areas
    }
    fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
        PackedTriangular::matvec_scaled(self, w, x)
    }
    fn self_term(&self, i: usize) -> f64 {
        PackedTriangular::self_term(self, i)
    }
    fn row_sums(&self) -> Vec<f64> {
        PackedTriangular::row_sums(self)
    }
    fn couplings(&self, f: &mut dyn FnMut(usize, usize)) {
        super::rowblock::couplings(self, f);
    }
}

/// The sparse store, as stored (symmetric once reciprocity is enforced: the solves and
/// scalings that use the trait need it to be).
impl Operator for Exchange {
    fn len(&self) -> usize {
        Exchange::len(self)
    }
    fn areas(&self) -> &[f64] {
        &self.areas
    }
    fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
        let (ip, idx, d) = (self.indptr(), self.s.indices(), self.s.data());
        let wt = |i: usize| w.map_or(1.0, |w| w[i]);
        (0..Exchange::len(self))
            .into_par_iter()
            .map(|i| wt(i) * (ip[i]..ip[i + 1]).map(|k| d[k] * wt(idx[k]) * x[idx[k]]).sum::<f64>())
            .collect()
    }
    fn self_term(&self, i: usize) -> f64 {
        self.get(i, i)
    }
    fn row_sums(&self) -> Vec<f64> {
        Exchange::row_sums(self)
    }
    fn couplings(&self, f: &mut dyn FnMut(usize, usize)) {
        let (ip, idx, d) = (self.indptr(), self.s.indices(), self.s.data());
        for i in 0..Exchange::len(self) {
            for k in ip[i]..ip[i + 1] {
                if d[k] != 0.0 && idx[k] != i {
                    f(i, idx[k]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewfactor::{Entry, Level, MethodSet, ViewFactors};

    /// Three nodes: 0–1 coupled, 2 alone with a self term.
    fn sparse() -> Exchange {
        let e = |to: u32, factor: f64| Entry { to, factor, std_error: 0.0, method: MethodSet::default() };
        let vf = ViewFactors {
            level: Level::Surface,
            names: vec!["a".into(), "b".into(), "c".into()],
            areas: vec![1.0, 2.0, 4.0],
            rows: vec![vec![e(1, 0.5)], vec![e(0, 0.25)], vec![e(2, 0.125)]],
            patch_row_sums: Vec::new(),
            patch_samples: Vec::new(),
            pairs: 0,
            wall: std::time::Duration::ZERO,
            warnings: Vec::new(),
            flags: Vec::new(),
        };
        Exchange::from_viewfactors(&vf)
    }

    #[test]
    fn the_sparse_store_is_an_operator() {
        let ex = sparse();
        let op: &dyn Operator = &ex;
        // S = [[0, .5, 0], [.5, 0, 0], [0, 0, .5]]; W S W x with w = (1, 2, 3), x = (1, 1, 2).
        assert_eq!(op.matvec_scaled(Some(&[1.0, 2.0, 3.0]), &[1.0, 1.0, 2.0]), vec![1.0, 1.0, 9.0]);
        assert_eq!(op.diagonal(), vec![0.0, 0.0, 0.5]);
        assert_eq!(Operator::row_sums(op), vec![0.5, 0.5, 0.5]);
        let mut pairs = Vec::new();
        op.couplings(&mut |i, j| pairs.push((i, j)));
        assert_eq!(pairs, vec![(0, 1), (1, 0)]);
    }
}
