//! Occluder detection for the unshadowed analytic method: which patch pairs have part of their
//! view cut by another patch or an obstruction.
//!
//! **Criterion.** For convex parts A ⊂ patch i (clipped to j's front half-space) and B ⊂ patch j
//! (clipped to i's), the sight lines a→b fill H = conv(A ∪ B). A convex blocker K cuts a set of
//! sight lines of positive measure iff relint(K) meets int(H). K lies in a plane P, so this holds
//! iff A ∪ B has points strictly on both sides of P and relint(K) overlaps relint(H ∩ P) in P:
//! a 2-D separating-axis test between two convex polygons, with overlaps thinner than
//! `OCCLUSION_TOL`·(scene size) counted as touching.
//!
//! **Pre-filter.** Blockers are grouped by plane. A plane can only block when some patch has a
//! vertex strictly on one side and another patch strictly on the other; in a convex enclosure
//! (the cube) no plane qualifies, so the check costs O(N·planes) once and nothing per pair.
//! Candidate search within an active plane is a linear scan with a bounding-box test; a BVH
//! will replace it.
use crate::geometry::convex::convex_overlap;
use crate::geometry::planes::{Plane, PlaneGroups};
use crate::geometry::tolerance::OCCLUSION_TOL;
use crate::geometry::Polygon;
use crate::scene::Scene;
use crate::visibility::Occluder;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// One convex blocker polygon projected into its group's plane frame.
#[derive(Debug, Clone)]
struct Projected {
    owner: Occluder,
    pts: Vec<DVec2>,
    lo: DVec2,
    hi: DVec2,
}

/// An active blocking plane with its blockers.
#[derive(Debug, Clone)]
struct Group {
    plane: Plane,
    e1: DVec3,
    e2: DVec3,
    blockers: Vec<Projected>,
}

/// Occluder detection for one scene.
#[derive(Debug, Clone)]
pub struct Occlusion {
    tol: f64,
    groups: Vec<Group>,
    /// Convex parts of each patch (the patch itself when convex, else its triangles).
    parts: Vec<Vec<Polygon>>,
}

/// Convex pieces of a polygon.
fn convex_parts(poly: &Polygon) -> Vec<Polygon> {
    if poly.is_convex() {
        return vec![poly.clone()];
    }
    poly.triangulate().into_iter().filter_map(|[a, b, c]| Polygon::triangle(a, b, c)).collect()
}

/// (has a vertex strictly in front, has a vertex strictly behind) of `poly` w.r.t. `plane`.
fn sides(poly: &Polygon, plane: &Plane, tol: f64) -> (bool, bool) {
    let d = plane.distance(poly.centroid());
    let r = poly.bounding_radius();
    if d - r > tol {
        return (true, false);
    }
    if d + r < -tol {
        return (false, true);
    }
    poly.vertices().iter().fold((false, false), |(p, m), v| {
        let d = plane.distance(*v);
        (p || d > tol, m || d < -tol)
    })
}

impl Occlusion {
    /// Groups every patch and obstruction polygon by plane and keeps the planes that can block.
    pub fn new(scene: &Scene) -> Self {
        let scale = scene_size(scene);
        let tol = OCCLUSION_TOL * scale;
        let mut polys: Vec<(&Polygon, Occluder)> =
            scene.patches.iter().enumerate().map(|(p, patch)| (&patch.polygon, Occluder::Patch(p))).collect();
        for (k, o) in scene.obstructions.iter().enumerate() {
            polys.extend(
                o.polygons
                    .iter()
                    .enumerate()
                    .map(|(m, poly)| (poly, Occluder::Obstruction { obstruction: k, polygon: m })),
            );
        }
        let grouping = PlaneGroups::new(polys.iter().map(|(p, _)| *p), scale, tol);
        // Side census per plane: a plane blocks only if two different patches lie strictly on
        // opposite sides of it.
        let active: Vec<bool> = grouping
            .planes
            .par_iter()
            .map(|plane| {
                let (mut plus, mut minus) = (None, None);
                for (p, patch) in scene.patches.iter().enumerate() {
                    let (sp, sm) = sides(&patch.polygon, plane, tol);
                    if sp && plus.is_none() {
                        plus = Some(p);
                    }
                    if sm && (minus.is_none() || minus == plus) {
                        minus = Some(p);
                    }
                    if let (Some(a), Some(b)) = (plus, minus) {
                        if a != b {
                            return true;
                        }
                    }
                }
                false
            })
            .collect();
        let mut groups: Vec<Option<Group>> = grouping
            .planes
            .iter()
            .zip(&active)
            .map(|(plane, &on)| {
                on.then(|| {
                    let (e1, e2) = plane.n.any_orthonormal_pair();
                    Group { plane: *plane, e1, e2, blockers: Vec::new() }
                })
            })
            .collect();
        for ((poly, owner), &g) in polys.iter().zip(&grouping.id) {
            if let Some(group) = groups[g as usize].as_mut() {
                for part in convex_parts(poly) {
                    let pts: Vec<DVec2> = part
                        .vertices()
                        .iter()
                        .map(|v| DVec2::new(v.dot(group.e1), v.dot(group.e2)))
                        .collect();
                    let (lo, hi) = bbox(&pts);
                    group.blockers.push(Projected { owner: *owner, pts, lo, hi });
                }
            }
        }
        let groups: Vec<Group> = groups.into_iter().flatten().collect();
        let parts = if groups.is_empty() {
            Vec::new()
        } else {
            scene.patches.iter().map(|p| convex_parts(&p.polygon)).collect()
        };
        Occlusion { tol, groups, parts }
    }

