//! The `analytic` method end to end through `viewfactor::compute`: subdivided-cube totals
//! against the closed forms, surface aggregation with F_II > 0, open scenes, the Gauss
//! ladder's error bound swept over separations, determinism, and pairs whose view is partly
//! blocked (shadowed exactly; blocker detection checked against brute-force sampling).
use crate::common;

use common::analytic_scenes as scenes;

use glam::{DQuat, DVec3};
use lambert::geometry::Polygon;
use lambert::scene::Scene;
use lambert::viewfactor::analytic::kernel::{AnalyticKernel, Rung, GAUSS_REL_TOL};
use lambert::viewfactor::closed_form::{parallel_opposed_rectangles, perpendicular_common_edge};
use lambert::viewfactor::exact::pair::polygon_polygon;
use lambert::viewfactor::shadow::detect::Occlusion;
use lambert::viewfactor::{compute, Level, Method, MethodSet, Params};
use rand::{Rng, SeedableRng};

/// Exact-rung and closed-form round-off on sums of a few hundred pairs.
const EXACT_TOL: f64 = 1e-9;

fn analytic() -> Params {
    Params { method: Method::Analytic, ..Params::default() }
}

fn cube_values() -> (f64, f64) {
    (parallel_opposed_rectangles(1.0, 1.0, 1.0), perpendicular_common_edge(1.0, 1.0, 1.0))
}

#[test]
fn subdivided_cube_matches_closed_forms() {
    let (opp, adj) = cube_values();
    for n in [1, 3, 6] {
        let scene = scenes::cube(n);
        let vf = compute(&scene, &analytic(), Level::Surface).unwrap();
        for i in 0..6 {
            for j in 0..6 {
                let want = if i == j {
                    0.0
                } else if i / 2 == j / 2 {
                    opp
                } else {
                    adj
                };
                let got = vf.get(i, j);
                assert!((got - want).abs() < EXACT_TOL, "n={n} F({i},{j}) = {got}, want {want}");
            }
        }
        let (row, at) = vf.max_patch_row_error();
        assert!(row < EXACT_TOL, "n={n}: patch {at} row sum off by {row}");
        assert_eq!(vf.pairs, (6 * n * n * (6 * n * n - 1) / 2) as u64);
    }
}

#[test]
fn auto_on_a_clear_scene_is_the_analytic_ladder_within_its_tolerance() {
    // Without blockers `auto` is the analytic kernel with the ladder's relative target
    // LADDER_SHARE × --tolerance: same sparsity, entries within that share of each factor.
    let scene = scenes::cube(2);
    let a = compute(&scene, &analytic(), Level::Patch).unwrap();
    let params = Params { method: Method::Auto, ..Params::default() };
    let b = compute(&scene, &params, Level::Patch).unwrap();
    let rel = lambert::viewfactor::auto::LADDER_SHARE * params.tolerance;
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        assert_eq!(ra.len(), rb.len());
        for (ea, eb) in ra.iter().zip(rb) {
            assert_eq!(ea.to, eb.to);
            assert_eq!(eb.method, MethodSet::ANALYTIC);
            assert!((ea.factor - eb.factor).abs() <= rel * ea.factor, "{} vs {}", ea.factor, eb.factor);
        }
    }
}

