//! The whole `solve` pipeline on the obstructed room (validation/solve.md): a 3 m cube with
//! 34×34 patches per face and a block [1,2]³ with 16×16 per face (N = 8,472), view factors by
//! mc-cosine, closure by constrained ML, sparse LLT solve. Prints the stage times and the peak
//! resident memory.
//!
//! Run: `cargo run --release --features studies --example room_pipeline -- [SAMPLES] [SEED]`
use lambert::exchange::{enforce, Enforce, EnforceParams, Exchange};
use lambert::solve::{self, Params};
use lambert::viewfactor::{self, Level, Method};
use std::time::Instant;

fn face(name: &str, o: [f64; 3], u: [f64; 3], v: [f64; 3], n: usize, props: &str) -> String {
    format!("[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o:?}, u = {u:?}, v = {v:?} }}\nsubdivide = [{n}, {n}]\n{props}\n\n")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let samples: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2000);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let wall = "emissivity = 0.5\nheat_flux = 0.0";
    let block = "emissivity = 0.9\ntemperature = 500.0";
    let mut toml = String::from("title = \"Obstructed room: 3 m cube, block [1,2]^3\"\n\n");
    // Room faces, normals inward.
    toml += &face(
        "floor",
        [0.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
        [0.0, 3.0, 0.0],
        34,
        "emissivity = 0.8\ntemperature = 1000.0",
    );
    toml += &face(
        "ceiling",
        [0.0, 0.0, 3.0],
        [0.0, 3.0, 0.0],
        [3.0, 0.0, 0.0],
        34,
        "emissivity = 0.6\ntemperature = 300.0",
    );
    toml += &face("wall_x0", [0.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 3.0], 34, wall);
    toml += &face("wall_x1", [3.0, 0.0, 0.0], [0.0, 0.0, 3.0], [0.0, 3.0, 0.0], 34, wall);
    toml += &face("wall_y0", [0.0, 0.0, 0.0], [0.0, 0.0, 3.0], [3.0, 0.0, 0.0], 34, wall);
    toml += &face("wall_y1", [0.0, 3.0, 0.0], [3.0, 0.0, 0.0], [0.0, 0.0, 3.0], 34, wall);
    // Block faces, normals outward.
    toml += &face("block_z1", [1.0, 1.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], 16, block);
    toml += &face("block_z2", [1.0, 1.0, 2.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 16, block);
    toml += &face("block_x1", [1.0, 1.0, 1.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], 16, block);
    toml += &face("block_x2", [2.0, 1.0, 1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 16, block);
    toml += &face("block_y1", [1.0, 1.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 16, block);
    toml += &face("block_y2", [1.0, 2.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 16, block);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("room.toml");
    std::fs::write(&path, toml).expect("write scene");

    let t = Instant::now();
    let scene = lambert::scene::load(&path).expect("load");
    println!("scene: {} patches, load {:.2} s", scene.patches.len(), t.elapsed().as_secs_f64());
    let params = viewfactor::Params { method: Method::McCosine, samples, seed, ..Default::default() };
    let t = Instant::now();
    let vf = viewfactor::compute(&scene, &params, Level::Patch).expect("view factors");
    let nnz: usize = vf.rows.iter().map(Vec::len).sum();
    println!("view factors (mc-cosine, {samples} rays/patch): {:.2} s, nnz {nnz}", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let mut ex = Exchange::from_viewfactors(&vf);
    drop(vf);
    // Sobol rows report replicate spreads, not ray counts: give ML the rays per patch (as the CLI does).
    ex.samples = vec![samples as u32; ex.len()];
    let rep =
        enforce(&mut ex, &EnforceParams { mode: Enforce::Closure, ..Default::default() }).expect("closure");
    println!(
        "closure ({}, {} steps): {:.2} s; before: {}",
        rep.method,
        rep.iterations,
        t.elapsed().as_secs_f64(),
        rep.before
    );
    println!("  after: {}", rep.after);
    let t = Instant::now();
    let sol = solve::solve_gray(&scene, &ex, &Params::default()).expect("solve");
    let (sum, max) = sol.heat_balance();
    println!(
        "solve: {:.2} s ({}, {} unknowns, residual {:.1e}), balance {:.1e} of max",
        t.elapsed().as_secs_f64(),
        sol.info.solver,
        sol.info.unknowns,
        sol.info.residual,
        sum.abs() / max
    );
    let by = sol.by_surface(&scene);
    for (name, r) in by.names.iter().zip(&by.results) {
        println!("  {name:>9}: T = {:8.2} K, Q = {:12.2} W", r.temperature, r.heat_rate);
    }
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    if let Some(l) = status.lines().find(|l| l.starts_with("VmHWM")) {
        println!(
            "peak RSS: {}",
            l.split_whitespace().nth(1).map_or(0, |k| k.parse::<u64>().unwrap_or(0)) / 1024
        );
    }
}
