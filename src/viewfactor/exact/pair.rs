//! Polygon-to-polygon exchange area A_p F_pq, exact: the double contour integral
//! ([`super::contour`]), or, for a polygon much larger than the other and than their distance,
//! the near/far split (`super::split`) whose terms do not cancel.
use super::contour::{contour, mean, radius, Exchange};
use super::split;
use crate::geometry::Polygon;
use glam::DVec3;

/// Exchange area A_p F_pq between the front faces of two planar polygons, m².
pub fn polygon_polygon(p: &Polygon, q: &Polygon) -> f64 {
    ring_ring(p.vertices(), p.normal(), q.vertices(), q.normal()).value
}

/// [`polygon_polygon`] with its round-off bound.
pub fn polygon_polygon_with_round_off(p: &Polygon, q: &Polygon) -> Exchange {
    ring_ring(p.vertices(), p.normal(), q.vertices(), q.normal())
}

/// Exchange area between two planar rings (counter-clockwise about unit normals `np`, `nq`),
/// clipped to each other's front half-space; the rings are not validated.
pub fn ring_ring(p: &[DVec3], np: DVec3, q: &[DVec3], nq: DVec3) -> Exchange {
    if p.len() < 3 || q.len() < 3 {
        return Exchange::default();
    }
    // Step: a polygon much larger than the other and than their distance goes to the split
    // of [`super::split`], whose terms do not cancel.
    let (cp, cq) = (mean(p), mean(q));
    let (rp, rq) = (radius(p, cp), radius(q, cq));
    let (hp, hq) = (nq.dot(cp - q[0]).abs(), np.dot(cq - p[0]).abs());
    match split::small_side(rp, rq, hp, hq) {
        Some(true) => split::exchange(p, np, cp, rp, q, nq),
        Some(false) => split::exchange(q, nq, cq, rq, p, np),
        None => contour((p, np, cp, rp), (q, nq, cq, rq)),
    }
}
