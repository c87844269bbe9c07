//! Programmatic scenes of the studies, with their independent references (module
//! [`crate::validate::oracle`], or constants computed by `cases/_generator`).
use crate::geometry::{DVec3, Polygon};
use crate::scene::{Scene, SceneBuilder, Shape};
use crate::validate::oracle::{closed, far, lambert};
use crate::viewfactor::ViewFactors;

/// Ambient temperature of the open study scenes (only its presence matters here).
const AMBIENT_K: f64 = 300.0;

/// The n×m parallelogram patches of o + s·u + t·v.
pub fn grid(o: DVec3, u: DVec3, v: DVec3, n: usize, m: usize) -> Vec<Polygon> {
    let mut out = Vec::with_capacity(n * m);
    for i in 0..n {
        for j in 0..m {
            let p = o + u * (i as f64 / n as f64) + v * (j as f64 / m as f64);
            let (du, dv) = (u / n as f64, v / m as f64);
            out.push(Polygon::new(vec![p, p + du, p + du + dv, p + dv]).expect("valid parallelogram"));
        }
    }
    out
}

fn rect(b: &mut SceneBuilder, name: &str, o: DVec3, u: DVec3, v: DVec3, n: usize) {
    b.push_surface(name, Shape::Rectangle { origin: o, u, v }, grid(o, u, v, n, n), 1.0, None);
}

/// Closed unit cube, inward faces, n×n patches each (V15).
pub fn cube(n: usize) -> Scene {
    let mut b = Scene::builder().title("unit cube interior");
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    for (name, o, u, v) in [
        ("floor", DVec3::ZERO, x, y),
        ("ceiling", z, y, x),
        ("wall_y0", DVec3::ZERO, z, x),
        ("wall_y1", y, x, z),
        ("wall_x0", DVec3::ZERO, y, z),
        ("wall_x1", x, z, y),
    ] {
        rect(&mut b, name, o, u, v, n);
    }
    b.build()
}

/// Largest |F_IJ − exact| over the cube's face pairs (C-11 opposite, C-14 adjacent, 0 self).
pub fn cube_error(vf: &ViewFactors) -> f64 {
    let opp = closed::parallel_rectangles(1.0, 1.0, 1.0);
    let adj = closed::perpendicular_common_edge(1.0, 1.0, 1.0);
    let mut worst: f64 = 0.0;
    for i in 0..6 {
        for j in 0..6 {
            let exact = if i == j {
                0.0
            } else if i / 2 == j / 2 {
                opp
            } else {
                adj
            };
            worst = worst.max((vf.get(i, j) - exact).abs());
        }
    }
    worst
}

/// F(bottom → top) of unit squares 1 apart with a centred 0.5×0.5 blocker midway, by exact
/// shadow integration in cases/_generator (o1_squares_centred_blocker, converged to 2e-15).
pub const BLOCKED_SQUARES: f64 = 0.09950629459898472;

/// The o1 geometry built in code: n×n patches per square, the blocker as an obstruction.
pub fn blocked_squares(n: usize) -> Scene {
    let mut b = Scene::builder().title("squares with a centred blocker").ambient(AMBIENT_K);
    rect(&mut b, "bottom", DVec3::ZERO, DVec3::X, DVec3::Y, n);
    rect(&mut b, "top", DVec3::Z, DVec3::Y, DVec3::X, n);
    let blocker = Polygon::new(vec![
        DVec3::new(0.25, 0.25, 0.5),
        DVec3::new(0.25, 0.75, 0.5),
        DVec3::new(0.75, 0.75, 0.5),
        DVec3::new(0.75, 0.25, 0.5),
    ])
    .expect("valid square");
    b.obstruction("blocker", vec![blocker]).build()
}

/// Room 3 m cube around the block \[1,2\]³: row F(floor → ·) by exact shadow integration in
/// cases/_generator (o3_obstructed_room, converged to 1e-12; the row closes to 4e-12).
pub(crate) mod room_ref {
    /// Floor to ceiling, past the block.
    pub const OPPOSITE: f64 = 0.12772265829922155;
    /// Floor to one wall, past the block.
    pub const ADJACENT: f64 = 0.19029155764683442;
    /// Floor to the block face that faces it.
    pub const BLOCK_FACING: f64 = 0.07970405451156848;
    /// Floor to one block side face.
    pub const BLOCK_SIDE: f64 = 0.007851764149885691;
}

