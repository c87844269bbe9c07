//! Semi-gray bands: blackbody fractions against quadrature, one-band and equal-band limits
//! against the gray solve, the two-surface closed form per band, and Newton recovering a
//! temperature from its flux.
use crate::common;

use lambert::exchange::{enforce, Enforce, EnforceParams, Exchange};
use lambert::geometry::quadrature::gauss_legendre;
use lambert::scene::BoundaryCondition::{HeatFlux, Temperature};
use lambert::scene::Scene;
use lambert::solve::bands::{solve_bands, Band, BandSpec};
use lambert::solve::planck::{band_power, fraction, fraction_derivative, C2};
use lambert::solve::{self, Params};
use lambert::viewfactor::{Level, MethodSet};
use std::f64::consts::PI;

/// The brief's accuracy goal for F_{0→λT}.
const F_TOL: f64 = 1e-10;

/// (15/π⁴)∫_ζ^∞ t³/(eᵗ−1) dt by 40-point Gauss–Legendre on 400 panels up to ζ + 60.
fn fraction_by_quadrature(lambda_t: f64) -> f64 {
    let z = C2 / lambda_t;
    let (x, w) = gauss_legendre(40);
    let (a, b, panels) = (z, z + 60.0, 400);
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        for (xi, wi) in x.iter().zip(&w) {
            let t = a + h * (p as f64 + xi);
            sum += h * wi * t.powi(3) / t.exp_m1();
        }
    }
    15.0 / PI.powi(4) * sum
}

#[test]
fn band_fractions_match_quadrature() {
    for lt in [300.0, 1000.0, 2897.771955, 5000.0, 7193.88, 7193.89, 10_000.0, 50_000.0, 1e6] {
        let (f, q) = (fraction(lt), fraction_by_quadrature(lt));
        assert!((f - q).abs() < F_TOL, "F({lt}) = {f}, quadrature {q}");
    }
    // Wien peak: F ≈ 0.25; limits; derivative by central differences.
    assert!((fraction(2897.771955) - 0.250054).abs() < 1e-5);
    assert_eq!(fraction(0.0), 0.0);
    assert_eq!(fraction(f64::INFINITY), 1.0);
    for lt in [1500.0, 7193.8, 20_000.0] {
        let d = (fraction(lt * (1.0 + 1e-6)) - fraction(lt * (1.0 - 1e-6))) / (2e-6 * lt);
        assert!((d - fraction_derivative(lt)).abs() < 1e-6 * d.abs(), "{d} vs {}", fraction_derivative(lt));
    }
    let (e, de) = band_power(1.0, 4.0, 800.0);
    let fd = (band_power(1.0, 4.0, 800.01).0 - band_power(1.0, 4.0, 799.99).0) / 0.02;
    assert!(e > 0.0 && (de - fd).abs() < 1e-6 * fd, "{de} vs {fd}");
}

fn bands(limits: &[f64]) -> Vec<Band> {
    limits
        .windows(2)
        .enumerate()
        .map(|(k, w)| Band { name: format!("b{k}"), lower: w[0], upper: w[1] })
        .collect()
}

/// Two concentric cubes (inner 6 m², outer 54 m²) with exact factors, as in tests/heat/solve.rs.
fn two_surface(
    c1: lambert::scene::BoundaryCondition,
    c2: lambert::scene::BoundaryCondition,
) -> (Scene, Exchange) {
    let faces = |d: f64| common::rect_exact::box_faces([d; 3], 1).iter().map(|f| f.1[0].polygon()).collect();
    let scene = Scene::builder()
        .surface("inner", faces(1.0), 0.5, Some(c1))
        .surface("outer", faces(3.0), 0.5, Some(c2))
        .build();
    let names = vec!["inner".to_string(), "outer".to_string()];
    let vf = common::vf_from_s(
        names,
        vec![6.0, 54.0],
        &[vec![0.0, 6.0], vec![6.0, 48.0]],
        Level::Surface,
        MethodSet::ANALYTIC,
    );
    let mut ex = Exchange::from_viewfactors(&vf);
    enforce(&mut ex, &EnforceParams { mode: Enforce::Closure, ..Default::default() }).unwrap();
    (scene, ex)
}

fn closed_form(eps: &[[f64; 2]], limits: &[f64], t1: f64, t2: f64) -> f64 {
    let (a1, a2) = (6.0, 54.0);
    limits
        .windows(2)
        .zip(eps)
        .map(|(w, e)| {
            let (e1, e2) = (band_power(w[0], w[1], t1).0, band_power(w[0], w[1], t2).0);
            a1 * (e1 - e2) / (1.0 / e[0] + a1 / a2 * (1.0 / e[1] - 1.0))
        })
        .sum()
}

