//! Grouping polygons by the (unoriented) plane they lie in: coplanar patch pairs exchange
//! nothing, and blockers in one plane are tested together.
use super::tolerance::PLANE_NORMAL_COS_TOL;
use super::Polygon;
use glam::DVec3;
use std::collections::HashMap;

/// Quantisation of the hash key; only speeds up the search, membership is verified exactly.
const KEY_STEPS: f64 = 1e6;

/// An unoriented plane n·x = h with n's first non-zero component positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal (canonical sign).
    pub normal: DVec3,
    /// Offset h = n·x for points x on the plane.
    pub offset: f64,
}

impl Plane {
    /// The unoriented plane of `poly`.
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
        Plane { normal: n, offset: n.dot(poly.centroid()) }
    }
    /// Signed distance of `p`.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
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
            [q(p.normal.x), q(p.normal.y), q(p.normal.z), q(p.offset / length_scale)]
        };
        for poly in polys {
            let plane = Plane::of(poly);
            let found = index.get(&key(&plane)).and_then(|cands| {
                cands.iter().copied().find(|&c| {
                    let rep = &g.planes[c as usize];
                    rep.normal.dot(plane.normal) > 1.0 - PLANE_NORMAL_COS_TOL
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
