//! The analytic method on whole scenes (the speed target: the closed unit cube, 36×36 patches
//! per face, all pairs, per-surface output) and its far-field Gauss rung per pair.
//!
//! `cargo bench --bench analytic_method`. On a shared machine prefer the CPU-time examples
//! (`analytic_scaling`, `cube_speed`): criterion measures wall time.
#[path = "../tests/common/analytic_scenes.rs"]
mod scenes;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::DVec3;
use lambert::viewfactor::analytic::ladder::{gauss_exchange, PatchRules, Points};
use lambert::viewfactor::{compute, Level, Method, Params};
use std::hint::black_box;

fn cube(c: &mut Criterion) {
    let params = Params { method: Method::Analytic, ..Params::default() };
    let mut g = c.benchmark_group("analytic cube");
    g.sample_size(10);
    for n in [12, 36] {
        let scene = scenes::cube(n);
        g.bench_function(format!("{n}x{n} per face, N = {}", scene.patches.len()), |b| {
            b.iter(|| compute(black_box(&scene), &params, Level::Surface).unwrap())
        });
    }
    g.finish();
}

fn gauss_rung(c: &mut Criterion) {
    // Two 1/36-wide patches on opposite faces of the unit cube (a typical far pair).
    let h = 1.0 / 36.0;
    let lower = scenes::grid(DVec3::ZERO, DVec3::X * h, DVec3::Y * h, 1, 1).remove(0);
    let upper = scenes::grid(DVec3::new(0.3, 0.2, 1.0), DVec3::Y * h, DVec3::X * h, 1, 1).remove(0);
    let rules = PatchRules::new([&lower, &upper]);
    let (ni, hi) = (lower.normal(), lower.normal().dot(lower.centroid()));
    let (nj, hj) = (upper.normal(), upper.normal().dot(upper.centroid()));
    let mut g = c.benchmark_group("gauss rung");
    for order in [2, 3, 4, 6] {
        let (mut b1, mut b2, mut scratch) = (Points::default(), Points::default(), Vec::new());
        g.bench_function(format!("{order}x{order} per patch"), |b| {
            b.iter(|| {
                let pi = rules.points(0, order, &mut b1);
                let pj = rules.points(1, order, &mut b2);
                gauss_exchange(black_box(pi), ni, hi, pj, nj, hj, &mut scratch)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, gauss_rung, cube);
criterion_main!(benches);
