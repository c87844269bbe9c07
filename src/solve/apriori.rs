//! What the boundary conditions and the geometry bound before any view factor is known: the
//! refinement budget of the hierarchical solve reads these.
//!
//! - **View caps.** Every surface lies in a bounding sphere (centre c, radius R). From a point
//!   at distance d > R from c, the cosine-weighted fraction of the hemisphere the sphere can
//!   fill is at most sin²α = (R/d)², so F(patch → surface) ≤ (R/d)² with d the smallest
//!   distance from c to the patch (its centroid distance less its radius), and 1 within R.
//!   Surfaces are also grouped bottom-up by their joint boxes, and every group's sphere caps
//!   the sum over its surfaces (a cube of six faces is capped as one body).
//! - **Radiosity bounds.** J_i = ε_i E_b,i + ρ_i H_i with the irradiation H_i = Σ_s F_is J̄_s.
//!   Given bounds on every surface's radiosity, H_i is at most the largest Σ_s F_is J_s,hi over
//!   the F_is within their caps that sum to 1 (the highest sources filled first), and at least
//!   the smallest (the lowest first); the ambient of an open scene is a source of cap 1. Starting
//!   from the range of the scene's emissive powers and iterating keeps every bound valid and
//!   shrinks it: a room wall that sees a small hot part only within its cap is bounded near its
//!   own emission, not by the part's.
//! - **Surface weights.** A bound on Σ_t S_st ΔJ_st over the surfaces t that surface s exchanges
//!   with (S_st ≤ Σ_{i∈s} A_i cap(i, t), Σ_t S_st ≤ A_s, ΔJ_st the radiosity range of s ∪ t):
//!   the largest heat rate the exchange areas of s can carry across radiosity differences
//!   (the group caps hold here too). A
//!   link's share of the heat-rate budget weighed by its S·ΔJ against this weight keeps every
//!   surface's summed link errors within the budget ([`crate::exchange::hierarchy::Budget`]).
//!
//! Scenes with more than [`MAX_SURFACES`] surfaces keep the emissive-power range and no weights
//! (the caps cost O(patches × surfaces)).
use crate::scene::{BoundaryCondition, Scene};
use crate::SIGMA;
use glam::DVec3;
use rayon::prelude::*;

/// Surfaces above which the caps are not computed (O(patches × surfaces) work and memory).
pub const MAX_SURFACES: usize = 256;
/// Rounds of the radiosity-bound iteration: each can only narrow the bounds; the walls of a
/// room around a small hot part settle within three (unit test below).
const ROUNDS: usize = 4;

/// A box (lo, hi) and a sphere (centre, radius), m.
type Bounds = ((DVec3, DVec3), (DVec3, f64));

/// Each surface's box (lo, hi) and bounding sphere (the box's centre, the farthest vertex).
fn spheres(scene: &Scene) -> Vec<Bounds> {
    let m = scene.surfaces.len();
    let mut lo = vec![DVec3::splat(f64::INFINITY); m];
    let mut hi = vec![DVec3::splat(f64::NEG_INFINITY); m];
    for p in &scene.patches {
        for &v in p.polygon.vertices() {
            lo[p.surface] = lo[p.surface].min(v);
            hi[p.surface] = hi[p.surface].max(v);
        }
    }
    let mut out: Vec<Bounds> = (0..m).map(|s| ((lo[s], hi[s]), (0.5 * (lo[s] + hi[s]), 0.0))).collect();
    for p in &scene.patches {
        let (_, (c, r)) = &mut out[p.surface];
        for &v in p.polygon.vertices() {
            *r = r.max(v.distance(*c));
        }
    }
    out
}

/// Surfaces grouped bottom-up, the two groups whose joint box has the smallest diagonal first:
/// nodes 0..m are the surfaces, each later node joins two earlier ones, its sphere around the
/// joint box. Returns every node's sphere and parent (`usize::MAX` at the root). A body of
/// several surfaces (a cube's six faces) then has its own sphere, which caps the faces together.
fn groups(surfaces: &[Bounds]) -> (Vec<(DVec3, f64)>, Vec<usize>) {
    let mut boxes: Vec<(DVec3, DVec3)> = surfaces.iter().map(|s| s.0).collect();
    let mut sphere: Vec<(DVec3, f64)> = surfaces.iter().map(|s| s.1).collect();
    let mut parent = vec![usize::MAX; surfaces.len()];
    let mut active: Vec<usize> = (0..surfaces.len()).collect();
    let joint = |a: (DVec3, DVec3), b: (DVec3, DVec3)| (a.0.min(b.0), a.1.max(b.1));
    while active.len() > 1 {
        let mut best = (f64::INFINITY, 0, 1);
        for x in 0..active.len() {
            for y in x + 1..active.len() {
                let (lo, hi) = joint(boxes[active[x]], boxes[active[y]]);
                let d = lo.distance(hi);
                if d < best.0 {
                    best = (d, x, y);
                }
            }
        }
        let (_, x, y) = best;
        let node = sphere.len();
        let (lo, hi) = joint(boxes[active[x]], boxes[active[y]]);
        boxes.push((lo, hi));
        sphere.push((0.5 * (lo + hi), 0.5 * lo.distance(hi)));
        parent.push(usize::MAX);
        parent[active[x]] = node;
        parent[active[y]] = node;
        active[x] = node;
        active.swap_remove(y);
    }
    (sphere, parent)
}

