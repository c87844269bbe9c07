//! The shaft between two axis-aligned boxes (Haines and Wallace 1991, "Shaft culling for
//! efficient ray-traced radiosity"): their union box cut by one plane through each pair of
//! parallel box edges where the two boxes take turns being outermost (box A reaches further
//! along one axis, box B along the neighbouring one). Every segment from a point of one box to
//! a point of the other lies inside it, so an object outside the shaft cannot cut a sight line
//! between them. Objects are tested against one face at a time (a conservative test: an object
//! that only a combination of faces keeps out is kept).
use glam::DVec3;

/// Most planes of a shaft: one per pair of axes (3) and pair of sides (4).
const MAX_PLANES: usize = 12;

/// The shaft of two boxes: inside is `lo ≤ x ≤ hi` and `n·x ≤ d` for every plane (n, d),
/// each loosened by the slack given at construction.
#[derive(Debug, Clone, Copy)]
pub struct Shaft {
    lo: DVec3,
    hi: DVec3,
    planes: [(DVec3, f64); MAX_PLANES],
    count: usize,
}

impl Shaft {
    /// The shaft of boxes a = (lo, hi) and b = (lo, hi), every face moved out by `slack` (m).
    pub fn new(a: (DVec3, DVec3), b: (DVec3, DVec3), slack: f64) -> Shaft {
        let lo = a.0.min(b.0) - DVec3::splat(slack);
        let hi = a.1.max(b.1) + DVec3::splat(slack);
        let mut planes = [(DVec3::ZERO, 0.0); MAX_PLANES];
        let mut count = 0;
        // Side s of axis i: the box coordinate there, and the outward sign.
        let side = |bx: (DVec3, DVec3), i: usize, s: usize| if s == 0 { bx.0[i] } else { bx.1[i] };
        let sign = |s: usize| if s == 0 { -1.0 } else { 1.0 };
        // +1 when a is strictly outermost on that side, −1 when b is, 0 when they are level.
        let owner = |i: usize, s: usize| {
            let (x, y) = (sign(s) * side(a, i, s), sign(s) * side(b, i, s));
            (x > y) as i32 - (y > x) as i32
        };
        for i in 0..3 {
            for j in i + 1..3 {
                for si in 0..2 {
                    for sj in 0..2 {
                        let (oi, oj) = (owner(i, si), owner(j, sj));
                        if oi * oj != -1 {
                            continue;
                        }
                        // The plane through a's edge at (side si of i, side sj of j) and b's,
                        // both along the third axis; its normal lies in the (i, j) plane.
                        let p = (side(a, i, si), side(a, j, sj));
                        let q = (side(b, i, si), side(b, j, sj));
                        let (ti, tj) = (q.0 - p.0, q.1 - p.1);
                        let (mut ni, mut nj) = (tj, -ti);
                        if ni * sign(si) + nj * sign(sj) < 0.0 {
                            (ni, nj) = (-ni, -nj);
                        }
                        let len = ni.hypot(nj);
                        if !(len > 0.0) {
                            continue;
                        }
                        let mut n = DVec3::ZERO;
                        n[i] = ni / len;
                        n[j] = nj / len;
                        planes[count] = (n, n[i] * p.0 + n[j] * p.1 + slack);
                        count += 1;
                    }
                }
            }
        }
        Shaft { lo, hi, planes, count }
    }

    /// The cutting planes (n, d): inside is n·x ≤ d.
    pub fn planes(&self) -> &[(DVec3, f64)] {
        &self.planes[..self.count]
    }

