//! Exact exchange areas between axis-aligned rectangles (test and study oracle):
//! parallel pairs by the corner-sum formula (docs/literature.md V7, catalogue C-13), perpendicular
//! pairs from the common-edge formula C-14 (V2) extended by bilinearity across the edge
//! (V4) and the translation-kernel identity along it (V5):
//! S([a,b],[c,d]) = ½[Φ(b−c) − Φ(a−c) − Φ(b−d) + Φ(a−d)].
use glam::DVec3;
use lambert::geometry::Polygon;
use std::f64::consts::PI;

/// An axis-aligned rectangle facing `inward` (±1) along `axis`, in the plane x[axis] = pos.
#[derive(Debug, Clone, Copy)]
pub struct Rect {
    pub axis: usize,
    pub pos: f64,
    pub inward: f64,
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

impl Rect {
    pub fn area(&self) -> f64 {
        let (u, v) = others(self.axis);
        (self.hi[u] - self.lo[u]) * (self.hi[v] - self.lo[v])
    }
    /// The polygon with its normal along `inward`.
    pub fn polygon(&self) -> Polygon {
        let (u, v) = others(self.axis);
        let corner = |a: f64, b: f64| {
            let mut p = [0.0; 3];
            p[self.axis] = self.pos;
            p[u] = a;
            p[v] = b;
            DVec3::from_array(p)
        };
        let (u0, u1, v0, v1) = (self.lo[u], self.hi[u], self.lo[v], self.hi[v]);
        let poly =
            Polygon::new(vec![corner(u0, v0), corner(u1, v0), corner(u1, v1), corner(u0, v1)]).unwrap();
        if poly.normal()[self.axis] * self.inward > 0.0 {
            poly
        } else {
            poly.flipped()
        }
    }
}

fn others(axis: usize) -> (usize, usize) {
    ((axis + 1) % 3, (axis + 2) % 3)
}

/// Faces of the box [0,d0]×[0,d1]×[0,d2] facing inward, each split `split`×`split`; names
/// follow the face order −x, +x, −y, +y, −z, +z.
pub fn box_faces(d: [f64; 3], split: usize) -> Vec<(String, Vec<Rect>)> {
    let names = ["x0", "x1", "y0", "y1", "z0", "z1"];
    let mut out = Vec::new();
    for axis in 0..3 {
        for side in 0..2 {
            let (u, v) = others(axis);
            let pos = if side == 0 { 0.0 } else { d[axis] };
            let inward = if side == 0 { 1.0 } else { -1.0 };
            let mut rects = Vec::new();
            for a in 0..split {
                for b in 0..split {
                    let mut lo = [pos; 3];
                    let mut hi = [pos; 3];
                    lo[u] = d[u] * a as f64 / split as f64;
                    hi[u] = d[u] * (a + 1) as f64 / split as f64;
                    lo[v] = d[v] * b as f64 / split as f64;
                    hi[v] = d[v] * (b + 1) as f64 / split as f64;
                    rects.push(Rect { axis, pos, inward, lo, hi });
                }
            }
            out.push((names[2 * axis + side].to_string(), rects));
        }
    }
    out
}

/// C-14: F from a w-wide rectangle to an h-high one sharing an edge of length l.
pub fn f_c14(w: f64, h: f64, l: f64) -> f64 {
    let (w, h) = (w / l, h / l);
    let (w2, h2) = (w * w, h * h);
    let s = (w2 + h2).sqrt();
    let ln = ((1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2)).ln()
        + w2 * (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).ln()
        + h2 * (h2 * (1.0 + w2 + h2) / ((1.0 + h2) * (w2 + h2))).ln();
    (w * (1.0 / w).atan() + h * (1.0 / h).atan() - s * (1.0 / s).atan() + 0.25 * ln) / (PI * w)
}

/// C-11: identical directly opposed a×b rectangles at gap c.
pub fn f_c11(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * (((1.0 + x2) * (1.0 + y2) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Common-edge exchange area of a floor [0,x]×[0,l] and a wall [0,z]×[0,l].
fn phi(x: f64, z: f64, l: f64) -> f64 {
    if x <= 0.0 || z <= 0.0 || l <= 0.0 {
        return 0.0;
    }
    x * l * f_c14(x, z, l)
}

/// Perpendicular: floor x∈[x1,x2] (distance from the wall plane), wall z∈[z1,z2] (distance
/// from the floor plane), along-edge intervals [a,b] (floor) and [c,d] (wall).
pub fn perpendicular(x: [f64; 2], z: [f64; 2], ab: [f64; 2], cd: [f64; 2]) -> f64 {
    let big = |l: f64| {
        let l = l.abs();
        phi(x[1], z[1], l) - phi(x[0], z[1], l) - phi(x[1], z[0], l) + phi(x[0], z[0], l)
    };
    let [a, b] = ab;
    let [c, d] = cd;
    0.5 * (big(b - c) - big(a - c) - big(b - d) + big(a - d))
}

/// Parallel corner sum (V7): rectangles [x1,x2]×[y1,y2] and [ξ1,ξ2]×[η1,η2] at gap z.
pub fn parallel(x: [f64; 2], y: [f64; 2], xi: [f64; 2], eta: [f64; 2], z: f64) -> f64 {
    let g = |u: f64, v: f64| {
        let a = (u * u + z * z).sqrt();
        let b = (v * v + z * z).sqrt();
        let t1 = if a > 0.0 { v * a * (v / a).atan() } else { 0.0 };
        let t2 = if b > 0.0 { u * b * (u / b).atan() } else { 0.0 };
        (t1 + t2 - 0.5 * z * z * (u * u + v * v + z * z).ln()) / (2.0 * PI)
    };
    let mut sum = 0.0;
    for (i, xv) in x.iter().enumerate() {
        for (j, yv) in y.iter().enumerate() {
            for (k, ev) in eta.iter().enumerate() {
                for (l, xiv) in xi.iter().enumerate() {
                    let sign = if (i + j + k + l) % 2 == 0 { 1.0 } else { -1.0 };
                    sum += sign * g(xv - xiv, yv - ev);
                }
            }
        }
    }
    sum
}

/// Exact A_a F_ab for two inward-facing rectangles of one box.
pub fn exchange_area(a: &Rect, b: &Rect) -> f64 {
    if a.axis == b.axis {
        if (a.pos - b.pos).abs() < 1e-15 {
            return 0.0;
        }
        let (u, v) = others(a.axis);
        return parallel(
            [a.lo[u], a.hi[u]],
            [a.lo[v], a.hi[v]],
            [b.lo[u], b.hi[u]],
            [b.lo[v], b.hi[v]],
            (a.pos - b.pos).abs(),
        );
    }
    // a is the floor (normal along p), b the wall (normal along q), r the common axis.
    let (p, q) = (a.axis, b.axis);
    let r = 3 - p - q;
    let xs = [(a.lo[q] - b.pos).abs(), (a.hi[q] - b.pos).abs()];
    let zs = [(b.lo[p] - a.pos).abs(), (b.hi[p] - a.pos).abs()];
    let x = [xs[0].min(xs[1]), xs[0].max(xs[1])];
    let z = [zs[0].min(zs[1]), zs[0].max(zs[1])];
    perpendicular(x, z, [a.lo[r], a.hi[r]], [b.lo[r], b.hi[r]])
}