/// cap(i, k) for every patch i and group node k (row-major, one row per patch): the bound on
/// F(i → the surfaces of k).
fn caps(scene: &Scene, spheres: &[(DVec3, f64)]) -> Vec<f32> {
    let m = spheres.len();
    let mut out = vec![0.0f32; scene.patches.len() * m];
    out.par_chunks_mut(m.max(1)).zip(scene.patches.par_iter()).for_each(|(row, p)| {
        let (c, r) = (p.polygon.centroid(), p.polygon.bounding_radius());
        for (cap, &(cs, rs)) in row.iter_mut().zip(spheres) {
            let d = c.distance(cs) - r;
            let f = if d > rs { (rs / d).powi(2) } else { 1.0 };
            // Rounded up to storage, so the cap stays a bound.
            let f32v = f as f32;
            *cap = if f64::from(f32v) < f { f32v.next_up() } else { f32v }.min(1.0);
        }
    });
    out
}

/// The largest Σ F_s value_s over the sources in `order` (surfaces; `m` is the ambient, capped
/// by `total` alone) with Σ F_s ≤ `total` and each group node's F within `room` (a surface's
/// own and every enclosing group's; used up): the greedy fill, optimal under nested caps. What
/// the caps leave of `total` takes `rest`.
fn fill(
    order: &[usize],
    value: &[f64],
    room: &mut [f64],
    parent: &[usize],
    m: usize,
    total: f64,
    rest: f64,
) -> f64 {
    let (mut left, mut sum) = (total, 0.0);
    for &s in order {
        if left <= 0.0 {
            break;
        }
        let mut take = left;
        if s < m {
            let mut k = s;
            while k != usize::MAX {
                take = take.min(room[k]);
                k = parent[k];
            }
            let mut k = s;
            while k != usize::MAX {
                room[k] -= take;
                k = parent[k];
            }
        }
        sum += take * value[s];
        left -= take;
    }
    sum + left.max(0.0) * rest
}

/// Each patch's radiosity range (lo, hi), W/m², before the solve (see the module notes); the
/// emissive-power range alone when the scene has more than [`MAX_SURFACES`] surfaces.
pub fn radiosity_bounds(scene: &Scene) -> Vec<(f64, f64)> {
    let coarse = emissive_bounds(scene);
    let m = scene.surfaces.len();
    if m > MAX_SURFACES || m == 0 {
        return coarse;
    }
    let (sphere, parent) = groups(&spheres(scene));
    let k = sphere.len();
    let caps = caps(scene, &sphere);
    let amb = scene.ambient.map(|a| SIGMA * a.temperature.powi(4));
    let mut b = coarse.clone();
    for _ in 0..ROUNDS {
        // Surface-level bounds, then the ambient as one more source of cap 1.
        let mut lo = vec![f64::INFINITY; m + 1];
        let mut hi = vec![f64::NEG_INFINITY; m + 1];
        for (p, &(l, h)) in scene.patches.iter().zip(&b) {
            lo[p.surface] = lo[p.surface].min(l);
            hi[p.surface] = hi[p.surface].max(h);
        }
        let (top, bottom) = (
            hi.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            lo.iter().copied().fold(f64::INFINITY, f64::min),
        );
        let (lo_amb, hi_amb) = amb.map_or((bottom, top), |e| (e, e));
        lo[m] = lo_amb;
        hi[m] = hi_amb;
        let mut up: Vec<usize> =
            (0..=m).filter(|&s| s == m && amb.is_some() || s < m && hi[s].is_finite()).collect();
        let mut down = up.clone();
        up.sort_by(|&x, &y| hi[y].total_cmp(&hi[x]));
        down.sort_by(|&x, &y| lo[x].total_cmp(&lo[y]));
        let next: Vec<(f64, f64)> = scene
            .patches
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let room = || caps[i * k..(i + 1) * k].iter().map(|&c| f64::from(c)).collect::<Vec<f64>>();
                let s = &scene.surfaces[p.surface];
                match s.condition {
                    Some(BoundaryCondition::Temperature(t)) => {
                        let (e, r) = (s.emissivity * SIGMA * t.powi(4), 1.0 - s.emissivity);
                        // A closed scene's unfilled share cannot exist; bounded by the extremes.
                        let h_hi = fill(&up, &hi, &mut room(), &parent, m, 1.0, top);
                        let h_lo = fill(&down, &lo, &mut room(), &parent, m, 1.0, bottom);
                        ((e + r * h_lo).max(coarse[i].0), (e + r * h_hi).min(coarse[i].1))
                    }
                    _ => coarse[i],
                }
            })
            .collect();
        b = next.into_iter().zip(&b).map(|(n, o)| (n.0.max(o.0), n.1.min(o.1))).collect();
    }
    b
}

