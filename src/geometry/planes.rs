//! The one plane type ([`Plane`], oriented or canonical-unoriented) and grouping polygons by
//! the (unoriented) plane they lie in: coplanar patch pairs exchange nothing, and blockers in
//! one plane are tested together.
use super::tolerance::PLANE_NORMAL_COS_TOL;
use super::Polygon;
use glam::DVec3;
use std::collections::HashMap;

/// Quantisation of the hash key; only speeds up the search, membership is verified exactly.
const KEY_STEPS: f64 = 1e6;

/// A plane n·x + d = 0 with a unit normal n; `distance` is signed, positive on n's side.
///
/// [`Plane::of`] gives the unoriented plane of a polygon (n's first non-zero component
/// positive, for grouping); [`Plane::through`] and [`plane_of`] give oriented ones (the
/// half-space n·x + d ≥ 0 is the region of interest of the shadow volumes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub n: DVec3,
    /// Offset: −n·x for points x on the plane.
    pub d: f64,
}

impl Plane {
    /// The unoriented plane of `poly`: its normal with the first non-zero component positive.
    pub fn of(poly: &Polygon) -> Self {
        let mut n = poly.normal();
        let flip = if n.x != 0.0 {
            n.x < 0.0
        } else if n.y != 0.0 {
            n.y < 0.0
        } else {
            n.z < 0.0
        };
        if flip {
            n = -n;
        }
        Plane { n, d: -n.dot(poly.centroid()) }
    }
    /// The plane through a, b, c oriented by (b − a) × (c − a); `None` when they are collinear
    /// within `min_len` (the normal's length before normalising).
    pub fn through(a: DVec3, b: DVec3, c: DVec3, min_len: f64) -> Option<Self> {
        let n = (b - a).cross(c - a);
        let len = n.length();
        if !(len > min_len) {
            return None;
        }
        let n = n / len;
        Some(Self { n, d: -n.dot(a) })
    }
    /// Signed distance of `x`, positive on the normal's side.
    #[inline]
    pub fn distance(&self, x: DVec3) -> f64 {
        self.n.dot(x) + self.d
    }
    /// The opposite orientation.
    pub fn flipped(&self) -> Self {
        Self { n: -self.n, d: -self.d }
    }
    /// Largest signed distance over the axis-aligned box [lo, hi].
    pub fn box_max(&self, lo: DVec3, hi: DVec3) -> f64 {
        let (c, h) = centre_half(lo, hi);
        self.box_max_ch(c, h)
    }
    /// Smallest signed distance over the axis-aligned box [lo, hi].
    pub fn box_min(&self, lo: DVec3, hi: DVec3) -> f64 {
        let (c, h) = centre_half(lo, hi);
        self.box_min_ch(c, h)
    }
    /// [`Self::box_max`] of the box of centre `c` and half-extents `h` ([`centre_half`]): one
    /// box tested against many planes computes them once.
    #[inline]
    pub fn box_max_ch(&self, c: DVec3, h: DVec3) -> f64 {
        self.distance(c) + self.n.abs().dot(h)
    }
    /// [`Self::box_min`] of the box of centre `c` and half-extents `h`.
    #[inline]
    pub fn box_min_ch(&self, c: DVec3, h: DVec3) -> f64 {
        self.distance(c) - self.n.abs().dot(h)
    }
}

/// Centre and half-extents of the axis-aligned box [lo, hi].
#[inline]
pub fn centre_half(lo: DVec3, hi: DVec3) -> (DVec3, DVec3) {
    (0.5 * (lo + hi), 0.5 * (hi - lo))
}

/// The oriented plane of a ring (any vertex count, possibly not quite planar): Newell's normal
/// (right-hand rule) through the vertex mean; `None` for fewer than 3 vertices or a zero area.
pub fn plane_of(ring: &[DVec3]) -> Option<Plane> {
    let m = ring.len();
    if m < 3 {
        return None;
    }
    let mut n = DVec3::ZERO;
    let mut c = DVec3::ZERO;
    for k in 0..m {
        let (a, b) = (ring[k], ring[(k + 1) % m]);
        n += a.cross(b);
        c += a;
    }
    let len = n.length();
    if !(len > 0.0) {
        return None;
    }
    let n = n / len;
    Some(Plane { n, d: -n.dot(c / m as f64) })
}

/// Plane groups of a polygon list: `id[k]` is the group of polygon k; `planes[g]` its plane.
#[derive(Debug, Clone, Default)]
pub struct PlaneGroups {
    /// Group of each polygon.
    pub id: Vec<u32>,
    /// Representative plane of each group (its first member's).
    pub planes: Vec<Plane>,
}

impl PlaneGroups {
    /// Groups polygons whose vertices all lie within `tol` of a group's plane and whose normals
    /// are parallel; a polygon that matches no group opens a new one.
    pub fn new<'a>(polys: impl IntoIterator<Item = &'a Polygon>, length_scale: f64, tol: f64) -> Self {
        let mut g = PlaneGroups::default();
        let mut index: HashMap<[i64; 4], Vec<u32>> = HashMap::new();
        let key = |p: &Plane| {
            let q = |x: f64| (x * KEY_STEPS).round() as i64;
            [q(p.n.x), q(p.n.y), q(p.n.z), q(-p.d / length_scale)]
        };
        for poly in polys {
            let plane = Plane::of(poly);
            let found = index.get(&key(&plane)).and_then(|cands| {
                cands.iter().copied().find(|&c| {
                    let rep = &g.planes[c as usize];
                    rep.n.dot(plane.n) > 1.0 - PLANE_NORMAL_COS_TOL
                        && poly.vertices().iter().all(|v| rep.distance(*v).abs() <= tol)
                })
            });
            let id = found.unwrap_or_else(|| {
                let id = g.planes.len() as u32;
                g.planes.push(plane);
                index.entry(key(&plane)).or_default().push(id);
                id
            });
            g.id.push(id);
        }
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sq(z: f64, flip: bool) -> Polygon {
        let p = Polygon::new(vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(1.0, 0.0, z),
            DVec3::new(1.0, 1.0, z),
            DVec3::new(0.0, 1.0, z),
        ])
        .unwrap();
        if flip {
            p.flipped()
        } else {
            p
        }
    }

    #[test]
    fn groups_coplanar_polygons_of_either_facing() {
        let polys = [sq(0.0, false), sq(1.0, false), sq(0.0, true), sq(1e-14, false)];
        let g = PlaneGroups::new(&polys, 1.0, 1e-9);
        assert_eq!(g.id, vec![0, 1, 0, 0]);
        assert_eq!(g.planes.len(), 2);
        assert!((g.planes[1].distance(DVec3::new(5.0, 5.0, 3.0)) - 2.0).abs() < 1e-15);
    }
}
