//! The one Sutherland–Hodgman clipper of convex rings, for plain 2-D or 3-D points and for
//! homogeneous coordinates: keeps dist(x) ≥ 0 for a signed distance `dist`.
//!
//! The edge a → b is walked from the last vertex; a crossing is emitted only on a strict sign
//! change and interpolated from a as a + (b − a)·dₐ/(dₐ − d_b), then b is kept when d_b ≥ 0.
//! Distances within `snap` of zero count as on the boundary, so no sliver thinner than `snap`
//! and no near-duplicate vertex is created.
//!
//! [`clip_ring_each`] is that loop; the others collect its vertices:
//! - [`clip_ring`], [`clip_ring_keep`], [`clip_homogeneous`]: into a `Vec`;
//! - [`Polygon::clip`](super::Polygon::clip): rotated to start at the first kept vertex (patch
//!   vertex order feeds every result), de-duplicated, degenerate remainders rejected;
//! - `viewfactor::exact::ring::clip_into`: into a stack ring, repeated vertices dropped.
//!
//! Variants whose arithmetic differs, on purpose:
//! - [`watertight`]: clips by several half-spaces, interpolating from the inside vertex, so
//!   two polygons sharing an edge get the same crossing bit for bit (projection rasters);
//! - [`super::grid_clip`] snaps vertices onto axis-aligned lines and interpolates in a
//!   canonical direction (glued cells must match exactly);
//! - `validate::oracle::lambert::clip_ring` is the validation oracle's own, independent code.
use glam::DVec3;

pub(crate) mod watertight;

/// Sutherland–Hodgman on a convex ring of 2-D or 3-D points: keeps `dist(x) ≥ 0`, a signed
/// distance, writing the kept ring to `out` (cleared first; left empty when fewer than three
/// vertices remain). Distances within `snap` of zero count as on the boundary.
pub fn clip_ring<P>(src: &[P], dist: impl Fn(P) -> f64, snap: f64, out: &mut Vec<P>)
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Sub<Output = P> + std::ops::Mul<f64, Output = P>,
{
    clip_ring_keep(src, dist, snap, out);
    if out.len() < 3 {
        out.clear();
    }
}

/// As [`clip_ring`], but a remainder of one or two vertices is left in `out` (callers that
/// test the remainder themselves).
pub fn clip_ring_keep<P>(src: &[P], dist: impl Fn(P) -> f64, snap: f64, out: &mut Vec<P>)
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Sub<Output = P> + std::ops::Mul<f64, Output = P>,
{
    out.clear();
    clip_ring_each(src, dist, snap, |p| out.push(p));
}

/// The Sutherland–Hodgman loop itself: passes each vertex of the kept ring, in order, to
/// `emit` (nothing for an empty `src`).
#[inline]
pub fn clip_ring_each<P>(src: &[P], dist: impl Fn(P) -> f64, snap: f64, mut emit: impl FnMut(P))
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Sub<Output = P> + std::ops::Mul<f64, Output = P>,
{
    let Some(&last) = src.last() else { return };
    let side = |x: P| {
        let d = dist(x);
        if d.abs() <= snap {
            0.0
        } else {
            d
        }
    };
    let mut a = last;
    let mut da = side(a);
    for &b in src {
        let db = side(b);
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            emit(a + (b - a) * (da / (da - db)));
        }
        if db >= 0.0 {
            emit(b);
        }
        a = b;
        da = db;
    }
}

/// Sutherland–Hodgman in homogeneous coordinates against l·(X, Y, W) ≥ 0, no snapping; a
/// remainder of one or two vertices is left in `out`.
pub fn clip_homogeneous(src: &[DVec3], l: DVec3, out: &mut Vec<DVec3>) {
    clip_ring_keep(src, |x| l.dot(x), 0.0, out);
}
