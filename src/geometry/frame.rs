//! The one orthonormal frame: an origin and axes (t, b, n), n a unit normal, b = n × t.
//!
//! Constructors differ only in how the first tangent t is chosen (and, for
//! [`Frame::from_normal`], how b is computed), each the choice its callers' numbers rest on:
//! - [`Frame::from_normal`]: origin 0, (t, b) from Duff et al. (2017) "Building an orthonormal
//!   basis, revisited" (glam's `any_orthonormal_pair`), for sampling directions;
//! - [`Frame::new`]: an origin, t from the same construction, b = n × t (shadow clipping);
//! - [`Frame::along`] and [`Frame::of_polygon`]: t along a given edge projected into the plane,
//!   so rectangles align with pixels or grid lines (projection eyes, grid cells).
use super::Polygon;
use glam::{DVec2, DVec3};

/// An orthonormal frame (t, b, n) at `origin`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Origin (world point of local 0).
    pub origin: DVec3,
    /// First tangent.
    pub t: DVec3,
    /// Second tangent, n × t.
    pub b: DVec3,
    /// Unit normal.
    pub n: DVec3,
}

impl Frame {
    /// Frame at the world origin around unit `n` (Duff et al. 2017, branchless).
    pub fn from_normal(n: DVec3) -> Self {
        let (t, b) = n.any_orthonormal_pair();
        Self { origin: DVec3::ZERO, t, b, n }
    }
    /// Frame at `origin` around unit `n`: t as in [`Self::from_normal`], b = n × t.
    pub fn new(origin: DVec3, n: DVec3) -> Self {
        let (t, _) = n.any_orthonormal_pair();
        Self { origin, t, b: n.cross(t), n }
    }
    /// Frame at `origin` around unit `n` whose t runs along `edge` projected into the plane
    /// (any tangent when that projection is exactly zero).
    pub fn along(origin: DVec3, n: DVec3, edge: DVec3) -> Self {
        let mut t = edge - n * edge.dot(n);
        if t.length_squared() <= f64::MIN_POSITIVE {
            t = n.any_orthonormal_vector();
        }
        let t = t.normalize();
        Self { origin, t, b: n.cross(t), n }
    }
    /// The frame of `poly`: origin its first vertex, t along its first edge, n its normal.
    pub fn of_polygon(poly: &Polygon) -> Self {
        let v = poly.vertices();
        Self::along(v[0], poly.normal(), v[1] - v[0])
    }
    /// The same frame with its tangents turned by `angle` about the normal.
    pub fn turned(self, angle: f64) -> Self {
        let (s, c) = angle.sin_cos();
        let t = c * self.t + s * self.b;
        Self { t, b: self.n.cross(t), ..self }
    }
    /// World direction → local (t, b, n) components.
    #[inline]
    pub fn vector(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
    /// World point → local coordinates.
    #[inline]
    pub fn point(&self, x: DVec3) -> DVec3 {
        self.vector(x - self.origin)
    }
    /// Local direction → world.
    #[inline]
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
    /// Local coordinates → world point.
    #[inline]
    pub fn point_to_world(&self, l: DVec3) -> DVec3 {
        self.origin + l.x * self.t + l.y * self.b + l.z * self.n
    }
    /// In-plane coordinates (along t, b) of world point `x`.
    pub fn in_plane(&self, x: DVec3) -> DVec2 {
        let d = x - self.origin;
        DVec2::new(d.dot(self.t), d.dot(self.b))
    }
    /// The world point origin + s·t + u·b of in-plane coordinates (s, u).
    pub fn from_plane(&self, p: DVec2) -> DVec3 {
        self.origin + self.t * p.x + self.b * p.y
    }
    /// Bounding box [min, max] of the polygon's vertices in in-plane coordinates.
    pub fn bounds(&self, poly: &Polygon) -> (DVec2, DVec2) {
        poly.vertices()
            .iter()
            .map(|v| self.in_plane(*v))
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Round-off allowed on a unit-scale round trip.
    const ROUND_TRIP_TOL: f64 = 1e-14;

    #[test]
    fn every_constructor_is_orthonormal_and_round_trips() {
        let n = DVec3::new(0.3, -0.5, 0.8).normalize();
        let o = DVec3::new(1.0, 2.0, -3.0);
        for f in [
            Frame::from_normal(n),
            Frame::new(o, n),
            Frame::along(o, n, DVec3::X),
            Frame::along(o, n, DVec3::ZERO),
            Frame::new(o, n).turned(0.7),
        ] {
            for (a, b) in [(f.t, f.b), (f.b, f.n), (f.n, f.t)] {
                assert!(a.dot(b).abs() < ROUND_TRIP_TOL);
                assert!((a.length() - 1.0).abs() < ROUND_TRIP_TOL);
            }
            assert!((f.t.cross(f.b) - f.n).length() < ROUND_TRIP_TOL);
            let x = DVec3::new(-0.4, 0.9, 2.5);
            assert!((f.point_to_world(f.point(x)) - x).length() < 10.0 * ROUND_TRIP_TOL);
            assert!((f.to_world(f.vector(x)) - x).length() < 10.0 * ROUND_TRIP_TOL);
            let q = f.from_plane(DVec2::new(0.25, -1.5));
            assert!(f.point(q).z.abs() < 10.0 * ROUND_TRIP_TOL);
            assert!((f.in_plane(q) - DVec2::new(0.25, -1.5)).length() < 10.0 * ROUND_TRIP_TOL);
        }
    }

    #[test]
    fn from_normal_is_orthonormal_and_right_handed_on_every_axis() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(0.3, -0.4, 0.5).normalize(),
            DVec3::new(1e-9, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.t.length() - 1.0).abs() < 1e-14 && (f.b.length() - 1.0).abs() < 1e-14, "{n}");
            assert!(
                f.t.dot(f.b).abs() < 1e-14 && f.t.dot(n).abs() < 1e-14 && f.b.dot(n).abs() < 1e-14,
                "{n}"
            );
            assert!((f.t.cross(f.b) - n).length() < 1e-14, "{n}");
            let v = DVec3::new(0.2, -0.7, 0.4);
            assert!((f.vector(f.to_world(v)) - v).length() < 1e-14);
        }
    }

    #[test]
    fn a_polygon_frame_runs_along_the_first_edge_and_bounds_the_vertices() {
        let p = Polygon::new(vec![
            DVec3::new(1.0, 1.0, 2.0),
            DVec3::new(3.0, 1.0, 2.0),
            DVec3::new(3.0, 2.0, 2.0),
            DVec3::new(1.0, 2.0, 2.0),
        ])
        .unwrap();
        let f = Frame::of_polygon(&p);
        assert_eq!((f.origin, f.t, f.n), (DVec3::new(1.0, 1.0, 2.0), DVec3::X, DVec3::Z));
        assert_eq!(f.bounds(&p), (DVec2::ZERO, DVec2::new(2.0, 1.0)));
    }
}
