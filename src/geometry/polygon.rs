//! Planar simple polygons: construction with validation, Newell normal, area, centroid,
//! ear-clipping triangulation and Sutherland–Hodgman clipping by a plane.
use super::clip::clip_ring_keep;
use super::convex::{ear_indices, is_convex_local};
use super::tolerance::{DEGENERACY_TOL, PLANARITY_TOL};
use glam::{DMat3, DVec2, DVec3};

/// Why a vertex list is not a valid polygon.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than three vertices.
    #[error("a polygon needs at least 3 vertices, got {0}")]
    TooFewVertices(usize),
    /// A coordinate is NaN or infinite.
    #[error("vertex {0} has a NaN or infinite coordinate")]
    NonFinite(usize),
    /// All vertices on one line, or zero area.
    #[error("the vertices are collinear or the area is zero")]
    Degenerate,
    /// A vertex lies off the polygon's plane.
    #[error("the polygon is not planar: vertex {vertex} is {distance:.3e} off its plane (tolerance {tolerance:.3e})")]
    NonPlanar {
        /// Index of the worst vertex.
        vertex: usize,
        /// Its distance from the best-fit plane.
        distance: f64,
        /// The allowed distance.
        tolerance: f64,
    },
    /// Two non-adjacent edges cross or touch.
    #[error("the polygon is not simple: edges {0} and {1} cross")]
    SelfIntersecting(usize, usize),
}

/// A planar, simple polygon; the front side is the one from which the vertices run
/// counter-clockwise (normal by the right-hand rule).
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    vertices: Vec<DVec3>,
    normal: DVec3,
    area: f64,
    centroid: DVec3,
}

