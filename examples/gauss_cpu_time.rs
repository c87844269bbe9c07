//! CPU time per far-field Gauss pair (the ladder's hot path) for orders 2–4, for shared
//! (loaded) machines where wall-clock benches are inflated:
//! `cargo run --release --features studies --example gauss_cpu_time`. Reads the thread's on-CPU nanoseconds from
//! /proc/thread-self/schedstat (Linux only).
#[path = "../tests/common/analytic_scenes.rs"]
mod scenes;

use glam::DVec3;
use lambert::viewfactor::analytic::ladder::{gauss_exchange, PatchRules, Points};
use std::hint::black_box;

fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux /proc");
    stat.split_whitespace().next().and_then(|t| t.parse::<f64>().ok()).expect("schedstat field") * 1e-9
}

fn main() {
    // Two 1/36-wide patches on opposite faces of the unit cube (a typical far pair).
    let h = 1.0 / 36.0;
    let lower = scenes::grid(DVec3::ZERO, DVec3::X * h, DVec3::Y * h, 1, 1).remove(0);
    let upper = scenes::grid(DVec3::new(0.3, 0.2, 1.0), DVec3::Y * h, DVec3::X * h, 1, 1).remove(0);
    let rules = PatchRules::new([&lower, &upper]);
    let (ni, hi) = (lower.normal(), lower.normal().dot(lower.centroid()));
    let (nj, hj) = (upper.normal(), upper.normal().dot(upper.centroid()));
    for order in [2usize, 3, 4] {
        let (mut b1, mut b2, mut scratch) = (Points::default(), Points::default(), Vec::new());
        let calls = 40_000_000 / order.pow(4);
        let mut sum = 0.0;
        let t = cpu_seconds();
        for _ in 0..calls {
            let pi = rules.points(0, order, &mut b1);
            let pj = rules.points(1, order, &mut b2);
            sum += gauss_exchange(black_box(pi), ni, hi, pj, nj, black_box(hj), &mut scratch);
        }
        let ns = (cpu_seconds() - t) / calls as f64 * 1e9;
        let evals = order.pow(4) as f64;
        println!(
            "{order}x{order} per patch: {ns:.1} ns CPU per pair, {:.2} ns per kernel evaluation [{sum:.3e}]",
            ns / evals
        );
    }
}
