//! Point-to-surface factors (`viewfactor::points`): Lambert's corner formula for parallel
//! rectangles, the centre of a closed cube, closure in a room with re-entrant walls, exact
//! shadows against their closed form and against a cosine-ray Monte Carlo of this file,
//! sensors on and behind surfaces, rigid motion and thread counts.
use crate::common::analytic_scenes::{grid, l_room};
use crate::common::concave_meshes::{extruded, L_PROFILE};
use crate::common::{cube_interior, rect};
use glam::{DQuat, DVec2};
use lambert::geometry::{frame::Frame, sampling::sample_cosine_hemisphere};
use lambert::geometry::{DVec3, Polygon};
use lambert::scene::Scene;
use lambert::viewfactor::points::{compute, PointFactors, ViewPoint, ON_PLANE_REL, ROW_SUM_TOL};
use lambert::viewfactor::{Level, MethodSet};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::f64::consts::PI;

/// Element at unit distance below the corner of a parallel a×b rectangle (docs/literature.md V10).
fn corner(a: f64, b: f64) -> f64 {
    let (sa, sb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
    (a / sa * (b / sa).atan() + b / sb * (a / sb).atan()) / (2.0 * PI)
}

fn point(p: [f64; 3], n: [f64; 3]) -> ViewPoint {
    ViewPoint::new(p, n).expect("a valid point")
}

/// F(point k → column `name`), 0 when absent.
fn factor(pf: &PointFactors, k: usize, name: &str) -> f64 {
    let col = pf.names.iter().position(|n| n == name).unwrap_or_else(|| panic!("no column {name}"));
    pf.rows[k].iter().find(|e| e.to as usize == col).map_or(0.0, |e| e.factor)
}

fn row_sum(pf: &PointFactors, k: usize) -> f64 {
    pf.rows[k].iter().map(|e| e.factor).sum()
}

/// A 2×1 plate at height 0.7 facing down, in one patch or 4×3 patches.
fn plate_scene(split: (usize, usize)) -> Scene {
    let plate = grid(DVec3::new(0.0, 0.0, 0.7), DVec3::Y, 2.0 * DVec3::X, split.1, split.0);
    Scene::builder().surface("plate", plate, 0.9, None).ambient(300.0).build()
}

#[test]
fn a_point_facing_a_parallel_rectangle_matches_the_corner_formula() {
    let c = 0.7;
    // The foot of the normal inside the plate (four corner rectangles) and outside it (two
    // differences).
    let inside = corner(0.3 / c, 0.4 / c)
        + corner(1.7 / c, 0.4 / c)
        + corner(0.3 / c, 0.6 / c)
        + corner(1.7 / c, 0.6 / c);
    let outside = corner(2.5 / c, 0.4 / c) - corner(0.5 / c, 0.4 / c) + corner(2.5 / c, 0.6 / c)
        - corner(0.5 / c, 0.6 / c);
    let pts = [point([0.3, 0.4, 0.0], [0.0, 0.0, 1.0]), point([-0.5, 0.4, 0.0], [0.0, 0.0, 2.0])];
    for split in [(1, 1), (4, 3)] {
        let scene = plate_scene(split);
        let pf = compute(&scene, &pts, Level::Surface, false);
        for (k, exact) in [inside, outside].into_iter().enumerate() {
            let f = factor(&pf, k, "plate");
            assert!((f - exact).abs() < 1e-14, "split {split:?}, point {k}: {f} vs {exact}");
            assert_eq!(pf.rows[k][0].method, MethodSet::ANALYTIC);
            assert_eq!(pf.rows[k][0].std_error, 0.0);
        }
        // Per patch, the entries add up to the surface's (same order of summation).
        let patches = compute(&scene, &pts, Level::Patch, false);
        for k in 0..2 {
            assert_eq!(row_sum(&patches, k), factor(&pf, k, "plate"), "split {split:?}, point {k}");
        }
    }
    // Facing away, or behind the plate: nothing.
    let scene = plate_scene((1, 1));
    let away = [point([0.3, 0.4, 0.0], [0.0, 0.0, -1.0]), point([0.3, 0.4, 1.0], [0.0, 0.0, -1.0])];
    let pf = compute(&scene, &away, Level::Surface, false);
    assert!(pf.rows.iter().all(Vec::is_empty), "{:?}", pf.rows);
}

#[test]
fn a_point_at_the_centre_of_a_closed_cube_sees_its_hemisphere_and_sums_to_one() {
    let scene = cube_interior(3);
    let tilted = DVec3::new(1.0, 2.0, 3.0).normalize().to_array();
    let pts = [point([0.5; 3], [0.0, 0.0, 1.0]), point([0.5; 3], tilted)];
    let pf = compute(&scene, &pts, Level::Surface, false);
    // Facing +z: the top face is four unit corners (half side 0.5 at distance 0.5), the bottom
    // is behind, each side wall takes a quarter of the rest by symmetry.
    let top = 4.0 * corner(1.0, 1.0);
    assert!((factor(&pf, 0, "z+") - top).abs() < 1e-15, "{} vs {top}", factor(&pf, 0, "z+"));
    assert_eq!(factor(&pf, 0, "z-"), 0.0);
    for side in ["x+", "x-", "y+", "y-"] {
        let f = factor(&pf, 0, side);
        assert!((f - (1.0 - top) / 4.0).abs() < 1e-15, "{side}: {f} vs {}", (1.0 - top) / 4.0);
    }
    for k in 0..2 {
        assert!((row_sum(&pf, k) - 1.0).abs() < 1e-14, "point {k}: {}", row_sum(&pf, k));
    }
    let closure = pf.closure();
    assert!(closure.off.is_empty() && closure.worst < 1e-14, "{closure:?}");
    assert_eq!(closure.warning(&["a".into(), "b".into()], false), None);
}

#[test]
fn a_sensor_on_the_floor_sees_no_floor_and_typed_digits_keep_it_on_it() {
    let scene = cube_interior(4);
    let on = point([0.3, 0.6, 0.0], [0.0, 0.0, 1.0]);
    // 3e-7 below the floor: inside ON_PLANE_REL of the 1.7 m scene, as coordinates typed to
    // seven digits; the floor must not hide the room from it.
    let below = point([0.3, 0.6, -3e-7], [0.0, 0.0, 1.0]);
    assert!(3e-7 < ON_PLANE_REL * 3f64.sqrt());
    let pf = compute(&scene, &[on, below], Level::Surface, false);
    assert_eq!(factor(&pf, 0, "z-"), 0.0);
    let top = corner(0.3, 0.6) + corner(0.7, 0.6) + corner(0.3, 0.4) + corner(0.7, 0.4);
    assert!((factor(&pf, 0, "z+") - top).abs() < 1e-14, "{} vs {top}", factor(&pf, 0, "z+"));
    assert!((row_sum(&pf, 0) - 1.0).abs() < 1e-13, "{}", row_sum(&pf, 0));
    assert!((row_sum(&pf, 1) - 1.0).abs() < 1e-6, "{}", row_sum(&pf, 1));
    assert!((factor(&pf, 1, "z+") - top).abs() < 1e-6);
}

/// The closed 3 m room of one patch per wall (inward) with an optional 1×1×0.8 m table
/// (12 triangles, outward) standing on the floor.
fn room(table: bool) -> Scene {
    let mut b = Scene::builder();
    let names = ["x+", "x-", "y+", "y-", "z+", "z-"];
    for (name, face) in names.iter().zip(crate::common::cube_faces(DVec3::splat(1.5), 3.0, true, 1)) {
        b = b.surface(name, face, 0.9, None);
    }
    if table {
        b = b.obstruction("table", cuboid(DVec3::new(1.0, 1.0, 0.0), DVec3::new(2.0, 2.0, 0.8)));
    }
    b.build()
}

/// The box [lo, hi] as 12 outward triangles.
fn cuboid(lo: DVec3, hi: DVec3) -> Vec<Polygon> {
    let c = |i: usize| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2]);
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .map(|t| Polygon::new(t.iter().map(|&i| c(i)).collect()).expect("valid triangle"))
        .collect()
}

