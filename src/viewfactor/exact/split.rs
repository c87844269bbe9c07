//! Pairs of very different size: a small polygon s close to a polygon b many times larger
//! (a patch over a wide ground, a triangle stretched by a far vertex).
//!
//! The double contour integral of [`super::contour`] sums terms of the size of s's edges
//! times b's edges; when b is R times larger than s and than their distance, those terms
//! cancel to a result about R² times smaller, and the round-off grows with R² (a unit square
//! over a 1e9 m triangle: F = 10.3 instead of 0.258). Here b is split instead:
//!
//! A_s F_sb = A_s F_{s,b∩B} + ∫_s [F(x → b) − F(x → b∩B)] dA_x,
//!
//! with B the square of half-width D = [`NEAR_BOX`]·max(r_s, h) in b's plane around the foot
//! of s's centre (r_s: s's radius, h: its height over b's plane). The first term is the
//! contour integral between polygons of comparable size (b∩B is at most 2√2·D wide), so it
//! keeps full relative accuracy. In the second, b outside B is at least D − r_s from every
//! point of s, so the point factor of the far part is analytic over s and a Gauss rule on s
//! converges geometrically; each point factor is Lambert's formula (well conditioned at any
//! size: its terms are angles, not logarithms), and their difference is accurate to round-off
//! of F ≤ 1. When s is high above b (h ≥ [`HIGH`]·r_s) the whole point factor is analytic
//! over s and the Gauss rule alone is used.
//!
//! The Gauss error is estimated by comparing two orders ([`super::cubature`]: at the slowest
//! convergence here, singularity 3 r_s away, ρ ≥ 5.8, the higher order is 5.8⁻¹² ≈ 1e-9
//! times closer, so the difference over-estimates the error); it and the round-off make the
//! [`Exchange::round_off`] bound the kernel checks.
use super::contour::{ring_ring_unsplit, Exchange};
use super::cubature::{fan as integrate, POINT_ROUND_OFF};
use super::lambert::point_to_ring;
use super::ring::{classify, clip_into, Ring, Side};
use crate::geometry::tolerance::CONTOUR_CLIP_SNAP_REL;
use glam::DVec3;

/// A pair is split when the larger polygon's radius exceeds this many times max(r_s, h) of
/// the smaller: the contour's round-off, ε·(ratio)², then passes 1e-13 relative. Above
/// 2√2·[`NEAR_BOX`], so the near part never qualifies again.
pub const SPLIT_RATIO: f64 = 32.0;
/// Half-width of the near box in units of max(r_s, h): the far part is then at least 7 r_s
/// from s, so the Gauss rules below converge like 14^(−2n).
pub const NEAR_BOX: f64 = 8.0;
/// Above this height over b's plane (in units of r_s) the whole point factor is analytic
/// over s (nearest singularity 3 r_s away) and no contour part is needed.
pub const HIGH: f64 = 4.0;

/// Which polygon is small, when a pair needs the split: `Some(true)` when p is the small one.
pub fn small_side(rp: f64, rq: f64, hp: f64, hq: f64) -> Option<bool> {
    if rq > SPLIT_RATIO * rp.max(hp) {
        Some(true)
    } else if rp > SPLIT_RATIO * rq.max(hq) {
        Some(false)
    } else {
        None
    }
}

/// Exchange area between the small ring `s` (normal `ns`, centre `cs`, radius `rs`) and the
/// large ring `b` (normal `nb`), both counter-clockwise about their normals.
pub fn exchange(s: &[DVec3], ns: DVec3, cs: DVec3, rs: f64, b: &[DVec3], nb: DVec3) -> Exchange {
    // Step: a local frame centred on s, so nothing below depends on where the pair sits.
    let local = |v: &[DVec3]| -> Vec<DVec3> { v.iter().map(|x| *x - cs).collect() };
    let (s, b) = (local(s), local(b));
    let h = nb.dot(-b[0]);
    // Step: s clipped to b's front half-space (the part of s that sees b's front).
    let snap = CONTOUR_CLIP_SNAP_REL * rs;
    let mut s_front = Ring::new();
    match classify(&s, b[0], nb, snap) {
        Side::Outside => return Exchange::default(),
        Side::Inside => s.iter().for_each(|&v| s_front.push(v)),
        Side::Cut => clip_into(&s, b[0], nb, snap, &mut s_front),
    }
    if s_front.len() < 3 {
        return Exchange::default();
    }
    // Step: b clipped to s's front half-space (the same for every point of s).
    let Some(b_front) = front_of(&b, DVec3::ZERO, ns, snap) else { return Exchange::default() };
    if h.abs() >= HIGH * rs {
        let far = integrate(s_front.as_slice(), ns, |x| point_to_ring(x, ns, b_front.as_slice()));
        let round_off = point_round_off(b_front.len()) * area(s_front.as_slice(), ns);
        return Exchange { value: far.value.max(0.0), round_off: far.error + round_off };
    }
    // Step: the near part, b inside the box B around the foot of s's centre.
    let d = NEAR_BOX * rs.max(h.abs());
    let foot = -h * nb;
    let u = nb.any_orthonormal_vector();
    let v = nb.cross(u);
    let mut near = Ring::new();
    b.iter().for_each(|&x| near.push(x));
    for dir in [u, -u, v, -v] {
        let mut cut = Ring::new();
        clip_into(near.as_slice(), foot - d * dir, dir, snap, &mut cut);
        near = cut;
        if near.len() < 3 {
            break;
        }
    }
    let contour = if near.len() >= 3 {
        ring_ring_unsplit(s.as_slice(), ns, near.as_slice(), nb)
    } else {
        near.clear();
        Exchange::default()
    };
    // Step: the far part, F(x → b) − F(x → b∩B) over s by the Gauss rule.
    let near_front = if near.len() >= 3 { front_of(near.as_slice(), DVec3::ZERO, ns, snap) } else { None };
    let far = integrate(s_front.as_slice(), ns, |x| {
        let whole = point_to_ring(x, ns, b_front.as_slice());
        whole - near_front.as_ref().map_or(0.0, |r| point_to_ring(x, ns, r.as_slice()))
    });
    let vertices = b_front.len() + near_front.as_ref().map_or(0, |r| r.len());
    let round_off = point_round_off(vertices) * area(s_front.as_slice(), ns);
    Exchange {
        value: (contour.value + far.value).max(0.0),
        round_off: contour.round_off + far.error + round_off,
    }
}

/// Round-off of a difference of Lambert sums over `vertices` vertices in all, per unit area.
fn point_round_off(vertices: usize) -> f64 {
    POINT_ROUND_OFF * f64::EPSILON * vertices.max(1) as f64
}

/// The part of `ring` in front of the plane through `point` with normal `normal`; `None` when
/// nothing of it is.
fn front_of(ring: &[DVec3], point: DVec3, normal: DVec3, snap: f64) -> Option<Ring> {
    let mut out = Ring::new();
    match classify(ring, point, normal, snap) {
        Side::Outside => return None,
        Side::Inside => ring.iter().for_each(|&v| out.push(v)),
        Side::Cut => clip_into(ring, point, normal, snap, &mut out),
    }
    (out.len() >= 3).then_some(out)
}

/// Signed area of a planar ring about `n`.
fn area(ring: &[DVec3], n: DVec3) -> f64 {
    let m = ring.len();
    (1..m.saturating_sub(1)).map(|k| 0.5 * (ring[k] - ring[0]).cross(ring[k + 1] - ring[0]).dot(n)).sum()
}