#[test]
fn open_box_sees_itself() {
    // Floor and four walls of the unit cube as one surface "box", the ceiling as "lid".
    let faces = scenes::box_faces(1.0, 1.0, 1.0);
    let mut walls = Vec::new();
    let mut lid = Vec::new();
    for (name, o, u, v) in faces {
        let patches = scenes::grid(o, u, v, 3, 3);
        if name == "ceiling" {
            lid = patches;
        } else {
            walls.extend(patches);
        }
    }
    let scene = Scene::builder().surface("box", walls, 0.9, None).surface("lid", lid, 0.9, None).build();
    assert!(!scene.surfaces[0].planar);
    let vf = compute(&scene, &analytic(), Level::Surface).unwrap();
    let (opp, adj) = cube_values();
    // Box → box: the floor sees 4 walls, each wall the floor, 2 walls beside it and 1 opposite.
    let f_bb = (4.0 * adj + 4.0 * (3.0 * adj + opp)) / 5.0;
    let f_bl = (adj * 4.0 + opp) / 5.0;
    assert!((vf.get(0, 0) - f_bb).abs() < EXACT_TOL, "F_box,box = {} want {f_bb}", vf.get(0, 0));
    assert!((vf.get(0, 1) - f_bl).abs() < EXACT_TOL, "F_box,lid = {}", vf.get(0, 1));
    assert!((vf.get(1, 0) - 1.0).abs() < EXACT_TOL, "F_lid,box = {}", vf.get(1, 0));
    assert_eq!(vf.get(1, 1), 0.0, "the planar lid cannot see itself");
    assert!((f_bb - 0.8).abs() < 1e-12, "closed-form identity 16·adj + 4·opp = 4");
}

#[test]
fn open_scene_sends_the_rest_to_ambient() {
    let (lower, upper) = scenes::opposed_squares();
    let scene = Scene::builder()
        .surface("lower", vec![lower], 0.9, None)
        .surface("upper", vec![upper], 0.9, None)
        .ambient(300.0)
        .build();
    let vf = compute(&scene, &analytic(), Level::Surface).unwrap();
    let mut csv = Vec::new();
    let geometry = lambert::scene::fingerprint::geometry(&scene);
    lambert::report::csv::write_viewfactors(&mut csv, &vf, true, &geometry, std::path::Path::new("-"))
        .unwrap();
    let text = String::from_utf8(csv).unwrap();
    let want = 1.0 - parallel_opposed_rectangles(1.0, 1.0, 1.0);
    for from in ["lower", "upper"] {
        let row = text.lines().find(|l| l.starts_with(&format!("{from},ambient,"))).expect("ambient row");
        let f: f64 = row.split(',').nth(2).unwrap().parse().unwrap();
        assert!((f - want).abs() < 1e-12, "{from} → ambient = {f}, want {want}\n{text}");
    }
}

#[test]
fn results_do_not_depend_on_thread_count() {
    let scene = scenes::box_room(2.0, 1.5, 1.0, 0.3);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| compute(&scene, &analytic(), Level::Patch).unwrap())
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.rows, two.rows);
    assert_eq!(one.patch_row_sums, two.patch_row_sums);
}

/// A random receiver in front of the unit square z = 0 at distance scale `d` (parallel,
/// perpendicular and grazing, tilted, or random), of side `side`; triangles when `tri`.
fn receiver(rng: &mut rand_pcg::Pcg64, d: f64, side: f64, tri: bool) -> Polygon {
    let kind = rng.random_range(0..4);
    let (c, n) = match kind {
        0 => {
            (DVec3::new(rng.random_range(-2.0..2.0) * d, rng.random_range(-1.0..1.0) * d, d + 0.5), -DVec3::Z)
        }
        1 => (
            DVec3::new(0.5 + d, rng.random_range(-1.0..1.0) * d, side / 2.0 + rng.random_range(0.0..1.0)),
            -DVec3::X,
        ),
        2 => {
            let t = rng.random_range(0.1..1.4f64);
            (DVec3::new(0.5 + d * t.sin(), 0.0, d * t.cos() + side), DVec3::new(-t.sin(), 0.0, -t.cos()))
        }
        _ => {
            let dir = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(0.2..1.0),
            );
            let c = dir.normalize() * (d + 1.0 + side);
            let jitter = DVec3::new(
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
            );
            (c, (-c.normalize() + jitter).normalize())
        }
    };
    let rot = DQuat::from_rotation_arc(DVec3::Z, n) * DQuat::from_rotation_z(rng.random_range(0.0..3.0));
    let h = side / 2.0;
    let corners: Vec<(f64, f64)> = if tri {
        vec![(-h, -h), (h, -0.5 * h), (0.2 * h, h)]
    } else {
        vec![(-h, -h), (h, -h), (h, h), (-h, h)]
    };
    Polygon::new(corners.iter().map(|&(x, y)| c + rot * DVec3::new(x, y, 0.0)).collect()).unwrap()
}