/// Names and inward (room) or outward (block) normals of the room scene, in surface order.
const ROOM_FACES: [(&str, [f64; 3]); 12] = [
    ("floor", [0.0, 0.0, 1.0]),
    ("ceiling", [0.0, 0.0, -1.0]),
    ("wall_x0", [1.0, 0.0, 0.0]),
    ("wall_x1", [-1.0, 0.0, 0.0]),
    ("wall_y0", [0.0, 1.0, 0.0]),
    ("wall_y1", [0.0, -1.0, 0.0]),
    ("block_bottom", [0.0, 0.0, -1.0]),
    ("block_top", [0.0, 0.0, 1.0]),
    ("block_x0", [-1.0, 0.0, 0.0]),
    ("block_x1", [1.0, 0.0, 0.0]),
    ("block_y0", [0.0, -1.0, 0.0]),
    ("block_y1", [0.0, 1.0, 0.0]),
];

/// The obstructed room: `nr`×`nr` patches per room face, `nb`×`nb` per block face.
pub fn room(nr: usize, nb: usize) -> Scene {
    let mut b = Scene::builder().title("obstructed room");
    let l = 3.0;
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let one = DVec3::ONE;
    let faces: [(DVec3, DVec3, DVec3, usize); 12] = [
        (DVec3::ZERO, x * l, y * l, nr),
        (z * l, y * l, x * l, nr),
        (DVec3::ZERO, y * l, z * l, nr),
        (x * l, z * l, y * l, nr),
        (DVec3::ZERO, z * l, x * l, nr),
        (y * l, x * l, z * l, nr),
        (one, y, x, nb),
        (one + z, x, y, nb),
        (one, z, y, nb),
        (one + x, y, z, nb),
        (one, x, z, nb),
        (one + y, z, x, nb),
    ];
    for ((name, normal), (o, u, v, n)) in ROOM_FACES.iter().zip(faces) {
        debug_assert!(u.cross(v).normalize().abs_diff_eq(DVec3::from(*normal), 1e-12), "{name}");
        rect(&mut b, name, o, u, v, n);
    }
    b.build()
}

/// Largest |F_IJ − reference| over the six room-face rows (the cube's symmetry maps every row
/// onto the floor's).
pub fn room_error(vf: &ViewFactors) -> f64 {
    let mut worst: f64 = 0.0;
    for (i, (_, n)) in ROOM_FACES.iter().enumerate().take(6) {
        let ni = DVec3::from(*n);
        for (j, (_, nj)) in ROOM_FACES.iter().enumerate() {
            let d = ni.dot(DVec3::from(*nj));
            let exact = match (j < 6, d.round() as i32) {
                (true, 1) => 0.0,
                (true, -1) => room_ref::OPPOSITE,
                (true, _) => room_ref::ADJACENT,
                (false, -1) => room_ref::BLOCK_FACING,
                (false, 1) => 0.0,
                (false, _) => room_ref::BLOCK_SIDE,
            };
            worst = worst.max((vf.get(i, j) - exact).abs());
        }
    }
    worst
}

/// Two surfaces `a` → `b` with `n`×`n` patches each (stability scenes), open to an ambient.
fn pair(a: (DVec3, DVec3, DVec3, usize), b: (DVec3, DVec3, DVec3, usize)) -> Scene {
    let mut s = Scene::builder().ambient(AMBIENT_K);
    rect(&mut s, "a", a.0, a.1, a.2, a.3);
    rect(&mut s, "b", b.0, b.1, b.2, b.3);
    s.build()
}

/// Perpendicular unit squares, the wall lifted by `gap` off the common edge; F(floor → wall)
/// by the V4 strip algebra.
pub fn perpendicular_gap(gap: f64, n: usize) -> (Scene, f64) {
    let scene =
        pair((DVec3::ZERO, DVec3::X, DVec3::Y, n), (DVec3::new(0.0, 0.0, gap), DVec3::Y, DVec3::Z, n));
    (scene, closed::perpendicular_strips_exchange(0.0, 1.0, gap, 1.0 + gap, 1.0))
}

