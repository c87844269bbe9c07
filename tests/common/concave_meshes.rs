//! Concave closed meshes built from an extruded 2-D profile (an L-bracket, a U-channel, a
//! finned heat sink), and a brute Monte Carlo view factor with exact per-ray visibility
//! against triangles, independent of the library's shadow code.
use glam::DVec2;
use lambert::geometry::convex::ear_indices;
use lambert::geometry::{DVec3, Polygon};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// L-bracket profile in the unit square, counter-clockwise (legs 0.25 thick).
pub const L_PROFILE: &[[f64; 2]] =
    &[[0.0, 0.0], [1.0, 0.0], [1.0, 0.25], [0.25, 0.25], [0.25, 1.0], [0.0, 1.0]];
/// U-channel profile, counter-clockwise (walls 0.2 thick, opening up).
pub const U_PROFILE: &[[f64; 2]] =
    &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.8, 1.0], [0.8, 0.2], [0.2, 0.2], [0.2, 1.0], [0.0, 1.0]];
/// Heat-sink profile: a base 0.2 thick with three fins 0.1 wide (the middle one half as
/// tall, so the bays see over it in part), counter-clockwise.
pub const FIN_PROFILE: &[[f64; 2]] = &[
    [0.0, 0.0],
    [1.0, 0.0],
    [1.0, 0.8],
    [0.9, 0.8],
    [0.9, 0.2],
    [0.55, 0.2],
    [0.55, 0.4],
    [0.45, 0.4],
    [0.45, 0.2],
    [0.1, 0.2],
    [0.1, 0.8],
    [0.0, 0.8],
];

/// The closed triangle mesh (outward normals) of `profile` (counter-clockwise, in (u, v))
/// extruded over w ∈ [0, 1], placed by `place(u, v, w)`, which must keep orientation
/// (a rotation, translation and uniform scale).
pub fn extruded(profile: &[[f64; 2]], place: impl Fn(f64, f64, f64) -> DVec3) -> Vec<Polygon> {
    let p: Vec<DVec2> = profile.iter().map(|&[u, v]| DVec2::new(u, v)).collect();
    let m = p.len();
    let at = |q: DVec2, w: f64| place(q.x, q.y, w);
    let tri = |a, b, c| Polygon::new(vec![a, b, c]).expect("valid triangle");
    let mut out = Vec::new();
    for k in 0..m {
        let (a, b) = (p[k], p[(k + 1) % m]);
        // Outward normal (d.y, −d.x, 0) for a counter-clockwise profile.
        out.push(tri(at(a, 0.0), at(b, 0.0), at(b, 1.0)));
        out.push(tri(at(a, 0.0), at(b, 1.0), at(a, 1.0)));
    }
    for [i, j, k] in ear_indices(&p) {
        out.push(tri(at(p[i], 1.0), at(p[j], 1.0), at(p[k], 1.0)));
        out.push(tri(at(p[k], 0.0), at(p[j], 0.0), at(p[i], 0.0)));
    }
    out
}

/// True when the open segment a → b crosses triangle `t` (Möller–Trumbore).
fn hits(a: DVec3, b: DVec3, t: &[DVec3]) -> bool {
    let d = b - a;
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-300 {
        return false;
    }
    let tv = a - t[0];
    let u = tv.dot(pv) / det;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) / det;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let s = e2.dot(qv) / det;
    s > 1e-9 && s < 1.0 - 1e-9
}

/// Brute Monte Carlo F(from → to) past the triangles `blockers` with `n` uniform point pairs
/// (seeded): the mean of A_to·cosθ₁cosθ₂/(πr²)·V and its standard error. `from` and `to`
/// are triangles.
pub fn brute_vf(from: &Polygon, to: &Polygon, blockers: &[Polygon], n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let tris: Vec<&[DVec3]> = blockers.iter().map(|p| p.vertices()).collect();
    let pick = |t: &[DVec3], rng: &mut Pcg64Mcg| {
        let (mut r1, mut r2): (f64, f64) = (rng.random(), rng.random());
        if r1 + r2 > 1.0 {
            (r1, r2) = (1.0 - r1, 1.0 - r2);
        }
        t[0] + r1 * (t[1] - t[0]) + r2 * (t[2] - t[0])
    };
    let (n1, n2, a2) = (from.normal(), to.normal(), to.area());
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let x = pick(from.vertices(), &mut rng);
        let y = pick(to.vertices(), &mut rng);
        let d = y - x;
        let r2 = d.length_squared();
        let c = n1.dot(d) * -n2.dot(d);
        let mut k = 0.0;
        if c > 0.0 && !tris.iter().any(|t| hits(x, y, t)) {
            k = a2 * c / (std::f64::consts::PI * r2 * r2);
        }
        sum += k;
        sum2 += k * k;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}
