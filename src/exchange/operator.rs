//! The symmetric exchange operator that enforcement and the lean solve work on, whatever
//! stores it: the packed triangle of the dense path or the link hierarchy of the clustered
//! path. Everything they need is a scaled mat-vec W S W x, the areas, the self terms s_ii and
//! (for the anchoring diagnostic only) the coupled pairs.
use crate::viewfactor::triangle::Triangle;

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
    /// Calls `f(i, j)` for pairs that couple i and j (s_ij ≠ 0), enough to join every group of
    /// coupled patches; used only to name an unanchored group.
    fn couplings(&self, f: &mut dyn FnMut(usize, usize));
}

impl Operator for Triangle {
    fn len(&self) -> usize {
        self.n
    }
    fn areas(&self) -> &[f64] {
        &self.areas
    }
    fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
        Triangle::matvec_scaled(self, w, x)
    }
    fn self_term(&self, i: usize) -> f64 {
        self.row(i)[0]
    }
    fn couplings(&self, f: &mut dyn FnMut(usize, usize)) {
        for i in 0..self.n {
            for (k, &s) in self.row(i).iter().enumerate().skip(1) {
                if s != 0.0 {
                    f(i, i + k);
                }
            }
        }
    }
}
