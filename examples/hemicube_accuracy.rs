//! Accuracy and cost of the hemicube and single-plane methods on the unit cube, per
//! resolution and projection-position rule: surface factors floor→ceiling (V1) and
//! floor→wall (V2), worst patch row-sum error, wall time.
//!
//! `cargo run --release --features studies --example hemicube_accuracy [n ...]` (n = patches per cube edge).
use glam::DVec3;
use lambert::geometry::Polygon;
use lambert::scene::Scene;
use lambert::viewfactor::engine::{run, RowKernel};
use lambert::viewfactor::hemicube::{HemicubeKernel, Positions};
use lambert::viewfactor::single_plane::{SinglePlaneKernel, SinglePlaneOptions};
use lambert::viewfactor::{Level, Params};
use std::time::Instant;

/// V1 and V2 for the unit cube (docs/literature.md §1.1).
const F_OPPOSITE: f64 = 0.19982490;
const F_ADJACENT: f64 = 0.20004378;

fn grid(o: DVec3, u: DVec3, w: DVec3, n: usize) -> Vec<Polygon> {
    let (du, dw) = (u / n as f64, w / n as f64);
    (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let p = o + i as f64 * du + j as f64 * dw;
            Polygon::new(vec![p, p + du, p + du + dw, p + dw]).unwrap()
        })
        .collect()
}

fn cube(n: usize) -> Scene {
    let (o, x, y, z) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
    Scene::builder()
        .surface("floor", grid(o, x, y, n), 1.0, None)
        .surface("ceiling", grid(z, y, x, n), 1.0, None)
        .surface("x0", grid(o, y, z, n), 1.0, None)
        .surface("x1", grid(x, z, y, n), 1.0, None)
        .surface("y0", grid(o, z, x, n), 1.0, None)
        .surface("y1", grid(y, x, z, n), 1.0, None)
        .build()
}

fn report(label: &str, scene: &Scene, kernel: &dyn RowKernel) {
    let t = Instant::now();
    let vf = run(scene, kernel, &Params::default(), Level::Surface).unwrap();
    let wall = t.elapsed().as_secs_f64();
    let (e_opp, e_adj) = (vf.get(0, 1) - F_OPPOSITE, vf.get(0, 3) - F_ADJACENT);
    let (row, _) = vf.max_patch_row_error();
    println!("{label:<34} opp {e_opp:+.2e}  adj {e_adj:+.2e}  |row−1| {row:.1e}  {wall:>7.3} s");
}

fn main() {
    let ns: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let ns = if ns.is_empty() { vec![1, 4, 8] } else { ns };
    let modes = [
        ("centroid", Positions::Centroid),
        ("gauss2", Positions::Gauss(2)),
        ("gauss3", Positions::Gauss(3)),
        ("adaptive", Positions::Adaptive),
    ];
    for n in ns {
        let scene = cube(n);
        println!("cube {n}×{n} per face ({} patches)", scene.patches.len());
        for r in [64, 128, 256] {
            for (name, pos) in modes {
                let k = HemicubeKernel::new(&scene, r, pos).unwrap();
                report(&format!("  hemicube R={r} {name}"), &scene, &k);
            }
            for (name, pos) in modes {
                let opts = SinglePlaneOptions { positions: pos, ..Default::default() };
                let k = SinglePlaneKernel::new(&scene, r, opts).unwrap();
                report(&format!("  single-plane R={r} {name}"), &scene, &k);
            }
        }
    }
}