    /// True when no plane of the scene can block any pair (every convex enclosure).
    pub fn is_clear(&self) -> bool {
        self.groups.is_empty()
    }

    /// Number of planes that can block some pair.
    pub fn active_planes(&self) -> usize {
        self.groups.len()
    }

    /// A blocker that cuts part of the view between patches `i` and `j`, if any.
    pub fn first_blocker(&self, scene: &Scene, i: usize, j: usize) -> Option<Occluder> {
        if self.groups.is_empty() || i == j {
            return None;
        }
        let (pi, pj) = (&scene.patches[i].polygon, &scene.patches[j].polygon);
        let mut clipped: Option<(Vec<Polygon>, Vec<Polygon>)> = None;
        for g in &self.groups {
            let (ip, im) = sides(pi, &g.plane, self.tol);
            let (jp, jm) = sides(pj, &g.plane, self.tol);
            if !((ip && jm) || (im && jp)) {
                continue;
            }
            // Parts of each patch in front of the other's plane (computed once per pair).
            let (a_parts, b_parts) = clipped.get_or_insert_with(|| {
                let a = self.parts[i].iter().filter_map(|p| p.clip(pj.centroid(), pj.normal())).collect();
                let b = self.parts[j].iter().filter_map(|p| p.clip(pi.centroid(), pi.normal())).collect();
                (a, b)
            });
            for a in a_parts.iter() {
                for b in b_parts.iter() {
                    let Some(x) = self.section(g, a, b) else { continue };
                    let (lo, hi) = bbox(&x);
                    for k in &g.blockers {
                        if matches!(k.owner, Occluder::Patch(p) if p == i || p == j) {
                            continue;
                        }
                        if k.lo.x >= hi.x - self.tol
                            || k.hi.x <= lo.x + self.tol
                            || k.lo.y >= hi.y - self.tol
                            || k.hi.y <= lo.y + self.tol
                        {
                            continue;
                        }
                        if convex_overlap(&x, &k.pts, self.tol) {
                            return Some(k.owner);
                        }
                    }
                }
            }
        }
        None
    }

    /// Every pair i < j whose view is partly blocked, with a blocker (row order).
    pub fn blocked_pairs(&self, scene: &Scene) -> Vec<(usize, usize, Occluder)> {
        if self.is_clear() {
            return Vec::new();
        }
        let n = scene.patches.len();
        (0..n)
            .into_par_iter()
            .with_max_len(1)
            .flat_map_iter(|i| {
                (i + 1..n).filter_map(move |j| self.first_blocker(scene, i, j).map(|k| (i, j, k)))
            })
            .collect()
    }

    /// The section conv(a ∪ b) ∩ plane as a convex polygon in the plane frame, when it has
    /// interior (a and b together strictly on both sides).
    fn section(&self, g: &Group, a: &Polygon, b: &Polygon) -> Option<Vec<DVec2>> {
        let verts: Vec<(DVec3, f64)> =
            a.vertices().iter().chain(b.vertices()).map(|v| (*v, g.plane.distance(*v))).collect();
        let mut pts = Vec::with_capacity(16);
        for (k, &(v, dv)) in verts.iter().enumerate() {
            if dv.abs() <= self.tol {
                pts.push(v);
            }
            if dv > self.tol {
                for &(w, dw) in &verts[..] {
                    if dw < -self.tol {
                        pts.push(v + (w - v) * (dv / (dv - dw)));
                    }
                }
            }
            let _ = k;
        }
        let p2: Vec<DVec2> = pts.iter().map(|v| DVec2::new(v.dot(g.e1), v.dot(g.e2))).collect();
        let hull = convex_hull(p2);
        (hull.len() >= 3).then_some(hull)
    }
}

/// Bounding-box diagonal of every patch and obstruction vertex (1 for an empty scene).
fn scene_size(scene: &Scene) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let polys =
        scene.patches.iter().map(|p| &p.polygon).chain(scene.obstructions.iter().flat_map(|o| &o.polygons));
    for poly in polys {
        for v in poly.vertices() {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    let d = (hi - lo).length();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

fn bbox(pts: &[DVec2]) -> (DVec2, DVec2) {
    pts.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
}

/// Convex hull of the distinct points of `p`, counter-clockwise, collinear points dropped
/// (the shared [`geometry::convex::convex_hull`](crate::geometry::convex::convex_hull), which
/// sorts them and takes each once).
fn convex_hull(mut pts: Vec<DVec2>) -> Vec<DVec2> {
    let mut hull = Vec::with_capacity(2 * pts.len());
    crate::geometry::convex::convex_hull(&mut pts, &mut hull);
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_distinct_points() {
        let v = |p: &[[f64; 2]]| p.iter().map(|&[x, y]| DVec2::new(x, y)).collect::<Vec<_>>();
        let h = convex_hull(v(&[[0.0, 0.0], [1.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.0, 1.0], [0.5, 0.0]]));
        assert_eq!(h.len(), 4, "{h:?}");
    }
}