#[test]
fn gauss_rungs_stay_within_their_target_over_a_separation_sweep() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let emitters = [
        scenes::plate(DVec3::ZERO, 1.0, true),
        Polygon::new(vec![
            DVec3::new(-0.5, -0.4, 0.0),
            DVec3::new(0.5, -0.4, 0.0),
            DVec3::new(0.0, 0.5, 0.0),
        ])
        .unwrap(),
        Polygon::new(vec![
            DVec3::new(-0.5, -0.1, 0.0),
            DVec3::new(0.5, -0.1, 0.0),
            DVec3::new(0.5, 0.1, 0.0),
            DVec3::new(-0.5, 0.1, 0.0),
        ])
        .unwrap(),
    ];
    let (mut gauss, mut worst) = (0, 0.0f64);
    let mut orders = std::collections::BTreeSet::new();
    for trial in 0..1500 {
        let d = 0.3 * 10f64.powf(rng.random_range(0.0..2.5));
        let side = [0.1, 0.5, 1.0, 2.0][trial % 4];
        let emitter = &emitters[trial % 3];
        let recv = receiver(&mut rng, d, side, trial % 5 == 0);
        let scene = Scene::builder()
            .surface("e", vec![emitter.clone()], 1.0, None)
            .surface("r", vec![recv.clone()], 1.0, None)
            .build();
        let kernel = AnalyticKernel::new(&scene, GAUSS_REL_TOL);
        let Rung::Gauss(mi, mj) = kernel.rung(0, 1) else { continue };
        let exact = polygon_polygon(emitter, &recv);
        let vf = compute(&scene, &analytic(), Level::Patch).unwrap();
        let got = vf.get(0, 1) * emitter.area();
        let err = ((got - exact) / exact).abs();
        assert!(err <= GAUSS_REL_TOL, "trial {trial}: orders ({mi},{mj}) error {err:.3e} > {GAUSS_REL_TOL:e}\n emitter {emitter:?}\n receiver {recv:?}");
        gauss += 1;
        orders.insert((mi, mj));
        worst = worst.max(err);
    }
    assert!(gauss > 500, "the sweep must exercise the Gauss rungs ({gauss} pairs)");
    assert!(orders.len() >= 8, "the sweep must reach many orders: {orders:?}");
    eprintln!("{gauss} Gauss pairs, orders {orders:?}, worst relative error {worst:.2e}");
}

#[test]
fn cube_and_box_rooms_have_no_blockers() {
    for scene in [scenes::cube(4), scenes::box_room(3.0, 2.0, 1.5, 0.5)] {
        let occ = Occlusion::new(&scene);
        assert!(occ.is_clear(), "a convex enclosure has no blocking plane ({} active)", occ.active_planes());
        assert!(occ.blocked_pairs(&scene).is_empty());
    }
}

/// True when the open segment a→b passes strictly through polygon `poly` (margin `eps`).
fn segment_hits(a: DVec3, b: DVec3, poly: &Polygon, eps: f64) -> bool {
    let (da, db) = (poly.plane_distance(a), poly.plane_distance(b));
    if !((da > eps && db < -eps) || (da < -eps && db > eps)) {
        return false;
    }
    let p = a + (b - a) * (da / (da - db));
    poly.triangulate().iter().any(|[x, y, z]| {
        let n = poly.normal();
        [(x, y), (y, z), (z, x)].iter().all(|(u, v)| (**v - **u).cross(p - **u).dot(n) > eps)
    })
}

