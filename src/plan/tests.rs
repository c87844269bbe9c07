//! The plan's route choice and refusals on a shipped case, and that the route's result agrees
//! with the sparse route's.
use super::*;
use crate::viewfactor::Level;
use std::path::Path;

/// The shipped cube furnace: six walls, closed, gray, with temperatures set.
fn furnace() -> Scene {
    crate::scene::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/cases/e3_cube_furnace/scene.toml")))
        .expect("the shipped cube furnace loads")
}

#[test]
fn auto_takes_the_packed_route_on_a_small_scene_and_says_why() {
    let s = furnace();
    let plan = Plan::new(&s, &Request::default()).unwrap();
    assert_eq!(plan.route, Route::Packed);
    assert_eq!(plan.reason, Reason::Small { patches: s.patches.len() });
    assert_eq!(plan.tolerance, Tolerance::Factor(viewfactor::DEFAULT_FACTOR_TOLERANCE));
}

#[test]
fn a_tight_tolerance_is_said_to_keep_every_pair() {
    let s = furnace();
    let plan = Plan::new(&s, &Request { tolerance: Some(1e-6), ..Request::default() }).unwrap();
    assert_eq!(plan.reason, Reason::Tight { patches: s.patches.len() });
    assert_eq!(plan.tolerance, Tolerance::Factor(1e-6));
}

#[test]
fn monte_carlo_and_iterative_solvers_take_the_sparse_route() {
    let s = furnace();
    let mc = Plan::new(&s, &Request { method: Method::McCosine, ..Request::default() }).unwrap();
    assert_eq!((mc.route, mc.reason), (Route::Sparse, Reason::OnlySparse));
    let jacobi = Plan::new(&s, &Request { solver: Solver::Jacobi, ..Request::default() }).unwrap();
    assert_eq!(jacobi.route, Route::Sparse);
}

#[test]
fn the_clustered_store_states_a_heat_rate_tolerance() {
    let s = furnace();
    let req = Request { store: Store::Hierarchical, tolerance: Some(1e-2), ..Request::default() };
    let plan = Plan::new(&s, &req).unwrap();
    assert_eq!(plan.route, Route::Clustered);
    let Tolerance::HeatRate { rate, factor } = plan.tolerance else { panic!("{:?}", plan.tolerance) };
    assert_eq!(rate, 1e-2);
    // The exact pairs' goal on each F: a tenth of the heat-rate tolerance.
    assert!((factor - 1e-3).abs() <= 1e-15, "{factor}");
}

#[test]
fn the_clustered_store_refuses_what_it_cannot_serve_in_library_words() {
    let s = furnace();
    let req = Request { store: Store::Hierarchical, method: Method::McCosine, ..Request::default() };
    let e = Plan::new(&s, &req).unwrap_err();
    assert!(matches!(e, PlanError::ClusteredUnserved), "{e}");
    // A deterministic method without an exact kernel is refused before any work, too.
    let req = Request { store: Store::Hierarchical, method: Method::Hemicube, ..Request::default() };
    assert!(matches!(Plan::new(&s, &req), Err(PlanError::ClusteredUnserved)));
    assert!(!e.to_string().contains("--"), "no command-line flag in a library error: {e}");
}

#[test]
fn packed_clustered_and_sparse_routes_agree_on_the_furnace_heat_rates() {
    let s = furnace();
    let run = |req: Request| {
        let plan = Plan::new(&s, &req).unwrap();
        let out = plan.run(&s, &mut Silent).unwrap();
        (plan.route, out.solution.results.iter().map(|r| r.heat_rate).collect::<Vec<_>>())
    };
    let (r0, packed) = run(Request::default());
    let (r1, sparse) = run(Request { conductances: true, ..Request::default() });
    let (r2, clustered) = run(Request { store: Store::Hierarchical, ..Request::default() });
    assert_eq!((r0, r1, r2), (Route::Packed, Route::Sparse, Route::Clustered));
    let scale = packed.iter().fold(0.0f64, |m, q| m.max(q.abs()));
    for i in 0..packed.len() {
        // Both dense routes integrate the same exact factors to 1e-4: heat rates agree to
        // that share of the largest heat rate.
        assert!((packed[i] - sparse[i]).abs() <= 1e-4 * scale, "{i}: {} vs {}", packed[i], sparse[i]);
        // The clustered route's default heat-rate tolerance is 1e-2 of the largest.
        assert!((packed[i] - clustered[i]).abs() <= 1e-2 * scale, "{i}: {} vs {}", packed[i], clustered[i]);
    }
}

#[test]
fn progress_hears_the_phases_of_the_sparse_route() {
    struct Log(Vec<Phase>);
    impl Progress for Log {
        fn phase(&mut self, p: Phase) {
            self.0.push(p);
        }
    }
    let s = furnace();
    let plan = Plan::new(&s, &Request { solver: Solver::Jacobi, ..Request::default() }).unwrap();
    let mut log = Log(Vec::new());
    plan.run(&s, &mut log).unwrap();
    assert_eq!(log.0, [Phase::ViewFactors, Phase::Enforcement, Phase::Solve]);
}

/// A view-factor request at `level` with `enforce`.
fn vf_request(level: Level, enforce: Option<Enforce>) -> Request {
    Request { goal: Goal::ViewFactors { level }, enforce, ..Request::default() }
}

