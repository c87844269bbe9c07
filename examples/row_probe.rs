//! Where a part row's time goes under `auto` (validation/cad.md, the channel's part rows):
//! `row_probe SCENE FIRST LAST [STEP]` classifies rows FIRST..LAST (every STEP-th) and computes
//! their partly obstructed pairs as the kernel does, one thread, and prints the time in each
//! step, the pairs sampled and integrated, samples per sampled pair, partial blockers per pair
//! and the share of pairs with u at most one goal.
use lambert::viewfactor::exact::pair::polygon_polygon;
use lambert::viewfactor::shadow::classify::Status;
use lambert::viewfactor::shadow::policy::pair_goal;
use lambert::viewfactor::shadow::{PairAt, Policy, ShadowScratch, Shadows};
use lambert::viewfactor::MethodSet;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = lambert::scene::load(std::path::Path::new(&args[1])).expect("scene loads");
    let (first, last): (usize, usize) = (args[2].parse().unwrap(), args[3].parse().unwrap());
    let step: usize = args.get(4).map_or(1, |s| s.parse().unwrap());
    let shadows = Shadows::new(&scene, Policy::Auto { tol: 1e-4, seed: 0 }).expect("blockers");
    println!("model {:?}", shadows.model());
    let mut s = ShadowScratch::default();
    let n = scene.patches.len();
    let (mut t_class, mut t_mc, mut t_int) = (0.0, 0.0, 0.0);
    let (mut n_mc, mut n_int, mut samples, mut nb, mut small, mut blocked, mut touched) =
        (0u64, 0u64, 0u64, 0u64, 0u64, 0u64, 0u64);
    let mut hist = [0u64; 8];
    for i in (first..last).step_by(step) {
        let t = Instant::now();
        shadows.classify_row(i, &mut s.row);
        t_class += t.elapsed().as_secs_f64();
        touched += s.row.touched().len() as u64;
        for j in i + 1..n {
            let partial = match s.row.status(j) {
                Status::Partial(p) => p.to_vec(),
                Status::Blocked => {
                    blocked += 1;
                    continue;
                }
                Status::Clear => continue,
            };
            let (pi, pj) = (&scene.patches[i].polygon, &scene.patches[j].polygon);
            let u = polygon_polygon(pi, pj);
            if u.is_nan() || u <= 0.0 {
                continue;
            }
            let goal = pair_goal(1e-4, pi.area(), pj.area());
            small += u64::from(u <= goal);
            nb += partial.len() as u64;
            let t = Instant::now();
            let r = shadows.pair(PairAt::new(i, j, u, &partial), &mut s.work);
            let dt = t.elapsed().as_secs_f64();
            if r.method == MethodSet::MC_AREA {
                n_mc += 1;
                samples += r.work;
                t_mc += dt;
                hist[(r.work as f64).log2().floor().clamp(3.0, 10.0) as usize - 3] += 1;
            } else {
                n_int += 1;
                t_int += dt;
            }
        }
    }
    let pairs = n_mc + n_int;
    println!(
        "classify {t_class:.2} s, sampled {n_mc} pairs {t_mc:.2} s ({:.1} samples each), integrated {n_int} pairs {t_int:.2} s; \
         blockers/pair {:.1}, u<=goal {:.1} %, blocked {blocked}, touched {touched}",
        samples as f64 / n_mc.max(1) as f64,
        nb as f64 / pairs.max(1) as f64,
        100.0 * small as f64 / pairs.max(1) as f64
    );
    println!("samples log2 histogram from 8: {hist:?}");
}
