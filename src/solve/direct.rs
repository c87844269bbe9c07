//! Direct solvers (faer), research/crates.md §2:
//! - N ≤ [`DENSE_MAX`]: dense LLT (partial-pivot LU if K is not SPD or not symmetric);
//! - N ≤ [`DENSE_FULL_MAX`] when the Cholesky factor would be mostly full anyway (K itself at
//!   least [`DENSE_FILL`] full, or the symbolic analysis predicts at least that share of the
//!   lower triangle): dense as well. Enclosures couple almost every patch pair, and sparse LLT
//!   then does dense work at sparse-kernel speed and memory;
//! - otherwise sparse LLT (AMD ordering) with the symbolic analysis cached in [`Cache`] and
//!   reused when only the values change (bands, conductances); sparse LU as the fallback.
//!
//! faer runs sequentially ([`FAER_PAR`]), so every factor and solve is the same on any
//! thread count.
use crate::{Error, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky;
use faer::sparse::linalg::solvers::{Llt as SpLlt, Lu as SpLu, SymbolicLlt};
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Mat, Par, Side};
use sprs::CsMat;

/// Largest unknown count solved densely. Measured (validation/solve.md; crates.md §2): on full
/// view-factor fill dense LLT factors faster than sparse LLT at N = 2,000 (70 vs 229 ms
/// unloaded; 0.47 vs 0.64 s on a loaded machine) and stays ahead to N ≈ 5,000, where the
/// dense matrix already costs 200 MB; 3,000 caps it at 72 MB.
pub const DENSE_MAX: usize = 3000;
/// Largest unknown count solved densely when the factor would be mostly full: K and its dense
/// factor take 2·N²·8 bytes, 2.3 GB at 12,000 (sparse LLT of a 7,776-patch cube interior
/// took 7.5 GB and 59 s; dense LLT takes ~1 GB and seconds, validation/solve.md).
pub const DENSE_FULL_MAX: usize = 12_000;
/// Share of the lower triangle (of K, or of its predicted Cholesky factor) above which the
/// dense factorisation is used up to [`DENSE_FULL_MAX`].
pub const DENSE_FILL: f64 = 0.25;

/// Cached layout decision (and sparse symbolic LLT), keyed by the pattern it was made for.
#[derive(Debug, Clone)]
pub struct SymbolicCache {
    indptr: Vec<usize>,
    indices: Vec<usize>,
    /// `None`: the factor would be mostly full, factor densely.
    symbolic: Option<SymbolicLlt<usize>>,
}

/// Reusable solver state across solves on one pattern.
pub type Cache = Option<SymbolicCache>;

/// A factorised K.
pub enum Factor {
    /// Dense Cholesky.
    DenseLlt(faer::linalg::solvers::Llt<f64>),
    /// Dense LU with partial pivoting.
    DenseLu(faer::linalg::solvers::PartialPivLu<f64>),
    /// Sparse Cholesky.
    SparseLlt(SpLlt<usize, f64>),
    /// Sparse LU.
    SparseLu(SpLu<usize, f64>),
    /// No unknowns.
    Empty,
}

impl Factor {
    /// Human-readable solver name.
    pub fn name(&self) -> &'static str {
        match self {
            Factor::DenseLlt(_) => "dense LLT",
            Factor::DenseLu(_) => "dense LU",
            Factor::SparseLlt(_) => "sparse LLT",
            Factor::SparseLu(_) => "sparse LU",
            Factor::Empty => "none",
        }
    }

    /// Solves K x = b.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let rhs = Mat::from_fn(b.len(), 1, |i, _| b[i]);
        let x = self.solve_many(rhs);
        (0..b.len()).map(|i| x[(i, 0)]).collect()
    }

    /// Solves K X = B for several right-hand sides.
    pub fn solve_many(&self, b: Mat<f64>) -> Mat<f64> {
        fix_parallelism();
        match self {
            Factor::DenseLlt(f) => f.solve(&b),
            Factor::DenseLu(f) => f.solve(&b),
            Factor::SparseLlt(f) => f.solve(&b),
            Factor::SparseLu(f) => f.solve(&b),
            Factor::Empty => b,
        }
    }
}

/// faer's parallelism for every factorisation and solve: sequential. faer's parallel kernels
/// split sums (a mat-vec's inner dimension, for one) into as many parts as threads, so the
/// last digits of a dense LLT followed the thread count; `solve --viewfactors` and
/// `--conductances` differed between `--threads 1` and `2`. A fixed split (`Par::rayon(2)`)
/// is also deterministic but rests on faer internals, and measured no faster here: dense LLT
/// of N = 3,750 took 0.98–1.29 s sequential, 1.18–1.57 s on all threads and 1.15–1.73 s
/// split in two (2 cores shared with other work). The lean, hierarchical and iterative paths
/// do not use faer.
pub const FAER_PAR: Par = Par::Seq;

/// Sets [`FAER_PAR`] as faer's global parallelism (faer's solvers read only the global).
pub fn fix_parallelism() {
    faer::set_global_parallelism(FAER_PAR);
}