#[test]
fn a_sensor_on_a_table_is_not_shadowed_by_it() {
    // On the table top, facing up: nothing of the table is in its hemisphere, so its row is
    // the row of the same point in the empty room, and sums to 1.
    let up = [point([1.5, 1.4, 0.8], [0.0, 0.0, 1.0])];
    let with = compute(&room(true), &up, Level::Surface, false);
    let without = compute(&room(false), &up, Level::Surface, false);
    assert_eq!(with.rows[0].len(), 5);
    for (a, b) in with.rows[0].iter().zip(&without.rows[0]) {
        assert!(a.to == b.to && a.factor == b.factor && a.method == MethodSet::ANALYTIC, "{a:?} vs {b:?}");
    }
    assert!((row_sum(&with, 0) - 1.0).abs() < 1e-13, "{}", row_sum(&with, 0));
    // Tilted, near the top's edge: the solid table hides every direction below its top (the
    // rays leave it through its far faces), so each wall counts above z = 0.8 only.
    let p = point([1.2, 1.9, 0.8], [0.3, -0.2, 1.0]);
    let with = compute(&room(true), &[p], Level::Surface, false);
    let empty = room(false);
    for s in &empty.surfaces {
        let wall = &empty.patches[s.patches.start].polygon;
        let above = wall.clip(p.position, DVec3::Z);
        let exact = above
            .map_or(0.0, |w| lambert::viewfactor::exact::lambert::point_to_polygon(p.position, p.normal, &w));
        let f = factor(&with, 0, &s.name);
        assert!((f - exact).abs() < 1e-14, "{}: {f} vs {exact} above the table top", s.name);
    }
    // On the floor beside the table, facing it: the table hides part of the room, and the
    // closure check says so (an obstruction takes no part in the exchange).
    let beside = [point([0.5, 1.5, 0.0], [1.0, 0.0, 0.2])];
    let pf = compute(&room(true), &beside, Level::Surface, false);
    let clear = compute(&room(false), &beside, Level::Surface, false);
    assert!(row_sum(&pf, 0) < row_sum(&clear, 0) - 0.1, "{} vs {}", row_sum(&pf, 0), row_sum(&clear, 0));
    let warning = pf.closure().warning(&["beside".into()], true).expect("the table hides part of the room");
    assert!(warning.contains("beside") && warning.contains("obstruction"), "{warning}");
}

