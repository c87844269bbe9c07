//! Solver timing on synthetic closed enclosures (validation/solve.md):
//! `cargo run --release --features studies --example solve_bench -- N FILL [solvers]`, e.g. `2000 1.0` (all
//! pairs) or `20000 0.02` (spatially local pattern: points in a unit cube joined within the
//! radius that gives the requested mean degree, as research/crates.md §2). Exchange areas are
//! random in [0.5, 1.5] per pair, closed by symmetric scaling; ε in {0.9, 0.5, 0.3, 0.7}
//! with mixed temperature and flux conditions. Prints wall times of each stage.
use lambert::exchange::{enforce, ClosureMethod, Enforce, EnforceParams, Exchange};
use lambert::solve::{self, Params, Solver};
use std::time::{Duration, Instant};

#[path = "../benches/support/synthetic.rs"]
mod synthetic;
use synthetic::synthetic;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2000);
    let fill: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let which = args.get(3).cloned().unwrap_or_else(|| "dense,sparse,jacobi,gs".into());
    let t0 = Instant::now();
    let (scene, vf) = synthetic(n, fill, 1);
    let nnz: usize = vf.rows.iter().map(Vec::len).sum();
    println!("N = {n}, fill {fill}, nnz(S) = {nnz}, build {:.2} s", t0.elapsed().as_secs_f64());
    let t0 = Instant::now();
    let mut ex = Exchange::from_viewfactors(&vf);
    drop(vf);
    let p = EnforceParams {
        mode: Enforce::Closure,
        method: ClosureMethod::SymmetricScaling,
        ..Default::default()
    };
    let rep = enforce(&mut ex, &p).unwrap();
    println!(
        "closure (symmetric scaling): {:.2} s, {} CG iterations, after: {}",
        t0.elapsed().as_secs_f64(),
        rep.iterations,
        rep.after
    );
    // Stage breakdown of the direct path: assembly of K, factorisation, triangular solves.
    {
        use lambert::solve::{direct, system};
        let nodes = system::nodes(&scene, &ex).unwrap();
        let eps: Vec<f64> = nodes.iter().map(|n| n.emissivity).collect();
        let rows: Vec<system::RowKind> = nodes.iter().map(|n| n.row_kind()).collect();
        let t = Instant::now();
        let sys = system::assemble(&ex, &eps, &rows, 0.0);
        let t_asm = t.elapsed();
        for (label, dense_max) in [("dense", usize::MAX), ("sparse", 0)] {
            if !which.contains(label) {
                continue;
            }
            let mut cache = None;
            let t = Instant::now();
            let f = direct::factor(&sys.k, sys.symmetric, dense_max, dense_max, &mut cache).unwrap();
            let t_f = t.elapsed();
            let t = Instant::now();
            let _ = f.solve(&sys.b);
            let t_s = t.elapsed();
            let t = Instant::now();
            let _ = direct::factor(&sys.k, sys.symmetric, dense_max, dense_max, &mut cache).unwrap();
            let t_re = t.elapsed();
            println!(
                "{label:>7} stages: assemble K {:.3} s, factor {:.3} s ({}), refactor reusing symbolic {:.3} s, solve {:.3} s",
                t_asm.as_secs_f64(),
                t_f.as_secs_f64(),
                f.name(),
                t_re.as_secs_f64(),
                t_s.as_secs_f64()
            );
        }
    }
    for name in which.split(',') {
        let (solver, dense_max) = match name {
            "dense" => (Solver::Direct, usize::MAX),
            "sparse" => (Solver::Direct, 0),
            "jacobi" => (Solver::Jacobi, 0),
            "gs" => (Solver::GaussSeidel, 0),
            _ => panic!("unknown solver {name}"),
        };
        let params =
            Params { solver, dense_max, dense_full_max: dense_max, tolerance: 1e-10, ..Params::default() };
        let mut best = Duration::MAX;
        let mut last = None;
        for _ in 0..2 {
            let t = Instant::now();
            let sol = solve::solve_gray(&scene, &ex, &params).unwrap();
            best = best.min(t.elapsed());
            last = Some(sol);
        }
        let sol = last.unwrap();
        let (sum, max) = sol.heat_balance();
        println!(
            "{name:>7}: {:.3} s (best of 2), {} , {} iterations, residual {:.1e}, balance {:.1e}",
            best.as_secs_f64(),
            sol.info.solver,
            sol.info.iterations,
            sol.info.residual,
            sum.abs() / max
        );
    }
}
