//! Calibrates the Gauss-ladder error model of src/viewfactor/analytic/ladder.rs.
//!
//! For four emitter shapes (square, 5:1 rectangle, triangle, skinny triangle) and 20 000 random
//! receivers (parallel, offset, perpendicular and grazing, tilted, random; sides 0.02–3), it
//! integrates the emitter with the order-m rule and the receiver to round-off, and records the
//! relative error against λ = D/L (D as the kernel bounds it) and ν (the variation of the
//! receiver's cosine factor over the emitter). It prints, per piece kind and order, the
//! envelope constants A, B of err ≤ A·ρ^(−p) + B·ν·ρ^(1−p) (the values in `MODEL_A/MODEL_B`),
//! and per emitter the largest ratio of error to the current bound (must stay below 1/SAFETY;
//! errors at round-off, below 3e-14, are left out: the bound covers quadrature error only).
//!
//! `cargo run --release --features studies --example ladder_calibration`
use glam::{DQuat, DVec3};
use lambert::geometry::quadrature::AreaRule;
use lambert::geometry::Polygon;
use lambert::viewfactor::analytic::ladder::{
    gauss_exchange, rho, ErrorModel, PatchRules, Points, MAX_ORDER, SAFETY,
};
use rand::{Rng, SeedableRng};

/// Receivers drawn per emitter.
const TRIALS: usize = 20000;
/// Reference order per sub-triangle (4 sub-triangles per emitter triangle): round-off for λ ≥ 0.25.
const REF_ORDER: usize = 16;
/// Separations below this go to the exact contour integral in any case.
const LAMBDA_MIN: f64 = 0.5;
/// Errors below this are round-off of the reference, not quadrature error.
const ROUNDOFF: f64 = 3e-14;
/// Samples with ρ above this (λ ≳ 25) fix the slow ν-term of the envelope.
const RHO_ASYMPTOTIC: f64 = 100.0;

