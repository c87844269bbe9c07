//! Gauss rules: Gauss–Legendre on [0, 1], tensor rules on parallelograms and collapsed
//! (Duffy) Gauss rules on triangles, any order.
use glam::DVec3;

/// Gauss–Legendre nodes and weights on [0, 1] (weights sum to 1), exact for degree 2n − 1.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1, "a Gauss rule needs at least one node");
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Newton on P_n from the Chebyshev-like initial guess.
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 1 { z } else { p1 };
            let pnm1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * pn - pnm1) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        x[i] = 0.5 * (1.0 - z);
        x[n - 1 - i] = 0.5 * (1.0 + z);
        w[i] = 0.5 * wi;
        w[n - 1 - i] = 0.5 * wi;
    }
    (x, w)
}

/// A point rule on a planar region: points with weights that sum to the region's area.
#[derive(Debug, Clone, Default)]
pub struct AreaRule {
    /// Quadrature points.
    pub points: Vec<DVec3>,
    /// Weights, m²; they sum to the area.
    pub weights: Vec<f64>,
}

impl AreaRule {
    /// n×n tensor Gauss rule on the parallelogram o + s·u + t·v, s, t ∈ [0, 1].
    pub fn parallelogram(o: DVec3, u: DVec3, v: DVec3, n: usize) -> Self {
        let (x, w) = gauss_legendre(n);
        let area = u.cross(v).length();
        let mut r = AreaRule::default();
        for i in 0..n {
            for j in 0..n {
                r.points.push(o + x[i] * u + x[j] * v);
                r.weights.push(area * w[i] * w[j]);
            }
        }
        r
    }

    /// Collapsed n×n Gauss rule on a triangle (Duffy map), exact for degree 2n − 1.
    pub fn triangle(a: DVec3, b: DVec3, c: DVec3, n: usize) -> Self {
        let (x, w) = gauss_legendre(n);
        let area = 0.5 * (b - a).cross(c - a).length();
        let mut r = AreaRule::default();
        for i in 0..n {
            for j in 0..n {
                let (s, t) = (x[i], x[j] * (1.0 - x[i]));
                r.points.push(a + s * (b - a) + t * (c - a));
                r.weights.push(2.0 * area * w[i] * w[j] * (1.0 - x[i]));
            }
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in 1..=20 {
            let (x, w) = gauss_legendre(n);
            for deg in 0..2 * n {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = 1.0 / (deg as f64 + 1.0);
                assert!((q - exact).abs() < 1e-14, "n={n} deg={deg}: {q} vs {exact}");
            }
        }
    }

    #[test]
    fn triangle_rule_integrates_monomials() {
        // ∫ x² over the unit right triangle = 1/12.
        let r = AreaRule::triangle(DVec3::ZERO, DVec3::X, DVec3::Y, 3);
        let q: f64 = r.points.iter().zip(&r.weights).map(|(p, w)| w * p.x * p.x).sum();
        assert!((q - 1.0 / 12.0).abs() < 1e-15);
        assert!((r.weights.iter().sum::<f64>() - 0.5).abs() < 1e-15);
    }
}
