//! Synthetic closed enclosures for the solver benchmarks (benches/solve.rs,
//! examples/solve_bench.rs): N tiny triangles in four surfaces with mixed conditions and raw
//! exchange areas on an all-pairs or spatially local pattern (research/crates.md §2).
use lambert::geometry::Polygon;
use lambert::scene::BoundaryCondition::{HeatFlux, Temperature};
use lambert::scene::Scene;
use lambert::viewfactor::{Entry, Level, MethodSet, ViewFactors};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::time::Duration;

/// N tiny triangles (areas in [0.5, 2]) in four surfaces, and raw exchange areas on a
/// local pattern of the requested fill.
pub fn synthetic(n: usize, fill: f64, seed: u64) -> (Scene, ViewFactors) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let pts: Vec<[f64; 3]> = (0..n).map(|_| [rng.random(), rng.random(), rng.random()]).collect();
    let areas: Vec<f64> = (0..n).map(|_| 0.5 + 1.5 * rng.random::<f64>()).collect();
    // Neighbours within r: (4/3)πr³ n = mean degree (interior points), grid hashing.
    let deg = fill * n as f64;
    let r = if fill >= 1.0 { 2.0 } else { (deg / (n as f64 * 4.0 / 3.0 * std::f64::consts::PI)).cbrt() };
    let cells = ((1.0 / r).floor() as usize).clamp(1, 64);
    let cell = |p: &[f64; 3]| p.map(|x| ((x * cells as f64) as usize).min(cells - 1));
    let mut grid = vec![Vec::new(); cells * cells * cells];
    for (i, p) in pts.iter().enumerate() {
        let c = cell(p);
        grid[(c[0] * cells + c[1]) * cells + c[2]].push(i);
    }
    let rows: Vec<Vec<Entry>> = (0..n)
        .map(|i| {
            let c = cell(&pts[i]);
            let mut row = Vec::new();
            let range = |x: usize| x.saturating_sub(1)..(x + 2).min(cells);
            for a in range(c[0]) {
                for b in range(c[1]) {
                    for d in range(c[2]) {
                        for &j in &grid[(a * cells + b) * cells + d] {
                            let dist2: f64 = (0..3).map(|k| (pts[i][k] - pts[j][k]).powi(2)).sum();
                            if j != i && dist2 <= r * r {
                                // Symmetric random weight from the pair (min, max) hash.
                                let (lo, hi) = (i.min(j) as u64, i.max(j) as u64);
                                let h = Pcg64::seed_from_u64(lo * 1_000_003 + hi).random::<f64>();
                                row.push(Entry {
                                    to: j as u32,
                                    factor: 0.5 + h,
                                    std_error: 0.0,
                                    method: MethodSet::ANALYTIC,
                                });
                            }
                        }
                    }
                }
            }
            row.sort_by_key(|e| e.to);
            // Normalise to F (row sums 0.9995, inside the leak threshold) before closure scaling.
            let sum: f64 = row.iter().map(|e| e.factor).sum();
            for e in &mut row {
                e.factor *= 0.9995 / sum;
            }
            row
        })
        .collect();
    let tri = |i: usize| {
        let s = (2.0 * areas[i]).sqrt();
        let o = glam::DVec3::new(10.0 * i as f64, 0.0, 0.0);
        Polygon::triangle(o, o + glam::DVec3::X * s, o + glam::DVec3::Y * s).expect("valid triangle")
    };
    let cut = [0, n / 20, n / 2, 3 * n / 4, n];
    let props = [
        (0.9, Temperature(1000.0)),
        (0.5, HeatFlux(0.0)),
        (0.3, Temperature(300.0)),
        (0.7, HeatFlux(1000.0)),
    ];
    let mut b = Scene::builder();
    for k in 0..4 {
        b = b.surface(
            &format!("s{k}"),
            (cut[k]..cut[k + 1]).map(tri).collect(),
            props[k].0,
            Some(props[k].1),
        );
    }
    let scene = b.build();
    let names = (0..n).map(|p| scene.patch_name(p)).collect();
    let areas = scene.patch_areas();
    let sums = rows.iter().map(|r| r.iter().map(|e| e.factor).sum()).collect();
    let vf = ViewFactors {
        level: Level::Patch,
        names,
        areas,
        rows,
        patch_row_sums: sums,
        patch_samples: vec![0; n],
        pairs: 0,
        wall: Duration::ZERO,
        warnings: Vec::new(),
        flags: Vec::new(),
    };
    (scene, vf)
}
