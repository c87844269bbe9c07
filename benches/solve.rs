//! Criterion benches of the radiation solve on a synthetic closed enclosure (N = 600, all
//! pairs): dense LLT, sparse LLT, Gauss–Seidel; and closure by symmetric scaling. The large
//! cases (N = 2,000 dense, N = 20,000 at 2 % fill) run as `examples/solve_bench.rs`.
use criterion::{criterion_group, criterion_main, Criterion};
use lambert::exchange::{enforce, ClosureMethod, Enforce, EnforceParams, Exchange};
use lambert::solve::{self, Params, Solver};

#[path = "support/synthetic.rs"]
mod synthetic;

fn bench(c: &mut Criterion) {
    let (scene, vf) = synthetic::synthetic(600, 1.0, 1);
    let closure = EnforceParams {
        mode: Enforce::Closure,
        method: ClosureMethod::SymmetricScaling,
        ..Default::default()
    };
    let mut ex = Exchange::from_viewfactors(&vf);
    enforce(&mut ex, &closure).unwrap();
    let mut g = c.benchmark_group("solve_n600_full");
    g.sample_size(10);
    for (name, solver, dense_max) in [
        ("dense_llt", Solver::Direct, usize::MAX),
        ("sparse_llt", Solver::Direct, 0),
        ("gauss_seidel", Solver::GaussSeidel, 0),
    ] {
        let p =
            Params { solver, dense_max, dense_full_max: dense_max, tolerance: 1e-10, ..Params::default() };
        g.bench_function(name, |b| b.iter(|| solve::solve_gray(&scene, &ex, &p).unwrap()));
    }
    g.bench_function("closure_symmetric_scaling", |b| {
        b.iter(|| {
            let mut e = Exchange::from_viewfactors(&vf);
            enforce(&mut e, &closure).unwrap();
            e
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
