//! Per-pair shadow-integration statistics of one row under `auto`'s goal (validation/cad.md,
//! the channel's wall rows): `wall_probe SCENE ROW [EVERY]` integrates every EVERY-th partly
//! obstructed pair of row ROW and prints its value, error estimate, viewpoints, cells and
//! time; `GOALX=0.01` tightens the goal 100× for a reference. `AUTO=1` prints the entry as
//! `auto` makes it, `MC=1` the Monte Carlo estimate alone (`SEEDS=K` adds K seeds' spread
//! against their reported errors, `REF=` an exact value), `JMAX=K` the receivers below K only.
use lambert::viewfactor::exact::pair::polygon_polygon;
use lambert::viewfactor::shadow::classify::Status;
use lambert::viewfactor::shadow::policy::pair_goal;
use lambert::viewfactor::shadow::{PairAt, Policy, ShadowScratch, Shadows};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = lambert::scene::load(std::path::Path::new(&args[1])).expect("scene loads");
    let i: usize = args[2].parse().unwrap();
    let every: usize = args.get(3).map_or(1, |s| s.parse().unwrap());
    let shadows = Shadows::new(&scene, Policy::Auto { tol: 1e-4, seed: 1 }).expect("blockers");
    let mut s = ShadowScratch::default();
    let n = scene.patches.len();
    let t = Instant::now();
    shadows.classify_row(i, &mut s.row);
    println!("classify {:.3} ms", t.elapsed().as_secs_f64() * 1e3);
    let mut k = 0;
    let mut tot = 0.0;
    // `JMAX=K` probes only the receivers below K (the wall patches when they come first).
    let jmax: usize = std::env::var("JMAX").map_or(n, |v| v.parse().unwrap());
    for j in i + 1..n.min(jmax) {
        let Status::Partial(partial) = s.row.status(j) else { continue };
        k += 1;
        if k % every != 0 {
            continue;
        }
        let partial = partial.to_vec();
        let (pi, pj) = (&scene.patches[i].polygon, &scene.patches[j].polygon);
        let u = polygon_polygon(pi, pj);
        let goal = pair_goal(1e-4, pi.area(), pj.area())
            * std::env::var("GOALX").map_or(1.0, |v| v.parse::<f64>().unwrap());
        // The sample count of `MC=1` (the worst case, up to the sample cap).
        let n = lambert::viewfactor::shadow::policy::CostModel::samples(u, goal).min(65536.0) as u32;
        let t = Instant::now();
        // The pair's value and what the mode reports besides it.
        let (value, tail) = if std::env::var_os("MC").is_some() {
            // `MC=1`: the Monte Carlo estimate alone (up to its sample cap).
            let m = shadows.sample(PairAt::new(i, j, u, &partial), (n, goal), 1, &mut s.work);
            let tail = format!("sd/goal {:.2} samples {}", m.var.sqrt() / goal, m.samples);
            (m.s, tail)
        } else if std::env::var_os("AUTO").is_some() {
            // `AUTO=1`: the entry as `auto` makes it (its own choice of estimator).
            let r = shadows.pair(PairAt::new(i, j, u, &partial), &mut s.work);
            (r.s, format!("sd/goal {:.2} method {:?} work {}", r.var.sqrt() / goal, r.method, r.work))
        } else {
            let r = shadows.integrate(PairAt::new(i, j, u, &partial), goal, u64::MAX, &mut s.work);
            let f = &r.info;
            let tail = format!(
                "err/goal {:.2} evals {} work {} cells {} roots {} maxd {} stalled {} swapped {}",
                r.error / goal,
                f.evals,
                f.work,
                f.cells,
                f.roots,
                f.at_max_depth,
                f.stalled,
                r.swapped
            );
            (r.s, tail)
        };
        let dt = t.elapsed().as_secs_f64();
        tot += dt;
        println!(
            "{i} {j} s {value:.10e} nb {} u/goal {:.1} s/u {:.4} {tail} ms {:.3}",
            partial.len(),
            u / goal,
            value / u,
            dt * 1e3
        );
        let seeds: u64 = std::env::var("SEEDS").map_or(0, |v| v.parse().unwrap());
        if std::env::var_os("MC").is_some() && seeds > 0 {
            // `SEEDS=K` (with `MC=1`): the spread of K seeds' estimates against their reported
            // errors.
            let runs: Vec<_> = (0..seeds)
                .map(|seed| shadows.sample(PairAt::new(i, j, u, &partial), (n, goal), seed, &mut s.work))
                .collect();
            let mean = runs.iter().map(|m| m.s).sum::<f64>() / seeds as f64;
            let sd = (runs.iter().map(|m| (m.s - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64).sqrt();
            let rep = (runs.iter().map(|m| m.var).sum::<f64>() / seeds as f64).sqrt();
            let samples = runs.iter().map(|m| u64::from(m.samples)).sum::<u64>() / seeds;
            // Against REF (an exact value of this pair's exchange area, when given).
            let truth = std::env::var("REF").map_or(mean, |v| v.parse().unwrap());
            let far = runs.iter().filter(|m| (m.s - truth).abs() > 3.0 * m.var.sqrt()).count();
            let over = runs.iter().filter(|m| (m.s - truth).abs() > goal).count();
            println!(
                "{i} {j} seeds {seeds} mean {mean:.6e} spread {sd:.3e} reported {rep:.3e} goal {goal:.3e} samples {samples} beyond3sd {far} beyond_goal {over}"
            );
        }
    }
    println!("pairs {k} total {tot:.2} s");
}
