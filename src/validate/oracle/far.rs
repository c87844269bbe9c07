//! Tensor Gauss "2AI" reference, A_1 F_12 = ∫∫ cos θ_1 cos θ_2 / (π r²) dA_2 dA_1, for pairs
//! separated by several sizes, where the closed forms lose digits to cancellation (docs/literature.md
//! §2: round-off ≈ 1e-16·(c/L)²) while Gauss converges geometrically.
use crate::geometry::quadrature::gauss_legendre;
use glam::DVec3;
use std::f64::consts::PI;

/// A_1 F_12 between parallelograms (o, u, v) with n×n points on each: front normals u × v.
pub fn exchange_area_2ai(p: (DVec3, DVec3, DVec3), q: (DVec3, DVec3, DVec3), n: usize) -> f64 {
    let (x, w) = gauss_legendre(n);
    let (np, ap) = unit_and_area(p.1.cross(p.2));
    let (nq, aq) = unit_and_area(q.1.cross(q.2));
    let mut total = 0.0;
    for (xi, wi) in x.iter().zip(&w) {
        for (xj, wj) in x.iter().zip(&w) {
            let a = p.0 + xi * p.1 + xj * p.2;
            for (xk, wk) in x.iter().zip(&w) {
                for (xl, wl) in x.iter().zip(&w) {
                    let b = q.0 + xk * q.1 + xl * q.2;
                    let r = b - a;
                    let r2 = r.length_squared();
                    let c1 = np.dot(r).max(0.0);
                    let c2 = (-nq.dot(r)).max(0.0);
                    total += wi * wj * wk * wl * c1 * c2 / (r2 * r2);
                }
            }
        }
    }
    total * ap * aq / PI
}

fn unit_and_area(n: DVec3) -> (DVec3, f64) {
    let a = n.length();
    (n / a, a)
}

#[cfg(test)]
mod tests {
    use super::super::closed::parallel_rectangles;
    use super::*;

    /// Opposed unit squares at gap c (the far-field stability case).
    fn squares(c: f64, n: usize) -> f64 {
        let p = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let q = (DVec3::new(0.0, 0.0, c), DVec3::Y, DVec3::X);
        exchange_area_2ai(p, q, n)
    }

    #[test]
    fn gauss_agrees_with_c11_where_both_are_accurate() {
        for c in [3.0, 5.0, 10.0, 30.0] {
            let g = squares(c, 10);
            let exact = parallel_rectangles(1.0, 1.0, c);
            assert!(((g - exact) / exact).abs() < 1e-12, "c={c}: {g} vs {exact}");
        }
    }
}
