//! How `auto` prices a scene's partly obstructed pairs, and what its work units cost in time
//! (the ratios `SHADOW_UNIT_NS`, `MC_SAMPLE_NS` and `MC_TEST_NS` of
//! `lambert::viewfactor::shadow::policy` were measured with it).
//!
//! ```text
//! cargo run --release --features studies --example price_units -- SCENE [tolerance] [shadow cap factor]
//! ```
//! Prints the calibration pairs (blockers, u/goal, counted work of both estimators), the fitted
//! cost model, and for each pair both estimators timed (one thread): ns per shadow work unit,
//! and the least-squares split of the sampling time into per-sample and per-test costs.
//! Without a cap factor each sample pair's integration runs uncapped: it can take seconds.
use lambert::viewfactor::shadow::calibrate::{fit, measure, sample_pairs};
use lambert::viewfactor::shadow::policy::{setup_units, CostModel, MC_SAMPLE_NS, MC_TEST_NS, SHADOW_UNIT_NS};
use lambert::viewfactor::shadow::{PairWork, Policy, Shadows};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = lambert::scene::load(std::path::Path::new(&args[1])).expect("scene loads");
    let tol: f64 = args.get(2).map_or(1e-4, |s| s.parse().expect("tolerance"));
    let cap: Option<f64> = args.get(3).map(|s| s.parse().expect("cap factor"));
    let t = Instant::now();
    let shadows = Shadows::new(&scene, Policy::Auto { tol, seed: 0 }).expect("the scene has blockers");
    println!("Shadows::new with calibration: {:.3} s", t.elapsed().as_secs_f64());
    let measured = measure(&shadows, tol, 0);
    println!("fitted {:?}\n(prior {:?})", fit(&measured, CostModel::default()), CostModel::default());
    let mut work = PairWork::default();
    let (mut sh_ns, mut sh_units) = (0.0, 0.0);
    // Normal equations for t = a·samples + c·tests.
    let (mut ss, mut st, mut tt, mut ys, mut yt) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (p, m) in sample_pairs(&shadows, tol).iter().zip(&measured) {
        let n = CostModel::samples(p.u, p.goal) as u32;
        let t = Instant::now();
        let mc = shadows.sample(p.at(), (n, p.goal), 0, &mut work);
        let mc_t = t.elapsed().as_secs_f64() * 1e9;
        let max_work = cap.map_or(u64::MAX, |f| {
            let ns = mc.samples as f64 * MC_SAMPLE_NS + mc.tests as f64 * MC_TEST_NS;
            (f * ns / SHADOW_UNIT_NS) as u64
        });
        let t = Instant::now();
        let sh = shadows.integrate(p.at(), p.goal, max_work, &mut work);
        let sh_t = t.elapsed().as_secs_f64() * 1e9;
        let units = (sh.info.work + setup_units(p.partial.len())) as f64;
        (sh_ns, sh_units) = (sh_ns + sh_t, sh_units + units);
        let (s, c) = (mc.samples as f64, mc.tests as f64);
        (ss, st, tt, ys, yt) = (ss + s * s, st + s * c, tt + c * c, ys + mc_t * s, yt + mc_t * c);
        println!(
            "{:5} {:5} b {:4} u/goal {:8.2} | calibration: work {:9} capped {:5} samples {:6} tests {:9} \
             | timed: shadow {:9.0} units {:10.0} ns/unit {:6.1}  mc {:8.0} ns",
            p.i,
            p.j,
            m.blockers,
            m.ratio,
            m.shadow_work,
            m.capped,
            m.samples,
            m.tests,
            sh_t / 1e3,
            units,
            sh_t / units,
            mc_t,
        );
    }
    let det = ss * tt - st * st;
    println!(
        "shadow: {:.1} ns/unit; sampling: {:.1} ns/sample + {:.2} ns/test",
        sh_ns / sh_units,
        (ys * tt - yt * st) / det,
        (yt * ss - ys * st) / det
    );
}