/// Reference points: each triangle of `poly` split `split`-fold (midpoints), order `order`.
fn reference_points(poly: &Polygon, order: usize, split: usize) -> Points {
    let mut p = Points::default();
    for [a, b, c] in poly.triangulate() {
        let mut tris = vec![[a, b, c]];
        for _ in 1..split {
            tris = tris
                .into_iter()
                .flat_map(|[a, b, c]| {
                    let (ab, bc, ca) = ((a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0);
                    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
                })
                .collect();
        }
        for [a, b, c] in tris {
            p.push_rule(&AreaRule::triangle(a, b, c, order));
        }
    }
    p
}

fn plane(poly: &Polygon) -> (DVec3, f64) {
    (poly.normal(), poly.normal().dot(poly.centroid()))
}

/// Extent of `p`'s vertex distances to `q`'s plane, as the kernel computes it (bounding sphere
/// when it decides the sign).
fn extent(p: &Polygon, q: &Polygon) -> (f64, f64) {
    let (d, r) = (q.plane_distance(p.centroid()), p.bounding_radius());
    if d.abs() >= r {
        return (d - r, d + r);
    }
    p.vertices()
        .iter()
        .map(|v| q.plane_distance(*v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| (a.min(d), b.max(d)))
}

/// The kernel's lower bound of the distance between two front-facing patches.
fn d_lower(pi: &Polygon, pj: &Polygon) -> f64 {
    let sphere = pi.centroid().distance(pj.centroid()) - pi.bounding_radius() - pj.bounding_radius();
    sphere.max(extent(pj, pi).0).max(extent(pi, pj).0).max(0.0)
}

/// ν as the kernel computes it.
fn variation(lo: f64, hi: f64) -> f64 {
    if lo > 0.0 {
        (2.0 * (hi - lo) / (hi + lo)).min(2.0)
    } else {
        2.0
    }
}

fn square(c: DVec3, n: DVec3, side: f64, spin: f64) -> Polygon {
    let rot = DQuat::from_rotation_arc(DVec3::Z, n) * DQuat::from_rotation_z(spin);
    let h = side / 2.0;
    let v = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| c + rot * DVec3::new(x, y, 0.0));
    Polygon::new(v.to_vec()).unwrap()
}

fn front_facing(pi: &Polygon, pj: &Polygon) -> bool {
    extent(pj, pi).0 >= 0.0 && extent(pi, pj).0 >= 0.0
}

fn receiver(trial: usize, rng: &mut rand_pcg::Pcg64) -> Polygon {
    let d = 0.5 * 10f64.powf(rng.random_range(0.0..3.5));
    let side = [0.02, 0.3, 1.0, 3.0][trial % 4];
    match (trial / 4) % 6 {
        0 => square(DVec3::new(0.0, 0.0, d), -DVec3::Z, side, rng.random_range(0.0..1.0)),
        1 => {
            let off = rng.random_range(0.0..3.0) * d;
            square(DVec3::new(off, 0.3 * off, d), -DVec3::Z, side, rng.random_range(0.0..1.0))
        }
        2 => {
            // Perpendicular, often grazing: bottom edge on the emitter's plane.
            let z0 = if rng.random_bool(0.5) { 0.0 } else { rng.random_range(0.0..1.0) * d };
            square(
                DVec3::new(0.5 + d, rng.random_range(-1.0..1.0) * d, z0 + side / 2.0),
                -DVec3::X,
                side,
                0.0,
            )
        }
        3 => {
            // Receiver plane through an emitter edge (ν = 2 on the emitter).
            let h = rng.random_range(0.0..2.0) * d;
            square(DVec3::new(0.5, rng.random_range(-1.0..1.0) * d, d + h + side / 2.0), -DVec3::X, side, 0.0)
        }
        4 => {
            let t = rng.random_range(0.05..1.5f64);
            let n = DVec3::new(-t.sin(), 0.0, -t.cos());
            square(
                DVec3::new(0.5 + d * t.sin(), 0.0, d * t.cos() + side),
                n,
                side,
                rng.random_range(0.0..1.0),
            )
        }
        _ => {
            let mut r = || rng.random_range(-1.0..1.0);
            let dir = DVec3::new(r(), r(), r().abs()).normalize();
            let c = dir * (d + 0.7 + side);
            let n = (-c.normalize() + 0.8 * DVec3::new(r(), r(), r())).normalize();
            square(c, n, side, rng.random_range(0.0..1.0))
        }
    }
}

fn main() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let at =
        |pts: &[(f64, f64)]| Polygon::new(pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()).unwrap();
    let emitters = [
        ("square", square(DVec3::ZERO, DVec3::Z, 1.0, 0.0)),
        ("rect1x0.2", at(&[(-0.5, -0.1), (0.5, -0.1), (0.5, 0.1), (-0.5, 0.1)])),
        ("triangle", at(&[(-0.5, -0.4), (0.5, -0.4), (0.1, 0.5)])),
        ("skinny-tri", at(&[(-0.5, 0.0), (0.5, -0.05), (0.5, 0.05)])),
    ];
    // samples[kind][order] = (ρ, ν, relative error), kind 0 = parallelogram, 1 = triangles.
    let mut samples = vec![vec![Vec::new(); MAX_ORDER + 1]; 2];
    for (name, pi) in &emitters {
        let rules = PatchRules::new([pi]);
        let (li, tri) = (rules.param_len(0), rules.triangulated(0));
        let ref_i = reference_points(pi, REF_ORDER, 2);
        let (ni, hi) = plane(pi);
        let mut worst = [0.0f64; MAX_ORDER + 1];
        let (mut buf, mut scratch) = (Points::default(), Vec::new());
        for trial in 0..TRIALS {
            let pj = receiver(trial, &mut rng);
            if !front_facing(pi, &pj) {
                continue;
            }
            let dl = d_lower(pi, &pj);
            let lambda = dl / li;
            if lambda < LAMBDA_MIN {
                continue;
            }
            let (lo, hi_) = extent(pi, &pj);
            let nu = if tri { 2.0 } else { variation(lo, hi_) };
            let (nj, hj) = plane(&pj);
            let ref_j =
                reference_points(&pj, REF_ORDER, if pj.bounding_radius() > 0.25 * dl { 2 } else { 1 });
            let exact = gauss_exchange(ref_i.view(), ni, hi, ref_j.view(), nj, hj, &mut scratch);
            if exact <= 0.0 {
                continue;
            }
            for (m, w) in worst.iter_mut().enumerate().skip(1) {
                let s =
                    gauss_exchange(rules.points(0, m, &mut buf), ni, hi, ref_j.view(), nj, hj, &mut scratch);
                let e = ((s - exact) / exact).abs();
                if e > ROUNDOFF {
                    *w = w.max(e / ErrorModel::side_error(m, tri, lambda, nu));
                    samples[tri as usize][m].push((rho(lambda), nu, e));
                }
            }
        }
        let ratios: Vec<String> = worst[1..].iter().map(|w| format!("{w:.2e}")).collect();
        println!(
            "{name:>11}: max error / bound, orders 1..{MAX_ORDER}: {} (limit {:.2})",
            ratios.join(" "),
            1.0 / SAFETY
        );
    }
    // Envelope per kind: B from the asymptotic regime, then the least A covering every sample.
    for (kind, name) in ["parallelogram", "triangle"].iter().enumerate() {
        println!("\n{name}: order, exponent p, samples above round-off, B, A (before SAFETY)");
        for (m, s) in samples[kind].iter().enumerate().skip(1) {
            let p = 2 * m as i32 - kind as i32;
            let b = s
                .iter()
                .filter(|&&(r, nu, _)| r >= RHO_ASYMPTOTIC && nu > 0.0)
                .map(|&(r, nu, e)| e * r.powi(p - 1) / nu)
                .fold(0.0, f64::max);
            let a = s.iter().map(|&(r, nu, e)| (e - b * nu * r.powi(1 - p)) * r.powi(p)).fold(0.0, f64::max);
            println!("  m={m} p={p:>2} n={:>6} B={b:.3e} A={a:.3e}", s.len());
        }
    }
}
