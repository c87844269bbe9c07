//! Gauss rules per patch: parallelograms take an n×n tensor rule, other polygons the collapsed
//! (Duffy) n×n rule on each triangle of a triangulation made once. Points are stored as
//! structure-of-arrays, orders 1..=[`CACHED_ORDERS`] cached for every patch.
use crate::geometry::quadrature::{gauss_legendre, AreaRule};
use crate::geometry::tolerance::PARALLELOGRAM_CAD_REL;
use crate::geometry::Polygon;
use glam::DVec3;
use std::sync::OnceLock;

/// Highest Gauss order on a patch; beyond it the exact contour integral is as cheap.
pub const MAX_ORDER: usize = 6;
/// Orders 1..=CACHED_ORDERS are precomputed per patch (the far field uses them); higher
/// orders are generated per pair, where their n⁴ kernel evaluations dominate anyway.
pub const CACHED_ORDERS: usize = 4;

/// A piece of a patch on which a tensor Gauss rule is polynomially exact.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// o + s·u + t·v, s, t ∈ [0, 1].
    Parallelogram { o: DVec3, u: DVec3, v: DVec3 },
    /// Triangle a, b, c (Duffy-collapsed square).
    Triangle { a: DVec3, b: DVec3, c: DVec3 },
}

impl Piece {
    /// Longest parameter-direction length |∂x/∂s| over the piece (the L of the bound).
    fn param_len(&self) -> f64 {
        match *self {
            Piece::Parallelogram { u, v, .. } => u.length().max(v.length()),
            Piece::Triangle { a, b, c } => a.distance(b).max(b.distance(c)).max(c.distance(a)),
        }
    }
    /// Appends the order-`order` tensor rule (the same nodes as
    /// [`AreaRule::parallelogram`] / [`AreaRule::triangle`], from cached 1-D nodes).
    fn push_rule(&self, order: usize, out: &mut Points) {
        let (x, w) = gauss_nodes(order);
        match *self {
            Piece::Parallelogram { o, u, v } => {
                let area = u.cross(v).length();
                for (xs, ws) in x.iter().zip(w) {
                    for (xt, wt) in x.iter().zip(w) {
                        out.push(o + *xs * u + *xt * v, area * ws * wt);
                    }
                }
            }
            Piece::Triangle { a, b, c } => {
                let area = 0.5 * (b - a).cross(c - a).length();
                for (xs, ws) in x.iter().zip(w) {
                    for (xt, wt) in x.iter().zip(w) {
                        let t = xt * (1.0 - xs);
                        out.push(a + *xs * (b - a) + t * (c - a), 2.0 * area * ws * wt * (1.0 - xs));
                    }
                }
            }
        }
    }
}

/// Splits a polygon into Gauss pieces: itself when it is a parallelogram or a triangle,
/// otherwise its triangles.
fn pieces_of(poly: &Polygon) -> Vec<Piece> {
    let v = poly.vertices();
    if v.len() == 3 {
        return vec![Piece::Triangle { a: v[0], b: v[1], c: v[2] }];
    }
    if v.len() == 4 {
        let (u, w) = (v[1] - v[0], v[3] - v[0]);
        let scale = u.length().max(w.length());
        if (v[2] - (v[0] + u + w)).length() <= PARALLELOGRAM_CAD_REL * scale {
            return vec![Piece::Parallelogram { o: v[0], u, v: w }];
        }
    }
    poly.triangulate().into_iter().map(|[a, b, c]| Piece::Triangle { a, b, c }).collect()
}

/// Gauss points in structure-of-arrays form; weights in m² (they sum to the area).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Points {
    /// x coordinates.
    pub x: Vec<f64>,
    /// y coordinates.
    pub y: Vec<f64>,
    /// z coordinates.
    pub z: Vec<f64>,
    /// Weights, m².
    pub w: Vec<f64>,
}

impl Points {
    /// Empties the set, keeping its capacity.
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.w.clear();
    }
    /// Appends one point.
    pub fn push(&mut self, p: DVec3, w: f64) {
        self.x.push(p.x);
        self.y.push(p.y);
        self.z.push(p.z);
        self.w.push(w);
    }
    /// Appends every point of an [`AreaRule`].
    pub fn push_rule(&mut self, r: &AreaRule) {
        for (p, w) in r.points.iter().zip(&r.weights) {
            self.push(*p, *w);
        }
    }
    /// Borrowed view.
    pub fn view(&self) -> PointsRef<'_> {
        PointsRef { x: &self.x, y: &self.y, z: &self.z, w: &self.w }
    }
}

