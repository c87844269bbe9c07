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
/// ln(1/ε) for the per-interval target ρ^(−2n) ≤ ε = 1e-15. Measured on 3000 random near
/// polygon pairs against a 1e-26 target: the differences stay below 0.2 of the contour
/// round-off bound for any value from 33 up, and exceed it 150-fold at 25.
const LN_INV_EPS: f64 = 34.5;
/// Split point, as a fraction of the interval, when a singularity sits at or beyond an end:
/// the far piece then has ρ ≥ 2 + √3 at once, which 14 points integrate to 1e-15.
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
    let da = ((s.x - l) * (s.x - l) + s.y * s.y).sqrt();
    let db = ((s.x - r) * (s.x - r) + s.y * s.y).sqrt();
    let a = (da + db) / (r - l);
    a + (a * a - 1.0).max(0.0).sqrt()
}

/// Gauss points needed for ρ^(−2n) ≤ ε.
fn points_for(rho: f64, ln_inv_eps: f64) -> usize {
    if rho <= 1.0 {
        return usize::MAX;
    }
    ((ln_inv_eps / (2.0 * rho.ln())).ceil() as usize).max(N_MIN)
}

/// ∫₀ᴸ f(σ) dσ for an `f` analytic except at `sing` (and their conjugates).
pub fn integrate(len: f64, sing: &[Singularity], f: impl FnMut(f64) -> f64) -> f64 {
    integrate_to(len, sing, LN_INV_EPS, f)
}

/// [`integrate`] with a per-interval target ρ^(−2n) ≤ e^(−`ln_inv_eps`).
pub fn integrate_to(len: f64, sing: &[Singularity], ln_inv_eps: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let rules = rules();
    // Step: fast path, one rule on the whole interval (far pairs).
    let (rho, worst) = nearest(sing, 0.0, len);
    let n = points_for(rho, ln_inv_eps);
    if n <= N_MAX {
        return gauss(&rules[n - 1], 0.0, len, &mut f);
    }
    let min_piece = MIN_PIECE * len;
    let mut stack = [(0.0f64, 0.0f64); STACK];
    let mut top = split(&mut stack, 0, 0.0, len, worst);
    let mut total = 0.0;
    while top > 0 {
        top -= 1;
        let (l, r) = stack[top];
        let (rho, worst) = nearest(sing, l, r);
        let n = points_for(rho, ln_inv_eps);
        if n <= N_MAX || r - l <= min_piece || top + 2 > STACK {
            total += gauss(&rules[n.min(N_MAX) - 1], l, r, &mut f);
        } else {
            top = split(&mut stack, top, l, r, worst);
        }
    }
    total
}

/// The smallest Bernstein parameter over `sing` for [l, r], with its singularity.
fn nearest(sing: &[Singularity], l: f64, r: f64) -> (f64, Singularity) {
    let mut best = (f64::INFINITY, Singularity { x: 0.5 * (l + r), y: f64::INFINITY });
    for &s in sing {
        let q = bernstein_rho(s, l, r);
        if q < best.0 {
            best = (q, s);
        }
    }
    best
}

/// One n-point Gauss rule on [l, r].
fn gauss(rule: &(Vec<f64>, Vec<f64>), l: f64, r: f64, f: &mut impl FnMut(f64) -> f64) -> f64 {
    let h = r - l;
    h * rule.0.iter().zip(&rule.1).map(|(&x, &w)| w * f(l + h * x)).sum::<f64>()
}

/// Pushes the halves of [l, r], split at the singularity's real part when it lies well inside,
/// else a third of the way towards it; returns the new stack top.
fn split(stack: &mut [(f64, f64)], top: usize, l: f64, r: f64, s: Singularity) -> usize {
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
    top + 2
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
