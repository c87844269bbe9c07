//! Element-to-polygon and element-to-disk factors.
//!
//! Lambert (1760), docs/literature.md V12: for an element at p with unit normal n and a ring
//! counter-clockwise about its normal (which faces p),
//! F = −(1/2π) ∮ n·(R × dR)/|R|² = (1/2π) Σ_k β_k n·(R_{k+1} × R_k)/‖R_{k+1} × R_k‖,
//! R_k = v_k − p, β_k = ∠(R_k, R_{k+1}). Valid when the whole ring lies in the element's
//! front half-space, hence the clip in [`point_to_polygon`].
//!
//! The disk uses the same contour integral on the exact circle (see `super::disk`).
use super::angle::atan2_pos;
use super::ring::{classify, clip_into, Ring, Side};
use crate::geometry::tolerance::POINT_IN_PLANE_REL;
use crate::geometry::Polygon;
use glam::DVec3;
use std::f64::consts::TAU;

pub use super::disk::point_to_disk;

/// Lambert point-to-polygon factor F(dA → poly) for an element at `p` with unit normal `n`,
/// polygon clipped to the element's front half-space first (docs/literature.md V12).
pub fn point_to_polygon(p: DVec3, n: DVec3, poly: &Polygon) -> f64 {
    let size = poly.bounding_radius();
    if poly.plane_distance(p) <= POINT_IN_PLANE_REL * size {
        return 0.0;
    }
    let v = poly.vertices();
    match classify(v, p, n, POINT_IN_PLANE_REL * size) {
        Side::Outside => 0.0,
        Side::Inside => point_to_ring(p, n, v).max(0.0),
        Side::Cut => {
            let mut clipped = Ring::new();
            clip_into(v, p, n, POINT_IN_PLANE_REL * size, &mut clipped);
            if clipped.is_empty() {
                return 0.0;
            }
            point_to_ring(p, n, clipped.as_slice()).max(0.0)
        }
    }
}

/// Same on a raw vertex ring (no validation), for callers that clip themselves.
///
/// Signed: positive when the ring runs counter-clockwise about a normal pointing towards `p`;
/// the ring must lie in the element's front half-space.
pub fn point_to_ring(p: DVec3, n: DVec3, ring: &[DVec3]) -> f64 {
    let m = ring.len();
    if m < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    let mut a = ring[m - 1] - p;
    for &v in ring {
        let b = v - p;
        sum += edge_term(n, a, b);
        a = b;
    }
    sum / TAU
}

/// β·n·(b × a)/‖b × a‖ for one edge seen from the element: the edge's Lambert term.
pub fn edge_term(n: DVec3, a: DVec3, b: DVec3) -> f64 {
    let c = b.cross(a);
    let len = c.length();
    if len == 0.0 {
        return 0.0;
    }
    atan2_pos(len, a.dot(b)) * n.dot(c) / len
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_square_overhead_matches_corner_sum() {
        // Element at the origin facing +z, square [−1, 1]² at height 1 facing down:
        // four V10 corners, each (1/2π)(2/√2)·atan(1/√2).
        let sq = Polygon::new(vec![
            DVec3::new(-1.0, -1.0, 1.0),
            DVec3::new(-1.0, 1.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, 1.0),
        ])
        .unwrap();
        assert!(sq.normal().z < 0.0);
        let corner = (2.0 / 2f64.sqrt()) * (1.0 / 2f64.sqrt()).atan() / TAU;
        let f = point_to_polygon(DVec3::ZERO, DVec3::Z, &sq);
        assert!((f - 4.0 * corner).abs() < 1e-15, "{f} vs {}", 4.0 * corner);
        // Seen from behind, or facing away: nothing.
        assert_eq!(point_to_polygon(DVec3::new(0.0, 0.0, 2.0), DVec3::Z, &sq), 0.0);
        assert_eq!(point_to_polygon(DVec3::ZERO, -DVec3::Z, &sq), 0.0);
    }
}