#[test]
fn a_centred_blocker_takes_exactly_its_shadow_and_hides_all_from_its_umbra() {
    // Point at the origin facing +z; receiver of half side 1 at height 2 facing down; square
    // blocker of half side b at height 1. Its shadow is the square of half side 2b: F is the
    // receiver's corners minus the shadow's (both at the point's V10 corners).
    let receiver = rect(DVec3::new(-1.0, -1.0, 2.0), 2.0 * DVec3::Y, 2.0 * DVec3::X);
    let eye = [point([0.0; 3], [0.0, 0.0, 1.0])];
    for (b, exact) in [(0.3, 4.0 * corner(0.5, 0.5) - 4.0 * corner(0.3, 0.3)), (0.6, 0.0)] {
        let blocker = rect(DVec3::new(-b, -b, 1.0), 2.0 * b * DVec3::X, 2.0 * b * DVec3::Y);
        let scene = Scene::builder()
            .surface("receiver", vec![receiver.clone()], 0.9, None)
            .obstruction("blocker", vec![blocker])
            .ambient(0.0)
            .build();
        let pf = compute(&scene, &eye, Level::Surface, false);
        let f = factor(&pf, 0, "receiver");
        assert!((f - exact).abs() < 1e-14, "blocker {b}: {f} vs {exact}");
        if exact > 0.0 {
            assert_eq!(pf.rows[0][0].method, MethodSet::SHADOWED);
        } else {
            assert!(pf.rows[0].is_empty(), "in the umbra: {:?}", pf.rows[0]);
        }
    }
}

/// True when the ray o + t·d (t > 0) crosses the convex polygon; the distance t.
fn ray_hit(o: DVec3, d: DVec3, poly: &Polygon) -> Option<f64> {
    let v = poly.vertices();
    let n = poly.normal();
    let den = n.dot(d);
    if den.abs() < 1e-300 {
        return None;
    }
    let t = n.dot(v[0] - o) / den;
    if t.is_nan() || t <= 1e-12 {
        return None;
    }
    let x = o + t * d;
    let m = v.len();
    (0..m).all(|k| (v[(k + 1) % m] - v[k]).cross(x - v[k]).dot(n) >= 0.0).then_some(t)
}

