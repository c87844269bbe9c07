//! Exchange matrix and enforcement: exactness of reciprocity and closure, preserved zeros and
//! signs, ML on multinomial hit counts, the leak refusal, open scenes, bipartite pairs and
//! thread-count determinism.
// Dense matrix checks read clearest with (i, j) indices.
#![allow(clippy::needless_range_loop)]
use crate::common;

use lambert::exchange::{enforce, ClosureMethod, Diagnostics, Enforce, EnforceParams, Exchange};
use lambert::scene::BoundaryCondition::HeatFlux;
use lambert::viewfactor::{Level, MethodSet, ViewFactors};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Closure target of the library ([`lambert::exchange::enforce::CLOSURE_TOL`]) with room for
/// the sum of 24 terms.
const CLOSED: f64 = 1e-11;

fn box24() -> (lambert::scene::Scene, Vec<Vec<f64>>) {
    common::box_scene([1.0, 2.0, 3.0], 2, &[(0.5, HeatFlux(0.0)); 6])
}

/// Exact factors with a deterministic relative perturbation of up to `amp` (reciprocity and
/// closure both broken, zeros kept).
fn perturbed(amp: f64, seed: u64) -> (ViewFactors, Vec<Vec<f64>>) {
    let (scene, s) = box24();
    let mut rng = Pcg64::seed_from_u64(seed);
    let noisy: Vec<Vec<f64>> = s
        .iter()
        .map(|r| r.iter().map(|&v| v * (1.0 + amp * (2.0 * rng.random::<f64>() - 1.0))).collect())
        .collect();
    let mut vf = common::patch_vf(&scene, &noisy);
    // Declare the noise as each entry's standard error, so the leak check accepts it.
    for e in vf.rows.iter_mut().flatten() {
        e.std_error = amp * e.factor;
    }
    (vf, s)
}

fn closed(mode: Enforce, method: ClosureMethod) -> EnforceParams {
    EnforceParams { mode, method, ..Default::default() }
}

fn assert_closed_and_reciprocal(ex: &Exchange, exact: &[Vec<f64>]) {
    let d = Diagnostics::of(ex, false);
    assert!(d.max_row_error < CLOSED, "row error {}", d.max_row_error);
    assert_eq!(d.reciprocity, 0.0, "reciprocity must be exact");
    assert_eq!(d.negatives, 0);
    for i in 0..exact.len() {
        for j in 0..exact.len() {
            if exact[i][j] == 0.0 {
                assert_eq!(ex.get(i, j), 0.0, "structural zero {i},{j} perturbed");
            }
        }
    }
}

#[test]
fn every_closure_method_closes_and_keeps_zeros() {
    let (vf, exact) = perturbed(0.05, 1);
    for m in [ClosureMethod::SymmetricScaling, ClosureMethod::WeightedLs, ClosureMethod::UnweightedLs] {
        let mut ex = Exchange::from_viewfactors(&vf);
        let rep = enforce(&mut ex, &closed(Enforce::Closure, m)).unwrap();
        assert!(rep.before.max_row_error > 1e-3 && rep.before.reciprocity > 1e-3, "{m:?} {:?}", rep.before);
        assert_closed_and_reciprocal(&ex, &exact);
    }
}

#[test]
fn exact_factors_are_a_fixed_point() {
    let (scene, s) = box24();
    let vf = common::patch_vf(&scene, &s);
    for m in [ClosureMethod::SymmetricScaling, ClosureMethod::WeightedLs] {
        let mut ex = Exchange::from_viewfactors(&vf);
        enforce(&mut ex, &closed(Enforce::Closure, m)).unwrap();
        for i in 0..s.len() {
            for j in 0..s.len() {
                assert!((ex.get(i, j) - s[i][j]).abs() < 1e-12, "{m:?} moved exact S[{i}][{j}]");
            }
        }
    }
}

#[test]
fn max_likelihood_on_hit_counts() {
    let (scene, s) = box24();
    let vf = common::multinomial(&scene, &s, 1000, 7);
    let mut ex = Exchange::from_viewfactors(&vf);
    assert!(ex.has_hit_counts());
    let rep = enforce(&mut ex, &closed(Enforce::Closure, ClosureMethod::Auto)).unwrap();
    assert_eq!(rep.method, "maximum likelihood");
    assert!(rep.iterations <= 10, "Newton steps {}", rep.iterations);
    assert_closed_and_reciprocal(&ex, &s);
    // ML improves on the raw estimate (docs/literature.md §3: ~30 % lower rms error).
    let rms = |f: &dyn Fn(usize, usize) -> f64| {
        let a = scene.patch_areas();
        let mut sum = 0.0;
        for i in 0..s.len() {
            for j in 0..s.len() {
                sum += (f(i, j) / a[i] - s[i][j] / a[i]).powi(2);
            }
        }
        (sum / (s.len() * s.len()) as f64).sqrt()
    };
    let raw = rms(&|i, j| vf.get(i, j) * scene.patch_areas()[i]);
    let ml = rms(&|i, j| ex.get(i, j));
    assert!(ml < raw, "ML {ml} vs raw {raw}");
}

