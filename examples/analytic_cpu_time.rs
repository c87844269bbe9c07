//! CPU time per `polygon_polygon` call, for shared (loaded) machines where criterion's wall
//! clock is inflated: `cargo run --release --features studies --example analytic_cpu_time [config]`.
//! Reads the thread's on-CPU nanoseconds from /proc/thread-self/schedstat (Linux only).
use glam::{DAffine3, DQuat, DVec3};
use lambert::geometry::Polygon;
use lambert::viewfactor::exact::pair::polygon_polygon;
use std::hint::black_box;

fn cpu_ns() -> u64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux /proc");
    stat.split_whitespace().next().and_then(|t| t.parse().ok()).expect("schedstat field")
}

fn rect(o: DVec3, u: DVec3, w: DVec3) -> Polygon {
    Polygon::new(vec![o, o + u, o + u + w, o + w]).unwrap()
}

fn moved(p: &Polygon) -> Polygon {
    let m = DAffine3::from_rotation_translation(
        DQuat::from_euler(glam::EulerRot::ZYX, 0.7, -0.4, 1.1),
        DVec3::new(0.3, -2.0, 5.0),
    );
    p.transformed(&m).unwrap()
}

fn main() {
    let floor = rect(DVec3::ZERO, DVec3::X, DVec3::Y);
    let wall = rect(DVec3::ZERO, DVec3::Y, DVec3::Z);
    let ceiling = |z: f64| rect(DVec3::new(0.0, 0.0, z), DVec3::Y, DVec3::X);
    let t1 = Polygon::new(vec![DVec3::ZERO, DVec3::X, DVec3::new(0.3, 0.8, 0.0)]).unwrap();
    let t2 = Polygon::new(vec![DVec3::X, DVec3::ZERO, DVec3::new(0.4, 0.5, 3f64.sqrt() / 2.0)]).unwrap();
    let skew = moved(
        &rect(DVec3::new(0.2, -0.3, 0.9), DVec3::new(0.9, 0.2, 0.1), DVec3::new(-0.1, 0.8, 0.3)).flipped(),
    );
    let pairs = [
        ("edge90", floor.clone(), wall.clone()),
        ("edge90-moved", moved(&floor), moved(&wall)),
        ("gap1", floor.clone(), ceiling(1.0)),
        ("gap1-moved", moved(&floor), moved(&ceiling(1.0))),
        ("gap10-moved", moved(&floor), moved(&ceiling(10.0))),
        ("tri60", t1, t2),
        ("skew-near", moved(&floor), skew),
    ];
    let only = std::env::args().nth(1);
    for (name, p, q) in pairs {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let n = if only.is_some() { 2_000 } else { 20_000 };
        let t0 = cpu_ns();
        let mut s = 0.0;
        for _ in 0..n {
            s += polygon_polygon(black_box(&p), black_box(&q));
        }
        let dt = cpu_ns() - t0;
        assert!(s > 0.0);
        println!(
            "{name:>14}: {:7.0} ns CPU per call (A1F12 = {:.15})",
            dt as f64 / n as f64,
            polygon_polygon(&p, &q)
        );
    }
}