/// F(point → receiver) past `blockers` by `rays` cosine-weighted rays (Nusselt: every ray of
/// equal weight); the fraction that reaches the receiver's front first, and its binomial σ.
fn cosine_rays(
    p: &ViewPoint,
    receiver: &Polygon,
    blockers: &[Polygon],
    rays: usize,
    seed: u64,
) -> (f64, f64) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let frame = Frame::from_normal(p.normal);
    let mut hits = 0usize;
    for _ in 0..rays {
        let d = frame.to_world(sample_cosine_hemisphere(DVec2::new(rng.random(), rng.random())));
        if receiver.normal().dot(d) >= 0.0 {
            continue;
        }
        let Some(t) = ray_hit(p.position, d, receiver) else { continue };
        if !blockers.iter().any(|b| ray_hit(p.position, d, b).is_some_and(|s| s < t)) {
            hits += 1;
        }
    }
    let f = hits as f64 / rays as f64;
    (f, (f * (1.0 - f) / rays as f64).sqrt())
}

/// A tilted receiver behind an L-bracket (20 triangles, a closed concave mesh) or a block of 12
/// triangles (a closed convex one), seen by tilted points.
fn blocked_scene(convex: bool) -> (Scene, Polygon, Vec<Polygon>) {
    let receiver = rect(DVec3::new(-1.0, -0.8, 2.2), DVec3::new(0.3, 2.0, 0.4), DVec3::new(2.2, 0.0, -0.5));
    let body = if convex {
        cuboid(DVec3::new(-0.3, -0.2, 0.9), DVec3::new(0.4, 0.3, 1.3))
    } else {
        extruded(L_PROFILE, |u, v, w| DVec3::new(0.8 * u - 0.5, 0.9 * w - 0.4, 0.8 * v + 0.7))
    };
    let scene = Scene::builder()
        .surface("receiver", vec![receiver.clone()], 0.9, None)
        .obstruction("body", body.clone())
        .ambient(0.0)
        .build();
    (scene, receiver, body)
}

#[test]
fn shadows_of_closed_meshes_agree_with_cosine_rays() {
    let pts = [
        point([0.1, 0.05, 0.0], [0.1, -0.2, 1.0]),
        point([-0.4, 0.3, 0.2], [0.3, 0.1, 1.0]),
        point([0.5, -0.3, 0.1], [-0.4, 0.2, 1.0]),
    ];
    const RAYS: usize = 400_000;
    for convex in [true, false] {
        let (scene, receiver, body) = blocked_scene(convex);
        let pf = compute(&scene, &pts, Level::Surface, false);
        for (k, p) in pts.iter().enumerate() {
            let f = factor(&pf, k, "receiver");
            let (mc, sigma) = cosine_rays(p, &receiver, &body, RAYS, 7 + k as u64);
            let clear =
                lambert::viewfactor::exact::lambert::point_to_polygon(p.position, p.normal, &receiver);
            assert!(
                clear - f > 0.02,
                "convex {convex}, point {k}: the body must cut the view ({f} of {clear})"
            );
            assert!(
                (f - mc).abs() <= 4.0 * sigma + 1e-12,
                "convex {convex}, point {k}: {f} vs rays {mc} ± {sigma} ({:.1} σ)",
                (f - mc).abs() / sigma
            );
        }
    }
}

#[test]
fn rigid_motion_leaves_the_factors_unchanged() {
    let (scene, receiver, body) = blocked_scene(false);
    let pts = [point([0.1, 0.05, 0.0], [0.1, -0.2, 1.0]), point([-0.4, 0.3, 0.2], [0.3, 0.1, 1.0])];
    let q = DQuat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 2.3);
    let shift = DVec3::new(12.5, -3.0, 7.25);
    let move_poly =
        |p: &Polygon| Polygon::new(p.vertices().iter().map(|&v| q * v + shift).collect()).unwrap();
    let moved = Scene::builder()
        .surface("receiver", vec![move_poly(&receiver)], 0.9, None)
        .obstruction("body", body.iter().map(move_poly).collect())
        .ambient(0.0)
        .build();
    let moved_pts: Vec<ViewPoint> =
        pts.iter().map(|p| point((q * p.position + shift).to_array(), (q * p.normal).to_array())).collect();
    let a = compute(&scene, &pts, Level::Surface, false);
    let b = compute(&moved, &moved_pts, Level::Surface, false);
    for k in 0..pts.len() {
        let (fa, fb) = (factor(&a, k, "receiver"), factor(&b, k, "receiver"));
        assert!(fa > 1e-3 && (fa - fb).abs() < 1e-14, "point {k}: {fa} vs {fb} moved");
    }
}

