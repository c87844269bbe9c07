//! Polygon-to-polygon exchange area A_p F_pq by the double contour integral
//! (literature.md §2, "robust integrator recipe"):
//!
//! A_p F_pq = (1/2π) Σ_i Σ_j (e_i·f_j) I_ij,   I_ij = ∫₀¹∫₀¹ ln‖p_i + s e_i − q_j − t f_j‖ ds dt,
//!
//! with both rings counter-clockwise about their own normals. Steps:
//! 1. coplanar pairs give exactly 0;
//! 2. each polygon is clipped to the other's front half-space (back-facing → 0; this also covers
//!    intersecting and touching planes), so every point of one sees the whole contour of the other;
//! 3. coordinates are shifted to the pair's centre and scaled by a power of two L (exact), so
//!    ln r is ln(r/L): the constant drops out because Σ e_i·f_j = 0 over closed rings;
//! 4. every edge pair is evaluated exactly by [`super::edge::pair_term`].
//!
//! No vertex is nudged; shared vertices and edges are exact limits of the formulas.
use super::edge::{pair_term, Edge};
use super::ring::{classify, clip_into, Ring, Side, INLINE};
use crate::geometry::Polygon;
use glam::DVec3;
use std::f64::consts::TAU;

/// A polygon whose vertices all lie within this distance (normalised frame, i.e. relative to
/// the pair's size) of the other's plane is coplanar with it: F = 0. Round-off level, so
/// nearly coplanar geometry is still integrated as given.
const COPLANAR: f64 = 1e-12;
/// Clipping counts vertices within this distance (normalised) of the plane as on it, so a
/// polygon touching the other's plane along an edge is kept whole, not cut into slivers.
const CLIP_SNAP: f64 = 1e-13;

/// Exchange area A_p F_pq between the front faces of two planar polygons, m².
pub fn polygon_polygon(p: &Polygon, q: &Polygon) -> f64 {
    ring_ring(p.vertices(), p.normal(), q.vertices(), q.normal())
}

/// Exchange area between two planar rings (counter-clockwise about unit normals `np`, `nq`),
/// clipped to each other's front half-space; the rings are not validated.
pub fn ring_ring(p: &[DVec3], np: DVec3, q: &[DVec3], nq: DVec3) -> f64 {
    if p.len() < 3 || q.len() < 3 {
        return 0.0;
    }
    // Step: normalised frame centred on the pair, scaled by a power of two.
    let cp = mean(p);
    let cq = mean(q);
    let origin = 0.5 * (cp + cq);
    let reach = p.iter().chain(q).map(|v| v.distance_squared(origin)).fold(0.0, f64::max).sqrt();
    if !(reach > 0.0 && reach.is_finite()) {
        return 0.0;
    }
    let scale = 2f64.powi(reach.log2().ceil() as i32);
    let inv = 1.0 / scale;
    let (mut pr, mut qr) = (Ring::new(), Ring::new());
    pr.fill_mapped(p, origin, inv);
    qr.fill_mapped(q, origin, inv);
    let (op, oq) = ((cp - origin) * inv, (cq - origin) * inv);
    // Step: coplanar pairs exchange nothing.
    let coplanar =
        |ring: &Ring, o: DVec3, n: DVec3| ring.as_slice().iter().all(|v| (*v - o).dot(n).abs() <= COPLANAR);
    if coplanar(&qr, op, np) || coplanar(&pr, oq, nq) {
        return 0.0;
    }
    // Step: each polygon clipped to the other's front half-space.
    let (mut pc, mut qc) = (Ring::new(), Ring::new());
    let p_ring = match classify(pr.as_slice(), oq, nq, CLIP_SNAP) {
        Side::Outside => return 0.0,
        Side::Inside => pr.as_slice(),
        Side::Cut => {
            clip_into(pr.as_slice(), oq, nq, CLIP_SNAP, &mut pc);
            pc.as_slice()
        }
    };
    let q_ring = match classify(qr.as_slice(), op, np, CLIP_SNAP) {
        Side::Outside => return 0.0,
        Side::Inside => qr.as_slice(),
        Side::Cut => {
            clip_into(qr.as_slice(), op, np, CLIP_SNAP, &mut qc);
            qc.as_slice()
        }
    };
    if p_ring.len() < 3 || q_ring.len() < 3 {
        return 0.0;
    }
    // Step: the double sum over edge pairs.
    let sum = with_edges(q_ring, |fs| {
        let n = p_ring.len();
        let mut sum = 0.0;
        for i in 0..n {
            let e = Edge::new(p_ring[i], p_ring[(i + 1) % n]);
            if e.len == 0.0 {
                continue;
            }
            sum += fs.iter().filter(|f| f.len > 0.0).map(|f| pair_term(&e, f)).sum::<f64>();
        }
        sum
    });
    (sum / TAU * scale * scale).max(0.0)
}

/// Vertex average (a point of the ring's plane).
fn mean(v: &[DVec3]) -> DVec3 {
    v.iter().copied().sum::<DVec3>() / v.len() as f64
}

/// Calls `f` with the edges of `ring`, on the stack when the ring is small.
fn with_edges<R>(ring: &[DVec3], f: impl FnOnce(&[Edge]) -> R) -> R {
    let n = ring.len();
    let edge = |k: usize| Edge::new(ring[k], ring[(k + 1) % n]);
    if n <= INLINE {
        let mut buf = [Edge::new(DVec3::ZERO, DVec3::ZERO); INLINE];
        for (k, slot) in buf.iter_mut().enumerate().take(n) {
            *slot = edge(k);
        }
        f(&buf[..n])
    } else {
        let edges: Vec<Edge> = (0..n).map(edge).collect();
        f(&edges)
    }
}
