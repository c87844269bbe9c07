//! Programmatic scenes for the analytic method's tests, benches and examples (benches and
//! examples include this file alone with `#[path]`): subdivided boxes, an L-shaped room and
//! plates with blockers.
#![allow(dead_code)]
use glam::DVec3;
use lambert::geometry::Polygon;
use lambert::scene::Scene;

/// n×m parallelogram patches of o + s·u + t·v; the normal is u × v.
pub fn grid(o: DVec3, u: DVec3, v: DVec3, n: usize, m: usize) -> Vec<Polygon> {
    let (du, dv) = (u / n as f64, v / m as f64);
    let mut out = Vec::with_capacity(n * m);
    for b in 0..m {
        for a in 0..n {
            let p = o + a as f64 * du + b as f64 * dv;
            out.push(Polygon::new(vec![p, p + du, p + du + dv, p + dv]).expect("valid patch"));
        }
    }
    out
}

/// The six inward faces of the box [0,a]×[0,b]×[0,c] as (name, origin, u, v) with u × v inward.
pub fn box_faces(a: f64, b: f64, c: f64) -> [(&'static str, DVec3, DVec3, DVec3); 6] {
    let (x, y, z) = (DVec3::X * a, DVec3::Y * b, DVec3::Z * c);
    [
        ("floor", DVec3::ZERO, x, y),
        ("ceiling", z, y, x),
        ("west", DVec3::ZERO, y, z),
        ("east", x, z, y),
        ("south", DVec3::ZERO, z, x),
        ("north", y, x, z),
    ]
}

/// A closed box room, faces split into patches no wider than `h` (at least one per side).
pub fn box_room(a: f64, b: f64, c: f64, h: f64) -> Scene {
    let mut s = Scene::builder();
    for (name, o, u, v) in box_faces(a, b, c) {
        let (n, m) = ((u.length() / h).ceil().max(1.0) as usize, (v.length() / h).ceil().max(1.0) as usize);
        s = s.surface(name, grid(o, u, v, n, m), 0.9, None);
    }
    s.build()
}

/// The closed unit cube with n×n patches per face (surfaces floor, ceiling, west, east, south,
/// north; floor/ceiling, west/east and south/north are opposite).
pub fn cube(n: usize) -> Scene {
    let mut s = Scene::builder();
    for (name, o, u, v) in box_faces(1.0, 1.0, 1.0) {
        s = s.surface(name, grid(o, u, v, n, n), 0.9, None);
    }
    s.build()
}

/// Inward L-shaped room: the 2×2×1 box minus the quadrant x > 1, y > 1, with n patches per
/// unit length. Surfaces: floor, ceiling (non-convex L polygons cut into unit squares) and
/// six walls; walls `inner-x` (x = 1, y ∈ [1,2]) and `inner-y` (y = 1, x ∈ [1,2]) are the
/// re-entrant ones that block views across the corner.
pub fn l_room(n: usize) -> Scene {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let squares = [DVec3::ZERO, x, y];
    let mut floor = Vec::new();
    let mut ceiling = Vec::new();
    for o in squares {
        floor.extend(grid(o, x, y, n, n));
        ceiling.extend(grid(o + z, y, x, n, n));
    }
    let walls: [(&str, DVec3, DVec3, DVec3, usize); 6] = [
        ("south", DVec3::ZERO, z, 2.0 * x, 2),
        ("west", DVec3::ZERO, 2.0 * y, z, 2),
        ("north", 2.0 * y, x, z, 1),
        ("east", 2.0 * x, z, y, 1),
        ("inner-x", x + y, z, y, 1),
        ("inner-y", x + y, x, z, 1),
    ];
    let mut s = Scene::builder().surface("floor", floor, 0.9, None).surface("ceiling", ceiling, 0.9, None);
    for (name, o, u, v, len) in walls {
        let (nu, nv) = if u == z { (n, len * n) } else { (len * n, n) };
        s = s.surface(name, grid(o, u, v, nu, nv), 0.9, None);
    }
    s.build()
}

/// Two directly opposed unit squares at gap 1 (lower faces up, upper faces down).
pub fn opposed_squares() -> (Polygon, Polygon) {
    let lower = grid(DVec3::ZERO, DVec3::X, DVec3::Y, 1, 1).remove(0);
    let upper = grid(DVec3::Z, DVec3::Y, DVec3::X, 1, 1).remove(0);
    (lower, upper)
}

/// A square plate of side `side` centred at `c`, horizontal, normal `up` (±Z).
pub fn plate(c: DVec3, side: f64, up: bool) -> Polygon {
    let h = side / 2.0;
    let p = grid(c - DVec3::new(h, h, 0.0), DVec3::X * side, DVec3::Y * side, 1, 1).remove(0);
    if up {
        p
    } else {
        p.flipped()
    }
}
