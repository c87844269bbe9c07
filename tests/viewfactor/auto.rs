//! `auto`, the default method: each pair by the cheapest estimator meeting `--tolerance`.
use crate::common;

use common::{cube_faces, F_BLOCKED, F_PARALLEL, F_PERPENDICULAR};
use lambert::geometry::DVec3;
use lambert::scene::Scene;
use lambert::viewfactor::analytic::kernel::{AnalyticKernel, GAUSS_REL_TOL};
use lambert::viewfactor::engine;
use lambert::viewfactor::shadow::calibrate::measure;
use lambert::viewfactor::shadow::policy::{
    Choice, CostModel, Policy, MC_SAMPLE_NS, MC_SIGMAS, MC_TEST_NS, SHADOW_UNIT_NS,
};
use lambert::viewfactor::shadow::Shadows;
use lambert::viewfactor::{self, Level, Method, MethodSet, Params, ViewFactors};

fn run(scene: &Scene, method: Method, tolerance: f64, level: Level) -> ViewFactors {
    let params = Params { method, tolerance, seed: 5, ..Params::default() };
    viewfactor::compute(scene, &params, level).expect("computes")
}

fn entry(vf: &ViewFactors, i: usize, j: usize) -> Option<lambert::viewfactor::Entry> {
    vf.rows[i].iter().find(|e| e.to as usize == j).copied()
}

#[test]
fn default_method_is_auto_with_tolerance_1e4() {
    let p = Params::default();
    assert_eq!(p.method, Method::Auto);
    assert_eq!(p.tolerance, 1e-4);
}

#[test]
fn centred_blocker_within_each_tolerance() {
    let scene = common::blocked_squares();
    for tol in [1e-3, 1e-4, 1e-6] {
        let vf = run(&scene, Method::Auto, tol, Level::Surface);
        let e = entry(&vf, 0, 1).expect("an entry");
        assert!((e.factor - F_BLOCKED).abs() <= tol, "tol {tol}: {} vs {F_BLOCKED} ({})", e.factor, e.method);
        // A large pair: integrating the shadows is cheaper than sampling to this goal.
        assert_eq!(e.method, MethodSet::SHADOWED, "tol {tol}");
    }
}

#[test]
fn clear_scenes_are_pure_analytic() {
    let vf = run(&common::cube_interior(3), Method::Auto, 1e-4, Level::Surface);
    for (i, row) in vf.rows.iter().enumerate() {
        for e in row {
            assert_eq!(e.method, MethodSet::ANALYTIC);
            let exact = if e.to as usize == i ^ 1 { F_PARALLEL } else { F_PERPENDICULAR };
            // The ladder's target is a tenth of the tolerance, relative.
            assert!((e.factor - exact).abs() <= 1e-5 * exact, "F({i}→{}) = {} vs {exact}", e.to, e.factor);
        }
    }
}

#[test]
fn concentric_boxes_within_tolerance() {
    let vf = run(&common::concentric_boxes(2), Method::Auto, 1e-4, Level::Surface);
    let (inner, outer) = (0, 1);
    for (i, j, exact) in [(inner, outer, 1.0), (outer, inner, 0.0625), (outer, outer, 0.9375)] {
        let f = vf.get(i, j);
        assert!((f - exact).abs() <= 1e-4, "F({i}→{j}) = {f}, exact {exact}");
    }
}

/// A 3 m room (n² per wall) with the block [1, 2]³ (m² per face).
fn room(n: usize, m: usize) -> Scene {
    let mut b = Scene::builder();
    for (k, f) in cube_faces(DVec3::splat(1.5), 3.0, true, n).into_iter().enumerate() {
        b = b.surface(&format!("wall{k}"), f, 1.0, None);
    }
    for (k, f) in cube_faces(DVec3::splat(1.5), 1.0, false, m).into_iter().enumerate() {
        b = b.surface(&format!("block{k}"), f, 1.0, None);
    }
    b.build()
}

#[test]
fn every_pair_meets_its_goal_against_exact_shadows() {
    // Patch by patch against the analytic kernel with shadows to 1e-7 relative (a tenth of the
    // finest goal below, at a fraction of `analytic`'s cost): integrated pairs within
    // the tolerance, sampled pairs within 5 reported standard errors, and those errors within
    // the goal (σ ≤ τ/Z). A coarse tolerance makes the sampled branch appear, a fine one the
    // integrated branch.
    let scene = room(3, 1);
    let kernel = AnalyticKernel::with_policy(&scene, GAUSS_REL_TOL, Policy::Exact { rel_tol: 1e-7 });
    let exact = engine::run(&scene, &kernel, &Params::default(), Level::Patch).unwrap();
    let mut seen = [0usize; 2];
    for tol in [3e-2, 1e-5] {
        let vf = run(&scene, Method::Auto, tol, Level::Patch);
        for (i, row) in vf.rows.iter().enumerate() {
            for e in row {
                let f = exact.get(i, e.to as usize);
                let err = (e.factor - f).abs();
                let what =
                    format!("tol {tol} {}→{}: {} vs {f} ± {} ({})", i, e.to, e.factor, e.std_error, e.method);
                if e.method == MethodSet::MC_AREA {
                    seen[1] += 1;
                    assert!(err <= 5.0 * e.std_error + 1e-12, "{what}");
                    assert!(e.std_error <= tol / MC_SIGMAS * (1.0 + 1e-9), "{what}");
                } else {
                    seen[0] += usize::from(e.method == MethodSet::SHADOWED);
                    assert!(err <= tol, "{what}");
                }
            }
        }
    }
    assert!(seen[0] > 0 && seen[1] > 0, "both branches exercised: {seen:?}");
}