    /// False when the box (lo, hi) lies outside the union box or wholly outside one plane.
    pub fn meets_box(&self, lo: DVec3, hi: DVec3) -> bool {
        if !(lo.cmple(self.hi).all() && hi.cmpge(self.lo).all()) {
            return false;
        }
        let (c, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        self.planes().iter().all(|&(n, d)| n.dot(c) - n.abs().dot(h) <= d)
    }

    /// False when every point lies outside one face of the union box or one plane: then
    /// neither they nor their convex hull (a blocker polygon) meet the shaft.
    pub fn meets_points(&self, pts: &[DVec3]) -> bool {
        for k in 0..3 {
            if pts.iter().all(|p| p[k] > self.hi[k]) || pts.iter().all(|p| p[k] < self.lo[k]) {
                return false;
            }
        }
        self.planes().iter().all(|&(n, d)| pts.iter().any(|p| n.dot(*p) <= d))
    }

    /// True when the point lies inside.
    #[cfg(test)]
    fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all() && self.planes().iter().all(|&(n, d)| n.dot(p) <= d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    fn random_box(rng: &mut Pcg64Mcg) -> (DVec3, DVec3) {
        let c = DVec3::new(rng.random(), rng.random(), rng.random()) * 4.0 - 2.0;
        // Some boxes flat along an axis (a planar cluster), some not.
        let mut h = DVec3::new(rng.random(), rng.random(), rng.random());
        if rng.random::<f64>() < 0.5 {
            h[rng.random_range(0..3)] = 0.0;
        }
        (c - h, c + h)
    }

    fn point_in(rng: &mut Pcg64Mcg, b: (DVec3, DVec3)) -> DVec3 {
        b.0 + (b.1 - b.0) * DVec3::new(rng.random(), rng.random(), rng.random())
    }

    #[test]
    fn every_segment_between_the_boxes_lies_inside_the_shaft() {
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        for _ in 0..2000 {
            let (a, b) = (random_box(&mut rng), random_box(&mut rng));
            let shaft = Shaft::new(a, b, 1e-12);
            for _ in 0..20 {
                let (x, y) = (point_in(&mut rng, a), point_in(&mut rng, b));
                let t: f64 = rng.random();
                assert!(shaft.contains(x + t * (y - x)), "{a:?} {b:?} {x} {y} {t}");
                // A tiny box and a triangle about that point meet the shaft.
                let p = x + t * (y - x);
                assert!(shaft.meets_box(p, p));
                assert!(shaft.meets_points(&[p, p + DVec3::X, p + DVec3::Y]));
            }
        }
    }

    #[test]
    fn the_shaft_is_the_hull_of_the_two_boxes() {
        // A point of the union box is inside the shaft exactly when it is a convex combination
        // of points of the boxes: checked against the hull's corners (the boxes' 16 corners)
        // by a separating plane through each shaft plane being tight on a corner.
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        for _ in 0..2000 {
            let (a, b) = (random_box(&mut rng), random_box(&mut rng));
            let shaft = Shaft::new(a, b, 0.0);
            let corners: Vec<DVec3> = [a, b]
                .iter()
                .flat_map(|bx| {
                    (0..8).map(move |k| {
                        DVec3::new(
                            if k & 1 == 0 { bx.0.x } else { bx.1.x },
                            if k & 2 == 0 { bx.0.y } else { bx.1.y },
                            if k & 4 == 0 { bx.0.z } else { bx.1.z },
                        )
                    })
                })
                .collect();
            // Every plane supports the hull: it touches a corner of each box.
            for &(n, d) in shaft.planes() {
                let tol = 1e-12 * (1.0 + d.abs());
                let top = |bx: &[DVec3]| bx.iter().map(|c| n.dot(*c)).fold(f64::NEG_INFINITY, f64::max);
                assert!((top(&corners[..8]) - d).abs() <= tol, "{a:?} {b:?} {n} {d}");
                assert!((top(&corners[8..]) - d).abs() <= tol, "{a:?} {b:?} {n} {d}");
            }
        }
    }

    #[test]
    fn a_blocker_beside_the_segment_of_two_thin_boxes_is_outside() {
        // Floor strip x in [0, 1] at z = 0 and ceiling strip x in [2, 3] at z = 1: their
        // shaft leans; a triangle over the floor strip at z = 0.8 lies outside it though
        // inside the union box.
        let a = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0));
        let b = (DVec3::new(2.0, 0.0, 1.0), DVec3::new(3.0, 1.0, 1.0));
        let shaft = Shaft::new(a, b, 1e-12);
        let tri = [DVec3::new(0.1, 0.2, 0.8), DVec3::new(0.5, 0.2, 0.8), DVec3::new(0.3, 0.6, 0.8)];
        assert!(!shaft.meets_points(&tri));
        let lo = DVec3::new(0.1, 0.2, 0.8);
        assert!(!shaft.meets_box(lo, DVec3::new(0.5, 0.6, 0.8)));
        // The same triangle over the middle of the segment is inside.
        let mid: Vec<DVec3> = tri.iter().map(|p| *p + DVec3::new(1.2, 0.0, -0.3)).collect();
        assert!(shaft.meets_points(&mid));
    }
}
