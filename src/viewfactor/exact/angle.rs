//! Fast two-argument arctangent for the kernels' angles (y ≥ 0, result in [0, π]).
//!
//! The contour and Lambert kernels evaluate one angle per edge and node; glibc's correctly
//! rounded `atan2` costs about 150 instructions, a third of the whole inner integral. Here:
//! octant reduction to |t| ≤ 1, then atan t = π/4 + atan((t − 1)/(t + 1)) for t > tan(π/8), and
//! atan z = z + z³·P(z²) with a degree-10 Chebyshev fit P on z² ≤ tan²(π/8) (max relative
//! error 1.1e-16 in double, fitted with mpmath). Plain Horner (no `mul_add`: without the FMA
//! target feature it is a libm call). About 1 ulp overall, checked in the tests.
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// tan(π/8): the reduction threshold.
const TAN_PI_8: f64 = 0.414_213_562_373_095_05;
/// Chebyshev-fit coefficients of (atan √s/√s − 1)/s on [0, tan²(π/8)], highest degree first.
const P: [f64; 11] = [
    -0.01917688711906226,
    0.03923165829558719,
    -0.0508544973794026,
    0.0585814891280221,
    -0.06664511447381948,
    0.07692183190826087,
    -0.09090904578123903,
    0.11111111015256361,
    -0.14285714284666542,
    0.1999999999999552,
    -0.3333333333333333,
];

/// atan z for |z| ≤ tan(π/8).
fn atan_small(z: f64) -> f64 {
    let s = z * z;
    let mut p = 0.0f64;
    for c in P {
        p = p * s + c;
    }
    z + z * s * p
}

/// atan t for |t| ≤ 1.
fn atan_unit(t: f64) -> f64 {
    let a = t.abs();
    if a <= TAN_PI_8 {
        return atan_small(t);
    }
    let r = FRAC_PI_4 + atan_small((a - 1.0) / (a + 1.0));
    r.copysign(t)
}

/// atan2(y, x) for y ≥ 0, in [0, π]; 0 when x = y = 0.
pub fn atan2_pos(y: f64, x: f64) -> f64 {
    if x >= y {
        if x == 0.0 {
            return 0.0;
        }
        atan_unit(y / x)
    } else if x > -y {
        FRAC_PI_2 - atan_unit(x / y)
    } else {
        PI - atan_unit(y / -x)
    }
}

/// atan2(y, x) for any y, in [−π, π] (the sign of a zero y is not honoured).
pub fn atan2(y: f64, x: f64) -> f64 {
    if y < 0.0 {
        -atan2_pos(-y, x)
    } else {
        atan2_pos(y, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_std_atan2_to_two_ulp() {
        let mut worst: f64 = 0.0;
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..200_000i32 {
            let y = next() * 10f64.powi(k % 9 - 4);
            let x = (next() - 0.5) * 10f64.powi(k % 7 - 3);
            let (got, want) = (atan2_pos(y, x), y.atan2(x));
            worst = worst.max((got - want).abs() / want.abs().max(f64::MIN_POSITIVE));
            let (got, want) = (atan2(-y, x), (-y).atan2(x));
            worst = worst.max((got - want).abs() / want.abs().max(f64::MIN_POSITIVE));
        }
        assert!(worst <= 2.0 * f64::EPSILON, "worst relative error {worst:e}");
        for (y, x) in
            [(0.0, 1.0), (0.0, -1.0), (1.0, 0.0), (1.0, 1.0), (1.0, -1.0), (0.0, 0.0), (1e-300, -1.0)]
        {
            assert!(
                (atan2_pos(y, x) - f64::atan2(y, x)).abs() <= 2.0 * f64::EPSILON * f64::atan2(y, x).abs(),
                "{y} {x}"
            );
        }
    }
}
