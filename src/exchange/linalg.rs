//! Small sparse linear-algebra kernels shared by the enforcement methods and the iterative
//! solvers:
//! - [`dot`] / [`norm`]: reductions in fixed-size chunks summed in order, so results do not
//!   depend on the thread count;
//! - [`SignlessLaplacian`]: the operator (diag(Σ_j w_ij) + W)x of the row-sum constraints
//!   Σ_j w_ij(λ_i + λ_j) = r_i, on the pattern of S;
//! - [`cg`]: Jacobi-preconditioned conjugate gradients for that PSD operator (it stays in the
//!   range of the operator, so it also solves the consistent singular bipartite case).
use rayon::prelude::*;

/// Chunk length of the ordered reductions (fixed, so the sum order never changes).
const CHUNK: usize = 4096;

/// Σ a_i b_i, identical on any thread count.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum())
        .collect();
    parts.iter().sum()
}

/// Euclidean norm, identical on any thread count.
pub fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// The operator y_i = (Σ_j w_ij) x_i + Σ_j w_ij x_j on a CSR pattern (W symmetric, diagonal
/// entries counted in both terms: ∂/∂λ_i of w_ii(λ_i + λ_i) is 2w_ii).
pub struct SignlessLaplacian<'a> {
    /// CSR row pointer.
    pub indptr: &'a [usize],
    /// CSR columns.
    pub indices: &'a [usize],
    /// Weights w_ij aligned with `indices`.
    pub w: &'a [f64],
}

impl SignlessLaplacian<'_> {
    /// y = (diag(W·1) + W) x.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut().enumerate().for_each(|(i, yi)| {
            let (lo, hi) = (self.indptr[i], self.indptr[i + 1]);
            let mut acc = 0.0;
            for k in lo..hi {
                acc += self.w[k] * (x[i] + x[self.indices[k]]);
            }
            *yi = acc;
        });
    }

    /// Diagonal of the operator: Σ_j w_ij + w_ii.
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.indptr.len() - 1)
            .into_par_iter()
            .map(|i| {
                let (lo, hi) = (self.indptr[i], self.indptr[i + 1]);
                (lo..hi).map(|k| if self.indices[k] == i { 2.0 * self.w[k] } else { self.w[k] }).sum()
            })
            .collect()
    }
}

/// Outcome of [`cg`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CgInfo {
    /// Iterations taken.
    pub iterations: usize,
    /// Final ‖b − Ax‖ / ‖b‖.
    pub residual: f64,
    /// True when `residual <= tol`.
    pub converged: bool,
}

/// Solves the PSD system A x = b by Jacobi-preconditioned CG from x = 0.
pub fn cg(a: &SignlessLaplacian, b: &[f64], tol: f64, max_iter: usize) -> (Vec<f64>, CgInfo) {
    let n = b.len();
    let diag = a.diagonal();
    let inv: Vec<f64> = diag.iter().map(|&d| if d > 0.0 { 1.0 / d } else { 0.0 }).collect();
    let bnorm = norm(b);
    let mut x = vec![0.0; n];
    if bnorm == 0.0 {
        return (x, CgInfo { iterations: 0, residual: 0.0, converged: true });
    }
    let mut r = b.to_vec();
    let mut z: Vec<f64> = r.iter().zip(&inv).map(|(r, d)| r * d).collect();
    let mut p = z.clone();
    let mut ap = vec![0.0; n];
    let mut rz = dot(&r, &z);
    let mut res = 1.0;
    for it in 1..=max_iter {
        a.apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap <= 0.0 {
            return (x, CgInfo { iterations: it, residual: res, converged: res <= tol });
        }
        let alpha = rz / pap;
        x.par_iter_mut().zip(&p).for_each(|(x, p)| *x += alpha * p);
        r.par_iter_mut().zip(&ap).for_each(|(r, ap)| *r -= alpha * ap);
        res = norm(&r) / bnorm;
        if res <= tol {
            return (x, CgInfo { iterations: it, residual: res, converged: true });
        }
        z.par_iter_mut().zip(&r).zip(&inv).for_each(|((z, r), d)| *z = r * d);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        p.par_iter_mut().zip(&z).for_each(|(p, z)| *p = z + beta * *p);
    }
    (x, CgInfo { iterations: max_iter, residual: res, converged: false })
}