/// Pairs (i < j) for which some sampled sight line between front-facing points is blocked.
fn sampled_blocked_pairs(scene: &Scene, samples: usize, seed: u64) -> Vec<(usize, usize)> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let n = scene.patches.len();
    let point = |poly: &Polygon, rng: &mut rand_pcg::Pcg64| {
        let tris = poly.triangulate();
        let t = &tris[rng.random_range(0..tris.len())];
        let (mut u, mut v): (f64, f64) = (rng.random(), rng.random());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0])
    };
    let mut out = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            let (pi, pj) = (&scene.patches[i].polygon, &scene.patches[j].polygon);
            let blocked = (0..samples).any(|_| {
                let (a, b) = (point(pi, &mut rng), point(pj, &mut rng));
                if pi.plane_distance(b) <= 1e-9 || pj.plane_distance(a) <= 1e-9 {
                    return false;
                }
                (0..n)
                    .filter(|&k| k != i && k != j)
                    .any(|k| segment_hits(a, b, &scene.patches[k].polygon, 1e-9))
                    || scene
                        .obstructions
                        .iter()
                        .flat_map(|o| &o.polygons)
                        .any(|q| segment_hits(a, b, q, 1e-9))
            });
            if blocked {
                out.push((i, j));
            }
        }
    }
    out
}

#[test]
fn l_shaped_room_blockers_match_sampling() {
    for (n, samples) in [(1, 3000), (2, 300)] {
        let scene = scenes::l_room(n);
        let occ = Occlusion::new(&scene);
        assert!(!occ.is_clear());
        let exact: Vec<(usize, usize)> = occ.blocked_pairs(&scene).iter().map(|&(i, j, _)| (i, j)).collect();
        let sampled = sampled_blocked_pairs(&scene, samples, 5);
        assert!(!sampled.is_empty());
        let pairs = scene.patches.len() * (scene.patches.len() - 1) / 2;
        eprintln!(
            "n={n}: {} of {pairs} pairs detected blocked, {} seen blocked by sampling",
            exact.len(),
            sampled.len()
        );
        for p in &sampled {
            assert!(exact.contains(p), "n={n}: sampling found pair {p:?} blocked, detection missed it");
        }
        if n == 1 {
            // Dense sampling: every detected pair must show a blocked sight line.
            for p in &exact {
                assert!(sampled.contains(p), "n={n}: pair {p:?} detected as blocked, never seen blocked");
            }
        }
    }
}

/// Row-sum tolerance of a closed scene with shadowed pairs: each is integrated to 1e-8
/// relative (`EXACT_REL_TOL`), so rows of a few hundred pairs close far inside 1e-7.
const SHADOWED_ROW_TOL: f64 = 1e-7;