#[test]
fn same_seed_same_numbers_on_any_thread_count() {
    let scene = room(6, 2);
    let once = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| run(&scene, Method::Auto, 3e-2, Level::Patch))
    };
    let (a, b) = (once(1), once(2));
    assert_eq!(a.rows, b.rows);
    assert_eq!(a.patch_row_sums, b.patch_row_sums);
}

/// Two 1 m plates 1 m apart (4 × 4 patches each) with a 320-facet sphere of radius 0.3 between.
fn plates_around_a_meshed_sphere() -> Scene {
    let sphere = common::inward_sphere(DVec3::splat(0.5), 0.3, 2);
    Scene::builder()
        .surface("bottom", common::rect_grid(DVec3::ZERO, DVec3::X, DVec3::Y, 4), 1.0, None)
        .surface("top", common::rect_grid(DVec3::Z, DVec3::Y, DVec3::X, 4), 1.0, None)
        .obstruction("sphere", sphere)
        .ambient(0.0)
        .build()
}

#[test]
fn pairs_behind_a_meshed_body_are_priced_from_the_scene() {
    // Both estimators measured on the scene's own pairs behind the sphere: wherever one was
    // clearly cheaper (3×; a capped integration only bounds its cost from below), the fitted
    // prices choose it.
    let scene = plates_around_a_meshed_sphere();
    let tol = 1e-3;
    let shadows = Shadows::new(&scene, Policy::Auto { tol, seed: 5 }).expect("the sphere blocks");
    let measured = measure(&shadows, tol, 5);
    assert!(measured.iter().any(|m| m.blockers >= 20), "sample pairs behind many facets: {measured:?}");
    let model = shadows.model();
    let mut decided = 0;
    for m in &measured {
        let shadow = m.shadow_work as f64 * SHADOW_UNIT_NS;
        let mc = m.samples as f64 * MC_SAMPLE_NS + m.tests as f64 * MC_TEST_NS;
        let choice = model.choose(m.ratio, 1.0, m.blockers);
        if shadow > 3.0 * mc {
            assert!(matches!(choice, Choice::MonteCarlo(_)), "{m:?}: {model:?}");
            decided += 1;
        } else if mc > 3.0 * shadow && !m.capped {
            assert_eq!(choice, Choice::Shadowed, "{m:?}: {model:?}");
            decided += 1;
        }
    }
    assert!(decided > 0, "{measured:?}");
}

#[test]
fn calibration_is_the_same_on_any_thread_count() {
    let scene = plates_around_a_meshed_sphere();
    let policy = Policy::Auto { tol: 1e-3, seed: 5 };
    let once = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let shadows = Shadows::new(&scene, policy).expect("the sphere blocks");
            (*shadows.model(), measure(&shadows, 1e-3, 5))
        })
    };
    let (a, b) = (once(1), once(2));
    assert_eq!(a, b);
    assert_ne!(a.0, CostModel::default(), "the model was fitted");
}

#[test]
fn a_sampled_zero_keeps_its_error() {
    // Patches behind the sphere at a coarse goal: Monte Carlo with every sample blocked gives
    // 0 with a standard error from its prior. That entry is reported (not dropped as a zero),
    // and every pair that is not zero exactly has an entry within its error or the goal.
    let scene = plates_around_a_meshed_sphere();
    let kernel = AnalyticKernel::with_policy(&scene, GAUSS_REL_TOL, Policy::Exact { rel_tol: 1e-7 });
    let exact = engine::run(&scene, &kernel, &Params::default(), Level::Patch).unwrap();
    let tol = 3e-2;
    let vf = run(&scene, Method::Auto, tol, Level::Patch);
    let mut zeros = 0;
    for i in 0..scene.patches.len() {
        for j in 0..scene.patches.len() {
            let f = exact.get(i, j);
            let Some(e) = entry(&vf, i, j) else {
                assert!(f == 0.0, "{i}→{j}: {f} has no entry");
                continue;
            };
            let what = format!("{i}→{j}: {} vs {f} ± {} ({})", e.factor, e.std_error, e.method);
            if e.method == MethodSet::MC_AREA {
                assert!((e.factor - f).abs() <= 5.0 * e.std_error + 1e-12, "{what}");
                zeros += usize::from(e.factor == 0.0);
            } else {
                assert!((e.factor - f).abs() <= tol, "{what}");
            }
        }
    }
    assert!(zeros > 0, "some sampled pair saw no visible sample");
}

