//! One view-factor row of the hemicube (and, for comparison, the single plane) on the unit
//! cube with 8×8 patches per face (384 patches), at R = 128, 256, 512.
//!
//! Throughput is in pixels: 3R² per hemicube (R² top + 4 half sides), R² for the plane;
//! rows per second (patches/s) is the inverse of the reported time.
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::DVec3;
use lambert::geometry::Polygon;
use lambert::scene::Scene;
use lambert::viewfactor::engine::{Row, RowKernel};
use lambert::viewfactor::hemicube::{HemicubeKernel, Positions};
use lambert::viewfactor::single_plane::{SinglePlaneKernel, SinglePlaneOptions};
use std::hint::black_box;

fn grid(o: DVec3, u: DVec3, w: DVec3, n: usize) -> Vec<Polygon> {
    let (du, dw) = (u / n as f64, w / n as f64);
    (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let p = o + i as f64 * du + j as f64 * dw;
            Polygon::new(vec![p, p + du, p + du + dw, p + dw]).unwrap()
        })
        .collect()
}

fn cube(n: usize) -> Scene {
    let (o, x, y, z) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
    Scene::builder()
        .surface("floor", grid(o, x, y, n), 1.0, None)
        .surface("ceiling", grid(z, y, x, n), 1.0, None)
        .surface("x0", grid(o, y, z, n), 1.0, None)
        .surface("x1", grid(x, z, y, n), 1.0, None)
        .surface("y0", grid(o, z, x, n), 1.0, None)
        .surface("y1", grid(y, x, z, n), 1.0, None)
        .build()
}

fn rows(c: &mut Criterion) {
    let scene = cube(8);
    // A floor patch off the centre: it sees all five other faces.
    let patch = 8 * 3 + 3;
    let mut group = c.benchmark_group("row_cube_8x8");
    group.sample_size(20);
    for r in [128usize, 256, 512] {
        let hc = HemicubeKernel::new(&scene, r, Positions::Centroid).unwrap();
        group.throughput(Throughput::Elements((3 * r * r) as u64));
        group.bench_with_input(BenchmarkId::new("hemicube", r), &r, |b, _| {
            let mut row = Row::default();
            b.iter(|| hc.row(black_box(patch), &mut row).unwrap());
        });
        let sp = SinglePlaneKernel::new(
            &scene,
            r,
            SinglePlaneOptions { positions: Positions::Centroid, ..Default::default() },
        )
        .unwrap();
        group.throughput(Throughput::Elements((r * r) as u64));
        group.bench_with_input(BenchmarkId::new("single_plane", r), &r, |b, _| {
            let mut row = Row::default();
            b.iter(|| sp.row(black_box(patch), &mut row).unwrap());
        });
    }
    group.finish();
}

criterion_group!(benches, rows);
criterion_main!(benches);
