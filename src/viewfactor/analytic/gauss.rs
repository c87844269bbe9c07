//! Composite Gauss–Legendre quadrature graded towards known complex singularities.
//!
//! The outer integrand of the contour method, σ ↦ J(x(σ)), is analytic on the real interval
//! except for branch points at known complex positions z = x + iy (the other edge's endpoints
//! and, for skew edges, the pinch where the two lines pass closest). An n-point Gauss rule on
//! [l, r] errs by about ρ^(−2n), where ρ is the Bernstein-ellipse parameter of the nearest
//! singularity for that interval (Trefethen, *Approximation Theory and Practice*, ch. 19).
//! [`integrate`] therefore picks n from ρ per interval, splits at the real part of a close
//! singularity and grades geometrically towards it: O(log(L/y)) intervals, no error estimate
//! needed, and far pairs cost only 2–6 evaluations.
use crate::geometry::quadrature::gauss_legendre;
use std::sync::OnceLock;

/// Largest Gauss rule used; intervals that would need more are split.
pub const N_MAX: usize = 20;
/// Smallest rule used (2 points integrate a straight line exactly).
const N_MIN: usize = 2;
/// ln(1/ε) for the per-interval target ε ≈ 1e-16 relative; a factor 4 margin on the
/// ρ^(−2n) model covers the modest constant of a logarithmic singularity.
const LN_INV_EPS: f64 = 38.2;
/// Split point, as a fraction of the interval, when a singularity sits at or beyond an end:
/// the far piece then has ρ ≥ 2 + √3 at once (3.73^(−2·15) ≈ 1e-17).
const GRADE: f64 = 1.0 / 3.0;
/// Intervals shorter than this fraction of the whole are integrated as they are: the
/// integrand is continuous, so such a piece errs by at most its length times the variation.
const MIN_PIECE: f64 = 1e-15;
/// Bound on the interval stack (depth grows like log₃(1/MIN_PIECE) ≈ 32 per singularity).
const STACK: usize = 160;

/// Gauss–Legendre rules on [0, 1] for n = 1..=N_MAX, computed once.
fn rules() -> &'static [(Vec<f64>, Vec<f64>)] {
    static RULES: OnceLock<Vec<(Vec<f64>, Vec<f64>)>> = OnceLock::new();
    RULES.get_or_init(|| (1..=N_MAX).map(gauss_legendre).collect())
}

/// A complex singularity x ± iy of the integrand (y ≥ 0 is the distance from the real axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Singularity {
    /// Real part.
    pub x: f64,
    /// Imaginary part, ≥ 0.
    pub y: f64,
}

/// Bernstein-ellipse parameter ρ of `s` for the interval [l, r]: foci l and r, ellipse
/// through s; ρ = a + √(a² − 1) with a the semi-major axis in half-lengths.
fn bernstein_rho(s: Singularity, l: f64, r: f64) -> f64 {
    let da = (s.x - l).hypot(s.y);
    let db = (s.x - r).hypot(s.y);
    let a = (da + db) / (r - l);
    a + (a * a - 1.0).max(0.0).sqrt()
}

/// Gauss points needed for ρ^(−2n) ≤ ε.
fn points_for(rho: f64) -> usize {
    if rho <= 1.0 {
        return usize::MAX;
    }
    ((LN_INV_EPS / (2.0 * rho.ln())).ceil() as usize).max(N_MIN)
}

/// ∫₀ᴸ f(σ) dσ for an `f` analytic except at `sing` (and their conjugates).
pub fn integrate(len: f64, sing: &[Singularity], mut f: impl FnMut(f64) -> f64) -> f64 {
    let rules = rules();
    let min_piece = MIN_PIECE * len;
    let mut stack = [(0.0f64, 0.0f64); STACK];
    stack[0] = (0.0, len);
    let mut top = 1;
    let mut total = 0.0;
    while top > 0 {
        top -= 1;
        let (l, r) = stack[top];
        // Step: nearest singularity in the Bernstein sense.
        let (mut rho, mut worst) = (f64::INFINITY, None);
        for &s in sing {
            let q = bernstein_rho(s, l, r);
            if q < rho {
                rho = q;
                worst = Some(s);
            }
        }
        let n = points_for(rho);
        let tiny = r - l <= min_piece || top + 2 > STACK;
        if n <= N_MAX || tiny {
            // Step: one Gauss rule on [l, r].
            let (x, w) = &rules[n.min(N_MAX) - 1];
            let h = r - l;
            total += h * x.iter().zip(w).map(|(&x, &w)| w * f(l + h * x)).sum::<f64>();
            continue;
        }
        // Step: split at the singularity's real part, or grade towards the near end.
        let s = worst.expect("a finite ρ comes from a singularity");
        let h = r - l;
        let m = if s.x > l + GRADE * h && s.x < r - GRADE * h {
            s.x
        } else if s.x <= l + GRADE * h {
            l + GRADE * h
        } else {
            r - GRADE * h
        };
        stack[top] = (l, m);
        stack[top + 1] = (m, r);
        top += 2;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_singularity_close_to_the_interval() {
        // ∫₀¹ ½ ln((σ − a)² + y²) dσ in closed form, with a singularity at a ± iy.
        let exact = |a: f64, y: f64| {
            let g = |t: f64| 0.5 * t * (t * t + y * y).ln() - t + y * (t / y).atan();
            g(1.0 - a) - g(-a)
        };
        for &(a, y) in &[(0.3, 1e-9), (0.0, 1e-6), (1.0, 1e-12), (-0.5, 0.01), (0.5, 2.0), (3.0, 0.1)] {
            let s = [Singularity { x: a, y }];
            let q = integrate(1.0, &s, |t| 0.5 * ((t - a).powi(2) + y * y).ln());
            let e = exact(a, y);
            assert!((q - e).abs() < 2e-15 * (1.0 + e.abs()), "a={a} y={y}: {q} vs {e}");
        }
    }

    #[test]
    fn far_singularity_needs_few_points() {
        let mut calls = 0;
        let s = [Singularity { x: 0.5, y: 50.0 }];
        let q = integrate(1.0, &s, |t| {
            calls += 1;
            0.5 * ((t - 0.5).powi(2) + 2500.0).ln()
        });
        assert!(calls <= 4, "{calls} evaluations");
        assert!((q - 2500f64.ln() / 2.0).abs() < 1e-4);
    }
}
