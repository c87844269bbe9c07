//! The a-priori error model of the Gauss rungs and the order selector built on it (see the
//! parent module for the bound and its calibration).
use super::rules::MAX_ORDER;

/// Calibrated constants of E(m, λ, ν) = A·ρ^(−p) + B·ν·ρ^(1−p) per order m = 1..=MAX_ORDER,
/// `[parallelogram, triangle]`: p = 2m on parallelograms (m-point Gauss is exact to degree
/// 2m − 1), p = 2m − 1 on Duffy triangles (the Jacobian 1 − s costs one degree).
/// Envelopes of `examples/ladder_calibration` (20 000 receivers × 4 emitter shapes, seed 7;
/// the larger of two runs' fits);
/// B of orders ≥ 4 (parallelograms) and ≥ 5 (triangles) had no sample above round-off in the
/// asymptotic range and is extrapolated geometrically.
const MODEL_A: [[f64; MAX_ORDER]; 2] =
    [[18.1, 33.5, 117.6, 298.4, 816.7, 2097.0], [1.02, 3.08, 6.22, 12.4, 38.4, 85.1]];
/// See [`MODEL_A`].
const MODEL_B: [[f64; MAX_ORDER]; 2] =
    [[1.94, 5.35, 11.3, 25.0, 50.0, 100.0], [0.128, 0.185, 0.202, 0.25, 0.3, 0.4]];
/// Factor between the calibrated envelope and the bound used: margin for geometry the sweep
/// did not draw; it costs only 4^(1/p) in the separation thresholds.
pub const SAFETY: f64 = 4.0;
/// ν bins of the threshold table (ν ∈ [0, 2] is rounded up to a bin edge).
const NU_BINS: usize = 8;

/// Bernstein-ellipse parameter of a pole at normalised distance 2λ beyond an end of [−1, 1].
pub fn rho(lambda: f64) -> f64 {
    1.0 + 2.0 * lambda + 2.0 * (lambda * lambda + lambda).sqrt()
}

/// The order selector: smallest Gauss order per patch that keeps the pair within target.
#[derive(Debug, Clone)]
pub struct ErrorModel {
    /// Per-patch share of the pair's relative error target.
    side_tol: f64,
    /// λ_min[kind][m − 1][bin]: the least λ at which order m meets `side_tol` for ν ≤ bin
    /// edge, kind 0 = parallelogram, 1 = triangles.
    lambda_min: [[[f64; NU_BINS + 1]; MAX_ORDER]; 2],
}

impl ErrorModel {
    /// Relative error bound of an order-`m` rule on one patch at separation λ = D/L, where ν
    /// is the relative variation of the other patch's cosine factor over this patch (0 to 2).
    pub fn side_error(m: usize, triangles: bool, lambda: f64, nu: f64) -> f64 {
        let r = rho(lambda);
        let k = triangles as usize;
        let p = 2 * m as i32 - k as i32;
        SAFETY * (MODEL_A[k][m - 1] * r.powi(-p) + MODEL_B[k][m - 1] * nu * r.powi(1 - p))
    }

    /// Threshold table for a per-pair relative target `rel_tol` (half per patch).
    pub fn new(rel_tol: f64) -> Self {
        let side_tol = 0.5 * rel_tol;
        let mut lambda_min = [[[f64::INFINITY; NU_BINS + 1]; MAX_ORDER]; 2];
        for (kind, table) in lambda_min.iter_mut().enumerate() {
            for (m, row) in table.iter_mut().enumerate() {
                for (bin, slot) in row.iter_mut().enumerate() {
                    let nu = 2.0 * bin as f64 / NU_BINS as f64;
                    let err = |lambda| Self::side_error(m + 1, kind == 1, lambda, nu);
                    // Bisection on log λ: the bound decreases in λ.
                    let (mut lo, mut hi) = (1e-3f64, 1e9f64);
                    if err(hi) > side_tol {
                        continue;
                    }
                    for _ in 0..100 {
                        let mid = (lo * hi).sqrt();
                        if err(mid) <= side_tol {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    *slot = hi;
                }
            }
        }
        ErrorModel { side_tol, lambda_min }
    }

    /// The per-patch relative error budget.
    pub fn side_tol(&self) -> f64 {
        self.side_tol
    }

    /// Smallest order whose bound meets the budget at (λ, ν), or `None` (use the exact integral).
    /// ν is given by the extremes lo ≥ 0, hi of the linear factor: ν = 2(hi − lo)/(hi + lo).
    #[inline]
    pub fn order(&self, triangles: bool, lambda: f64, lo: f64, hi: f64) -> Option<usize> {
        // Bin = ⌈ν·NU_BINS/2⌉ without a division: count the edges k with ν·NU_BINS/2 > k.
        let (num, den) = (NU_BINS as f64 * (hi - lo), hi + lo);
        let bin =
            if triangles { NU_BINS } else { (0..NU_BINS).map(|k| (num > k as f64 * den) as usize).sum() };
        // λ_min falls with the order, so the first order that fits is one past the count of
        // orders that do not (branch-free: the pattern varies from pair to pair).
        let table = &self.lambda_min[triangles as usize];
        let misses: usize = (0..MAX_ORDER).map(|m| (lambda < table[m][bin]) as usize).sum();
        (misses < MAX_ORDER).then_some(misses + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_fall_with_the_order_and_orders_meet_the_budget() {
        for tol in [1e-3, 5e-8, 1e-10, 1e-12] {
            let model = ErrorModel::new(tol);
            for (kind, table) in model.lambda_min.iter().enumerate() {
                for m in 1..MAX_ORDER {
                    for (bin, (now, before)) in table[m].iter().zip(&table[m - 1]).enumerate() {
                        assert!(now <= before, "tol {tol} kind {kind} order {} bin {bin}", m + 1);
                    }
                }
            }
            // The chosen order meets the budget at ν; the one below it fails at ν rounded up to
            // its bin edge (the lookup is conservative by at most one bin).
            let tol_ok = model.side_tol() * (1.0 + 1e-9);
            for k in 0..2000 {
                let lambda = 0.3 * 1.01f64.powi(k);
                let (lo, hi) = (k as f64 % 7.0, 7.0);
                for tri in [false, true] {
                    let nu = if tri { 2.0 } else { 2.0 * (hi - lo) / (hi + lo) };
                    let nu_edge = (nu * NU_BINS as f64 / 2.0).ceil() * 2.0 / NU_BINS as f64;
                    match model.order(tri, lambda, lo, hi) {
                        Some(m) => {
                            assert!(
                                ErrorModel::side_error(m, tri, lambda, nu) <= tol_ok,
                                "λ {lambda} ν {nu} m {m}"
                            );
                            if m > 1 {
                                assert!(
                                    ErrorModel::side_error(m - 1, tri, lambda, nu_edge)
                                        > model.side_tol() * 0.999
                                );
                            }
                        }
                        None => assert!(
                            ErrorModel::side_error(MAX_ORDER, tri, lambda, nu_edge)
                                > model.side_tol() * 0.999
                        ),
                    }
                }
            }
        }
    }
}
