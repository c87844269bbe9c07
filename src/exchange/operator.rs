//! The exchange operator that enforcement and the solves work on, whatever stores it: the
//! sparse patch pairs ([`super::Exchange`], sprs CSR; `super::sparse`), the packed triangle of the dense path
//! ([`super::dense::DenseExchange`]: whole or, under MPI, one row block per rank,
//! `super::rowblock`, whose sums are cross-rank collectives) or the link hierarchy of the
//! clustered path (`super::hierarchy::Hierarchy`).
//!
//! - The operator: a scaled mat-vec W S W x, the areas, the diagonal s_ii, the row sums, the
//!   coupled pairs (for the anchoring check), the node names and the ambient column. The
//!   systems built on it (closure Newton steps, the net-radiation K = D − S) reach faer's
//!   conjugate gradients as a `super::linalg::Linear` over [`Operator::matvec_scaled`].
//! - The enforcement hooks: what [`fn@super::enforce`] reads and changes on every store — the
//!   raw row sums, asymmetry and sign count for the diagnostics, the leak check's rows and
//!   thresholds, reciprocity by averaging, the diagonal scales s_ij ← s_ij g_i g_j, the ambient
//!   column, and the closure methods only a store of single entries serves (maximum
//!   likelihood, least squares).
//!
//! Hooks with a natural default have one: a store held symmetric by construction needs no
//! `symmetrize`, a deterministic store no hit counts.
use super::leak::LeakRow;
use crate::viewfactor::accuracy::DETERMINISTIC_LEAK_TOL;
use crate::Result;

/// A symmetric operator of exchange areas S (m²) over n patches, with the hooks of its
/// enforcement.
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
    /// Node names, as in the outputs.
    fn names(&self) -> &[String];
    /// S_i,amb of open scenes once enforcement set it.
    fn ambient(&self) -> Option<&[f64]>;

    /// Enforcement hook: sets the ambient column S_i,amb.
    fn set_ambient(&mut self, ambient: Vec<f64>);
    /// Enforcement hook: s_ij ← s_ij g_i g_j for diagonal scales g > 0 (reciprocity, zeros and
    /// signs are kept).
    fn scale(&mut self, g: &[f64]);
    /// Enforcement hook: reciprocity by averaging, s̄ = ½(s + sᵀ). Default: nothing, the
    /// store holds s̄ by construction.
    fn symmetrize(&mut self) {}
    /// Enforcement hook: max |s_ij − s_ji| / max |s_ij| of the store as it now is. Default:
    /// 0, symmetric by construction.
    fn asymmetry(&self) -> f64 {
        0.0
    }
    /// Enforcement hook: the same residual of the raw exchange areas, before the store
    /// averaged them (read before enforcement). Default: [`Operator::asymmetry`].
    fn raw_asymmetry(&self) -> f64 {
        self.asymmetry()
    }
    /// Enforcement hook: Σ_j s_ij per node of the raw exchange areas (read before
    /// enforcement). Default: [`Operator::row_sums`].
    fn raw_row_sums(&self) -> Vec<f64> {
        self.row_sums()
    }
    /// Enforcement hook: the number of stored negative s_ij (ambient excluded).
    fn negatives(&self) -> usize;
    /// Enforcement hook: the leak check's rows of a closed scene from the raw row sums `raw`
    /// (m², [`Operator::raw_row_sums`]): per row, Σ_j F_ij and the shortfall below 1 that the
    /// method's error allows. Default: every node against [`DETERMINISTIC_LEAK_TOL`].
    fn leak_budget(&self, raw: &[f64]) -> Vec<(f64, f64)> {
        raw.iter().zip(self.areas()).map(|(s, a)| (s / a, DETERMINISTIC_LEAK_TOL)).collect()
    }
    /// Enforcement hook: the name of leak-check row `k`. Default: node k's name.
    fn leak_row_name(&self, k: usize) -> String {
        self.names()[k].clone()
    }
    /// Enforcement hook: the leaking rows `(row, row sum)` with their sampled entries, for the
    /// refusal's hint. Default: the rows without entries.
    fn leak_rows(&self, leaks: &[(usize, f64)]) -> Vec<LeakRow> {
        leaks.iter().map(|&(k, sum)| LeakRow::new(&self.leak_row_name(k), sum)).collect()
    }
    /// Enforcement hook: true when every row comes from a hit-counting estimator with its rays
    /// known (closure by maximum likelihood). Default: false.
    fn has_hit_counts(&self) -> bool {
        false
    }
    /// Enforcement hook: closure by `method` when it is not a diagonal scaling (maximum
    /// likelihood, least squares), on a store of single entries: the method's name and its
    /// iterations. Default: `None`, the store serves symmetric scaling only.
    fn close_by(&mut self, method: ClosureMethod, tol: f64) -> Option<Result<(&'static str, usize)>> {
        let _ = (method, tol);
        None
    }
}

/// How closure is reached (the study compares all of them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ClosureMethod {
    /// ML for hit counts, symmetric scaling otherwise.
    #[default]
    Auto,
    /// Constrained maximum likelihood (needs hit counts).
    MaxLikelihood,
    /// s_ij = s̄_ij g_i g_j.
    SymmetricScaling,
    /// One weighted least-squares projection, w = s̄.
    WeightedLs,
    /// One least-squares projection, w = 1 on the pattern.
    UnweightedLs,
}
