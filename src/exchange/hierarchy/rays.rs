//! Far patch pairs by visibility rays, without the row's blocker classification.
//!
//! A leaf pair (i, j) whose patches are small against their distance ([`RAY_PAIR_NEAR`]), each
//! wholly in front of the other's plane, is estimated as s = S·v̂: S the unobstructed exchange
//! (the second-order estimate of `refine::second_order` where its remainder bound is below
//! [`TAYLOR_SHARE`] of the goal, else the exact contour integral), v̂ the fraction of k sight
//! lines found clear, each drawn with density ∝ the kernel K(x, y) (uniform point pairs kept
//! with probability A_i A_j K / K̂, K̂ = `refine::kernel_max`). Then E[S v̂] is the visible
//! exchange exactly, a clear pair is S and a hidden one 0, and the variance S² v(1 − v)/k is
//! at most S²/(4k): that bound is the variance the pair reports, whatever its rays found,
//! and k is the fewest rays ([`RAY_PAIR_MIN`] at least) that bring it within the pair's goal
//! as a standard error on both F_ij and F_ji. A pair needing more than [`RAY_PAIR_MAX`], or
//! whose kernel is far below K̂ (grazing), is left to the kernel. On the 7,582-triangle
//! channel in its 10k room, 84 % of the patch pairs go this way (validation/cad.md).
use super::refine;
use super::tree::Tree;
use crate::scene::Scene;
use crate::viewfactor::exact::pair::polygon_polygon;
use crate::visibility::Visibility;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::f64::consts::PI;

/// Fewest rays of a pair. Each pair reports its variance bound S²/(4k) whatever it found, so
/// fewer rays only widen a patch's estimate: on the channel's 10k room, 2 rays instead of 4
/// took the pair phase from 94 s to 74 s with every patch still within its own estimate
/// (1 ray: 6 % faster again, estimates √2 wider).
pub const RAY_PAIR_MIN: usize = 2;
/// Most rays of a pair (a ray costs about 0.9 µs, a pair classified behind blockers 7–18 µs).
pub const RAY_PAIR_MAX: usize = 16;
/// Radius sum against distance below which a pair may go by rays (K̂ is then within a few
/// times the kernel's mean over the pair, so the draws keep a pair often).
pub const RAY_PAIR_NEAR: f64 = 0.2;
/// The second-order estimate stands for S when its remainder bound is below this share of
/// the pair's goal (an error of the second order 10⁻³ of the standard error allowed).
pub const TAYLOR_SHARE: f64 = 1e-3;
/// Least mean acceptance S/K̂ of the draws, as its inverse.
const MIN_ACCEPT: f64 = 8.0;
/// Uniform point pairs drawn for one kept by the kernel before the pair is left to the kernel
/// (each kept with probability at least 1/[`MIN_ACCEPT`] on average).
const REJECT_TRIES: usize = 64;

