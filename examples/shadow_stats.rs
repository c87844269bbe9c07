//! What the exact shadow branch (`analytic`) does on a scene's partly obstructed pairs: every
//! `stride`-th row is classified, and each of its partly obstructed pairs integrated to the
//! relative target (default `EXACT_REL_TOL`), one thread, timed.
//!
//! ```text
//! cargo run --release --features studies --example shadow_stats -- SCENE [row stride] [relative target]
//! ```
//! Prints partly obstructed pairs, viewpoints (evaluations) and cells per pair, root cells after
//! the split along the kinks of g, cells stopped at the depth limit, and µs per pair. With
//! `DUMP=file` it appends `i j A_iF_ij u error blockers viewpoints roots cells` per pair
//! (compare two targets to measure the error of the looser one); with `ONLY=j` it integrates
//! only the pairs with receiver j; with `PAIR=i,j` it prints those patches' vertices and stops.
//! With `AUTO=tol` each pair goes through `auto`'s choice instead ([`Shadows::pair`]), and the
//! time, work and count are broken down by estimator and by pair kind (mesh–mesh, mesh–plane,
//! plane–plane: a patch is a mesh patch when its surface has more than [`MESH_PATCHES`] patches
//! that are not all parallelograms). With `PLANEDUMP=k` as well, each pair of kind k (0
//! plane–plane, 1 mesh–plane, 2 mesh–mesh) prints `auto`'s time and work beside a full
//! integration's and a sample's alone (the cost of each estimator on that pair).
use lambert::viewfactor::exact::pair::polygon_polygon;
use lambert::viewfactor::shadow::classify::Status;
use lambert::viewfactor::shadow::policy::{probe_pilot, EXACT_REL_TOL, MC_MAX_SAMPLES};
use lambert::viewfactor::shadow::{PairAt, Policy, ShadowScratch, Shadows};
use std::io::Write;
use std::time::Instant;

/// Patches of a surface above which a triangle surface counts as a meshed part.
const MESH_PATCHES: usize = 1;

