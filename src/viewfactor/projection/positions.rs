//! Where on a patch the projections are taken, against the proximity error.
//!
//! One projection at the centroid gives the *point* factor F(x_c → j), not the area average
//! A_i F_ij = ∫ F(x → j) dA: +20 % for opposed unit squares at unit gap, −5 % for adjacent ones
//! (docs/literature.md §4, Baum et al. 1989). A q×q Gauss rule over the patch (a tensor rule on a
//! parallelogram, collapsed rules on the triangles of any other polygon) integrates that
//! smooth-away-from-neighbours point factor to O(size/distance)^(2q).
//!
//! Frame orientation: [`Positions::Centroid`] keeps the classic frame along the patch's first
//! edge, so edges parallel to it project onto pixel rows (exact when they fall on pixel
//! boundaries, a systematic O(h) row error when they do not). The Gauss modes turn the frame
//! of position k by (k + 1) golden angles about the normal: the row errors of edges parallel
//! to the patch become independent pixel errors that average out over the positions
//! (parallel unit squares, 3×3 positions at R = 128: pixel error 5.8e-4 aligned, 3.0e-5
//! turned; tests/viewfactor/hemicube.rs).
use super::prepare::Prepared;
use crate::geometry::quadrature::AreaRule;
use crate::geometry::tolerance::PARALLELOGRAM_REL;
use crate::geometry::Polygon;
use glam::DVec2;

/// Projection positions per patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Positions {
    /// One projection at the area centroid: the classic hemicube (point factors).
    Centroid,
    /// A fixed q×q Gauss rule on every patch (q = 1 is the centroid of a parallelogram).
    Gauss(usize),
    /// q chosen per patch from its size D (diameter) against a lower bound d on the distance
    /// from its centroid to the nearest polygon in front: 1 while D ≤ `NEAR_RATIO_1`·d (0.3),
    /// 2 while D ≤ `NEAR_RATIO_2`·d (1.5), else 3 (about 1 % relative proximity error or less).
    Adaptive,
}

/// Patch size / neighbour distance up to which one projection is kept. The relative
/// proximity error of a single projection is ≈ 0.1·(D/d)² (opposed squares, docs/literature.md §4:
/// 20 % at D/d = 1.41, 1.3 % at 0.28), so 0.3 keeps it near 1 %, on small far factors.
pub const NEAR_RATIO_1: f64 = 0.3;
/// Up to this ratio a 2×2 rule; beyond it (patches touching another surface) 3×3. Measured
/// relative errors: 2×2 gives 7e-3 at D/d = 1.41 (C-11), scaling as (D/d)⁴, so ≈ 1 % at 1.5;
/// 3×3 gives 1e-4 at 1.41 and 2.4e-5 at 2.83 (C-14, adjacent).
pub const NEAR_RATIO_2: f64 = 1.5;

/// The golden angle π(3 − √5): successive turns never repeat modulo the faces' 90° symmetry.
const GOLDEN_ANGLE: f64 = 2.399963229728653;

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

impl Positions {
    /// Turn of position k's frame about the normal, radians (module docs).
    pub(crate) fn turn(self, k: usize) -> f64 {
        match self {
            Positions::Centroid => 0.0,
            Positions::Gauss(_) | Positions::Adaptive => (k + 1) as f64 * GOLDEN_ANGLE,
        }
    }
}

/// Points and weights (summing to the area) of a q×q rule on `polygon`; q = 1 is the
/// centroid. Parallelograms get the tensor Gauss rule and triangles the collapsed one (points
/// strictly inside); any other polygon is cut by a q×q grid of its bounding box in its own
/// frame, each piece contributing its centroid and area (a composite midpoint rule: at most
/// q² positions however many vertices, e.g. a 64-gon disk).
pub(crate) fn rule(polygon: &Polygon, q: usize) -> AreaRule {
    if q <= 1 {
        return AreaRule { points: vec![polygon.centroid()], weights: vec![polygon.area()] };
    }
    let v = polygon.vertices();
    let diameter = 2.0 * polygon.bounding_radius();
    if v.len() == 3 {
        return AreaRule::triangle(v[0], v[1], v[2], q);
    }
    if v.len() == 4 && (v[0] + v[2] - v[1] - v[3]).length() <= PARALLELOGRAM_REL * diameter {
        return AreaRule::parallelogram(v[0], v[1] - v[0], v[3] - v[0], q);
    }
    let n = polygon.normal();
    let t = (v[1] - v[0]).normalize();
    let b = n.cross(t);
    let (lo, hi) = v.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
        let uv = DVec2::new((*p - v[0]).dot(t), (*p - v[0]).dot(b));
        (lo.min(uv), hi.max(uv))
    });
    let step = (hi - lo) / q as f64;
    let mut all = AreaRule::default();
    for i in 0..q {
        for j in 0..q {
            let c0 = v[0] + t * (lo.x + i as f64 * step.x) + b * (lo.y + j as f64 * step.y);
            let c1 = c0 + t * step.x + b * step.y;
            let piece = polygon
                .clip(c0, t)
                .and_then(|p| p.clip(c0, b))
                .and_then(|p| p.clip(c1, -t))
                .and_then(|p| p.clip(c1, -b));
            if let Some(p) = piece {
                all.points.push(p.centroid());
                all.weights.push(p.area());
            }
        }
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
        let hexagon = Polygon::new(
            (0..6)
                .map(|k| {
                    let a = k as f64 * std::f64::consts::PI / 3.0;
                    DVec3::new(0.5 + 0.4 * a.cos(), 0.5 + 0.4 * a.sin(), 0.0)
                })
                .collect(),
        )
        .unwrap();
        let r = rule(&hexagon, 3);
        assert!(r.points.len() <= 9 && (r.weights.iter().sum::<f64>() - hexagon.area()).abs() < 1e-14);
        assert!(r.points.iter().all(|x| (x.x - 0.5).hypot(x.y - 0.5) < 0.4));
        for (p, q, n, inside) in
            [(&sq, 1, 1, &in_sq as &dyn Fn(&DVec3) -> bool), (&sq, 3, 9, &in_sq), (&tri, 2, 4, &in_tri)]
        {
            let r = rule(p, q);
            assert_eq!(r.points.len(), n);
            assert!((r.weights.iter().sum::<f64>() - p.area()).abs() < 1e-14);
            assert!(r.points.iter().all(inside), "{:?}", r.points);
        }
    }
}
