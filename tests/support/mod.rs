//! Shared test helpers: exact box factors and hand-made view-factor matrices.
#![allow(dead_code)]
pub mod rect;

use lambert::scene::{BoundaryCondition, Scene};
use lambert::viewfactor::{Entry, Level, MethodSet, ViewFactors};
use std::time::Duration;

/// A ViewFactors from a dense exchange-area matrix (entries ≤ 0 are dropped).
pub fn vf_from_s(names: Vec<String>, areas: Vec<f64>, s: &[Vec<f64>], level: Level, method: MethodSet) -> ViewFactors {
    let rows: Vec<Vec<Entry>> = s
        .iter()
        .enumerate()
        .map(|(i, r)| {
            r.iter()
                .enumerate()
                .filter(|(_, &v)| v > 0.0)
                .map(|(j, &v)| Entry { to: j as u32, factor: v / areas[i], std_error: 0.0, method })
                .collect()
        })
        .collect();
    let sums = rows.iter().map(|r: &Vec<Entry>| r.iter().map(|e| e.factor).sum()).collect();
    let n = names.len();
    ViewFactors { level, names, areas, rows, patch_row_sums: sums, patch_samples: vec![0; n], pairs: 0, wall: Duration::ZERO }
}

/// The box of `rect::box_faces` as a scene (one surface per face, `split²` patches each),
/// with its exact patch-level exchange areas.
pub fn box_scene(
    d: [f64; 3],
    split: usize,
    props: &[(f64, BoundaryCondition); 6],
) -> (Scene, Vec<Vec<f64>>) {
    let faces = rect::box_faces(d, split);
    let mut b = Scene::builder();
    let mut rects = Vec::new();
    for (k, (name, rs)) in faces.iter().enumerate() {
        b = b.surface(name, rs.iter().map(|r| r.polygon()).collect(), props[k].0, Some(props[k].1));
        rects.extend(rs.iter().copied());
    }
    let s = rects.iter().map(|a| rects.iter().map(|c| rect::exchange_area(a, c)).collect()).collect();
    (b.build(), s)
}

/// Exact patch-level view factors of a scene built by [`box_scene`].
pub fn patch_vf(scene: &Scene, s: &[Vec<f64>]) -> ViewFactors {
    let names = (0..scene.patches.len()).map(|p| scene.patch_name(p)).collect();
    vf_from_s(names, scene.patch_areas(), s, Level::Patch, MethodSet::ANALYTIC)
}
