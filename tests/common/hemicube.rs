//! Closed forms, scenes and helpers for tests/viewfactor/hemicube.rs (the hemicube and single-plane
//! kernels).
use glam::DVec3;
use lambert::geometry::quadrature::AreaRule;
use lambert::geometry::Polygon;
use lambert::scene::Scene;
use lambert::viewfactor::engine::{Row, RowKernel};
use lambert::viewfactor::hemicube::{HemicubeKernel, Positions};
use lambert::viewfactor::single_plane::{SinglePlaneKernel, SinglePlaneOptions};
use std::f64::consts::PI;

// Closed forms: the shared catalogue (docs/literature.md §1.1) and Lambert's point factor (V12).
pub use lambert::viewfactor::closed_form::{
    parallel_opposed_rectangles as c11, perpendicular_common_edge as c14,
};
pub use lambert::viewfactor::exact::lambert::point_to_polygon;

// ---------------------------------------------------------------------------------------
// Scenes.

pub fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// The parallelogram o, o+u, o+u+v, o+v (normal u × v).
pub fn rect(o: DVec3, u: DVec3, w: DVec3) -> Polygon {
    Polygon::new(vec![o, o + u, o + u + w, o + w]).unwrap()
}

/// `rect` split into n×n patches.
pub fn grid(o: DVec3, u: DVec3, w: DVec3, n: usize) -> Vec<Polygon> {
    let (du, dw) = (u / n as f64, w / n as f64);
    (0..n).flat_map(|i| (0..n).map(move |j| rect(o + i as f64 * du + j as f64 * dw, du, dw))).collect()
}

/// Inward-facing unit cube, faces n×n: floor, ceiling, x0, x1, y0, y1.
pub fn cube(n: usize) -> Scene {
    let (o, x, y, z) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
    Scene::builder()
        .surface("floor", grid(o, x, y, n), 1.0, None)
        .surface("ceiling", grid(z, y, x, n), 1.0, None)
        .surface("x0", grid(o, y, z, n), 1.0, None)
        .surface("x1", grid(x, z, y, n), 1.0, None)
        .surface("y0", grid(o, z, x, n), 1.0, None)
        .surface("y1", grid(y, x, z, n), 1.0, None)
        .build()
}

/// Unit floor square facing up, unit ceiling square at `gap` facing down; open.
pub fn parallel(gap: f64) -> Scene {
    Scene::builder()
        .surface("floor", vec![rect(DVec3::ZERO, DVec3::X, DVec3::Y)], 1.0, None)
        .surface("ceiling", vec![rect(v(0.0, 0.0, gap), DVec3::Y, DVec3::X)], 1.0, None)
        .ambient(300.0)
        .build()
}

/// Unit floor and unit wall x = 1 facing −x, sharing the edge x = 1, z = 0; open.
pub fn perpendicular() -> Scene {
    Scene::builder()
        .surface("floor", vec![rect(DVec3::ZERO, DVec3::X, DVec3::Y)], 1.0, None)
        .surface("wall", vec![rect(DVec3::X, DVec3::Z, DVec3::Y)], 1.0, None)
        .ambient(300.0)
        .build()
}

/// The 0.5×0.5 blocker centred midway between the parallel squares at gap 1.
pub fn blocker() -> Polygon {
    rect(v(0.25, 0.25, 0.5), DVec3::X * 0.5, DVec3::Y * 0.5)
}

/// Obstructed parallel squares: F = 0.0995062946 (task brief).
pub const F_BLOCKED: f64 = 0.0995062946;

// ---------------------------------------------------------------------------------------
// Helpers.

/// Row `i` of a kernel as F_ij (dense, for small test scenes).
pub fn row_factors(kernel: &dyn RowKernel, scene: &Scene, i: usize) -> Vec<f64> {
    let mut row = Row::default();
    kernel.row(i, &mut row).unwrap();
    let area = scene.patches[i].polygon.area();
    let mut f = vec![0.0; scene.patches.len()];
    for e in &row.entries {
        f[e.j as usize] += e.s / area;
    }
    f
}

pub fn hemicube(scene: &Scene, r: usize, positions: Positions) -> HemicubeKernel<'_> {
    HemicubeKernel::new(scene, r, positions).unwrap()
}

pub fn single_plane(scene: &Scene, r: usize, positions: Positions) -> SinglePlaneKernel<'_> {
    SinglePlaneKernel::new(scene, r, SinglePlaneOptions { positions, ..Default::default() }).unwrap()
}

/// Patch `i`'s projection positions for Gauss order q, as the kernels place them.
pub fn positions_rule(poly: &Polygon, q: usize) -> AreaRule {
    if q == 1 {
        return AreaRule { points: vec![poly.centroid()], weights: vec![poly.area()] };
    }
    let vs = poly.vertices();
    AreaRule::parallelogram(vs[0], vs[1] - vs[0], vs[3] - vs[0], q)
}

