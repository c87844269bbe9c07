//! Accuracy study of the Monte Carlo estimators: RMSE against the closed form and the mean
//! reported standard error, over many seeds, for Sobol (RQMC) and plain random sampling.
//!
//! `cargo run --release --features studies --example mc_study [seeds]` — numbers go to validation/rays.md.
#[path = "../tests/common/mod.rs"]
mod common;

use common::*;
use lambert::scene::Scene;
use lambert::viewfactor::monte_carlo::{compute_with, McOptions, Sampler};
use lambert::viewfactor::{Level, Method, Params};

fn main() {
    let seeds: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(40);
    let cases: [(&str, Scene, f64); 3] = [
        ("C-11 parallel", parallel_squares(), F_PARALLEL),
        ("C-14 perpendicular", perpendicular_squares(), F_PERPENDICULAR),
        ("blocked (d)", blocked_squares(), F_BLOCKED),
    ];
    println!("| case | method | N | random RMSE | random SE/RMSE | sobol RMSE | sobol SE/RMSE | gain (RMSE ratio) |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, scene, exact) in &cases {
        for m in [Method::McArea, Method::McUniform, Method::McCosine] {
            for n in [1usize << 10, 1 << 13, 1 << 16] {
                let mut row = Vec::new();
                for sampler in [Sampler::Random, Sampler::Sobol] {
                    let (mut se2, mut se_sum) = (0.0, 0.0);
                    for s in 0..seeds {
                        let p = Params { method: m, samples: n, seed: 1000 + s, ..Params::default() };
                        let vf = compute_with(scene, &p, Level::Surface, McOptions { sampler }).unwrap();
                        let e = vf.rows[0].iter().find(|e| e.to == 1).copied();
                        let (f, se) = e.map_or((0.0, 0.0), |e| (e.factor, e.std_error));
                        se2 += (f - exact).powi(2);
                        se_sum += se;
                    }
                    let rmse = (se2 / seeds as f64).sqrt();
                    row.push((rmse, se_sum / seeds as f64 / rmse));
                }
                println!(
                    "| {name} | {m} | {n} | {:.3e} | {:.2} | {:.3e} | {:.2} | {:.2} |",
                    row[0].0,
                    row[0].1,
                    row[1].0,
                    row[1].1,
                    row[0].0 / row[1].0
                );
            }
        }
    }
}
