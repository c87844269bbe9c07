//! The plan's route choice and refusals on a shipped case, and that the route's result agrees
//! with the sparse route's.
use super::*;
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
    assert_eq!(plan.tolerance, Tolerance::Factor(viewfactor::DEFAULT_TOLERANCE));
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
    assert_eq!(factor, 1e-4);
}

#[test]
fn the_clustered_store_refuses_what_it_cannot_serve_in_library_words() {
    let s = furnace();
    let req = Request { store: Store::Hierarchical, method: Method::McCosine, ..Request::default() };
    let e = Plan::new(&s, &req).unwrap_err();
    assert!(matches!(e, PlanError::ClusteredUnserved), "{e}");
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
