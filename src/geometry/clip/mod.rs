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

/// [`clip_homogeneous`] with a label per vertex naming the edge from it to the next one: a
/// kept piece of an edge keeps its label, an edge along l·(X, Y, W) = 0 gets `boundary`.
/// Each crossing is interpolated from the edge's inside end, so two rings that share an edge
/// (walked in opposite directions) get the same crossing bit for bit.
pub fn clip_homogeneous_labelled(src: &[(DVec3, u32)], l: DVec3, boundary: u32, out: &mut Vec<(DVec3, u32)>) {
    out.clear();
    let n = src.len();
    if n == 0 {
        return;
    }
    let (mut a, mut la) = src[n - 1];
    let mut da = l.dot(a);
    let mut db = l.dot(src[0].0);
    for i in 0..n {
        let (b, lb) = src[i];
        let dn = l.dot(src[(i + 1) % n].0);
        if da > 0.0 && db < 0.0 {
            out.push((a + (b - a) * (da / (da - db)), boundary));
        } else if da < 0.0 && db > 0.0 {
            out.push((b + (a - b) * (db / (db - da)), la));
        }
        if db >= 0.0 {
            out.push((b, if db == 0.0 && dn < 0.0 { boundary } else { lb }));
        }
        (a, la, da, db) = (b, lb, db, dn);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_follow_the_kept_edges_and_shared_crossings_match_bit_for_bit() {
        // The square (0,0)-(1,0)-(1,1)-(0,1) at W = 1, cut by X ≤ 0.3 W... i.e. 0.3·W − X ≥ 0.
        let sq = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let src: Vec<(DVec3, u32)> =
            sq.iter().enumerate().map(|(k, &(x, y))| (DVec3::new(x, y, 1.0), k as u32)).collect();
        let l = DVec3::new(-1.0, 0.0, 0.3);
        let mut out = Vec::new();
        clip_homogeneous_labelled(&src, l, 99, &mut out);
        // Kept: (0.3,0) on edge 0 → boundary → (0.3,1) on edge 2 → (0,1) edge 3 → (0,0) edge 0.
        let labels: Vec<u32> = out.iter().map(|v| v.1).collect();
        let xs: Vec<f64> = out.iter().map(|v| v.0.x).collect();
        assert_eq!(out.len(), 4, "{out:?}");
        let at = |x: f64, y: f64| out.iter().position(|v| v.0.x == x && v.0.y == y).unwrap();
        assert_eq!(labels[at(0.0, 0.0)], 0);
        assert_eq!(labels[at(0.0, 1.0)], 3);
        let cut0 = out.iter().position(|v| v.0.y == 0.0 && v.0.x > 0.0).unwrap();
        let cut2 = out.iter().position(|v| v.0.y == 1.0 && v.0.x > 0.0).unwrap();
        assert_eq!(labels[cut0], 99, "from the crossing on edge 0 the ring runs along the plane");
        assert_eq!(labels[cut2], 2, "from the crossing on edge 2 it follows edge 2");
        assert!(xs.iter().all(|&x| x <= 0.3 + 1e-15));
        // The same square walked the other way round crosses at the same points, bit for bit.
        let rev: Vec<(DVec3, u32)> = src.iter().rev().map(|v| (v.0, 0)).collect();
        let mut out2 = Vec::new();
        clip_homogeneous_labelled(&rev, l, 99, &mut out2);
        for v in &out {
            assert!(out2.iter().any(|w| w.0 == v.0), "{v:?} not in {out2:?}");
        }
        // A vertex on the plane whose next edge leaves: its edge runs along the plane.
        let tri =
            [(DVec3::new(0.0, 0.0, 1.0), 0), (DVec3::new(0.3, 0.0, 1.0), 1), (DVec3::new(0.6, 1.0, 1.0), 2)];
        clip_homogeneous_labelled(&tri, l, 99, &mut out);
        let on = out.iter().find(|v| v.0.x == 0.3 && v.0.y == 0.0).unwrap();
        assert_eq!(on.1, 99, "{out:?}");
    }
}
