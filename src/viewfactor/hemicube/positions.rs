//! Where on a patch the projections are taken, against the proximity error.
//!
//! One projection at the centroid gives the *point* factor F(x_c → j), not the area average
//! A_i F_ij = ∫ F(x → j) dA: +20 % for opposed unit squares at unit gap, −5 % for adjacent ones
//! (literature.md §4, Baum et al. 1989). A q×q Gauss rule over the patch (a tensor rule on a
//! parallelogram, collapsed rules on the triangles of any other polygon) integrates that
//! smooth-away-from-neighbours point factor to O(size/distance)^(2q).
use super::prepare::Prepared;
use crate::geometry::quadrature::AreaRule;
use crate::geometry::Polygon;

/// Projection positions per patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Positions {
    /// One projection at the area centroid: the classic hemicube (point factors).
    Centroid,
    /// A fixed q×q Gauss rule on every patch (q = 1 is the centroid of a parallelogram).
    Gauss(usize),
    /// q chosen per patch from its size D against the distance d to its nearest neighbour in
    /// front: 1 while D ≤ [`NEAR_RATIO_1`]·d, 2 while D ≤ [`NEAR_RATIO_2`]·d, else 3.
    Adaptive,
}

/// Patch size / neighbour distance up to which one centroid projection is kept: the proximity
/// error of opposed squares is ≈ 0.3·(D/d)² relative (literature.md §4: 20 % at 1, 1.3 % at
/// 0.2), so 0.25 keeps it near 2 %, comparable to the pixel error at R = 64–128.
pub const NEAR_RATIO_1: f64 = 0.25;
/// Up to this ratio a 2×2 rule suffices (its error falls as (D/2d)⁴ for smooth neighbours);
/// beyond it, typically the patches touching another surface, 3×3 is used.
pub const NEAR_RATIO_2: f64 = 1.0;

/// Parallelogram test: |v0 + v2 − v1 − v3| below this fraction of the diameter.
const PARALLELOGRAM_TOL: f64 = 1e-12;

impl Positions {
    /// The Gauss order q for patch `i` of `prep`.
    pub(crate) fn order(self, prep: &Prepared, polygon: &Polygon, i: usize) -> usize {
        match self {
            Positions::Centroid => 1,
            Positions::Gauss(q) => q.max(1),
            Positions::Adaptive => {
                let size = 2.0 * polygon.bounding_radius();
                let d = prep.nearest_in_front(polygon.centroid(), polygon.normal(), i);
                if size <= NEAR_RATIO_1 * d {
                    1
                } else if size <= NEAR_RATIO_2 * d {
                    2
                } else {
                    3
                }
            }
        }
    }
}

/// Points (strictly inside) and weights (summing to the area) of a q×q rule on `polygon`;
/// q = 1 is the centroid.
pub(crate) fn rule(polygon: &Polygon, q: usize) -> AreaRule {
    if q <= 1 {
        return AreaRule { points: vec![polygon.centroid()], weights: vec![polygon.area()] };
    }
    let v = polygon.vertices();
    let diameter = 2.0 * polygon.bounding_radius();
    if v.len() == 4 && (v[0] + v[2] - v[1] - v[3]).length() <= PARALLELOGRAM_TOL * diameter {
        return AreaRule::parallelogram(v[0], v[1] - v[0], v[3] - v[0], q);
    }
    let mut all = AreaRule::default();
    for [a, b, c] in polygon.triangulate() {
        let r = AreaRule::triangle(a, b, c, q);
        all.points.extend(r.points);
        all.weights.extend(r.weights);
    }
    all
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn rules_cover_the_area_and_stay_inside() {
        let sq = Polygon::new(vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]).unwrap();
        let tri = Polygon::new(vec![DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::Y]).unwrap();
        let in_sq = |x: &DVec3| x.x > 0.0 && x.y > 0.0 && x.x < 1.0 && x.y < 1.0;
        let in_tri = |x: &DVec3| x.x > 0.0 && x.y > 0.0 && x.x + 2.0 * x.y < 2.0;
        for (p, q, n, inside) in [(&sq, 1, 1, &in_sq as &dyn Fn(&DVec3) -> bool), (&sq, 3, 9, &in_sq), (&tri, 2, 4, &in_tri)] {
            let r = rule(p, q);
            assert_eq!(r.points.len(), n);
            assert!((r.weights.iter().sum::<f64>() - p.area()).abs() < 1e-14);
            assert!(r.points.iter().all(inside), "{:?}", r.points);
        }
    }
}