/// Each surface's weight (W): a bound on Σ_t S_st ΔJ_st (see the module notes) under the
/// radiosity ranges `radiosity` (per patch); `None` above [`MAX_SURFACES`] surfaces.
pub fn surface_weights(scene: &Scene, radiosity: &[(f64, f64)]) -> Option<Vec<f64>> {
    let m = scene.surfaces.len();
    if m > MAX_SURFACES || m == 0 || radiosity.len() != scene.patches.len() {
        return None;
    }
    let (sphere, parent) = groups(&spheres(scene));
    let k = sphere.len();
    let caps = caps(scene, &sphere);
    let (mut lo, mut hi) = (vec![f64::INFINITY; m], vec![f64::NEG_INFINITY; m]);
    let mut area = vec![0.0; m];
    // Σ_{t∈node} S_st ≤ Σ_{i∈s} A_i cap(i, node) for every group node.
    let mut reach = vec![0.0; m * k];
    for (i, (p, &(l, h))) in scene.patches.iter().zip(radiosity).enumerate() {
        let s = p.surface;
        lo[s] = lo[s].min(l);
        hi[s] = hi[s].max(h);
        let a = p.polygon.area();
        area[s] += a;
        for node in 0..k {
            reach[s * k + node] += a * f64::from(caps[i * k + node]);
        }
    }
    Some(
        (0..m)
            .map(|s| {
                if !hi[s].is_finite() {
                    return 0.0;
                }
                let mut order: Vec<usize> = (0..m).filter(|&t| hi[t].is_finite()).collect();
                let dj: Vec<f64> =
                    (0..m)
                        .map(|t| {
                            if hi[t].is_finite() {
                                (hi[s].max(hi[t]) - lo[s].min(lo[t])).max(0.0)
                            } else {
                                0.0
                            }
                        })
                        .collect();
                order.sort_by(|&x, &y| dj[y].total_cmp(&dj[x]).then(x.cmp(&y)));
                // What the caps leave of the area exchanges with no surface (the ambient).
                fill(&order, &dj, &mut reach[s * k..(s + 1) * k].to_vec(), &parent, m, area[s], 0.0)
            })
            .collect(),
    )
}

/// Radiosity bounds from the emissive powers alone: J = εE_b + ρH with the irradiation H
/// between the scene's lowest and highest radiosity; flux patches span the whole range.
pub fn emissive_bounds(scene: &Scene) -> Vec<(f64, f64)> {
    let eb = |t: f64| SIGMA * t.powi(4);
    let mut e_lo = scene.ambient.map_or(f64::INFINITY, |a| eb(a.temperature));
    let mut e_hi = scene.ambient.map_or(0.0, |a| eb(a.temperature));
    let mut q_max: f64 = 0.0;
    let mut eps_min: f64 = 1.0;
    for s in &scene.surfaces {
        match s.condition {
            Some(BoundaryCondition::Temperature(t)) => (e_lo, e_hi) = (e_lo.min(eb(t)), e_hi.max(eb(t))),
            Some(BoundaryCondition::HeatFlux(q)) => {
                q_max = q_max.max(q.abs());
                eps_min = eps_min.min(s.emissivity.max(1e-3));
            }
            None => {}
        }
    }
    if !e_lo.is_finite() {
        e_lo = 0.0;
    }
    // A heated flux surface radiates above the hottest fixed temperature by about q/ε.
    let top = e_hi + q_max / eps_min;
    scene
        .patches
        .iter()
        .map(|p| {
            let s = &scene.surfaces[p.surface];
            match s.condition {
                Some(BoundaryCondition::Temperature(t)) => {
                    let (e, r) = (s.emissivity * eb(t), 1.0 - s.emissivity);
                    (e + r * e_lo, e + r * top)
                }
                // J ≥ 0 is all that is known below a flux surface's radiosity.
                _ => (0.0, top),
            }
        })
        .collect()
}
