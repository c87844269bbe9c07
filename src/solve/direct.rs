//! Direct solvers (faer), research/crates.md §2:
//! - N ≤ [`DENSE_MAX`]: dense LLT (partial-pivot LU if K is not SPD or not symmetric);
//! - above: sparse LLT (AMD ordering) with the symbolic analysis cached in [`Cache`] and reused
//!   when only the values change (bands, conductances); sparse LU as the fallback.
use super::system::Csr;
use crate::{Error, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt as SpLlt, Lu as SpLu, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Mat, Side};

/// Largest unknown count solved densely. Measured (validation/solve.md; crates.md §2): on full
/// view-factor fill dense LLT factors faster than sparse LLT at N = 2,000 (70 vs 229 ms
/// unloaded; 0.47 vs 0.64 s on a loaded machine) and stays ahead to N ≈ 5,000, where the
/// dense matrix already costs 200 MB; 3,000 caps it at 72 MB.
pub const DENSE_MAX: usize = 3000;

/// Cached sparse symbolic LLT, keyed by the pattern it was built for.
#[derive(Debug, Clone)]
pub struct SymbolicCache {
    indptr: Vec<usize>,
    indices: Vec<usize>,
    symbolic: SymbolicLlt<usize>,
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
        match self {
            Factor::DenseLlt(f) => f.solve(&b),
            Factor::DenseLu(f) => f.solve(&b),
            Factor::SparseLlt(f) => f.solve(&b),
            Factor::SparseLu(f) => f.solve(&b),
            Factor::Empty => b,
        }
    }
}

/// Factorises K: dense below `dense_max` unknowns, sparse above; LLT first, LU on failure.
pub fn factor(k: &Csr, dense_max: usize, cache: &mut Cache) -> Result<Factor> {
    let n = k.n();
    if n == 0 {
        return Ok(Factor::Empty);
    }
    if n <= dense_max {
        let mut a = Mat::<f64>::zeros(n, n);
        for i in 0..n {
            for p in k.indptr[i]..k.indptr[i + 1] {
                a[(i, k.indices[p])] = k.data[p];
            }
        }
        if k.symmetric {
            if let Ok(f) = a.llt(Side::Lower) {
                return Ok(Factor::DenseLlt(f));
            }
        }
        return Ok(Factor::DenseLu(a.partial_piv_lu()));
    }
    // CSR of K is the CSC of Kᵀ; for a symmetric K that is K itself.
    let sym = SymbolicSparseColMatRef::new_checked(n, n, &k.indptr, None, &k.indices);
    if k.symmetric {
        let reuse = matches!(cache, Some(c) if c.indptr == k.indptr && c.indices == k.indices);
        if !reuse {
            let symbolic = SymbolicLlt::try_new(sym, Side::Lower)
                .map_err(|e| Error::Compute(format!("sparse Cholesky analysis failed: {e:?}")))?;
            *cache = Some(SymbolicCache { indptr: k.indptr.clone(), indices: k.indices.clone(), symbolic });
        }
        let symbolic = cache.as_ref().map(|c| c.symbolic.clone()).expect("cache set above");
        if let Ok(f) = SpLlt::try_new_with_symbolic(symbolic, SparseColMatRef::new(sym, &k.data), Side::Lower)
        {
            return Ok(Factor::SparseLlt(f));
        }
    }
    // Non-symmetric K (no reciprocity) is stored by rows: factor Kᵀ's CSC = K's CSR transposed.
    let t = transpose(k);
    let tsym = SymbolicSparseColMatRef::new_checked(n, n, &t.indptr, None, &t.indices);
    let lu = SparseColMatRef::new(tsym, &t.data)
        .sp_lu()
        .map_err(|e| Error::Compute(format!("sparse LU failed (singular system): {e:?}")))?;
    Ok(Factor::SparseLu(lu))
}

/// Transpose of a CSR matrix (as CSR), i.e. the CSC arrays of the original.
fn transpose(k: &Csr) -> Csr {
    let n = k.n();
    let mut count = vec![0usize; n + 1];
    for &j in &k.indices {
        count[j + 1] += 1;
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let indptr = count.clone();
    let mut indices = vec![0; k.indices.len()];
    let mut data = vec![0.0; k.data.len()];
    for i in 0..n {
        for p in k.indptr[i]..k.indptr[i + 1] {
            let j = k.indices[p];
            indices[count[j]] = i;
            data[count[j]] = k.data[p];
            count[j] += 1;
        }
    }
    Csr { indptr, indices, data, symmetric: k.symmetric }
}
