//! Cost of the exact kernels per call: `cargo bench --bench analytic_kernels`.
//!
//! Configurations: unit squares sharing an edge at 90° (axis-aligned, and moved so that no edge
//! is axis-aligned), opposed unit squares at gap 1 (aligned and moved), a distant pair (gap 10),
//! triangles sharing an edge at 60°, a generic skew quad pair, and the point kernels.
use criterion::{criterion_group, criterion_main, Criterion};
use glam::{DAffine3, DQuat, DVec3};
use lambert::geometry::Polygon;
use lambert::scene::Disk;
use lambert::viewfactor::exact::lambert::{point_to_disk, point_to_polygon};
use lambert::viewfactor::exact::pair::polygon_polygon;
use std::hint::black_box;

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

fn kernels(c: &mut Criterion) {
    let floor = rect(DVec3::ZERO, DVec3::X, DVec3::Y);
    let wall = rect(DVec3::ZERO, DVec3::Y, DVec3::Z);
    let ceiling = |z: f64| rect(DVec3::new(0.0, 0.0, z), DVec3::Y, DVec3::X);
    let t1 = Polygon::new(vec![DVec3::ZERO, DVec3::X, DVec3::new(0.3, 0.8, 0.0)]).unwrap();
    let lean = DVec3::new(0.4, 0.5, 3f64.sqrt() / 2.0);
    let t2 = Polygon::new(vec![DVec3::X, DVec3::ZERO, lean]).unwrap();
    let skew_q = moved(
        &rect(DVec3::new(0.2, -0.3, 0.9), DVec3::new(0.9, 0.2, 0.1), DVec3::new(-0.1, 0.8, 0.3)).flipped(),
    );
    let pairs = [
        ("squares sharing an edge at 90 deg", floor.clone(), wall.clone()),
        ("same, moved (no edge axis-aligned)", moved(&floor), moved(&wall)),
        ("opposed squares at gap 1", floor.clone(), ceiling(1.0)),
        ("same, moved", moved(&floor), moved(&ceiling(1.0))),
        ("distant pair, gap 10, moved", moved(&floor), moved(&ceiling(10.0))),
        ("triangles sharing an edge at 60 deg", t1.clone(), t2.clone()),
        ("generic skew quads, near", moved(&floor), skew_q),
    ];
    let mut g = c.benchmark_group("polygon_polygon");
    for (name, p, q) in &pairs {
        assert!(polygon_polygon(p, q) > 0.0, "{name}");
        g.bench_function(*name, |b| b.iter(|| polygon_polygon(black_box(p), black_box(q))));
    }
    g.finish();
    let mut g = c.benchmark_group("point");
    let sq = ceiling(1.0);
    g.bench_function("point_to_polygon, square", |b| {
        b.iter(|| point_to_polygon(black_box(DVec3::new(0.3, 0.2, 0.0)), DVec3::Z, &sq))
    });
    let d = Disk {
        center: DVec3::new(0.2, -0.1, 1.0),
        normal: DVec3::new(0.1, 0.2, -1.0).normalize(),
        radius: 0.8,
        segments: 64,
    };
    let (p, n_full, n_cut) = (
        DVec3::new(0.9, 0.3, 0.0),
        DVec3::new(-0.2, 0.1, 1.0).normalize(),
        DVec3::new(0.8, 0.1, 0.6).normalize(),
    );
    g.bench_function("point_to_disk, whole disk visible", |b| {
        b.iter(|| point_to_disk(black_box(p), n_full, &d))
    });
    g.bench_function("point_to_disk, plane cuts the disk", |b| {
        b.iter(|| point_to_disk(black_box(p), n_cut, &d))
    });
    g.finish();
}

criterion_group!(benches, kernels);
criterion_main!(benches);
