//! Area cubature of Lambert's point factor: A_p F_pq = ∫_p F(x → q) dA_x.
//!
//! Each point factor is Lambert's contour sum ([`super::lambert::point_to_ring`]), whose terms
//! are angles: it keeps full relative accuracy at any size and distance, where the double
//! contour integral's logarithms cancel. [`fan`] applies a fixed pair of collapsed Gauss
//! rules on the fan triangles of a ring, for an integrand known to be analytic over the
//! ring's hull with a known margin ([`super::split`]'s far part).
//!
//! The error estimate of a triangle is the difference of the two orders; where the margin
//! holds, the higher order converges at least twice as fast, so the difference
//! over-estimates its error. Without such a margin the estimate is not a bound (a long strip
//! sampled by 14 nodes misses what happens near its ends), so no adaptive use is made of it.
use glam::DVec3;
use std::sync::OnceLock;

/// Gauss–Legendre order (per direction, collapsed on each triangle) of the estimate.
pub const HIGH_ORDER: usize = 14;
/// Lower order whose difference from [`HIGH_ORDER`] is the error estimate.
pub const LOW_ORDER: usize = 8;
/// Round-off of one Lambert point factor per polygon vertex, in ε (an angle and a cosine
/// ratio per edge, each a few ulps).
pub const POINT_ROUND_OFF: f64 = 8.0;

/// An integral with its error estimate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Estimated absolute error (difference of the two orders).
    pub error: f64,
}

/// The two Gauss–Legendre rules on [0, 1], computed once.
struct Rules {
    high: (Vec<f64>, Vec<f64>),
    low: (Vec<f64>, Vec<f64>),
}

fn rules() -> &'static Rules {
    static RULES: OnceLock<Rules> = OnceLock::new();
    RULES.get_or_init(|| Rules {
        high: crate::geometry::quadrature::gauss_legendre(HIGH_ORDER),
        low: crate::geometry::quadrature::gauss_legendre(LOW_ORDER),
    })
}

/// ∫ g over triangle (a, b, c) with signed doubled area `twice`, collapsed (Duffy) rule.
fn collapsed(
    a: DVec3,
    b: DVec3,
    c: DVec3,
    twice: f64,
    (x, w): &(Vec<f64>, Vec<f64>),
    g: &impl Fn(DVec3) -> f64,
) -> f64 {
    let mut tri = 0.0;
    for (xi, wi) in x.iter().zip(w) {
        let mut inner = 0.0;
        for (xj, wj) in x.iter().zip(w) {
            inner += wj * g(a + xi * (b - a) + xj * (1.0 - xi) * (c - a));
        }
        tri += wi * (1.0 - xi) * inner;
    }
    twice * tri
}

/// Both orders on one triangle (normal `n` gives the sign of its area).
fn triangle(t: [DVec3; 3], n: DVec3, g: &impl Fn(DVec3) -> f64) -> Estimate {
    let [a, b, c] = t;
    let twice = (b - a).cross(c - a).dot(n);
    if twice == 0.0 {
        return Estimate::default();
    }
    let r = rules();
    let hi = collapsed(a, b, c, twice, &r.high, g);
    let lo = collapsed(a, b, c, twice, &r.low, g);
    Estimate { value: hi, error: (hi - lo).abs() }
}

/// ∫ g dA over `ring` (planar, normal `n`) on the fan triangles from vertex 0 with signed
/// areas, so non-convex rings are covered too (g must be analytic over the ring's hull).
pub fn fan(ring: &[DVec3], n: DVec3, g: impl Fn(DVec3) -> f64) -> Estimate {
    let mut sum = Estimate::default();
    for k in 1..ring.len().saturating_sub(1) {
        let e = triangle([ring[0], ring[k], ring[k + 1]], n, &g);
        sum.value += e.value;
        sum.error += e.error;
    }
    sum
}
