//! Lambert's point-to-polygon configuration factor (docs/literature.md V12) and its Gauss integral over
//! an emitter polygon: A_1 F_12 = ∫_{A_1} F(dA → A_2) dA.
use crate::geometry::quadrature::gauss_legendre;
use glam::DVec3;
use std::f64::consts::PI;

/// Keeps the part of `ring` with `(x − p)·n ≥ 0` (Sutherland–Hodgman on a convex ring).
// The oracle keeps its own clipper: it must not share code with what it checks.
pub fn clip_ring(ring: &[DVec3], p: DVec3, n: DVec3) -> Vec<DVec3> {
    let d: Vec<f64> = ring.iter().map(|v| (*v - p).dot(n)).collect();
    let mut out = Vec::with_capacity(ring.len() + 2);
    for k in 0..ring.len() {
        let k1 = (k + 1) % ring.len();
        let (a, b, da, db) = (ring[k], ring[k1], d[k], d[k1]);
        if da >= 0.0 {
            out.push(a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// Unit normal of a planar ring by Newell's rule (counter-clockwise ⇒ right-hand normal).
pub fn ring_normal(ring: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for k in 0..ring.len() {
        n += ring[k].cross(ring[(k + 1) % ring.len()]);
    }
    n.normalize()
}

/// F(dA → polygon) by Lambert (1760), V12: the element at `p` with unit normal `n` sees the
/// one-sided `ring` (counter-clockwise about its front normal) clipped to its front half-space.
pub fn point_to_ring(p: DVec3, n: DVec3, ring: &[DVec3]) -> f64 {
    // One-sided receiver: an element behind the receiver's plane sees its back side.
    let rn = ring_normal(ring);
    if (p - ring[0]).dot(rn) <= 0.0 {
        return 0.0;
    }
    let clipped = clip_ring(ring, p, n);
    if clipped.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..clipped.len() {
        let a = clipped[k] - p;
        let b = clipped[(k + 1) % clipped.len()] - p;
        let c = a.cross(b);
        let len = c.length();
        if len > 0.0 {
            // β_k · cos α_k with β_k = atan2(|a×b|, a·b).
            sum += len.atan2(a.dot(b)) * n.dot(c) / len;
        }
    }
    // Seen from the front, a receiver's counter-clockwise ring runs clockwise: sign flips.
    (-sum / (2.0 * PI)).max(0.0)
}

/// Exchange area A_1 F_12 by composite Gauss on a parallelogram emitter o + s·u + t·v
/// (`cells`² cells, `order`² points each) of Lambert's factor to `receiver`. Exponentially
/// convergent when F(dA → A_2) is smooth over the emitter (separated pairs).
pub fn exchange_area_parallelogram(
    o: DVec3,
    u: DVec3,
    v: DVec3,
    receiver: &[DVec3],
    cells: usize,
    order: usize,
) -> f64 {
    let n = u.cross(v);
    let area = n.length();
    let n = n / area;
    let (x, w) = gauss_legendre(order);
    let h = 1.0 / cells as f64;
    let mut total = 0.0;
    for ci in 0..cells {
        for cj in 0..cells {
            let mut cell = 0.0;
            for (xi, wi) in x.iter().zip(&w) {
                for (xj, wj) in x.iter().zip(&w) {
                    let p = o + (ci as f64 + xi) * h * u + (cj as f64 + xj) * h * v;
                    cell += wi * wj * point_to_ring(p, n, receiver);
                }
            }
            total += cell;
        }
    }
    total * area * h * h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Literature V12 reference (2-D adaptive quadrature): 0.131969942498.
    const V12: f64 = 0.131969942498;

    #[test]
    fn point_to_triangle_matches_v12() {
        // V12 lists the vertices counter-clockwise as seen from the point, i.e. clockwise about
        // the receiver's own front normal; reverse them for our one-sided convention.
        let tri = [DVec3::new(0.1, 1.2, 1.6), DVec3::new(1.5, 0.4, 0.7), DVec3::new(0.2, -0.3, 1.0)];
        let f = point_to_ring(DVec3::ZERO, DVec3::Z, &tri);
        assert!((f - V12).abs() < 1e-11, "V12: {f}");
    }

    #[test]
    fn back_side_and_behind_give_zero() {
        let facing_up = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 1.0)];
        assert_eq!(point_to_ring(DVec3::ZERO, DVec3::Z, &facing_up), 0.0);
        let facing_down = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 1.0), DVec3::new(1.0, 0.0, 1.0)];
        assert_eq!(point_to_ring(DVec3::ZERO, -DVec3::Z, &facing_down), 0.0);
        assert!(point_to_ring(DVec3::ZERO, DVec3::Z, &facing_down) > 0.0);
    }
}