/// `auto`'s choice per pair, broken down by estimator and pair kind.
fn auto_stats(scene: &lambert::scene::Scene, stride: usize, tol: f64) {
    let shadows = Shadows::new(scene, Policy::Auto { tol, seed: 1 }).expect("the scene has blockers");
    let mut s = ShadowScratch::default();
    let n = scene.patches.len();
    let mut count = vec![0usize; scene.surfaces.len()];
    for p in &scene.patches {
        count[p.surface] += 1;
    }
    let mesh: Vec<bool> = scene
        .patches
        .iter()
        .map(|p| count[p.surface] > MESH_PATCHES && p.polygon.vertices().len() == 3)
        .collect();
    // [kind][estimator]: pairs, work, seconds, blockers
    let mut table = [[(0u64, 0u64, 0.0f64, 0u64); 2]; 3];
    let (mut pairs, mut clear) = (0u64, 0u64);
    // Pair kind whose pairs are dumped one by one (`PLANEDUMP`).
    let dump_kind = std::env::var("PLANEDUMP").ok().and_then(|k| k.parse::<usize>().ok());
    let t0 = Instant::now();
    for i in (0..n).step_by(stride) {
        shadows.classify_row(i, &mut s.row);
        for j in i + 1..n {
            pairs += 1;
            let Status::Partial(partial) = s.row.status(j) else {
                clear += 1;
                continue;
            };
            let partial = partial.to_vec();
            let u = polygon_polygon(&scene.patches[i].polygon, &scene.patches[j].polygon);
            let t = Instant::now();
            let r = shadows.pair(PairAt::new(i, j, u, &partial), &mut s.work);
            let dt = t.elapsed().as_secs_f64();
            let kind = usize::from(mesh[i]) + usize::from(mesh[j]);
            let est = usize::from(r.method == lambert::viewfactor::MethodSet::MC_AREA);
            if dump_kind == Some(kind) {
                let goal = tol * scene.patches[i].polygon.area().min(scene.patches[j].polygon.area());
                let t1 = Instant::now();
                let full = shadows.integrate(PairAt::new(i, j, u, &partial), goal, u64::MAX, &mut s.work);
                let dt_int = t1.elapsed().as_secs_f64();
                let t2 = Instant::now();
                let m = shadows.sample(PairAt::new(i, j, u, &partial), (64, goal), 1, &mut s.work);
                let dt_mc = t2.elapsed().as_secs_f64();
                let model = shadows.model();
                let n_worst = lambert::viewfactor::shadow::policy::CostModel::samples(u, goal);
                let first = if n_worst <= f64::from(MC_MAX_SAMPLES) {
                    f64::from(probe_pilot(n_worst as u32))
                } else {
                    f64::NAN
                };
                println!(
                    "PP {i} {j} est {est} price_int {:.0}us price_probe {:.0}us u/goal {:.1} b {} pair {:.0}us work {} | int {:.0}us iwork {} evals {} roots {} cells {} err/goal {:.2} shaded/u {:.3} | mc {:.0}us n {} sd/goal {:.2}",
                    model.shadow_ns(u, goal, partial.len()) / 1e3,
                    model.mc_ns(first, partial.len()) / 1e3,
                    u / goal, partial.len(), 1e6 * dt, r.work, 1e6 * dt_int, full.info.work, full.info.evals, full.info.roots, full.info.cells,
                    full.error / goal, full.info.shaded / u, 1e6 * dt_mc, m.samples, m.var.sqrt() / goal
                );
            }
            let e = &mut table[kind][est];
            *e = (e.0 + 1, e.1 + r.work, e.2 + dt, e.3 + partial.len() as u64);
        }
    }
    println!(
        "rows {} pairs {pairs}, not partial {clear}, {:.3} s",
        n.div_ceil(stride),
        t0.elapsed().as_secs_f64()
    );
    for (kind, name) in ["plane-plane", "mesh-plane", "mesh-mesh"].iter().enumerate() {
        for (est, ename) in ["shadowed", "mc"].iter().enumerate() {
            let (p, w, sec, b) = table[kind][est];
            if p > 0 {
                println!(
                    "{name:12} {ename:9} pairs {p:6}  {:.3} s  {:7.1} us/pair  work/pair {:8.0}  blockers/pair {:.1}",
                    sec,
                    1e6 * sec / p as f64,
                    w as f64 / p as f64,
                    b as f64 / p as f64
                );
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = lambert::scene::load(std::path::Path::new(&args[1])).expect("scene loads");
    let stride: usize = args.get(2).map_or(10, |s| s.parse().expect("row stride"));
    let rel: f64 = args.get(3).map_or(EXACT_REL_TOL, |s| s.parse().expect("relative target"));
    if let Ok(tol) = std::env::var("AUTO") {
        auto_stats(&scene, stride, tol.parse().expect("AUTO=tolerance"));
        return;
    }
    if let Ok(pair) = std::env::var("PAIR") {
        for k in pair.split(',') {
            let k: usize = k.parse().expect("patch index");
            let v: Vec<[f64; 3]> = scene.patches[k].polygon.vertices().iter().map(|v| v.to_array()).collect();
            println!("{v:?}");
        }
        return;
    }
    let mut dump = std::env::var("DUMP").ok().map(|path| {
        std::fs::OpenOptions::new().create(true).append(true).open(path).expect("dump file opens")
    });
    let shadows = Shadows::new(&scene, Policy::Exact { rel_tol: rel }).expect("the scene has blockers");
    let mut s = ShadowScratch::default();
    let n = scene.patches.len();
    let (mut pairs, mut partial_pairs, mut blockers) = (0u64, 0u64, 0u64);
    let (mut evals, mut cells, mut roots, mut at_max) = (0u64, 0u64, 0u64, 0u64);
    let mut decades = [0u64; 8];
    let mut seconds = 0.0;
    for i in (0..n).step_by(stride) {
        shadows.classify_row(i, &mut s.row);
        for j in i + 1..n {
            pairs += 1;
            let Status::Partial(partial) = s.row.status(j) else { continue };
            if let Ok(only) = std::env::var("ONLY") {
                if only.parse::<usize>().ok() != Some(j) {
                    continue;
                }
            }
            let partial = partial.to_vec();
            partial_pairs += 1;
            blockers += partial.len() as u64;
            let u = polygon_polygon(&scene.patches[i].polygon, &scene.patches[j].polygon);
            let t = Instant::now();
            let r = shadows.integrate(PairAt::new(i, j, u, &partial), rel * u, u64::MAX, &mut s.work);
            seconds += t.elapsed().as_secs_f64();
            evals += r.info.evals;
            cells += u64::from(r.info.cells);
            roots += u64::from(r.info.roots);
            at_max += u64::from(r.info.at_max_depth);
            decades[((r.info.evals.max(1) as f64).log10() as usize).min(7)] += 1;
            if let Some(f) = dump.as_mut() {
                writeln!(
                    f,
                    "{i} {j} {:.17e} {:.17e} {:.3e} {} {} {} {}",
                    r.s,
                    u,
                    r.error,
                    partial.len(),
                    r.info.evals,
                    r.info.roots,
                    r.info.cells
                )
                .expect("dump writes");
            }
        }
    }
    let per = |x: u64| x as f64 / partial_pairs.max(1) as f64;
    println!(
        "rows {} pairs {pairs} partly obstructed {partial_pairs} ({:.1} %), blockers per pair {:.2}",
        n.div_ceil(stride),
        100.0 * partial_pairs as f64 / pairs.max(1) as f64,
        per(blockers)
    );
    println!(
        "per pair: viewpoints {:.0}, cells {:.1}, root cells {:.1}; cells at the depth limit {at_max}",
        per(evals),
        per(cells),
        per(roots)
    );
    println!(
        "integration {seconds:.2} s: {:.1} us per pair, {:.0} ns per viewpoint",
        1e6 * seconds / partial_pairs.max(1) as f64,
        1e9 * seconds / evals.max(1) as f64
    );
    println!("pairs by viewpoints 1, 10, 100, ... : {decades:?}");
}