/// Factorises K (sprs CSR, `symmetric` when K = Kᵀ exactly), read in place from sprs's
/// arrays: dense up to `dense_max` unknowns, and up to `dense_full_max` when the factor would
/// be mostly full ([`DENSE_FILL`]); sparse otherwise. LLT first, LU on failure.
pub fn factor(
    k: &CsMat<f64>,
    symmetric: bool,
    dense_max: usize,
    dense_full_max: usize,
    cache: &mut Cache,
) -> Result<Factor> {
    fix_parallelism();
    let n = k.rows();
    let ip = k.indptr();
    let indptr = ip.to_proper();
    let (indptr, indices, data) = (&indptr[..], k.indices(), k.data());
    if n == 0 {
        return Ok(Factor::Empty);
    }
    let triangle = (n * (n + 1) / 2) as f64;
    let full = n <= dense_full_max && (indices.len() + n) as f64 / 2.0 >= DENSE_FILL * triangle;
    // CSR of K is the CSC of Kᵀ; for a symmetric K that is K itself.
    let sym = SymbolicSparseColMatRef::new_checked(n, n, indptr, None, indices);
    if n > dense_max && !full && symmetric {
        let reuse = matches!(cache, Some(c) if c.indptr == indptr && c.indices == indices);
        if !reuse {
            let failed = |e: FaerError| Error::Compute(format!("sparse Cholesky analysis failed: {e:?}"));
            // The fill-reducing analysis predicts the factor's size; if mostly full, go dense.
            let sparse = n > dense_full_max || {
                let pre = cholesky::factorize_symbolic_cholesky(
                    sym,
                    Side::Lower,
                    Default::default(),
                    Default::default(),
                )
                .map_err(failed)?;
                (pre.len_val() as f64) < DENSE_FILL * triangle
            };
            let symbolic =
                sparse.then(|| SymbolicLlt::try_new(sym, Side::Lower)).transpose().map_err(failed)?;
            *cache = Some(SymbolicCache { indptr: indptr.to_vec(), indices: indices.to_vec(), symbolic });
        }
    }
    let sparse = cache.as_ref().and_then(|c| c.symbolic.clone());
    let dense = n <= dense_max || full || (symmetric && sparse.is_none());
    if dense {
        let mut a = Mat::<f64>::zeros(n, n);
        for i in 0..n {
            for p in indptr[i]..indptr[i + 1] {
                a[(i, indices[p])] = data[p];
            }
        }
        if symmetric {
            if let Ok(f) = a.llt(Side::Lower) {
                return Ok(Factor::DenseLlt(f));
            }
        }
        return Ok(Factor::DenseLu(a.partial_piv_lu()));
    }
    if let (true, Some(symbolic)) = (symmetric, sparse) {
        if let Ok(f) = SpLlt::try_new_with_symbolic(symbolic, SparseColMatRef::new(sym, data), Side::Lower) {
            return Ok(Factor::SparseLlt(f));
        }
    }
    // Non-symmetric K (no reciprocity) is stored by rows: sprs gives its columns.
    let t = k.to_csc();
    let tip = t.indptr();
    let tptr = tip.to_proper();
    let tsym = SymbolicSparseColMatRef::new_checked(n, n, &tptr, None, t.indices());
    let lu = SparseColMatRef::new(tsym, t.data())
        .sp_lu()
        .map_err(|e| Error::Compute(format!("sparse LU failed (singular system): {e:?}")))?;
    Ok(Factor::SparseLu(lu))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A symmetric, diagonally dominant K of order n with off-diagonal entries where `link(i, j)`.
    fn spd(n: usize, link: impl Fn(usize, usize) -> bool) -> CsMat<f64> {
        let (mut indptr, mut indices, mut data) = (vec![0], Vec::new(), Vec::new());
        for i in 0..n {
            let row: Vec<usize> = (0..n).filter(|&j| j != i && (link(i, j) || link(j, i))).collect();
            for j in 0..n {
                if j == i {
                    indices.push(j);
                    data.push(1.0 + row.len() as f64);
                } else if row.binary_search(&j).is_ok() {
                    indices.push(j);
                    data.push(-1.0 / (1.0 + (i + j) as f64));
                }
            }
            indptr.push(indices.len());
        }
        CsMat::new((n, n), indptr, indices, data)
    }

    fn residual(k: &CsMat<f64>, f: &Factor) -> f64 {
        let b: Vec<f64> = (0..k.rows()).map(|i| 1.0 + i as f64 % 7.0).collect();
        crate::solve::system::residual(k, &f.solve(&b), &b)
    }

    #[test]
    fn the_factor_is_dense_when_it_would_fill_and_sparse_otherwise() {
        let n = 300;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let random: Vec<bool> = (0..n * n).map(|_| rng.random_bool(0.04)).collect();
        let cases = [
            // Every pair coupled (a closed enclosure): dense without analysis.
            ("full", spd(n, |_, _| true), n, "dense LLT"),
            // 4 % random coupling: K is sparse, but its factor fills (no separators).
            ("random", spd(n, |i, j| random[i * n + j]), n, "dense LLT"),
            // A chain: the factor stays as sparse as K.
            ("chain", spd(n, |i, j| i + 1 == j), n, "sparse LLT"),
            // Dense factoring disabled above dense_max.
            ("full, dense_full_max 0", spd(n, |_, _| true), 0, "sparse LLT"),
        ];
        for (what, k, full_max, want) in cases {
            let mut cache = None;
            let f = factor(&k, true, 10, full_max, &mut cache).expect("SPD");
            assert_eq!(f.name(), want, "{what}");
            assert!(residual(&k, &f) < 1e-13, "{what}");
            // The decision is cached with the pattern and holds on refactoring.
            assert_eq!(factor(&k, true, 10, full_max, &mut cache).unwrap().name(), want, "{what} (cached)");
        }
    }
}
