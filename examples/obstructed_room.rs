//! The obstructed-room benchmark (validation/obstructed.md): a closed 3 m cube, each face split
//! 34×34, with a cubic block [1, 2]³ whose faces are split 16×16; N = 8 472 patches, all
//! radiating. View3D: 176 s single-threaded, 285 MB.
//!
//! ```text
//! cargo run --release --features studies --example obstructed_room -- [auto|analytic|stats] [tolerance] [grid] [block grid]
//! ```
//! Prints wall time, pairs/s, peak RSS (VmHWM), the face-to-face totals, their row sums and the
//! method mix. `stats` times the obstruction classification alone and counts pair classes.
use lambert::geometry::subdivide::parallelogram_grid;
use lambert::geometry::{DVec3, Polygon};
use lambert::scene::Scene;
use lambert::viewfactor::exact::pair::polygon_polygon;
use lambert::viewfactor::shadow::classify::Status;
use lambert::viewfactor::shadow::{PairAt, Policy, ShadowScratch, Shadows};
use lambert::viewfactor::{self, Level, Method, MethodSet, Params};
use std::time::Instant;

/// The six faces of the box [lo, lo + size]³ split n×n, facing out (or in when `inward`).
fn box_faces(lo: DVec3, size: f64, n: usize, inward: bool) -> Vec<Vec<Polygon>> {
    let (x, y, z) = (DVec3::X * size, DVec3::Y * size, DVec3::Z * size);
    let faces = [(lo, y, x), (lo + z, x, y), (lo, x, z), (lo + y, z, x), (lo, z, y), (lo + x, y, z)];
    faces
        .iter()
        .map(|&(o, u, v)| {
            let (u, v) = if inward { (v, u) } else { (u, v) };
            parallelogram_grid(o, u, v, n, n).expect("valid grid")
        })
        .collect()
}

const NAMES: [&str; 6] = ["z0", "z1", "y0", "y1", "x0", "x1"];

fn room(grid: usize, block_grid: usize) -> Scene {
    let mut b = Scene::builder();
    for (k, f) in box_faces(DVec3::ZERO, 3.0, grid, true).into_iter().enumerate() {
        b = b.surface(&format!("wall_{}", NAMES[k]), f, 0.9, None);
    }
    for (k, f) in box_faces(DVec3::ONE, 1.0, block_grid, false).into_iter().enumerate() {
        b = b.surface(&format!("block_{}", NAMES[k]), f, 0.9, None);
    }
    b.build()
}

fn vm_hwm_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|k| k.parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn stats(scene: &Scene, tol: f64) {
    let start = Instant::now();
    let shadows = Shadows::new(scene, Policy::Auto { tol, seed: 0 }).expect("the block blocks");
    println!("blockers: {} (built in {:.3} s)", shadows.blockers().len(), start.elapsed().as_secs_f64());
    let n = scene.patches.len();
    let (mut classify, mut partial_time) = (0.0, 0.0);
    let (mut blocked, mut partial, mut blockers) = (0u64, 0u64, 0u64);
    // Per branch: pairs, work (samples or viewpoints), seconds.
    let mut branch = [(0u64, 0u64, 0.0f64); 2];
    let mut s = ShadowScratch::default();
    for i in 0..n {
        let t = Instant::now();
        shadows.classify_row(i, &mut s.row);
        classify += t.elapsed().as_secs_f64();
        let touched: Vec<u32> = s.row.touched().to_vec();
        for j in touched {
            match s.row.status(j as usize) {
                Status::Blocked => blocked += 1,
                Status::Partial(b) => {
                    partial += 1;
                    blockers += b.len() as u64;
                    let u = polygon_polygon(&scene.patches[i].polygon, &scene.patches[j as usize].polygon);
                    if u > 0.0 {
                        let t = Instant::now();
                        let r = shadows.pair(PairAt::new(i, j as usize, u, b), &mut s.work);
                        let dt = t.elapsed().as_secs_f64();
                        partial_time += dt;
                        let k = usize::from(r.method == MethodSet::MC_AREA);
                        branch[k].0 += 1;
                        branch[k].1 += r.work;
                        branch[k].2 += dt;
                    }
                }
                Status::Clear => {}
            }
        }
    }
    let pairs = (n * (n - 1) / 2) as u64;
    println!(
        "classification: {classify:.2} s single-threaded ({:.1} ns/pair); pairs {pairs}, blocked {blocked}, \
         partial {partial} ({:.2} blockers each)",
        classify * 1e9 / pairs as f64,
        blockers as f64 / partial.max(1) as f64
    );
    println!("partial pairs: {partial_time:.2} s single-threaded");
    for (name, (count, work, secs)) in ["analytic-shadowed", "mc-area"].iter().zip(branch) {
        println!(
            "  {name}: {count} pairs, {:.1} {} each, {:.2} us each",
            work as f64 / count.max(1) as f64,
            if *name == "mc-area" { "samples" } else { "viewpoints" },
            secs * 1e6 / count.max(1) as f64
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).map_or("auto", String::as_str);
    let tol: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1e-4);
    let grid: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(34);
    let block: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(16);
    let scene = room(grid, block);
    println!("obstructed room: {grid}² per wall, {block}² per block face, N = {}", scene.patches.len());
    if mode == "stats" {
        stats(&scene, tol);
        return;
    }
    let method = if mode == "analytic" { Method::Analytic } else { Method::Auto };
    let params = Params { method, tolerance: tol, ..Params::default() };
    let start = Instant::now();
    let vf = viewfactor::compute(&scene, &params, Level::Surface).expect("computes");
    let wall = start.elapsed().as_secs_f64();
    let (worst, at) = vf.max_patch_row_error();
    println!(
        "{mode} tol {tol:e}: wall {wall:.2} s, {} pairs ({:.3e} pairs/s), peak RSS {:.0} MB, threads {}",
        vf.pairs,
        vf.pairs as f64 / wall,
        vm_hwm_mb(),
        rayon::current_num_threads()
    );
    println!("max |patch row sum - 1| = {worst:.3e} (patch {})", scene.patch_name(at));
    println!("from,to,factor,std_error,method");
    for (i, row) in vf.rows.iter().enumerate() {
        for e in row {
            println!(
                "{},{},{:.10},{:.2e},{}",
                vf.names[i], vf.names[e.to as usize], e.factor, e.std_error, e.method
            );
        }
    }
}