impl Polygon {
    /// Validates and builds a polygon: ≥ 3 finite vertices, non-degenerate, planar, simple.
    /// Repeated consecutive vertices are dropped first.
    pub fn new(mut vertices: Vec<DVec3>) -> Result<Self, PolygonError> {
        if let Some(k) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(PolygonError::NonFinite(k));
        }
        dedup_ring(&mut vertices);
        if vertices.len() < 3 {
            return Err(PolygonError::TooFewVertices(vertices.len()));
        }
        let diameter = ring_diameter(&vertices);
        let newell = newell(&vertices);
        let twice_area = newell.length();
        if !(twice_area > 2.0 * DEGENERACY_TOL * diameter * diameter) {
            return Err(PolygonError::Degenerate);
        }
        let normal = newell / twice_area;
        let centre = vertices.iter().copied().sum::<DVec3>() / vertices.len() as f64;
        let tolerance = PLANARITY_TOL * diameter;
        let (vertex, distance) = vertices
            .iter()
            .map(|v| (v - centre).dot(normal).abs())
            .enumerate()
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        if distance > tolerance {
            return Err(PolygonError::NonPlanar { vertex, distance, tolerance });
        }
        if vertices.len() > 3 {
            if let Some((a, b)) = first_crossing(&vertices, normal) {
                return Err(PolygonError::SelfIntersecting(a, b));
            }
        }
        Ok(Self::from_parts(vertices, normal))
    }

    /// Builds a triangle without the simplicity checks; `None` if degenerate.
    pub fn triangle(a: DVec3, b: DVec3, c: DVec3) -> Option<Self> {
        let n = (b - a).cross(c - a);
        let len = n.length();
        let scale = (b - a).length_squared().max((c - a).length_squared());
        if !(len > 2.0 * DEGENERACY_TOL * scale) || !len.is_finite() {
            return None;
        }
        Some(Self::from_parts(vec![a, b, c], n / len))
    }

    /// Builds from vertices already known to be planar and simple, with a known unit normal.
    fn from_parts(vertices: Vec<DVec3>, normal: DVec3) -> Self {
        let origin = vertices[0];
        let mut area2 = 0.0;
        let mut moment = DVec3::ZERO;
        for k in 1..vertices.len() - 1 {
            let (b, c) = (vertices[k], vertices[k + 1]);
            let a2 = (b - origin).cross(c - origin).dot(normal);
            area2 += a2;
            moment += a2 * (origin + b + c);
        }
        let centroid = moment / (3.0 * area2);
        Self { vertices, normal, area: 0.5 * area2, centroid }
    }

    /// The vertices, counter-clockwise about the normal.
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }
    /// Unit normal of the front side.
    pub fn normal(&self) -> DVec3 {
        self.normal
    }
    /// Area, m².
    pub fn area(&self) -> f64 {
        self.area
    }
    /// Area centroid.
    pub fn centroid(&self) -> DVec3 {
        self.centroid
    }
    /// Second moment of area about the centroid, ∫ (x − c)(x − c)ᵀ dA (m⁴): the fan triangles'
    /// A/12 Σ dᵢdᵢᵀ (dᵢ their vertices from their centroid) moved to c (parallel axes).
    pub fn second_moment(&self) -> DMat3 {
        let (v, c) = (&self.vertices, self.centroid);
        let mut m = DMat3::ZERO;
        for k in 1..v.len() - 1 {
            let t = [v[0], v[k], v[k + 1]];
            let a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).dot(self.normal);
            let g = (t[0] + t[1] + t[2]) / 3.0;
            m += (t.iter().map(|&p| outer(p - g)).fold(DMat3::ZERO, |s, o| s + o)) * (a / 12.0)
                + outer(g - c) * a;
        }
        m
    }
    /// Largest distance from the centroid to a vertex.
    pub fn bounding_radius(&self) -> f64 {
        self.vertices.iter().map(|v| v.distance(self.centroid)).fold(0.0, f64::max)
    }
    /// Edges as (start, end) pairs, closing the ring.
    pub fn edges(&self) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
        let n = self.vertices.len();
        (0..n).map(move |k| (self.vertices[k], self.vertices[(k + 1) % n]))
    }
    /// Signed distance of `p` from the polygon's plane, positive on the front side.
    pub fn plane_distance(&self, p: DVec3) -> f64 {
        (p - self.centroid).dot(self.normal)
    }
    /// True when every interior angle is below 180° (within round-off): the one corner test,
    /// [`is_convex_local`], on the polygon's in-plane coordinates.
    pub fn is_convex(&self) -> bool {
        is_convex_local(&project(&self.vertices, self.normal))
    }

    /// Ear-clipping triangulation ([`ear_indices`]); triangles keep the polygon's orientation.
    pub fn triangulate(&self) -> Vec<[DVec3; 3]> {
        let v = &self.vertices;
        let p = project(v, self.normal);
        if is_convex_local(&p) {
            return (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
        }
        ear_indices(&p).into_iter().map(|t| t.map(|k| v[k])).collect()
    }

    /// Part of the polygon on the side `(x − point)·normal ≥ 0`; `None` if nothing of positive
    /// area remains. Sutherland–Hodgman, so a non-convex polygon may come back with
    /// zero-width bridges, which integrate to nothing.
    pub fn clip(&self, point: DVec3, normal: DVec3) -> Option<Polygon> {
        let d: Vec<f64> = self.vertices.iter().map(|v| (*v - point).dot(normal)).collect();
        if d.iter().all(|&x| x >= 0.0) {
            return Some(self.clone());
        }
        if d.iter().all(|&x| x <= 0.0) {
            return None;
        }
        let n = self.vertices.len();
        let mut out = Vec::with_capacity(n + 2);
        clip_ring_keep(&self.vertices, |v| (v - point).dot(normal), 0.0, &mut out);
        // The loop starts on the closing edge: a crossing there goes last, so the ring starts
        // at the first vertex as the patch's does.
        let (dl, d0) = (d[n - 1], d[0]);
        if (dl > 0.0 && d0 < 0.0) || (dl < 0.0 && d0 > 0.0) {
            out.rotate_left(1);
        }
        dedup_ring(&mut out);
        if out.len() < 3 {
            return None;
        }
        let nw = newell(&out);
        let scale = ring_diameter(&out);
        if !(nw.length() > 2.0 * DEGENERACY_TOL * scale * scale) || nw.dot(self.normal) <= 0.0 {
            return None;
        }
        Some(Self::from_parts(out, self.normal))
    }

    /// The polygon moved by an affine map (rotation, translation, uniform scale); orientation
    /// is kept when the map preserves handedness.
    pub fn transformed(&self, map: &glam::DAffine3) -> Option<Polygon> {
        let v: Vec<DVec3> = self.vertices.iter().map(|p| map.transform_point3(*p)).collect();
        let nw = newell(&v);
        let len = nw.length();
        if !(len > 0.0) {
            return None;
        }
        Some(Self::from_parts(v, nw / len))
    }

    /// The same polygon with the vertex order reversed (normal flipped).
    pub fn flipped(&self) -> Polygon {
        let mut v = self.vertices.clone();
        v.reverse();
        Self::from_parts(v, -self.normal)
    }
}

/// Newell's vector: twice the area times the unit normal, for any planar ring.
pub fn newell(v: &[DVec3]) -> DVec3 {
    let o = v[0];
    let mut n = DVec3::ZERO;
    for k in 1..v.len() - 1 {
        n += (v[k] - o).cross(v[k + 1] - o);
    }
    n
}