#[test]
fn leaking_closed_scene_is_refused() {
    let (scene, s) = box24();
    // Drop everything the last face receives: rows now fall short by its share.
    let n = s.len();
    let cut: Vec<Vec<f64>> = s
        .iter()
        .map(|r| r.iter().enumerate().map(|(j, &v)| if j >= n - 4 { 0.0 } else { v }).collect())
        .collect();
    let mut ex = Exchange::from_viewfactors(&common::patch_vf(&scene, &cut));
    let p = EnforceParams { source: "box.toml".into(), ..closed(Enforce::Closure, ClosureMethod::Auto) };
    let err = enforce(&mut ex, &p).unwrap_err();
    assert_eq!(err.exit_code(), 2);
    let msg = err.to_string();
    assert!(msg.contains("box.toml") && msg.contains("leaks") && msg.contains("#"), "{msg}");
    // Reciprocity alone does not refuse, and a tiny shortfall below the threshold closes.
    assert!(enforce(
        &mut Exchange::from_viewfactors(&common::patch_vf(&scene, &cut)),
        &closed(Enforce::Reciprocity, ClosureMethod::Auto)
    )
    .is_ok());
    let short: Vec<Vec<f64>> = s.iter().map(|r| r.iter().map(|v| v * (1.0 - 5e-4)).collect()).collect();
    let mut ex = Exchange::from_viewfactors(&common::patch_vf(&scene, &short));
    enforce(&mut ex, &closed(Enforce::Closure, ClosureMethod::Auto)).unwrap();
    assert_closed_and_reciprocal(&ex, &s);
}

#[test]
fn open_scene_ambient_takes_the_rest() {
    let (vf, _) = perturbed(0.05, 3);
    // Remove the last face's columns: an opening.
    let n = vf.names.len();
    let mut vf = vf;
    for r in &mut vf.rows {
        r.retain(|e| (e.to as usize) < n - 4);
    }
    let mut ex = Exchange::from_viewfactors(&vf);
    let p = EnforceParams { mode: Enforce::Reciprocity, open: true, ..Default::default() };
    let rep = enforce(&mut ex, &p).unwrap();
    assert_eq!(rep.after.reciprocity, 0.0);
    let amb = ex.ambient.as_ref().unwrap();
    let sums = ex.row_sums();
    for i in 0..n {
        assert!(amb[i] >= 0.0 && (amb[i] + sums[i] - ex.areas[i]).abs() < 1e-12 * ex.areas[i]);
    }
}

#[test]
fn overfull_open_rows_are_scaled_down() {
    let (vf, _) = perturbed(0.2, 4);
    let mut ex = Exchange::from_viewfactors(&vf);
    let p = EnforceParams { mode: Enforce::Reciprocity, open: true, ..Default::default() };
    let rep = enforce(&mut ex, &p).unwrap();
    assert!(rep.before.max_row_error > 0.01, "test needs over-full rows");
    assert!(rep.after.max_row_error <= 1e-11, "{:?}", rep.after);
    assert_eq!(rep.after.negatives, 0);
}

#[test]
fn bipartite_pair_closes() {
    // Two plates that see only each other (a bipartite graph: singular constraint matrix).
    let names = vec!["a".to_string(), "b".to_string()];
    for m in [ClosureMethod::SymmetricScaling, ClosureMethod::WeightedLs, ClosureMethod::UnweightedLs] {
        let vf = common::vf_from_s(
            names.clone(),
            vec![2.0, 2.0],
            &[vec![0.0, 1.9995], vec![1.9991, 0.0]],
            Level::Surface,
            MethodSet::ANALYTIC,
        );
        let mut ex = Exchange::from_viewfactors(&vf);
        enforce(&mut ex, &closed(Enforce::Closure, m)).unwrap();
        assert!(
            (ex.get(0, 1) - 2.0).abs() < 1e-12 && (ex.get(1, 0) - 2.0).abs() < 1e-12,
            "{m:?}: {}",
            ex.get(0, 1)
        );
    }
    // Unequal areas on the two sides: closure is infeasible and says so.
    let vf = common::vf_from_s(
        names,
        vec![2.0, 2.001],
        &[vec![0.0, 1.9995], vec![1.9995, 0.0]],
        Level::Surface,
        MethodSet::ANALYTIC,
    );
    let mut ex = Exchange::from_viewfactors(&vf);
    let err = enforce(&mut ex, &closed(Enforce::Closure, ClosureMethod::WeightedLs)).unwrap_err();
    assert!(err.to_string().contains("no solution"), "{err}");
}

#[test]
fn enforcement_is_thread_count_independent() {
    let (scene, s) = box24();
    let vf = common::multinomial(&scene, &s, 200, 11);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut a = Exchange::from_viewfactors(&vf);
            enforce(&mut a, &closed(Enforce::Closure, ClosureMethod::Auto)).unwrap();
            let mut b = Exchange::from_viewfactors(&vf);
            enforce(&mut b, &closed(Enforce::Closure, ClosureMethod::SymmetricScaling)).unwrap();
            (a.s.data().to_vec(), b.s.data().to_vec())
        })
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn aggregation_preserves_closure() {
    let (scene, s) = box24();
    let vf = common::multinomial(&scene, &s, 500, 5);
    let mut ex = Exchange::from_viewfactors(&vf);
    enforce(&mut ex, &closed(Enforce::Closure, ClosureMethod::Auto)).unwrap();
    let group: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
    let names = scene.surfaces.iter().map(|s| s.name.clone()).collect();
    let areas = scene.surfaces.iter().map(|s| s.area).collect();
    let agg = ex.aggregate(&group, names, areas, Level::Surface);
    let d = Diagnostics::of(&agg, false);
    assert!(d.max_row_error < CLOSED && d.reciprocity < 1e-15, "{d:?}");
    let vf = agg.to_viewfactors(std::time::Duration::ZERO);
    assert_eq!(vf.names.len(), 6);
    assert!(vf.row_sums().iter().all(|r| (r - 1.0).abs() < CLOSED));
}
