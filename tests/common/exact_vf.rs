//! Hand-made view-factor matrices: exact box factors (from [`super::rect_exact`]) and
//! multinomial hit counts drawn from them.
use super::rect_exact as rect;

use lambert::scene::{BoundaryCondition, Scene};
use lambert::viewfactor::{Entry, Level, MethodSet, ViewFactors};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::time::Duration;

/// A ViewFactors from a dense exchange-area matrix (entries ≤ 0 are dropped).
pub fn vf_from_s(
    names: Vec<String>,
    areas: Vec<f64>,
    s: &[Vec<f64>],
    level: Level,
    method: MethodSet,
) -> ViewFactors {
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
    ViewFactors {
        level,
        names,
        areas,
        rows,
        patch_row_sums: sums,
        patch_samples: vec![0; n],
        pairs: 0,
        wall: Duration::ZERO,
        warnings: Vec::new(),
        flags: Vec::new(),
    }
}

/// The box of `rect::box_faces` as a scene (one surface per face, `split²` patches each),
/// with its exact patch-level exchange areas.
pub fn box_scene(d: [f64; 3], split: usize, props: &[(f64, BoundaryCondition); 6]) -> (Scene, Vec<Vec<f64>>) {
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

/// Multinomial hit counts from the exact rows: in a convex box every cosine ray from i lands
/// on j with probability F_ij (statistically identical to mc-cosine).
pub fn multinomial(scene: &Scene, s: &[Vec<f64>], rays: u32, seed: u64) -> ViewFactors {
    let areas = scene.patch_areas();
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut hits = vec![vec![0.0; s.len()]; s.len()];
    for i in 0..s.len() {
        let cdf: Vec<f64> = s[i]
            .iter()
            .scan(0.0, |c, v| {
                *c += v / areas[i];
                Some(*c)
            })
            .collect();
        for _ in 0..rays {
            let u: f64 = rng.random::<f64>() * cdf[cdf.len() - 1];
            let j = cdf.partition_point(|&c| c <= u).min(s.len() - 1);
            hits[i][j] += areas[i] / rays as f64;
        }
    }
    let mut vf = vf_from_s(
        (0..scene.patches.len()).map(|p| scene.patch_name(p)).collect(),
        areas,
        &hits,
        Level::Patch,
        MethodSet::MC_COSINE,
    );
    vf.patch_samples = vec![rays; s.len()];
    vf
}
