//! Radiative conductances RADK_ij = A_i ε_i B_ij (Gebhart): symmetry, row sums A_i ε_i, the
//! ambient node, and agreement with the radiosity solve (docs/literature.md §5).
// Dense matrix checks read clearest with (i, j) indices.
#![allow(clippy::needless_range_loop)]
use crate::common;

use lambert::exchange::{enforce, Enforce, EnforceParams, Exchange};
use lambert::scene::BoundaryCondition::{HeatFlux, Temperature};
use lambert::scene::{BoundaryCondition, Scene};
use lambert::solve::{self, Params};
use lambert::SIGMA;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

fn exchange(scene: &Scene, vf: &lambert::viewfactor::ViewFactors, mode: Enforce) -> Exchange {
    let mut ex = Exchange::from_viewfactors(vf);
    let p = EnforceParams { mode, open: !scene.is_closed(), ..Default::default() };
    enforce(&mut ex, &p).expect("enforce");
    ex
}

fn e3_props() -> [(f64, BoundaryCondition); 6] {
    let wall = (0.5, HeatFlux(0.0));
    [wall, wall, wall, wall, (0.8, Temperature(1000.0)), (0.6, Temperature(400.0))]
}

/// Gebhart conductances are symmetric with row sums A_i ε_i to round-off (docs/literature.md §5:
/// 2e-16 on E3); 1e-12 relative allows the sums of many terms.
const RADK_TOL: f64 = 1e-12;

fn check_radk(c: &lambert::solve::conductance::Conductances) {
    let n = c.names.len();
    let scale = c.emitting_area.iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(*v));
    for i in 0..n {
        for j in 0..n {
            assert!((c.radk[i][j] - c.radk[j][i]).abs() < RADK_TOL * scale, "RADK not symmetric at {i},{j}");
            assert!(c.radk[i][j] >= -RADK_TOL * scale);
        }
        if c.emitting_area[i].is_finite() {
            let sum: f64 = c.radk[i].iter().sum();
            assert!(
                (sum - c.emitting_area[i]).abs() < RADK_TOL * scale,
                "row {i}: {sum} vs {}",
                c.emitting_area[i]
            );
        }
    }
}

#[test]
fn conductances_reproduce_the_radiosity_solve() {
    // All-temperature cube (gray and black faces, patches): Q_i = σ Σ_j RADK_ij (T_i⁴ − T_j⁴).
    let t = [500.0, 600.0, 700.0, 800.0, 1000.0, 400.0];
    let e = [0.3, 0.5, 1.0, 0.7, 0.8, 0.6];
    let props: [(f64, BoundaryCondition); 6] = std::array::from_fn(|k| (e[k], Temperature(t[k])));
    let (scene, s) = common::box_scene([1.0, 2.0, 3.0], 2, &props);
    let ex = exchange(&scene, &common::patch_vf(&scene, &s), Enforce::Closure);
    let c = solve::conductance::radk(&scene, &ex, &Params::default()).unwrap();
    check_radk(&c);
    let sol = solve::solve_gray(&scene, &ex, &Params::default()).unwrap();
    let t4: Vec<f64> = sol.results.iter().map(|r| r.temperature.powi(4)).collect();
    for i in 0..t4.len() {
        let q: f64 = (0..t4.len()).map(|j| SIGMA * c.radk[i][j] * (t4[i] - t4[j])).sum();
        assert!((q - sol.results[i].heat_rate).abs() < 1e-9 * 3e4, "{q} vs {}", sol.results[i].heat_rate);
    }
    // Per surface: conductances add, properties hold.
    let group: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
    check_radk(&c.aggregate(&group, scene.surfaces.iter().map(|s| s.name.clone()).collect()));
}

#[test]
fn conductances_with_ambient_node() {
    let (closed, s) = common::box_scene([1.0; 3], 1, &e3_props());
    let mut b = Scene::builder().ambient(0.0);
    for surf in closed.surfaces.iter().take(5) {
        let polys = closed.patches[surf.patches.clone()].iter().map(|p| p.polygon.clone()).collect();
        b = b.surface(&surf.name, polys, surf.emissivity, Some(Temperature(900.0)));
    }
    let scene = b.build();
    let s: Vec<Vec<f64>> = s[..5].iter().map(|r| r[..5].to_vec()).collect();
    let ex = exchange(&scene, &common::patch_vf(&scene, &s), Enforce::Reciprocity);
    let c = solve::conductance::radk(&scene, &ex, &Params::default()).unwrap();
    assert_eq!(c.names.last().map(String::as_str), Some("ambient"));
    check_radk(&c);
    // Isothermal box at 900 K open to 0 K: everything emitted leaves through the opening.
    let sol = solve::solve_gray(&scene, &ex, &Params::default()).unwrap();
    let total: f64 = sol.results.iter().map(|r| r.heat_rate).sum();
    let via_radk: f64 = (0..5).map(|i| SIGMA * c.radk[i][5] * 900f64.powi(4)).sum();
    assert!(rel(via_radk, total) < 1e-12, "{via_radk} vs {total}");
}
