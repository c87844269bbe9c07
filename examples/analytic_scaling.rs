//! Scaling of the analytic method with the patch count: a closed unit cube with n×n patches
//! per face (N = 6n²) or a 5×4×3 m room with patches of side h, all pairs, per-surface output.
//!
//! `cargo run --release --features studies --example analytic_scaling -- cube N_PER_FACE [ROW_STRIDE]`
//! `cargo run --release --features studies --example analytic_scaling -- room PATCH_SIDE [ROW_STRIDE]`
//!
//! With ROW_STRIDE = 1 the whole matrix is computed through `viewfactor::compute`. With
//! ROW_STRIDE = k > 1 only every k-th row is computed (in parallel, through the same kernel)
//! and the full run's time is *estimated* from the pairs those rows cover: for runs that would
//! take too long (N ≈ 100k has 5e9 pairs). Prints wall and CPU time, pairs/s and peak RSS.
#[path = "../tests/common/analytic_scenes.rs"]
mod scenes;

use lambert::viewfactor::analytic::kernel::{AnalyticKernel, GAUSS_REL_TOL};
use lambert::viewfactor::engine::{Row, RowKernel};
use lambert::viewfactor::{compute, Level, Method, Params};
use rayon::prelude::*;
use std::time::Instant;

/// Peak resident set (VmHWM), MB.
fn vm_hwm_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// Process CPU time (user + system), s, from /proc/self/stat (10 ms ticks).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    let tick = |k: usize| fields.get(k).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN);
    (tick(11) + tick(12)) / 100.0
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map_or("cube", String::as_str);
    let size: f64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(13.0);
    let stride: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(1).max(1);
    let t0 = Instant::now();
    let scene = match kind {
        "room" => scenes::box_room(5.0, 4.0, 3.0, size),
        _ => scenes::cube(size as usize),
    };
    let n = scene.patches.len();
    let all_pairs = (n * (n - 1) / 2) as f64;
    let build = t0.elapsed().as_secs_f64();
    let (cpu0, t1) = (cpu_seconds(), Instant::now());
    let (pairs, wall, note) = if stride == 1 {
        let params = Params { method: Method::Analytic, ..Params::default() };
        let vf = compute(&scene, &params, Level::Surface).expect("unobstructed scene");
        let (row_err, _) = vf.max_patch_row_error();
        (vf.pairs as f64, vf.wall.as_secs_f64(), format!("measured, max |row sum - 1| = {row_err:.2e}"))
    } else {
        let kernel = AnalyticKernel::new(&scene, GAUSS_REL_TOL);
        let prep = t1.elapsed().as_secs_f64();
        let (unique, served) = kernel.reuse().stats();
        println!("  set-up {prep:.2} s; translated-pair tables: {unique} entries serve {served} pairs");
        let t2 = Instant::now();
        let sampled: u64 = (0..n)
            .step_by(stride)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|i| {
                let mut row = Row::default();
                kernel.row(i, &mut row).expect("unobstructed");
                row.pairs
            })
            .sum();
        let secs = t2.elapsed().as_secs_f64();
        let estimate = prep + secs * all_pairs / sampled as f64;
        (
            sampled as f64,
            estimate,
            format!("ESTIMATED from {sampled} pairs in every {stride}th row ({secs:.2} s)"),
        )
    };
    let cpu = cpu_seconds() - cpu0;
    let full_rate = if stride == 1 { pairs / wall } else { all_pairs / wall };
    println!(
        "{kind} {size}: N = {n}, pairs = {all_pairs:.3e}, wall = {wall:.2} s, {full_rate:.3e} pairs/s, CPU = {cpu:.2} s \
         (threads {}), scene build {build:.2} s, peak RSS {:.1} MB, load avg {} [{note}]",
        rayon::current_num_threads(),
        vm_hwm_mb(),
        load_average()
    );
}