#[test]
fn view_factor_plans_choose_packed_rows_or_the_sparse_store_and_say_why() {
    let s = furnace();
    let patch = Plan::new(&s, &vf_request(Level::Patch, None)).unwrap();
    assert_eq!(
        (patch.route, patch.reason, patch.enforce),
        (Route::Packed, Reason::PackedRows, Enforce::None)
    );
    let surface = Plan::new(&s, &vf_request(Level::Surface, None)).unwrap();
    assert_eq!((surface.route, surface.reason), (Route::Sparse, Reason::FewSurfaces));
    let enforced = Plan::new(&s, &vf_request(Level::Surface, Some(Enforce::Closure))).unwrap();
    assert_eq!(enforced.route, Route::Packed);
    let mc = Request { method: Method::McCosine, ..vf_request(Level::Patch, None) };
    let mc = Plan::new(&s, &mc).unwrap();
    assert_eq!((mc.route, mc.reason), (Route::Sparse, Reason::OnlySparse));
}

#[test]
fn a_plan_runs_only_its_own_goal() {
    let s = furnace();
    let solve = Plan::new(&s, &Request::default()).unwrap();
    assert!(matches!(solve.view_factors(&s, &mut Silent), Err(Error::Usage(_))));
    let vf = Plan::new(&s, &vf_request(Level::Patch, None)).unwrap();
    assert!(matches!(vf.run(&s, &mut Silent), Err(Error::Usage(_))));
}

#[test]
fn packed_view_factors_equal_the_sparse_computation_and_close_the_furnace() {
    let s = furnace();
    let plan = Plan::new(&s, &vf_request(Level::Patch, None)).unwrap();
    let out = plan.view_factors(&s, &mut Silent).unwrap();
    assert_eq!(out.route, Route::Packed);
    assert!(matches!(out.matrix, Matrix::Packed { .. }));
    let (worst, _, level) = out.worst_row.clone().expect("the furnace is closed");
    assert_eq!(level, Level::Patch);
    assert!(worst < 1e-4, "row sums of the exact cube within the tolerance: {worst}");
    assert!(out.diagnostics.leak_warnings.is_empty(), "{:?}", out.diagnostics.leak_warnings);
    let packed = out.into_viewfactors();
    let sparse = viewfactor::compute(&s, &plan.viewfactors, Level::Patch).unwrap();
    for (i, (a, b)) in packed.rows.iter().zip(&sparse.rows).enumerate() {
        let f = |r: &[viewfactor::Entry], j: u32| r.iter().find(|e| e.to == j).map_or(0.0, |e| e.factor);
        for j in 0..s.patches.len() as u32 {
            // Both integrate the same exact kernel to the 1e-4 goal on each F.
            assert!((f(a, j) - f(b, j)).abs() <= 1e-4, "F[{i}][{j}]: {} vs {}", f(a, j), f(b, j));
        }
    }
}

#[test]
fn enforced_view_factors_report_their_enforcement_and_hear_its_phase() {
    struct Log(Vec<Phase>);
    impl Progress for Log {
        fn phase(&mut self, p: Phase) {
            self.0.push(p);
        }
    }
    let s = furnace();
    for level in [Level::Patch, Level::Surface] {
        let plan = Plan::new(&s, &vf_request(level, Some(Enforce::Closure))).unwrap();
        let mut log = Log(Vec::new());
        let out = plan.view_factors(&s, &mut log).unwrap();
        assert_eq!(log.0, [Phase::ViewFactors, Phase::Enforcement]);
        assert!(out.diagnostics.enforcement.is_some());
        let (worst, ..) = out.worst_row.expect("closed");
        assert!(worst < 1e-9, "closure enforced: {worst}");
    }
}

/// A closed scene of `n` small triangles, one patch each (only the patch count matters to the
/// store choice).
fn triangles(n: usize) -> Scene {
    use crate::geometry::{DVec3, Polygon};
    use crate::scene::Shape;
    let tri = |k: usize| {
        let x = k as f64;
        Polygon::new(vec![DVec3::new(x, 0.0, 0.0), DVec3::new(x + 1.0, 0.0, 0.0), DVec3::new(x, 1.0, 0.0)])
            .unwrap()
    };
    let mut b = Scene::builder();
    b.push_surface("part", Shape::Mesh, (0..n).map(tri).collect(), 1.0, None);
    b.build()
}

#[test]
fn auto_never_clusters_a_method_the_clustered_store_refuses() {
    let n = HIERARCHICAL_MIN_PATCHES + 1;
    let s = triangles(n);
    // An exact kernel above the threshold is clustered (when the dense store fits, it is by
    // size; when it does not, by memory).
    let auto = Plan::new(&s, &Request::default()).unwrap();
    assert_eq!(auto.route, Route::Clustered);
    let fits = exchange::dense::check_fits(n, PACKED_BYTES_PER_PAIR, &s.source).is_ok();
    for method in [Method::Hemicube, Method::SinglePlane] {
        let plan = Plan::new(&s, &Request { method, ..Request::default() });
        if fits {
            // Every pair in the dense store, said in the library's words.
            let plan = plan.unwrap();
            assert_eq!((plan.route, plan.reason), (Route::Packed, Reason::NoExactKernel { patches: n }));
            let why = plan.reason.to_string();
            assert!(why.contains("exact kernel") && !why.contains("--"), "{why}");
        } else {
            // No store can run it: refused before any work, naming the method.
            let e = Error::from(plan.unwrap_err()).to_string();
            assert!(e.contains(&method.to_string()) && e.contains("would not fit"), "{e}");
        }
    }
    // Named stores keep their meaning: `dense` is served, `hierarchical` refused.
    let dense = Request { method: Method::Hemicube, store: Store::Dense, ..Request::default() };
    assert_eq!(Plan::new(&s, &dense).unwrap().route, Route::Packed);
    let clustered = Request { method: Method::Hemicube, store: Store::Hierarchical, ..Request::default() };
    assert!(matches!(Plan::new(&s, &clustered), Err(PlanError::ClusteredUnserved)));
}
