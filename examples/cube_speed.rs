//! Speed target of the analytic method: the closed unit cube with n×n patches per face, all
//! pairs, per-surface output. Prints wall time, pairs/s, face-total errors against the closed
//! forms (C-11, C-14), the largest patch row-sum error and peak RSS (VmHWM).
//!
//! `cargo run --release --features studies --example cube_speed -- [n=36] [threads] [rungs|direct]`; with `rungs`, a
//! second (untimed) pass counts the pairs per ladder rung; with `direct`, every pair is
//! evaluated (no translated-pair tables), which measures the ladder's raw speed.
#[path = "../tests/common/analytic_scenes.rs"]
mod scenes;

use lambert::viewfactor::analytic::kernel::{AnalyticKernel, Rung, GAUSS_REL_TOL};
use lambert::viewfactor::closed_form::{parallel_opposed_rectangles, perpendicular_common_edge};
use lambert::viewfactor::shadow::policy::{Policy, EXACT_REL_TOL};
use lambert::viewfactor::{engine, Level, Method, Params};
use rayon::prelude::*;
use std::collections::BTreeMap;

fn vm_hwm_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(36);
    if let Some(t) = args.get(2).and_then(|a| a.parse::<usize>().ok()) {
        rayon::ThreadPoolBuilder::new().num_threads(t).build_global().expect("thread pool");
    }
    let scene = scenes::cube(n);
    let params = Params { method: Method::Analytic, ..Params::default() };
    let direct = args.get(3).is_some_and(|a| a == "direct");
    // The same set-up and engine as `viewfactor::compute`, timed from kernel construction on;
    // `direct` evaluates every pair (no translated-pair tables): the raw speed of the ladder.
    let t = std::time::Instant::now();
    let policy = Policy::Exact { rel_tol: EXACT_REL_TOL };
    let kernel = if direct {
        AnalyticKernel::direct(&scene, GAUSS_REL_TOL, policy)
    } else {
        AnalyticKernel::with_policy(&scene, GAUSS_REL_TOL, policy)
    };
    let setup = t.elapsed().as_secs_f64();
    let mut vf = engine::run(&scene, &kernel, &params, Level::Surface).expect("cube is unobstructed");
    vf.wall = t.elapsed();
    let (opp, adj) = (parallel_opposed_rectangles(1.0, 1.0, 1.0), perpendicular_common_edge(1.0, 1.0, 1.0));
    let (mut e_opp, mut e_adj) = (0.0f64, 0.0f64);
    for i in 0..6 {
        for j in 0..6 {
            let f = vf.get(i, j);
            match (i == j, i / 2 == j / 2) {
                (true, _) => assert_eq!(f, 0.0, "planar face sees itself"),
                (false, true) => e_opp = e_opp.max((f - opp).abs()),
                (false, false) => e_adj = e_adj.max((f - adj).abs()),
            }
        }
    }
    let (row_err, _) = vf.max_patch_row_error();
    let secs = vf.wall.as_secs_f64();
    println!(
        "cube {n}x{n}/face: N = {}, pairs = {}, threads = {}, wall = {secs:.3} s, {:.3e} pairs/s",
        scene.patches.len(),
        vf.pairs,
        rayon::current_num_threads(),
        vf.pairs as f64 / secs
    );
    println!("  max |F_opp - C-11| = {e_opp:.3e}, max |F_adj - C-14| = {e_adj:.3e}, max |row sum - 1| = {row_err:.3e}");
    println!("  peak RSS (VmHWM) = {:.1} MB", vm_hwm_mb());
    if !direct {
        let (unique, served) = kernel.reuse().stats();
        println!(
            "  translated-pair tables: {unique} unique pairs evaluated for {served} pairs ({:.1} % of all); \
             kernel set-up with tables {setup:.3} s (included above)",
            100.0 * served as f64 / vf.pairs as f64
        );
    }
    if args.get(3).is_some_and(|a| a == "rungs") {
        let n = scene.patches.len();
        let census = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut c = BTreeMap::new();
                for j in i + 1..n {
                    let key = match kernel.rung(i, j) {
                        Rung::Zero => "zero (coplanar / back-facing)".to_string(),
                        Rung::Gauss(a, b) => format!("gauss {}x{}", a.min(b), a.max(b)),
                        Rung::Exact => "exact contour".to_string(),
                    };
                    *c.entry(key).or_insert(0u64) += 1;
                }
                c
            })
            .reduce(BTreeMap::new, |mut a, b| {
                for (k, v) in b {
                    *a.entry(k).or_insert(0) += v;
                }
                a
            });
        for (k, v) in census {
            println!("  {k:>30}: {v:>10} pairs ({:.2} %)", 100.0 * v as f64 / vf.pairs as f64);
        }
    }
}
