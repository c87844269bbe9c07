//! Calibrates the Gauss-ladder error model (src/viewfactor/analytic/ladder.rs): for each order m
//! on one patch (the other integrated to round-off) it sweeps worst-case geometries and prints
//! the largest relative error seen per separation bin λ = D/L, next to the model bound.
//!
//! `cargo run --release --example ladder_calibration`
use glam::{DQuat, DVec3};
use lambert::geometry::quadrature::AreaRule;
use lambert::geometry::Polygon;
use lambert::viewfactor::analytic::ladder::{gauss_exchange, ErrorModel, PatchRules, Points, MAX_ORDER};
use rand::{Rng, SeedableRng};

/// Reference order per sub-piece; with 2×2 sub-pieces it is at round-off for λ ≥ 0.25.
const REF_ORDER: usize = 16;

fn points_of(poly: &Polygon, order: usize, split: usize) -> Points {
    let mut p = Points::default();
    for [a, b, c] in poly.triangulate() {
        // Split each triangle into split² similar triangles (midpoint refinement).
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

/// D lower bound as the kernel computes it.
fn d_lower(pi: &Polygon, pj: &Polygon) -> f64 {
    let sphere = pi.centroid().distance(pj.centroid()) - pi.bounding_radius() - pj.bounding_radius();
    let dj = pj.vertices().iter().map(|v| pi.plane_distance(*v)).fold(f64::INFINITY, f64::min);
    let di = pi.vertices().iter().map(|v| pj.plane_distance(*v)).fold(f64::INFINITY, f64::min);
    sphere.max(dj).max(di).max(0.0)
}

fn square(c: DVec3, n: DVec3, side: f64, spin: f64) -> Polygon {
    let rot = DQuat::from_rotation_arc(DVec3::Z, n) * DQuat::from_rotation_z(spin);
    let h = side / 2.0;
    let v = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| c + rot * DVec3::new(x, y, 0.0));
    Polygon::new(v.to_vec()).unwrap()
}

fn front_facing(pi: &Polygon, pj: &Polygon) -> bool {
    pj.vertices().iter().all(|v| pi.plane_distance(*v) >= -1e-12)
        && pi.vertices().iter().all(|v| pj.plane_distance(*v) >= -1e-12)
}

fn main() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    // Emitters i (the side whose order varies), each of parameter length ~1.
    let emitters: Vec<(&str, Polygon)> = vec![
        ("square", square(DVec3::ZERO, DVec3::Z, 1.0, 0.0)),
        ("rect1x0.2", {
            let v = [(-0.5, -0.1), (0.5, -0.1), (0.5, 0.1), (-0.5, 0.1)];
            Polygon::new(v.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()).unwrap()
        }),
        (
            "triangle",
            Polygon::new(vec![
                DVec3::new(-0.5, -0.4, 0.0),
                DVec3::new(0.5, -0.4, 0.0),
                DVec3::new(0.1, 0.5, 0.0),
            ])
            .unwrap(),
        ),
        (
            "skinny-tri",
            Polygon::new(vec![
                DVec3::new(-0.5, 0.0, 0.0),
                DVec3::new(0.5, -0.05, 0.0),
                DVec3::new(0.5, 0.05, 0.0),
            ])
            .unwrap(),
        ),
    ];
    let mut samples: [Vec<Vec<(f64, f64, f64)>>; 2] =
        [vec![Vec::new(); MAX_ORDER + 1], vec![Vec::new(); MAX_ORDER + 1]];
    for (name, pi) in &emitters {
        let rules_i = PatchRules::new([pi]);
        let li = rules_i.param_len(0);
        let tri = pi.vertices().len() == 3;
        let ref_i = points_of(pi, REF_ORDER, 2);
        let (ni, hi) = plane(pi);
        let mut worst = vec![0.0f64; MAX_ORDER + 1];
        for trial in 0..TRIALS {
            let pj = receiver(trial, &mut rng);
            if !front_facing(pi, &pj) {
                continue;
            }
            let dl = d_lower(pi, &pj);
            let lam = dl / li;
            if lam < LAMBDA_MIN {
                continue;
            }
            // ν: relative variation over patch i of its distance to j's plane (2 on triangles).
            let (lo, hi_) = extent(pi, &pj);
            let nu = if tri { 2.0 } else { variation(lo, hi_) };
            let (nj, hj) = plane(&pj);
            let side = pj.bounding_radius();
            let ref_j = points_of(&pj, REF_ORDER, if side > 0.25 * dl { 2 } else { 1 });
            let exact = gauss_exchange(ref_i.view(), ni, hi, ref_j.view(), nj, hj, &mut Vec::new());
            if !(exact > 0.0) {
                continue;
            }
            let mut buf = Points::default();
            for m in 1..=MAX_ORDER {
                let pts = rules_i.points(0, m, &mut buf);
                let s = gauss_exchange(pts, ni, hi, ref_j.view(), nj, hj, &mut Vec::new());
                let e = ((s - exact) / exact).abs();
                worst[m] = worst[m].max(e / ErrorModel::side_error(m, tri, lam, nu));
                if e > ROUNDOFF {
                    samples[tri as usize][m].push((rho(lam), nu, e));
                }
            }
        }
        print!("{name:>12} L={li:.3}: max error / current model per order:");
        for m in 1..=MAX_ORDER {
            print!(" {:.2e}", worst[m]);
        }
        println!();
    }
    // Envelope fit per piece kind: err ≤ A ρ^(−p) + B ν ρ^(1−p), p = 2m (parallelograms) or
    // 2m − 1 (Duffy triangles). B from the asymptotic regime ρ ≥ RHO_ASYMPTOTIC, then the least A.
    for (kind, name) in [(0, "parallelogram"), (1, "triangle")] {
        println!("\n# {name}: p, samples, B, A (envelope constants before SAFETY)");
        for m in 1..=MAX_ORDER {
            let p = 2 * m as i32 - kind;
            let s = &samples[kind as usize][m];
            let b = s
                .iter()
                .filter(|&&(r, nu, _)| r >= RHO_ASYMPTOTIC && nu > 0.0)
                .map(|&(r, nu, e)| e * r.powi(p - 1) / nu)
                .fold(0.0, f64::max);
            let a = s.iter().map(|&(r, nu, e)| (e - b * nu * r.powi(1 - p)) * r.powi(p)).fold(0.0, f64::max);
            println!("m={m} p={p} n={:>6} B={b:.3e} A={a:.3e}", s.len());
        }
    }
}

