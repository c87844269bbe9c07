//! The sparse store ([`Exchange`], sprs CSR) as the one exchange [`Operator`]: its mat-vec,
//! couplings and leak rows, and the closure methods that only a store of single entries serves
//! (maximum likelihood on hit counts, least squares).
use super::leak::LeakRow;
use super::operator::{ClosureMethod, Operator};
use super::Exchange;
use crate::viewfactor::accuracy::LEAK_SIGMAS;
use crate::viewfactor::MethodSet;
use crate::Result;
use rayon::prelude::*;

/// The sparse store, as stored (symmetric once reciprocity is enforced: the solves and
/// scalings that use the operator need it to be).
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
    fn names(&self) -> &[String] {
        &self.names
    }
    fn ambient(&self) -> Option<&[f64]> {
        self.ambient.as_deref()
    }
    fn set_ambient(&mut self, ambient: Vec<f64>) {
        self.ambient = Some(ambient);
    }
    fn scale(&mut self, g: &[f64]) {
        for (i, mut row) in self.s.outer_iterator_mut().enumerate() {
            for (j, s) in row.iter_mut() {
                *s *= g[i] * g[j];
            }
        }
    }
    fn symmetrize(&mut self) {
        Exchange::symmetrize(self);
    }
    fn asymmetry(&self) -> f64 {
        let (num, den) = self.fold_mirrored((0.0f64, 0.0f64), |(num, den), s, sji| {
            (num.max((s - sji).abs()), den.max(s.abs()))
        });
        if den > 0.0 {
            num / den
        } else {
            0.0
        }
    }
    fn negatives(&self) -> usize {
        self.s.data().iter().filter(|&&x| x < 0.0).count()
    }
    /// Per node: the row's methods' own leak tolerance, or [`LEAK_SIGMAS`] standard errors of
    /// the row sum (binomial for hit counts, the entries' variances otherwise).
    fn leak_budget(&self, sums: &[f64]) -> Vec<(f64, f64)> {
        let ip = self.indptr();
        let hits = Exchange::has_hit_counts(self);
        (0..Exchange::len(self))
            .map(|i| {
                let p = sums[i] / self.areas[i];
                let methods =
                    self.methods[ip[i]..ip[i + 1]].iter().fold(MethodSet::default(), |a, &m| a.union(m));
                let sigma = if self.samples[i] > 0 && hits {
                    // Multinomial: the row sum is a binomial proportion of n rays.
                    let q = p.clamp(0.0, 1.0);
                    (q * (1.0 - q) / self.samples[i] as f64).sqrt()
                } else {
                    self.var[ip[i]..ip[i + 1]].iter().sum::<f64>().sqrt() / self.areas[i]
                };
                (p, methods.leak_tol().max(LEAK_SIGMAS * sigma))
            })
            .collect()
    }
    fn leak_rows(&self, leaks: &[(usize, f64)]) -> Vec<LeakRow> {
        super::leak::rows_from_exchange(self, leaks)
    }
    fn has_hit_counts(&self) -> bool {
        Exchange::has_hit_counts(self)
    }
    fn close_by(&mut self, method: ClosureMethod, tol: f64) -> Option<Result<(&'static str, usize)>> {
        use super::lsq::{weighted_least_squares, Weight};
        Some(match method {
            ClosureMethod::MaxLikelihood => {
                super::ml::max_likelihood(self, tol).map(|it| ("maximum likelihood", it))
            }
            ClosureMethod::WeightedLs => {
                Exchange::symmetrize(self);
                weighted_least_squares(self, Weight::Sbar).map(|it| ("weighted least squares (w = s)", it))
            }
            ClosureMethod::UnweightedLs => {
                Exchange::symmetrize(self);
                weighted_least_squares(self, Weight::Unit).map(|it| ("least squares (w = 1)", it))
            }
            ClosureMethod::Auto | ClosureMethod::SymmetricScaling => return None,
        })
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