/// Borrowed SoA points.
#[derive(Debug, Clone, Copy)]
pub struct PointsRef<'a> {
    /// x coordinates.
    pub x: &'a [f64],
    /// y coordinates.
    pub y: &'a [f64],
    /// z coordinates.
    pub z: &'a [f64],
    /// Weights, m².
    pub w: &'a [f64],
}

/// Gauss pieces and cached low-order rules of every patch of a scene.
#[derive(Debug, Clone, Default)]
pub struct PatchRules {
    pieces: Vec<Piece>,
    piece_start: Vec<u32>,
    param_len: Vec<f64>,
    cache: Points,
    /// Start of (patch p, order o) at p·CACHED_ORDERS + o − 1.
    cache_start: Vec<u32>,
}

impl PatchRules {
    /// Decomposes every polygon and caches its rules of order 1..=[`CACHED_ORDERS`].
    pub fn new<'a>(polys: impl IntoIterator<Item = &'a Polygon>) -> Self {
        let mut r = PatchRules::default();
        r.piece_start.push(0);
        r.cache_start.push(0);
        for poly in polys {
            let pieces = pieces_of(poly);
            r.param_len.push(pieces.iter().map(Piece::param_len).fold(0.0, f64::max));
            for order in 1..=CACHED_ORDERS {
                for piece in &pieces {
                    piece.push_rule(order, &mut r.cache);
                }
                r.cache_start.push(r.cache.w.len() as u32);
            }
            r.pieces.extend(pieces);
            r.piece_start.push(r.pieces.len() as u32);
        }
        r
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.param_len.len()
    }
    /// True when there are no patches.
    pub fn is_empty(&self) -> bool {
        self.param_len.is_empty()
    }
    /// The L of the error bound: the longest parameter-direction length of the patch's pieces.
    pub fn param_len(&self, p: usize) -> f64 {
        self.param_len[p]
    }
    /// True when patch `p` is integrated on Duffy triangles (not a single parallelogram).
    pub fn triangulated(&self, p: usize) -> bool {
        matches!(self.pieces[self.piece_start[p] as usize], Piece::Triangle { .. })
    }

    /// The order-`order` rule of patch `p`, from the cache or generated into `buf`.
    #[inline]
    pub fn points<'a>(&'a self, p: usize, order: usize, buf: &'a mut Points) -> PointsRef<'a> {
        debug_assert!((1..=MAX_ORDER).contains(&order));
        if order <= CACHED_ORDERS {
            let k = p * CACHED_ORDERS + order - 1;
            let (a, b) = (self.cache_start[k] as usize, self.cache_start[k + 1] as usize);
            let c = &self.cache;
            return PointsRef { x: &c.x[a..b], y: &c.y[a..b], z: &c.z[a..b], w: &c.w[a..b] };
        }
        buf.clear();
        let range = self.piece_start[p] as usize..self.piece_start[p + 1] as usize;
        for piece in &self.pieces[range] {
            piece.push_rule(order, buf);
        }
        buf.view()
    }
}

/// The 1-D Gauss–Legendre rules of every ladder order, computed once.
pub fn gauss_nodes(order: usize) -> &'static (Vec<f64>, Vec<f64>) {
    static NODES: OnceLock<Vec<(Vec<f64>, Vec<f64>)>> = OnceLock::new();
    &NODES.get_or_init(|| (1..=MAX_ORDER).map(gauss_legendre).collect())[order - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(o: DVec3, u: DVec3, v: DVec3) -> Polygon {
        Polygon::new(vec![o, o + u, o + u + v, o + v]).unwrap()
    }

    #[test]
    fn cached_rules_match_area_rules() {
        let p = square(DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.5, 0.1, 0.0), DVec3::new(-0.1, 0.4, 0.2));
        let t = Polygon::new(vec![DVec3::ZERO, DVec3::X, DVec3::new(0.3, 0.8, 0.1)]).unwrap();
        let rules = PatchRules::new([&p, &t]);
        let mut buf = Points::default();
        for order in 1..=MAX_ORDER {
            let v = p.vertices();
            let want = AreaRule::parallelogram(v[0], v[1] - v[0], v[3] - v[0], order);
            let got = rules.points(0, order, &mut buf);
            for (k, q) in want.points.iter().enumerate() {
                assert!((DVec3::new(got.x[k], got.y[k], got.z[k]) - *q).length() < 1e-15, "order {order}");
                assert!((got.w[k] - want.weights[k]).abs() < 1e-15);
            }
            let tv = t.vertices();
            let want = AreaRule::triangle(tv[0], tv[1], tv[2], order);
            let got = rules.points(1, order, &mut buf);
            let sum: f64 = got.w.iter().sum();
            assert!((sum - t.area()).abs() < 1e-15, "order {order}");
            assert_eq!(got.w.len(), want.weights.len());
        }
        assert!(!rules.triangulated(0) && rules.triangulated(1));
    }
}
