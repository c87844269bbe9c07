//! Blackbody band fractions F_{0→λT} (fraction of σT⁴ emitted below wavelength λ) and their
//! derivative, from the two convergent series of ζ = c₂/(λT):
//! - ζ ≥ 2: F = (15/π⁴) Σ_n e^{−nζ} (ζ³/n + 3ζ²/n² + 6ζ/n³ + 6/n⁴) (Chang & Rhee);
//! - ζ < 2: F = 1 − (15/π⁴) ∫₀^ζ t³/(eᵗ − 1) dt with the Bernoulli expansion
//!   ∫₀^ζ = ζ³/3 − ζ⁴/8 + Σ_m B_{2m} ζ^{2m+3} / ((2m+3)(2m)!), radius 2π.
//!
//! Both are accurate to ~1e-15 absolute where used (tests check 1e-10 against quadrature).
use std::f64::consts::PI;

/// Second radiation constant c₂ = hc/k, µm·K (CODATA 2018).
pub const C2: f64 = 14_387.768_775;
/// Switch between the two series: at ζ = 2 both converge fast (e^{-2n}, (1/π)^{2m}).
const ZETA_SWITCH: f64 = 2.0;
/// Terms of the exponential series: e^{-2·40} ≈ 2e-35.
const EXP_TERMS: usize = 40;
/// B_{2m}, m = 1..12.
const BERNOULLI: [f64; 12] = [
    1.0 / 6.0,
    -1.0 / 30.0,
    1.0 / 42.0,
    -1.0 / 30.0,
    5.0 / 66.0,
    -691.0 / 2730.0,
    7.0 / 6.0,
    -3617.0 / 510.0,
    43867.0 / 798.0,
    -174611.0 / 330.0,
    854513.0 / 138.0,
    -236364091.0 / 2730.0,
];

/// F_{0→λT} for λT in µm·K (0 at 0, 1 at ∞).
pub fn fraction(lambda_t: f64) -> f64 {
    if lambda_t <= 0.0 {
        return 0.0;
    }
    if !lambda_t.is_finite() {
        return 1.0;
    }
    let z = C2 / lambda_t;
    let c = 15.0 / PI.powi(4);
    if z >= ZETA_SWITCH {
        let mut sum = 0.0;
        for n in 1..=EXP_TERMS {
            let nf = n as f64;
            let term = (-nf * z).exp()
                * (z.powi(3) / nf + 3.0 * z * z / (nf * nf) + 6.0 * z / nf.powi(3) + 6.0 / nf.powi(4));
            sum += term;
            if term < 1e-18 * sum {
                break;
            }
        }
        c * sum
    } else {
        let mut integral = z.powi(3) / 3.0 - z.powi(4) / 8.0;
        let mut fact = 1.0; // (2m)!
        for (k, b) in BERNOULLI.iter().enumerate() {
            let m = (k + 1) as f64;
            fact *= (2.0 * m - 1.0) * (2.0 * m);
            integral += b * z.powf(2.0 * m + 3.0) / ((2.0 * m + 3.0) * fact);
        }
        1.0 - c * integral
    }
}

/// dF/d(λT), per µm·K: (15/π⁴) ζ⁴ / (λT (e^ζ − 1)).
pub fn fraction_derivative(lambda_t: f64) -> f64 {
    if lambda_t <= 0.0 || !lambda_t.is_finite() {
        return 0.0;
    }
    let z = C2 / lambda_t;
    15.0 / PI.powi(4) * z.powi(4) / (lambda_t * z.exp_m1())
}

/// Fraction of σT⁴ between `lower` and `upper` (µm; `upper` may be ∞) at temperature `t`.
pub fn band_fraction(lower: f64, upper: f64, t: f64) -> f64 {
    fraction(upper * t) - fraction(lower * t)
}

/// Band emissive power E_bk = f_k(T) σT⁴ and its derivative dE_bk/dT.
pub fn band_power(lower: f64, upper: f64, t: f64) -> (f64, f64) {
    let s = crate::SIGMA;
    let f = band_fraction(lower, upper, t);
    let df = upper_term(upper, t) - upper_term(lower, t);
    (f * s * t.powi(4), 4.0 * s * t.powi(3) * f + s * t.powi(4) * df)
}

/// λ F'(λT): the derivative of F(λT) with respect to T.
fn upper_term(lambda: f64, t: f64) -> f64 {
    if lambda <= 0.0 || !lambda.is_finite() {
        0.0
    } else {
        lambda * fraction_derivative(lambda * t)
    }
}