/// Samples with ρ above this (λ ≳ 25) fix the slow ν-term of the envelope.
const RHO_ASYMPTOTIC: f64 = 100.0;
const TRIALS: usize = 20000;
/// Separations below this go to the exact contour integral in any case.
const LAMBDA_MIN: f64 = 0.5;
/// Errors below this are round-off of the reference, not quadrature error.
const ROUNDOFF: f64 = 3e-14;

fn rho(lam: f64) -> f64 {
    1.0 + 2.0 * lam + 2.0 * (lam * lam + lam).sqrt()
}

fn variation(lo: f64, hi: f64) -> f64 {
    if hi + lo > 0.0 {
        (2.0 * (hi - lo) / (hi + lo)).min(2.0)
    } else {
        2.0
    }
}

/// Extent of patch i's vertex distances to j's plane, as the kernel computes it.
fn extent(pi: &Polygon, pj: &Polygon) -> (f64, f64) {
    let d = pj.plane_distance(pi.centroid());
    let r = pi.bounding_radius();
    if d.abs() >= r {
        return (d - r, d + r);
    }
    pi.vertices()
        .iter()
        .map(|v| pj.plane_distance(*v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| (a.min(d), b.max(d)))
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
            // Cube-like: emitter on the floor, receiver on a wall x = 0.5 + g facing −x...
            // placed so the emitter is grazing for the receiver (receiver plane through an
            // emitter edge).
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
            let dir = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(0.0..1.0),
            )
            .normalize();
            let c = dir * (d + 0.7 + side);
            let n = (-c.normalize()
                + 0.8
                    * DVec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    ))
            .normalize();
            square(c, n, side, rng.random_range(0.0..1.0))
        }
    }
}