/// Points spread over the L-shaped room (2×2×1 minus a quadrant), with normals in every
/// direction, some on its walls.
fn l_room_points() -> Vec<ViewPoint> {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let mut pts = Vec::new();
    while pts.len() < 40 {
        let p = DVec3::new(rng.random::<f64>() * 2.0, rng.random::<f64>() * 2.0, rng.random::<f64>());
        if p.x > 1.0 && p.y > 1.0 {
            continue;
        }
        let n = DVec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        pts.push(point(p.to_array(), n.to_array()));
    }
    // Sensors on the floor and on a re-entrant wall, facing into the room.
    pts.push(point([1.5, 0.5, 0.0], [0.0, 0.0, 1.0]));
    pts.push(point([1.0, 1.5, 0.5], [-1.0, 0.0, 0.0]));
    pts
}

#[test]
fn every_point_in_a_room_with_re_entrant_walls_sums_to_one() {
    // The inner walls hide parts of the room from most points: only exact shadows close.
    let scene = l_room(2);
    let pts = l_room_points();
    let pf = compute(&scene, &pts, Level::Patch, false);
    let closure = pf.closure();
    assert!(closure.off.is_empty(), "{closure:?}");
    assert!(closure.worst < 1e-12, "worst |row sum - 1| {:.3e} at point {}", closure.worst, closure.at);
    let shadowed = pf.rows.iter().flatten().filter(|e| e.method == MethodSet::SHADOWED).count();
    assert!(shadowed > 20, "the inner walls cut {shadowed} entries");
    assert!(closure.worst < ROW_SUM_TOL);
}

#[test]
fn a_point_outside_a_closed_room_sees_nothing_and_is_named() {
    let scene = cube_interior(2);
    // Below the floor looking up at its back, and beside the room looking at a wall's back.
    let pts = [
        point([0.5, 0.5, -1.0], [0.0, 0.0, 1.0]),
        point([0.5, 0.5, 0.5], [0.0, 0.0, 1.0]),
        point([-0.5, 0.5, 0.5], [1.0, 0.0, 0.0]),
    ];
    let pf = compute(&scene, &pts, Level::Surface, false);
    assert!(pf.rows[0].is_empty() && pf.rows[2].is_empty(), "{:?}", pf.rows);
    let names: Vec<String> = ["under", "inside", "beside"].map(String::from).to_vec();
    let closure = pf.closure();
    assert_eq!(closure.off, vec![(0, 0.0), (2, 0.0)]);
    let warning = closure.warning(&names, false).expect("two points see nothing");
    assert!(
        warning.contains("2 point(s)") && warning.contains("under") && warning.contains("beside"),
        "{warning}"
    );
    assert!(!warning.contains("inside") && !warning.contains("obstruction"), "{warning}");
}

#[test]
fn the_numbers_do_not_depend_on_the_thread_count() {
    let scene = l_room(2);
    let pts = l_room_points();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut pf = pool.install(|| compute(&scene, &pts, Level::Surface, false));
        pf.wall = std::time::Duration::ZERO;
        pf
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn bad_points_are_refused_with_the_reason() {
    assert!(ViewPoint::new([0.0, f64::NAN, 0.0], [0.0, 0.0, 1.0]).unwrap_err().contains("y is NaN"));
    assert!(ViewPoint::new([0.0; 3], [0.0, f64::INFINITY, 1.0]).unwrap_err().contains("ny is inf"));
    assert!(ViewPoint::new([0.0; 3], [0.0; 3]).unwrap_err().contains("length 0"));
    assert!(ViewPoint::new([2e12, 0.0, 0.0], [0.0, 0.0, 1.0]).unwrap_err().contains("beyond"));
    let p = ViewPoint::new([0.0; 3], [0.0, 0.0, 5.0]).unwrap();
    assert_eq!(p.normal, DVec3::Z);
}
