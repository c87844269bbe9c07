//! Translated-pair tables: the values the analytic kernel looks up equal the values it
//! evaluates directly, to round-off (or to the ladder's error where a rung threshold splits
//! congruent pairs), on gridded boxes (any grid sizes, mirrored and swapped
//! grid steps, rotated and shifted), on a scene file with blockers, and the tables do serve
//! the pairs they should.
use crate::common;

use common::analytic_scenes as scenes;

use glam::{DQuat, DVec3};
use lambert::scene::Scene;
use lambert::viewfactor::analytic::kernel::{AnalyticKernel, GAUSS_REL_TOL};
use lambert::viewfactor::engine::{Row, RowKernel};
use lambert::viewfactor::exact::pair::polygon_polygon_with_round_off;
use lambert::viewfactor::shadow::policy::{Policy, EXACT_REL_TOL};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Relative difference between a looked-up and a directly evaluated exchange area when both
/// come from the same rung: the representative pair differs from the pair by coordinate
/// round-off only.
const ROUND_OFF: f64 = 1e-12;
/// Share of pairs allowed to differ by more than [`ROUND_OFF`]: congruent pairs sitting on a
/// rung threshold may be taken by different rungs (Gauss against exact), which then differ
/// within the ladder's own per-pair error, [`GAUSS_REL_TOL`].
const RUNG_FLIP_SHARE: f64 = 0.01;

/// Row `i` of `kernel` as column → A_i F_ij.
fn row(kernel: &AnalyticKernel, i: usize) -> BTreeMap<u32, f64> {
    let mut row = Row::default();
    kernel.row(i, &mut row).expect("row");
    row.entries.iter().map(|e| (e.j, e.s)).collect()
}

/// Compares rows `rows` of the tabled and the direct kernel: every pair within the ladder's
/// error of the direct value (and, for unobstructed scenes, of the exact contour integral),
/// nearly all within round-off. Returns the pairs the tables serve.
fn compare(scene: &Scene, rows: &[usize], what: &str, unobstructed: bool) -> u64 {
    let policy = Policy::Exact { rel_tol: EXACT_REL_TOL };
    let tabled = AnalyticKernel::with_policy(scene, GAUSS_REL_TOL, policy);
    let direct = AnalyticKernel::direct(scene, GAUSS_REL_TOL, policy);
    let (pairs, flips, worst) = rows
        .par_iter()
        .map(|&i| {
            let (a, b) = (row(&tabled, i), row(&direct, i));
            let p = &scene.patches[i].polygon;
            let floor = 1e-15 * p.area();
            let (mut flips, mut worst) = (0u64, 0.0f64);
            for j in a.keys().chain(b.keys().filter(|j| !a.contains_key(j))) {
                let (x, y) = (a.get(j).copied().unwrap_or(0.0), b.get(j).copied().unwrap_or(0.0));
                let diff = (x - y).abs();
                assert!(
                    diff <= 2.0 * GAUSS_REL_TOL * y.abs() + floor,
                    "{what}: pair ({i}, {j}) tabled {x:e}, direct {y:e}"
                );
                if unobstructed {
                    let e = polygon_polygon_with_round_off(p, &scene.patches[*j as usize].polygon);
                    assert!(
                        (x - e.value).abs() <= GAUSS_REL_TOL * e.value + e.round_off + floor,
                        "{what}: pair ({i}, {j}) tabled {x:e}, exact {e:?}"
                    );
                }
                flips += (diff > ROUND_OFF * y.abs() + floor) as u64;
                if y.abs() > floor {
                    worst = worst.max(diff / y.abs());
                }
            }
            ((a.len() + b.len()) as u64 / 2, flips, worst)
        })
        .reduce(|| (0, 0, 0.0), |p, q| (p.0 + q.0, p.1 + q.1, p.2.max(q.2)));
    eprintln!("{what}: {pairs} pairs, {flips} beyond round-off, worst relative difference {worst:.1e}");
    assert!(
        flips as f64 <= RUNG_FLIP_SHARE * pairs as f64,
        "{what}: {flips} of {pairs} pairs beyond round-off"
    );
    tabled.reuse().stats().1
}

fn all_rows(scene: &Scene) -> Vec<usize> {
    (0..scene.patches.len()).collect()
}

#[test]
fn the_cube_tables_serve_every_cross_face_pair_with_one_evaluation_per_offset() {
    let n = 6;
    let scene = scenes::cube(n);
    let kernel = AnalyticKernel::new(&scene, GAUSS_REL_TOL);
    let (unique, served) = kernel.reuse().stats();
    // 12 adjacent face pairs: offsets (2n − 1)·n·n; 3 opposite pairs: (2n − 1)²; same face: coplanar.
    assert_eq!(unique, 12 * (2 * n - 1) * n * n + 3 * (2 * n - 1) * (2 * n - 1));
    assert_eq!(served, 15 * (n * n * n * n) as u64);
    assert_eq!(compare(&scene, &all_rows(&scene), "cube 6", true), served);
}

#[test]
fn box_rooms_with_unequal_mirrored_and_swapped_grids_match_direct_evaluation() {
    // Faces 6×4, 4×6 (steps swapped), 4×3, 3×4, 3×6, 6×3; box_faces mixes the step signs.
    let scene = scenes::box_room(3.0, 2.0, 1.5, 0.5);
    assert!(compare(&scene, &all_rows(&scene), "box 3×2×1.5", true) > 0);
    // Mirrored steps: the same box with every face's grid running the other way.
    let mut s = Scene::builder();
    for (name, o, u, v) in scenes::box_faces(2.0, 1.0, 1.5) {
        s = s.surface(name, scenes::grid(o + u + v, -u, -v, 8, 5), 0.9, None);
    }
    let mirrored = s.build();
    assert!(compare(&mirrored, &all_rows(&mirrored), "mirrored box", true) > 0);
}

#[test]
fn a_rotated_shifted_box_matches_direct_evaluation() {
    let q = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.7);
    let shift = DVec3::new(12.0, -7.0, 3.5);
    let mut s = Scene::builder();
    for (name, o, u, v) in scenes::box_faces(1.0, 2.0, 0.75) {
        s = s.surface(name, scenes::grid(q * o + shift, q * u, q * v, 7, 9), 0.9, None);
    }
    let scene = s.build();
    assert!(compare(&scene, &all_rows(&scene), "rotated box", true) > 0);
}

#[test]
fn a_scene_file_with_a_blocker_matches_direct_evaluation() {
    // Room 12×12 per face around a block 6×6 per face: clear and partly blocked pairs both
    // take their unobstructed value from the tables.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/o3_obstructed_room/scene.toml");
    let scene = lambert::scene::load(&path).expect("shipped case");
    let rows: Vec<usize> = (0..scene.patches.len()).step_by(23).collect();
    assert!(compare(&scene, &rows, "o3 room", false) > 0);
}