/// Σ_k w_k F(x_k → target)/A: the exact value a projection method approximates at q×q points,
/// with `visible(x)` giving the unshadowed part of the target seen from x.
pub fn position_average(poly: &Polygon, q: usize, visible: impl Fn(DVec3) -> f64) -> f64 {
    let rule = positions_rule(poly, q);
    rule.points.iter().zip(&rule.weights).map(|(x, w)| w * visible(*x)).sum::<f64>() / poly.area()
}

/// Observed order of convergence between the first and last of `errors` at resolutions `rs`.
pub fn observed_order(rs: &[usize], errors: &[f64]) -> f64 {
    let n = rs.len() - 1;
    (errors[0] / errors[n]).ln() / (rs[n] as f64 / rs[0] as f64).ln()
}

// ---------------------------------------------------------------------------------------
// Error models (docs/literature.md §4) and exact references at the projection positions.

/// Unit-cube floor centre to the opposite face (projection inside the top face): 7.4e-4 at
/// R = 32, falling as h² (docs/literature.md §4).
pub const INTERIOR_ERR_32: f64 = 7.4e-4;
/// Same point to an adjacent face (projection edge on the hemicube horizon): 1.3e-2 at R = 32,
/// falling as h; the worst edge case, so it bounds the pixel error of unit receivers.
pub const BOUNDARY_ERR_32: f64 = 1.3e-2;
/// The single plane's equal-angle pixels subtend up to 2·atan(100)/R ≈ 3.1/R rad at the
/// zenith against the hemicube's 2/R: its pixel errors are up to this factor larger.
pub const SINGLE_PLANE_PIXEL_FACTOR: f64 = 1.6;
/// Proximity budget of the 3×3 / adaptive position rules: 1 % relative (positions.rs).
pub const PROXIMITY_REL: f64 = 0.01;

/// O(h²) pixel error bound at resolution r.
pub fn interior_tol(r: usize) -> f64 {
    INTERIOR_ERR_32 * (32.0 / r as f64).powi(2)
}

/// O(h) pixel error bound at resolution r.
pub fn boundary_tol(r: usize) -> f64 {
    BOUNDARY_ERR_32 * 32.0 / r as f64
}

/// Exact F(x → ceiling) of the parallel squares at gap 1 with the centred blocker: the ceiling
/// minus the blocker's shadow (its central projection from x, clipped to the ceiling).
pub fn visible_past_blocker(x: DVec3, ceiling: &Polygon) -> f64 {
    let lo = |c: f64| (0.5 - c).max(0.0);
    let hi = |c: f64| (1.5 - c).min(1.0);
    // Spanned y then x so that it faces the floor (Lambert's factor is one-sided).
    let shadow =
        rect(v(lo(x.x), lo(x.y), 1.0), DVec3::Y * (hi(x.y) - lo(x.y)), DVec3::X * (hi(x.x) - lo(x.x)));
    point_to_polygon(x, DVec3::Z, ceiling) - point_to_polygon(x, DVec3::Z, &shadow)
}

/// The item-buffer model of a square target [−a, a]² on the top face: midpoint delta factors
/// h²/[π(x² + y² + 1)²] of the pixels whose centre lies in it (half-open), at resolution r,
/// divided by the raw total of all five faces as the hemicube normalises them.
pub fn top_face_pixel_model(r: usize, a: f64) -> f64 {
    top_face_midpoint_sum(r, a) / midpoint_total(r)
}

/// Σ of the raw midpoint delta factors of all five faces (the hemicube's normalisation).
fn midpoint_total(r: usize) -> f64 {
    let h = 2.0 / r as f64;
    let c = |k: usize| -1.0 + (k as f64 + 0.5) * h;
    let mut sum = top_face_midpoint_sum(r, 2.0);
    for row in 0..r / 2 {
        let z = (row as f64 + 0.5) * h;
        for col in 0..r {
            let d = c(col) * c(col) + z * z + 1.0;
            sum += 4.0 * z * h * h / (PI * d * d);
        }
    }
    sum
}

/// Σ of the raw midpoint delta factors of the top-face pixels whose centres lie in (−a, a)².
fn top_face_midpoint_sum(r: usize, a: f64) -> f64 {
    let h = 2.0 / r as f64;
    let centres: Vec<f64> =
        (0..r).map(|k| -1.0 + (k as f64 + 0.5) * h).filter(|c| (-a..a).contains(c)).collect();
    let mut sum = 0.0;
    for &y in &centres {
        for &x in &centres {
            let d = x * x + y * y + 1.0;
            sum += h * h / (PI * d * d);
        }
    }
    sum
}