#[test]
fn two_surface_semi_gray_closed_form_and_newton() {
    let limits = [0.0, 3.0, 8.0, f64::INFINITY];
    let eps = [[0.9, 0.2], [0.3, 0.6], [0.7, 0.95]];
    let spec = |_: ()| BandSpec {
        bands: bands(&limits),
        emissivity: vec![vec![0.9, 0.3, 0.7], vec![0.2, 0.6, 0.95]],
    };
    let q = closed_form(&eps, &limits, 1200.0, 350.0);
    let (scene, ex) = two_surface(Temperature(1200.0), Temperature(350.0));
    let sol = solve_bands(&scene, &ex, &spec(()), &Params::default()).unwrap();
    assert!(((sol.results[0].heat_rate - q) / q).abs() < 1e-12, "{} vs {q}", sol.results[0].heat_rate);
    // Newton: give the outer surface the flux of that answer; it must find 350 K.
    let (scene, ex) = two_surface(Temperature(1200.0), HeatFlux(-q / 54.0));
    let sol = solve_bands(&scene, &ex, &spec(()), &Params::default()).unwrap();
    assert!((sol.results[1].temperature - 350.0).abs() < 1e-8, "T = {}", sol.results[1].temperature);
    assert!(sol.info.iterations > 0 && sol.info.iterations < 20, "{} Newton steps", sol.info.iterations);
    let (sum, max) = sol.heat_balance();
    assert!(sum.abs() <= solve::BALANCE_TOL * max);
}

#[test]
fn equal_band_emissivities_reduce_to_gray() {
    // E3-like cube with adiabatic walls: bands with the gray ε everywhere give the gray answer.
    let wall = (0.5, HeatFlux(0.0));
    let props = [wall, wall, wall, wall, (0.8, Temperature(1000.0)), (0.6, Temperature(400.0))];
    let (scene, s) = common::box_scene([1.0; 3], 2, &props);
    let mut ex = Exchange::from_viewfactors(&common::patch_vf(&scene, &s));
    enforce(&mut ex, &EnforceParams { mode: Enforce::Closure, ..Default::default() }).unwrap();
    let gray = solve::solve_gray(&scene, &ex, &Params::default()).unwrap();
    let eps: Vec<Vec<f64>> = scene.surfaces.iter().map(|s| vec![s.emissivity; 3]).collect();
    let spec = BandSpec { bands: bands(&[0.0, 2.0, 5.0, f64::INFINITY]), emissivity: eps };
    let banded = solve_bands(&scene, &ex, &spec, &Params::default()).unwrap();
    for (g, b) in gray.results.iter().zip(&banded.results) {
        assert!(
            (g.temperature - b.temperature).abs() < 1e-9 * g.temperature,
            "{} vs {}",
            g.temperature,
            b.temperature
        );
        assert!((g.heat_rate - b.heat_rate).abs() < 1e-9 * 3e4);
    }
    // Non-gray walls change the answer but still conserve energy.
    let mut spec = spec;
    for e in spec.emissivity.iter_mut().take(4) {
        *e = vec![0.9, 0.5, 0.1];
    }
    let sol = solve_bands(&scene, &ex, &spec, &Params::default()).unwrap();
    let (sum, max) = sol.by_surface(&scene).heat_balance();
    assert!(sum.abs() <= solve::BALANCE_TOL * max, "{sum} vs {max}");
    assert!(sol.results.iter().take(16).all(|r| r.heat_flux.abs() < 1e-6));
}

#[test]
fn bad_band_tables_are_input_errors() {
    let (scene, ex) = two_surface(Temperature(1200.0), Temperature(350.0));
    let gap = BandSpec { bands: bands(&[0.0, 3.0]), emissivity: vec![vec![0.5], vec![0.5]] };
    let err = solve_bands(&scene, &ex, &gap, &Params::default()).unwrap_err();
    assert_eq!(err.exit_code(), 2, "{err}");
    let short =
        BandSpec { bands: bands(&[0.0, 3.0, f64::INFINITY]), emissivity: vec![vec![0.5], vec![0.5, 0.5]] };
    let err = solve_bands(&scene, &ex, &short, &Params::default()).unwrap_err();
    assert!(err.to_string().contains("inner") && err.to_string().contains("emissivity_bands"), "{err}");
}
