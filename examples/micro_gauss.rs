use glam::DVec3;
use lambert::geometry::Polygon;
use lambert::viewfactor::analytic::ladder::{gauss_exchange, PatchRules, Points};
/// Process CPU time in seconds (utime + stime from /proc/self/stat, 10 ms ticks).
fn cpu() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap();
    let f: Vec<&str> = s.rsplit(')').next().unwrap().split_whitespace().collect();
    (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / 100.0
}
fn main() {
    let h = 1.0 / 36.0;
    let a = Polygon::new(vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(h, 0.0, 0.0),
        DVec3::new(h, h, 0.0),
        DVec3::new(0.0, h, 0.0),
    ])
    .unwrap();
    let b = Polygon::new(vec![
        DVec3::new(0.3, 0.2, 1.0),
        DVec3::new(0.3, 0.2 + h, 1.0),
        DVec3::new(0.3 + h, 0.2 + h, 1.0),
        DVec3::new(0.3 + h, 0.2, 1.0),
    ])
    .unwrap();
    let rules = PatchRules::new([&a, &b]);
    for order in [2usize, 3, 4] {
        let (mut b1, mut b2) = (Points::default(), Points::default());
        let pi = rules.points(0, order, &mut b1);
        let pj = rules.points(1, order, &mut b2);
        let mut scratch = Vec::new();
        let mut sink = 0.0;
        let calls = 40_000_000 / order.pow(4);
        let t = cpu();
        for k in 0..calls {
            let hh = k as f64 * 1e-20;
            sink += gauss_exchange(pi, a.normal(), hh, pj, b.normal(), -1.0, &mut scratch);
        }
        let best = (cpu() - t) / calls as f64;
        println!(
            "order {order}: {:.1} ns/pair ({:.2} ns/eval) [{sink:.3e}]",
            best * 1e9,
            best * 1e9 / (order.pow(4) as f64)
        );
    }
}