fn ring_diameter(v: &[DVec3]) -> f64 {
    let (lo, hi) = v.iter().fold((v[0], v[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    (hi - lo).length()
}

/// Drops consecutive duplicates (including last == first).
fn dedup_ring(v: &mut Vec<DVec3>) {
    v.dedup();
    while v.len() > 1 && v.first() == v.last() {
        v.pop();
    }
}

/// In-plane 2-D coordinates along two axes orthogonal to `normal`.
fn project(v: &[DVec3], normal: DVec3) -> Vec<DVec2> {
    let (u, w) = normal.any_orthonormal_pair();
    v.iter().map(|p| DVec2::new(p.dot(u), p.dot(w))).collect()
}

/// Twice the signed area of triangle (a, b, c): positive when counter-clockwise.
fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

fn segments_cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2, eps: f64) -> bool {
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps))
        && ((d3 > eps && d4 < -eps) || (d3 < -eps && d4 > eps))
    {
        return true;
    }
    // Touching: an endpoint on the other segment.
    let on = |p: DVec2, q: DVec2, r: DVec2, o: f64| {
        o.abs() <= eps
            && r.x >= p.x.min(q.x) - 1e-15
            && r.x <= p.x.max(q.x) + 1e-15
            && r.y >= p.y.min(q.y) - 1e-15
            && r.y <= p.y.max(q.y) + 1e-15
    };
    on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4)
}

/// First pair of non-adjacent edges that cross or touch, if any (O(n²), polygons are small).
fn first_crossing(v: &[DVec3], normal: DVec3) -> Option<(usize, usize)> {
    let p = project(v, normal);
    let n = p.len();
    let scale = ring_diameter(v);
    let eps = 1e-12 * scale * scale;
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            if segments_cross(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n], eps) {
                return Some((i, j));
            }
        }
    }
    None
}

/// The outer product d dᵀ (second moments of area: a point mass's, and the parallel-axis shift).
pub fn outer(d: DVec3) -> DMat3 {
    DMat3::from_cols(d * d.x, d * d.y, d * d.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sq() -> Vec<DVec3> {
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]
    }

    #[test]
    fn unit_square_properties() {
        let p = Polygon::new(sq()).unwrap();
        assert!((p.area() - 1.0).abs() < 1e-15);
        assert!((p.normal() - DVec3::Z).length() < 1e-15);
        assert!((p.centroid() - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
        assert!(p.is_convex());
    }

    #[test]
    fn rejects_bad_input() {
        assert_eq!(Polygon::new(sq()[..2].to_vec()), Err(PolygonError::TooFewVertices(2)));
        let collinear = vec![DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        assert_eq!(Polygon::new(collinear), Err(PolygonError::Degenerate));
        let mut bent = sq();
        bent[2].z = 0.1;
        assert!(matches!(Polygon::new(bent), Err(PolygonError::NonPlanar { .. })));
        let bowtie = vec![DVec3::ZERO, DVec3::new(2.0, 2.0, 0.0), DVec3::new(2.0, 0.0, 0.0), DVec3::Y];
        assert!(matches!(Polygon::new(bowtie), Err(PolygonError::SelfIntersecting(..))));
        let mut nan = sq();
        nan[1].y = f64::NAN;
        assert_eq!(Polygon::new(nan), Err(PolygonError::NonFinite(1)));
    }

    #[test]
    fn l_shape_triangulates_to_its_area() {
        let l = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)];
        let p = Polygon::new(l.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()).unwrap();
        assert!(!p.is_convex());
        assert!((p.area() - 3.0).abs() < 1e-14);
        let tris = p.triangulate();
        assert_eq!(tris.len(), 4);
        let sum: f64 = tris.iter().map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).dot(DVec3::Z)).sum();
        assert!((sum - 3.0).abs() < 1e-14, "triangles must keep orientation and cover the area");
        assert!((p.centroid() - DVec3::new(5.0 / 6.0, 5.0 / 6.0, 0.0)).length() < 1e-14);
    }

    #[test]
    fn clip_keeps_front_half() {
        let p = Polygon::new(sq()).unwrap();
        let half = p.clip(DVec3::new(0.25, 0.0, 0.0), DVec3::X).unwrap();
        assert!((half.area() - 0.75).abs() < 1e-15);
        assert!(p.clip(DVec3::new(2.0, 0.0, 0.0), DVec3::X).is_none());
        assert_eq!(p.clip(DVec3::new(-1.0, 0.0, 0.0), DVec3::X).unwrap(), p);
    }
}
