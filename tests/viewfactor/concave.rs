//! `analytic` behind and inside concave closed meshes (an L-bracket, a U-channel, a finned
//! heat sink): entry by entry against a brute Monte Carlo with exact per-ray visibility,
//! reciprocity, and closure in a room.
use crate::common;

use common::concave_meshes::{brute_vf, extruded, FIN_PROFILE, L_PROFILE, U_PROFILE};
use common::cube_faces;
use lambert::geometry::{DVec3, Polygon};
use lambert::scene::Scene;
use lambert::viewfactor::analytic::kernel::GAUSS_REL_TOL;
use lambert::viewfactor::{self, Level, Method, MethodSet, Params, ViewFactors};

/// Point pairs of the brute reference: a standard error near 1e-4 of F.
const BRUTE_PAIRS: usize = 2_000_000;
/// Standard errors allowed between `analytic` (exact to 1e-9) and the brute reference.
const SIGMAS: f64 = 4.0;

fn run(scene: &Scene, level: Level) -> ViewFactors {
    let params = Params { method: Method::Analytic, ..Params::default() };
    viewfactor::compute(scene, &params, level).expect("computes")
}

fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Polygon {
    Polygon::new(vec![DVec3::from(a), DVec3::from(b), DVec3::from(c)]).expect("valid triangle")
}

/// The profile (scale 0.6) standing in the x–z plane over y ∈ [0.2, 0.8], bottom at z = 0.45
/// (an orientation-keeping placement: (u, v, w) → (x, −y, z) axes u, w, v).
fn standing(profile: &[[f64; 2]]) -> Vec<Polygon> {
    extruded(profile, |u, v, w| DVec3::new(0.2 + 0.6 * u, 0.8 - 0.6 * w, 0.45 + 0.6 * v))
}

#[test]
fn concave_blockers_between_two_triangles_match_brute_visibility() {
    let bottom = tri([-0.2, -0.2, 0.0], [1.4, -0.2, 0.0], [-0.2, 1.4, 0.0]);
    let top = tri([1.2, 1.2, 1.5], [1.2, -0.2, 1.5], [-0.2, 1.2, 1.5]);
    let clear = Scene::builder()
        .surface("bottom", vec![bottom.clone()], 1.0, None)
        .surface("top", vec![top.clone()], 1.0, None)
        .ambient(0.0)
        .build();
    let f_clear = run(&clear, Level::Surface).get(0, 1);
    for (name, profile) in [("L-bracket", L_PROFILE), ("U-channel", U_PROFILE), ("heat sink", FIN_PROFILE)] {
        let body = standing(profile);
        let scene = Scene::builder()
            .surface("bottom", vec![bottom.clone()], 1.0, None)
            .surface("top", vec![top.clone()], 1.0, None)
            .obstruction("body", body.clone())
            .ambient(0.0)
            .build();
        let vf = run(&scene, Level::Surface);
        let (f, f_back) = (vf.get(0, 1), vf.get(1, 0));
        let (brute, se) = brute_vf(&bottom, &top, &body, BRUTE_PAIRS, 18);
        assert!(
            (f - brute).abs() < SIGMAS * se,
            "{name}: analytic F = {f}, brute {brute} ± {se} (unobstructed {f_clear})"
        );
        assert!(f < f_clear - 0.1 * f_clear, "{name}: the body casts a shadow ({f} vs {f_clear})");
        let (a, b) = (bottom.area() * f, top.area() * f_back);
        assert!((a - b).abs() < 1e-9 * a, "{name}: reciprocity A·F {a} vs {b}");
    }
}

#[test]
fn concave_parts_in_a_room_stay_closed_and_see_themselves_exactly() {
    for (name, profile) in [("U-channel", U_PROFILE), ("heat sink", FIN_PROFILE)] {
        let body = extruded(profile, |u, v, w| DVec3::new(1.0 + u, 2.0 - w, 1.0 + v));
        let mut b = Scene::builder();
        for (k, f) in cube_faces(DVec3::new(1.5, 1.5, 1.5), 3.0, true, 1).into_iter().enumerate() {
            b = b.surface(&format!("wall{k}"), f, 1.0, None);
        }
        let scene = b.surface("part", body.clone(), 1.0, None).build();
        let vf = run(&scene, Level::Patch);
        let (worst, at) = vf.max_patch_row_error();
        assert!(worst < GAUSS_REL_TOL, "{name}: row sum off by {worst} at {}", scene.patch_name(at));
        let areas = scene.patch_areas();
        let n = areas.len();
        for i in 0..n {
            for j in 0..n {
                let (a, b) = (areas[i] * vf.get(i, j), areas[j] * vf.get(j, i));
                assert!((a - b).abs() <= 1e-9 * a.max(b) + 1e-15, "{name}: reciprocity {i}→{j}: {a} vs {b}");
            }
        }
        // Self-exchange past the part's own faces: the channel floor to its right inner wall;
        // for the heat sink the left bay's floor to the right fin's left face, partly hidden
        // by the short middle fin.
        let (floor, wall) = if profile == U_PROFILE { (10, 8) } else { (16, 6) };
        let first = 6; // the room's six walls come first
        let (i, j) = (first + floor, first + wall);
        let f = vf.get(i, j);
        assert!(f > 0.0, "{name}: floor sees the wall");
        if profile == FIN_PROFILE {
            let row = &vf.rows[i];
            let e = row.iter().find(|e| e.to as usize == j).expect("entry");
            assert_eq!(e.method, MethodSet::SHADOWED, "{name}: the middle fin hides part of the wall");
        }
        let (brute, se) = brute_vf(&body[floor], &body[wall], &body, BRUTE_PAIRS, 19);
        assert!((f - brute).abs() < SIGMAS * se, "{name}: analytic F = {f}, brute {brute} ± {se}");
    }
}