/// The exchange s_ij and its variance (m², m⁴) of leaf pair (i, j) by rays with the goal
/// `goal` on each F as a standard error, or None when the pair is left to the kernel.
pub fn estimate(
    scene: &Scene,
    tree: &Tree,
    vis: &Visibility,
    (i, j): (u32, u32),
    goal: f64,
    seed: u64,
) -> Option<(f64, f64)> {
    let (na, nb) =
        (&tree.nodes[tree.leaf_of[i as usize] as usize], &tree.nodes[tree.leaf_of[j as usize] as usize]);
    let dist = na.centroid.distance(nb.centroid);
    let rho = na.radius + nb.radius;
    if !(rho < RAY_PAIR_NEAR * dist) {
        return None;
    }
    let (pi, pj) = (&scene.patches[i as usize].polygon, &scene.patches[j as usize].polygon);
    // The draws fan out from the first vertex: convex patches only.
    let convex = |p: &crate::geometry::polygon::Polygon| p.vertices().len() == 3 || p.is_convex();
    if !(convex(pi) && convex(pj)) {
        return None;
    }
    let (ni, nj) = (pi.normal(), pj.normal());
    let (ci, cj) = (pi.vertices()[0], pj.vertices()[0]);
    // Every vertex strictly in front of the other's plane: the kernel is positive on the pair.
    let front = |vs: &[DVec3], n: DVec3, c: DVec3| vs.iter().all(|v| n.dot(*v - c) > 1e-9 * dist);
    if !(front(pj.vertices(), ni, ci) && front(pi.vertices(), nj, cj)) {
        return None;
    }
    let room = goal * na.area.min(nb.area);
    let kmax = refine::kernel_max(na, nb, rho);
    if !(room > 0.0 && kmax.is_finite()) {
        return None;
    }
    let floor = refine::SECOND_ORDER_FLOOR * (rho / dist).powi(4) * kmax;
    let unob =
        if floor <= TAYLOR_SHARE * room { refine::second_order(na, nb) } else { polygon_polygon(pi, pj) };
    if !(unob * MIN_ACCEPT >= kmax) {
        return None;
    }
    let k = ((0.5 * unob / room).powi(2).ceil() as usize).max(RAY_PAIR_MIN);
    if k > RAY_PAIR_MAX {
        return None;
    }
    let aa = na.area * nb.area;
    let mut rng = Pcg64Mcg::seed_from_u64(
        seed ^ (u64::from(i) << 32 | u64::from(j)).wrapping_mul(0xD1B5_4A32_D192_ED03),
    );
    let mut clear = 0usize;
    for _ in 0..k {
        let mut drawn = None;
        for _ in 0..REJECT_TRIES {
            let x = refine::fan_point(pi.vertices(), &mut rng);
            let y = refine::fan_point(pj.vertices(), &mut rng);
            let r = y - x;
            let rr = r.length_squared();
            let kernel = aa * ni.dot(r) * -nj.dot(r) / (PI * rr * rr);
            if rng.random::<f64>() * kmax <= kernel {
                drawn = Some((x, y));
                break;
            }
        }
        let (x, y) = drawn?;
        if !vis.occluded(x, y, i as usize, j as usize) {
            clear += 1;
        }
    }
    Some((unob * clear as f64 / k as f64, unob * unob / (4.0 * k as f64)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::toml_scene::from_str;
    use crate::viewfactor::closed_form::parallel_rectangles_exchange;

    /// Two parallel 0.1 m squares 2 m apart (a floor patch under a ceiling patch), and a
    /// plate `plate` (x range) at mid-height when given.
    fn pair_scene(plate: Option<[f64; 2]>) -> Scene {
        let mut text = String::from(
            "[[surface]]\nname = \"floor\"\nrectangle = { origin = [0.0, 0.0, 0.0], u = [0.1, 0.0, 0.0], v = [0.0, 0.1, 0.0] }\n\
             emissivity = 0.5\ntemperature = 300.0\n\n\
             [[surface]]\nname = \"ceiling\"\nrectangle = { origin = [0.0, 0.0, 2.0], u = [0.0, 0.1, 0.0], v = [0.1, 0.0, 0.0] }\n\
             emissivity = 0.5\ntemperature = 300.0\n\n",
        );
        if let Some([lo, hi]) = plate {
            text += &format!(
                "[[surface]]\nname = \"plate\"\nrectangle = {{ origin = [{lo}, -1.0, 1.0], u = [{}, 0.0, 0.0], v = [0.0, 2.0, 0.0] }}\n\
                 role = \"obstruction\"\n",
                hi - lo
            );
        }
        from_str(std::path::Path::new("pair.toml"), &text).unwrap()
    }

    #[test]
    fn a_clear_far_pair_is_its_unobstructed_exchange_and_a_hidden_one_zero() {
        let exact = parallel_rectangles_exchange([0.0, 0.1], [0.0, 0.1], [0.0, 0.1], [0.0, 0.1], 2.0);
        for (plate, want) in [(None, exact), (Some([-1.0, 1.0]), 0.0)] {
            let scene = pair_scene(plate);
            let (tree, vis) = (Tree::new(&scene), Visibility::new(&scene));
            let (s, var) = estimate(&scene, &tree, &vis, (0, 1), 1e-3, 7).expect("a far pair goes by rays");
            // Within the second-order estimate's share of the goal (A 0.01 m², goal 1e-3).
            assert!((s - want).abs() <= TAYLOR_SHARE * 1e-3 * 0.01, "{plate:?}: {s:e} against {want:e}");
            // The variance is the bound S²/(4k), within the goal on both F.
            assert!(var > 0.0 && var.sqrt() <= 1e-3 * 0.01, "{var:e}");
        }
    }

    #[test]
    fn a_half_hidden_pair_is_within_a_few_standard_errors_of_its_visible_exchange() {
        // A plate over x < 0.05 at mid-height hides from each floor point the half of the
        // ceiling's sight lines that cross it: by symmetry (the plate's edge at the squares'
        // mid-line, halfway up) the visible exchange is half the unobstructed one.
        let exact = parallel_rectangles_exchange([0.0, 0.1], [0.0, 0.1], [0.0, 0.1], [0.0, 0.1], 2.0);
        let scene = pair_scene(Some([-1.0, 0.05]));
        let (tree, vis) = (Tree::new(&scene), Visibility::new(&scene));
        let (mut sum, mut var_sum, n) = (0.0, 0.0, 200);
        for seed in 0..n {
            // A tight goal asks for the most rays; a loose one for the fewest.
            let goal = if seed % 2 == 0 { 1e-3 } else { 1e-2 };
            let (s, var) = estimate(&scene, &tree, &vis, (0, 1), goal, seed).expect("by rays");
            assert!(s >= 0.0 && s <= exact * (1.0 + 1e-12));
            sum += s;
            var_sum += var;
        }
        let (mean, sd) = (sum / n as f64, var_sum.sqrt() / n as f64);
        assert!((mean - 0.5 * exact).abs() <= 4.0 * sd, "{mean:e} against {:e} ± {sd:e}", 0.5 * exact);
        // The same seed gives the same estimate.
        assert_eq!(
            estimate(&scene, &tree, &vis, (0, 1), 1e-3, 3),
            estimate(&scene, &tree, &vis, (0, 1), 1e-3, 3)
        );
    }

    #[test]
    fn near_and_grazing_pairs_are_left_to_the_kernel() {
        // The ceiling 0.3 m over the floor: radius sum 0.14 against 0.3 m.
        let text = "[[surface]]\nname = \"a\"\nrectangle = { origin = [0.0, 0.0, 0.0], u = [0.1, 0.0, 0.0], v = [0.0, 0.1, 0.0] }\n\
                    emissivity = 0.5\ntemperature = 300.0\n\n\
                    [[surface]]\nname = \"b\"\nrectangle = { origin = [0.0, 0.0, 0.3], u = [0.0, 0.1, 0.0], v = [0.1, 0.0, 0.0] }\n\
                    emissivity = 0.5\ntemperature = 300.0\n\n\
                    [[surface]]\nname = \"c\"\nrectangle = { origin = [3.0, 0.0, 0.0001], u = [0.0, 0.0, 0.01], v = [0.0, 0.1, 0.0] }\n\
                    emissivity = 0.5\ntemperature = 300.0\n";
        let scene = from_str(std::path::Path::new("near.toml"), text).unwrap();
        let (tree, vis) = (Tree::new(&scene), Visibility::new(&scene));
        assert_eq!(estimate(&scene, &tree, &vis, (0, 1), 1e-3, 1), None);
        // c, a 10 mm strip 3 m away just above the floor's plane, faces it edge-on (grazing):
        // its kernel is far below K̂.
        assert_eq!(estimate(&scene, &tree, &vis, (0, 2), 1e-3, 1), None);
        // An L-shaped (non-convex) patch far from the floor square is left to the kernel too.
        let text = "[[surface]]\nname = \"a\"\nrectangle = { origin = [0.0, 0.0, 0.0], u = [0.1, 0.0, 0.0], v = [0.0, 0.1, 0.0] }\n\
                    emissivity = 0.5\ntemperature = 300.0\n\n\
                    [[surface]]\nname = \"l\"\npolygon = [[0.0, 0.0, 2.0], [0.0, 0.1, 2.0], [0.1, 0.1, 2.0], [0.1, 0.05, 2.0], [0.05, 0.05, 2.0], [0.05, 0.0, 2.0]]\n\
                    emissivity = 0.5\ntemperature = 300.0\n";
        let scene = from_str(std::path::Path::new("l.toml"), text).unwrap();
        let (tree, vis) = (Tree::new(&scene), Visibility::new(&scene));
        assert!(!scene.patches[1].polygon.is_convex());
        assert_eq!(estimate(&scene, &tree, &vis, (0, 1), 1e-3, 1), None);
    }
}
