//! The progress report's row prices against the rows' measured time under `auto`
//! (validation/cad.md, the time left on the channel): `row_cost_probe SCENE [EVERY] [FIRST LAST]`
//! prices every row as a drawn run does (`RowKernel::row_costs`, timed), then computes every
//! EVERY-th row of FIRST..LAST (default: all rows) one thread at a time and prints, per row,
//! its surface, the estimate, the time, the partly obstructed pairs; then per surface kind
//! (meshed or not) the estimate's share against the time's share.
use lambert::viewfactor::engine::{Row, RowKernel};
use lambert::viewfactor::shadow::classify::Status;
use lambert::viewfactor::shadow::ShadowScratch;
use lambert::viewfactor::Params;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = lambert::scene::load(std::path::Path::new(&args[1])).expect("scene loads");
    let n = scene.patches.len();
    let every: usize = args.get(2).map_or(1, |s| s.parse().unwrap());
    let first: usize = args.get(3).map_or(0, |s| s.parse().unwrap());
    let last: usize = args.get(4).map_or(n, |s| s.parse().unwrap());
    let t = Instant::now();
    let kernel = lambert::viewfactor::auto::kernel(&scene, &Params::default());
    println!("kernel {:.2} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let costs = kernel.row_costs().unwrap_or_else(|| (0..n).map(|i| (n - i) as u64).collect());
    println!("row_costs {:.3} s", t.elapsed().as_secs_f64());
    let meshed = |i: usize| scene.surfaces[scene.patches[i].surface].patches.len() > 256;
    // Per kind (0 = small surfaces, 1 = meshed parts): estimate and seconds.
    let mut sums = [(0.0f64, 0.0f64, 0usize); 2];
    let mut scratch = ShadowScratch::default();
    for i in (first..last.min(n)).step_by(every.max(1)) {
        let t = Instant::now();
        let partial = kernel.shadows().map_or(0, |s| {
            s.classify_row(i, &mut scratch.row);
            (i + 1..n).filter(|&j| matches!(scratch.row.status(j), Status::Partial(_))).count()
        });
        let classify = t.elapsed().as_secs_f64();
        let front = kernel.row_blockers(i, &mut Vec::new());
        let mut row = Row::default();
        let t = Instant::now();
        kernel.row(i, &mut row).expect("row");
        let dt = t.elapsed().as_secs_f64();
        let k = usize::from(meshed(i));
        sums[k].0 += costs[i] as f64;
        sums[k].1 += dt;
        sums[k].2 += 1;
        println!(
            "{i} {} est {:.3e} s {:.4} ns/est {:.3} pairs {} partial {partial} classify {classify:.4} front {front}",
            scene.patch_name(i),
            costs[i] as f64,
            dt,
            dt * 1e9 / (costs[i] as f64).max(1.0),
            n - i - 1
        );
    }
    let (est, time): (f64, f64) = (sums[0].0 + sums[1].0, sums[0].1 + sums[1].1);
    for (k, (e, s, rows)) in sums.iter().enumerate() {
        if *rows > 0 {
            println!(
                "{}: rows {rows} est share {:.4} time share {:.4} ns/est {:.3} ({:.2} s)",
                ["surfaces", "meshed"][k],
                e / est,
                s / time,
                s * 1e9 / e.max(1.0),
                s
            );
        }
    }
}
