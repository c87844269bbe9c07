//! Enforcement study (docs/literature.md §3): a 1×2×3 box in 24 patches, multinomial hit counts
//! from the exact rows (statistically identical to mc-cosine in a convex box) at 200 and 1000
//! rays per patch, 40 seeds; rms ΔF against the exact factors (over all 24² entries), the
//! worst surface heat-rate error of a mixed-ε, all-temperature solve (relative to the largest
//! |Q|), and negative entries, for every enforcement method.
//!
//! Run: `cargo run --release --features studies --example enforcement_study`

// Dense matrix sums read clearest with (i, j) indices.
#![allow(clippy::needless_range_loop)]
#[path = "../tests/common/mod.rs"]
mod common;

use lambert::exchange::{enforce, ClosureMethod, Diagnostics, Enforce, EnforceParams, Exchange};
use lambert::scene::BoundaryCondition::Temperature;
use lambert::scene::{BoundaryCondition, Scene};
use lambert::solve::{self, Params};

const SEEDS: u64 = 40;

#[derive(Clone, Copy, PartialEq)]
enum Variant {
    Raw,
    Average,
    AverageRowNormalised,
    Scaling,
    WlsSbar,
    LsUnit,
    Ml,
}

impl Variant {
    fn name(self) -> &'static str {
        match self {
            Variant::Raw => "raw MC (closed, not reciprocal)",
            Variant::Average => "reciprocity average only",
            Variant::AverageRowNormalised => "average, then row-normalise (reference only)",
            Variant::Scaling => "symmetric scaling",
            Variant::WlsSbar => "WLS w = s̄ (one step)",
            Variant::LsUnit => "unweighted LS (zeros masked)",
            Variant::Ml => "constrained ML",
        }
    }
}

fn props() -> [(f64, BoundaryCondition); 6] {
    let t = [300.0, 400.0, 500.0, 700.0, 1000.0, 600.0];
    let e = [0.3, 0.5, 0.7, 0.9, 0.8, 0.6];
    std::array::from_fn(|k| (e[k], Temperature(t[k])))
}

fn apply(v: Variant, ex: &mut Exchange) {
    let p = |mode, method| EnforceParams { mode, method, ..Default::default() };
    match v {
        Variant::Raw => {
            enforce(ex, &p(Enforce::None, ClosureMethod::Auto)).unwrap();
        }
        Variant::Average => {
            enforce(ex, &p(Enforce::Reciprocity, ClosureMethod::Auto)).unwrap();
        }
        Variant::AverageRowNormalised => {
            // Plain row scaling, which the library never does: shown only for comparison.
            ex.symmetrize();
            let sums = ex.row_sums();
            let ip = ex.indptr().to_vec();
            let areas = ex.areas.clone();
            let data = ex.s.data_mut();
            for i in 0..areas.len() {
                for v in &mut data[ip[i]..ip[i + 1]] {
                    *v *= areas[i] / sums[i];
                }
            }
        }
        Variant::Scaling => {
            enforce(ex, &p(Enforce::Closure, ClosureMethod::SymmetricScaling)).unwrap();
        }
        Variant::WlsSbar => {
            enforce(ex, &p(Enforce::Closure, ClosureMethod::WeightedLs)).unwrap();
        }
        Variant::LsUnit => {
            enforce(ex, &p(Enforce::Closure, ClosureMethod::UnweightedLs)).unwrap();
        }
        Variant::Ml => {
            enforce(ex, &p(Enforce::Closure, ClosureMethod::MaxLikelihood)).unwrap();
        }
    }
}

fn heat_rates(scene: &Scene, ex: &Exchange) -> Vec<f64> {
    let sol = solve::solve_gray(scene, ex, &Params::default()).unwrap().by_surface(scene);
    sol.results.iter().map(|r| r.heat_rate).collect()
}

fn main() {
    let (scene, s) = common::box_scene([1.0, 2.0, 3.0], 2, &props());
    let n = s.len();
    let areas = scene.patch_areas();
    let exact_ex = Exchange::from_viewfactors(&common::patch_vf(&scene, &s));
    let q_exact = heat_rates(&scene, &exact_ex);
    let variants = [
        Variant::Raw,
        Variant::Average,
        Variant::AverageRowNormalised,
        Variant::Scaling,
        Variant::WlsSbar,
        Variant::LsUnit,
        Variant::Ml,
    ];
    println!("| method | rms ΔF, 1000 rays/patch | rms ΔF, 200 rays/patch | max ΔQ ÷ max Q (200) | max ΔQ ÷ max Q (1000) | negative entries (200) |");
    println!("|---|---|---|---|---|---|");
    for v in variants {
        let mut cells = Vec::new();
        let mut dq = [0.0f64; 2];
        let mut neg = 0;
        for (k, rays) in [1000u32, 200].into_iter().enumerate() {
            let mut sum2 = 0.0;
            for seed in 0..SEEDS {
                let vf = common::multinomial(&scene, &s, rays, 1000 * rays as u64 + seed);
                let mut ex = Exchange::from_viewfactors(&vf);
                apply(v, &mut ex);
                for i in 0..n {
                    for j in 0..n {
                        sum2 += ((ex.get(i, j) - s[i][j]) / areas[i]).powi(2);
                    }
                }
                let q = heat_rates(&scene, &ex);
                let qmax = q_exact.iter().fold(0.0f64, |m, q| m.max(q.abs()));
                for (a, b) in q.iter().zip(&q_exact) {
                    dq[k] = dq[k].max((a - b).abs() / qmax);
                }
                if rays == 200 {
                    neg += Diagnostics::of(&ex, false).negatives;
                }
            }
            cells.push(format!("{:.3e}", (sum2 / (SEEDS as f64 * (n * n) as f64)).sqrt()));
        }
        println!(
            "| {} | {} | {} | {:.1} % | {:.1} % | {} |",
            v.name(),
            cells[0],
            cells[1],
            100.0 * dq[1],
            100.0 * dq[0],
            neg
        );
    }
}