#[test]
fn l_shaped_room_closes_with_shadowed_pairs() {
    let scene = scenes::l_room(2);
    let vf = compute(&scene, &analytic(), Level::Patch).unwrap();
    let worst = vf.row_sums().iter().map(|s| (s - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst < SHADOWED_ROW_TOL, "max |row sum - 1| = {worst:e}");
    // Each wing sees the other only past the inner corner: shadowed, not refused.
    let surf = compute(&scene, &analytic(), Level::Surface).unwrap();
    let row = surf.row_sums();
    assert!(row.iter().all(|s| (s - 1.0).abs() < SHADOWED_ROW_TOL), "{row:?}");
}

#[test]
fn plates_with_a_blocker_between_are_shadowed() {
    let (lower, upper) = scenes::opposed_squares();
    let shade = scenes::plate(DVec3::new(0.5, 0.5, 0.5), 0.2, true);
    let base = || {
        Scene::builder().surface("lower", vec![lower.clone()], 0.9, None).surface(
            "upper",
            vec![upper.clone()],
            0.9,
            None,
        )
    };
    let clear = parallel_opposed_rectangles(1.0, 1.0, 1.0);
    // An obstruction between the plates.
    let scene = base().obstruction("shade", vec![shade.clone()]).source("plates.toml").build();
    let by_obstruction = compute(&scene, &analytic(), Level::Surface).unwrap().get(0, 1);
    // An exchanging surface between them blocks the same view (from either side).
    let scene = base().surface("middle", vec![shade.flipped()], 0.9, None).build();
    let by_surface = compute(&scene, &analytic(), Level::Surface).unwrap().get(0, 1);
    assert!(by_obstruction > 0.0 && by_obstruction < clear, "{by_obstruction} vs clear {clear}");
    // The shade hides at most its own projected share of the view.
    assert!(clear - by_obstruction > 0.01 && clear - by_obstruction < 0.1, "{by_obstruction}");
    assert!((by_obstruction - by_surface).abs() <= EXACT_TOL * clear, "{by_obstruction} vs {by_surface}");
}

#[test]
fn blockers_beside_the_view_change_nothing() {
    let (lower, upper) = scenes::opposed_squares();
    let exact = parallel_opposed_rectangles(1.0, 1.0, 1.0);
    for shade in [
        scenes::plate(DVec3::new(2.5, 0.5, 0.5), 1.0, true), // beside the pair
        scenes::plate(DVec3::new(0.5, 0.5, 1.5), 0.5, true), // behind the upper plate
        scenes::plate(DVec3::new(1.55, 0.5, 0.5), 0.1, true), // close to, but outside, the hull
    ] {
        let scene = Scene::builder()
            .surface("lower", vec![lower.clone()], 0.9, None)
            .surface("upper", vec![upper.clone()], 0.9, None)
            .obstruction("shade", vec![shade])
            .build();
        let vf = compute(&scene, &analytic(), Level::Surface).unwrap();
        assert!((vf.get(0, 1) - exact).abs() < 1e-12);
    }
}

/// A unit-cube scene file; `lid_width` < 1 leaves a gap along the north wall.
fn cube_toml(lid_width: f64) -> String {
    let faces = [
        ("floor", "[0,0,0]", "[1,0,0]".to_string(), "[0,1,0]"),
        ("ceiling", "[0,0,1]", format!("[0,{lid_width},0]"), "[1,0,0]"),
        ("west", "[0,0,0]", "[0,1,0]".to_string(), "[0,0,1]"),
        ("east", "[1,0,0]", "[0,0,1]".to_string(), "[0,1,0]"),
        ("south", "[0,0,0]", "[0,0,1]".to_string(), "[1,0,0]"),
        ("north", "[0,1,0]", "[1,0,0]".to_string(), "[0,0,1]"),
    ];
    faces
        .iter()
        .map(|(name, o, u, v)| {
            format!("[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o}, u = {u}, v = {v} }}\nsubdivide = [3, 3]\n\n")
        })
        .collect()
}

fn cli_viewfactors(scene: &std::path::Path) -> (Option<i32>, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lambert"))
        .args(["viewfactors".as_ref(), scene.as_os_str(), "-m".as_ref(), "analytic".as_ref()])
        .output()
        .expect("run lambert");
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn cli_reports_closure_and_warns_about_leaks() {
    let dir = tempfile::tempdir().unwrap();
    let closed = dir.path().join("cube.toml");
    std::fs::write(&closed, cube_toml(1.0)).unwrap();
    let (code, err) = cli_viewfactors(&closed);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("54 patches, 1431 pairs"), "{err}");
    assert!(err.contains("max |row sum - 1| = "), "{err}");
    assert!(!err.contains("leaks"), "an exact cube does not leak: {err}");

    // A 1e-3-wide gap along the north wall: the rows of the surfaces that see it fall short.
    let leaky = dir.path().join("gap.toml");
    std::fs::write(&leaky, cube_toml(0.999)).unwrap();
    let (code, err) = cli_viewfactors(&leaky);
    assert_eq!(code, Some(0), "viewfactors only warns: {err}");
    let warning =
        err.lines().find(|l| l.contains("leaks")).unwrap_or_else(|| panic!("no leak warning: {err}"));
    assert!(warning.contains("north"), "the north wall borders the gap: {warning}");
}

#[test]
fn auto_on_a_closed_obstructed_room_does_not_cry_leak() {
    // Sampled pairs carry `auto`'s 1e-4 goal, not the exact method's 1e-6 leak threshold:
    // a watertight room with a block must not be reported as leaking, at either level.
    let room = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/o3_obstructed_room/scene.toml");
    for extra in [None, Some("--patches")] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_lambert"))
            .arg("viewfactors")
            .arg(&room)
            .args(["-o", "-"])
            .args(extra)
            .output()
            .expect("run lambert");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{err}");
        assert!(err.contains("method auto") && err.contains("max |row sum - 1| = "), "{err}");
        assert!(!err.contains("leaks"), "{extra:?}: {err}");
    }
}