/// Opposed unit squares at distance `c`; C-11 (with ln_1p) up to c = 3, 10-point 2AI beyond.
pub fn parallel_far(c: f64, n: usize) -> (Scene, f64) {
    let scene = pair((DVec3::ZERO, DVec3::X, DVec3::Y, n), (DVec3::new(0.0, 0.0, c), DVec3::Y, DVec3::X, n));
    let exact = if c <= 3.0 {
        closed::parallel_rectangles(1.0, 1.0, c)
    } else {
        far::exchange_area_2ai(
            (DVec3::ZERO, DVec3::X, DVec3::Y),
            (DVec3::new(0.0, 0.0, c), DVec3::Y, DVec3::X),
            10,
        )
    };
    (scene, exact)
}

/// Unit square emitter under a centred receiver square of side `s` at height 1 (one patch);
/// F(emitter → receiver) = A_r F(r → e)/A_e by Gauss over the small receiver.
pub fn small_receiver(s: f64, n: usize) -> (Scene, f64) {
    let o = DVec3::new(0.5 - s / 2.0, 0.5 - s / 2.0, 1.0);
    let mut b = Scene::builder().ambient(AMBIENT_K);
    rect(&mut b, "a", DVec3::ZERO, DVec3::X, DVec3::Y, n);
    rect(&mut b, "b", o, DVec3::Y * s, DVec3::X * s, 1);
    let emitter = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
    let exact = lambert::exchange_area_parallelogram(o, DVec3::Y * s, DVec3::X * s, &emitter, 4, 8);
    (b.build(), exact)
}

/// Unit square emitter centred at the origin, tilted by `theta` about y, under a unit receiver
/// at height 1 facing down; F(emitter → receiver) by Gauss over the emitter (the receiver
/// clipped to each point's horizon).
pub fn tilted(theta: f64, n: usize) -> (Scene, f64) {
    let (s, c) = theta.sin_cos();
    let u = DVec3::new(c, 0.0, -s);
    let o = -0.5 * u - 0.5 * DVec3::Y;
    let r = DVec3::new(-0.5, -0.5, 1.0);
    let scene = pair((o, u, DVec3::Y, n), (r, DVec3::Y, DVec3::X, n));
    let receiver = [r, r + DVec3::Y, r + DVec3::new(1.0, 1.0, 0.0), r + DVec3::X];
    (scene, lambert::exchange_area_parallelogram(o, u, DVec3::Y, &receiver, 8, 8))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stability_references_agree_with_closed_forms_and_converge() {
        // The small-receiver Gauss reference reproduces C-11 at s = 1.
        let (_, f) = small_receiver(1.0, 1);
        assert!((f - closed::parallel_rectangles(1.0, 1.0, 1.0)).abs() < 1e-13, "{f}");
        // The tilt reference at θ = 0 is the same C-11 pair.
        let (_, f) = tilted(0.0, 1);
        assert!((f - closed::parallel_rectangles(1.0, 1.0, 1.0)).abs() < 1e-13, "{f}");
        // Near grazing, doubling the rule changes nothing at 1e-12 relative.
        for deg in [60.0f64, 89.0, 89.99] {
            let t = deg.to_radians();
            let (s, c) = t.sin_cos();
            let u = DVec3::new(c, 0.0, -s);
            let o = -0.5 * u - 0.5 * DVec3::Y;
            let r = DVec3::new(-0.5, -0.5, 1.0);
            let ring = [r, r + DVec3::Y, r + DVec3::new(1.0, 1.0, 0.0), r + DVec3::X];
            let a = lambert::exchange_area_parallelogram(o, u, DVec3::Y, &ring, 8, 8);
            let b = lambert::exchange_area_parallelogram(o, u, DVec3::Y, &ring, 16, 10);
            assert!(((a - b) / b).abs() < 1e-12, "θ={deg}: {a} vs {b}");
        }
    }

    #[test]
    fn scenes_have_the_intended_orientation() {
        let s = room(2, 1);
        for (surface, (name, n)) in s.surfaces.iter().zip(ROOM_FACES) {
            let p = &s.patches[surface.patches.start].polygon;
            assert!(p.normal().abs_diff_eq(DVec3::from(n), 1e-12), "{name}");
        }
        assert_eq!(cube(3).patches.len(), 54);
    }
}