/// A closed U-channel (0.6 × 0.5 × 0.4 m, walls 0.1 m thick: a concave body of 28 triangles,
/// normals out) centred in a 2 m room of one patch per wall.
fn channel_in_a_room() -> Scene {
    use lambert::geometry::Polygon;
    let (o, len) = (DVec3::new(-0.3, -0.25, -0.2), 0.5);
    let outline =
        [(0.0, 0.0), (0.6, 0.0), (0.6, 0.4), (0.5, 0.4), (0.5, 0.1), (0.1, 0.1), (0.1, 0.4), (0.0, 0.4)];
    let at = |k: usize, y: f64| o + DVec3::new(outline[k % 8].0, y, outline[k % 8].1);
    let poly = |v: Vec<DVec3>| Polygon::new(v).expect("a valid triangle");
    let mut faces = Vec::new();
    // The caps: the outline runs counter-clockwise about −y.
    let near = poly((0..8).map(|k| at(k, 0.0)).collect());
    let far = poly((0..8).rev().map(|k| at(k, len)).collect());
    for cap in [near, far] {
        faces.extend(cap.triangulate().into_iter().map(|t| poly(t.to_vec())));
    }
    for k in 0..8 {
        let (a, b, c, d) = (at(k, 0.0), at(k, len), at(k + 1, len), at(k + 1, 0.0));
        faces.push(poly(vec![a, b, c]));
        faces.push(poly(vec![a, c, d]));
    }
    // Walls first: a row's goal set on its own (large) patch would then be the loose one.
    let mut b = Scene::builder();
    for (k, f) in cube_faces(DVec3::ZERO, 2.0, true, 1).into_iter().enumerate() {
        b = b.surface(&format!("wall{k}"), f, 0.8, None);
    }
    b.surface("channel", faces, 0.85, None).build()
}

#[test]
fn behind_a_concave_part_every_entry_meets_the_goal_both_ways() {
    // The goal holds on each F in both directions: a channel triangle of 0.005 m² facing a
    // 4 m² wall has F_ij up to 0.5, so a goal set on the wall's row alone (τ·A_wall on the
    // exchange area) would let the triangle's F carry 800 τ. Reference: the exact shadow
    // integration to 1e-7 relative. Integrated entries within τ both ways; sampled entries
    // within 5 reported standard errors, with 2σ ≤ τ both ways; no entry over its goal; and
    // every row sums to 1 within 10 τ before enforcement (1e-3 at the default 1e-4). The
    // coarsest goal makes the sampled branch appear (the integration's cut emitters price it
    // out at 3e-3).
    let scene = channel_in_a_room();
    assert_eq!(scene.patches.len(), 34);
    let kernel = AnalyticKernel::with_policy(&scene, GAUSS_REL_TOL, Policy::Exact { rel_tol: 1e-7 });
    let exact = engine::run(&scene, &kernel, &Params::default(), Level::Patch).unwrap();
    let mut seen = [0usize; 2];
    for tol in [3e-2, 3e-3, 1e-4] {
        let vf = run(&scene, Method::Auto, tol, Level::Patch);
        assert!(vf.warnings.is_empty(), "{:?}", vf.warnings);
        for (i, row) in vf.rows.iter().enumerate() {
            let sum: f64 = row.iter().map(|e| e.factor).sum();
            assert!((sum - 1.0).abs() <= 10.0 * tol, "tol {tol}: row {i} sums to {sum}");
            for e in row {
                let j = e.to as usize;
                let (f, back) = (exact.get(i, j), entry(&vf, j, i).expect("reciprocal entry"));
                let err = (e.factor - f).abs();
                let what = format!(
                    "tol {tol} {i}→{j}: {} vs {f} ± {} ({}); back {back:?}",
                    e.factor, e.std_error, e.method
                );
                if e.method == MethodSet::MC_AREA {
                    seen[1] += 1;
                    assert!(err <= 5.0 * e.std_error + 1e-12, "{what}");
                    assert!(MC_SIGMAS * e.std_error.max(back.std_error) <= tol * (1.0 + 1e-9), "{what}");
                } else {
                    seen[0] += usize::from(e.method == MethodSet::SHADOWED);
                    assert!(err <= tol, "{what}");
                }
            }
        }
    }
    assert!(seen[0] > 0 && seen[1] > 0, "both branches exercised: {seen:?}");
}
