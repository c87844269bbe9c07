//! The three visibility queries: [`Visibility::first_hit`] (closest hit),
//! [`Visibility::occluded`] (any blocker between two points) and
//! [`Visibility::candidates_between`] (possible blockers of a patch pair, from the BVH).
//!
//! All take world coordinates; the near-origin sidedness rule is documented in the module
//! above.
use super::triangle::{ShearedRay, TriHit};
use super::{tri_aabb, Hit, Visibility, COPLANAR_SLOPE, NO_SKIP};
use crate::geometry::DVec3;
use glam::{UVec2, Vec3A};
use obvhs::ray::{Ray, RayHit};

impl Visibility {
    /// Closest hit along the unit direction `dir` from `origin`, up to `tmax` (world units),
    /// ignoring the triangles of `skip_patch` (the ray's own patch, whose front the ray leaves)
    /// and every triangle behind or in that patch's plane (coplanar neighbours, the far face of
    /// a two-sided thin plate, the other faces of a convex solid).
    pub fn first_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip_patch: Option<usize>) -> Option<Hit> {
        if self.is_empty() {
            return None;
        }
        let skip = skip_patch.map_or(NO_SKIP, |p| p as u32);
        let o = self.to_frame(origin).as_vec3a();
        let d = dir.as_vec3a();
        let tmax_f = (tmax * self.scale()).min(f32::MAX as f64) as f32;
        let (id, h) = self.first_hit_frame(o, d, tmax_f, skip)?;
        Some(Hit {
            occluder: self.occluder(self.owner[id]),
            t: h.t.max(0.0) as f64 / self.scale(),
            front_facing: h.front,
        })
    }

    /// Closest hit in the normalised frame: (triangle slot, hit).
    #[inline]
    pub(crate) fn first_hit_frame(
        &self,
        o: Vec3A,
        d: Vec3A,
        tmax: f32,
        skip: u32,
    ) -> Option<(usize, TriHit)> {
        let (near, far) = (self.near, self.far);
        let plane = self.patch_plane.get(skip as usize).copied().map(|pl| (pl, skip as usize));
        let sheared = ShearedRay::new(o, d);
        let mut best: Option<(usize, TriHit)> = None;
        let mut hit = RayHit::none();
        self.bvh.ray_traverse(Ray::new(o, d, -far, tmax), &mut hit, |r, id| {
            if self.owner[id] == skip {
                return f32::INFINITY;
            }
            match sheared.intersect_rows(&self.tri_rows[id]) {
                Some(h) if h.t > -far && h.t < r.tmax && !plane.is_some_and(|pl| self.behind(id, pl)) => {
                    // Sides by the origin's distance to the plane, rounding band counted as front.
                    let front_origin = self.side(id, o) > -near;
                    if h.front != front_origin {
                        return f32::INFINITY;
                    }
                    let t = h.t.max(0.0);
                    // Coincident faces (a two-sided plate as two opposite surfaces) cross within
                    // the rounding band: the face turned towards the ray takes the hit.
                    let wins = best.is_none_or(|(_, b)| {
                        if (t - b.t).abs() <= near && h.front != b.front {
                            h.front
                        } else {
                            t < b.t
                        }
                    });
                    if wins {
                        best = Some((id, TriHit { t, front: h.front }));
                    }
                    // Keep the band beyond the best hit open for such a tie.
                    best.map_or(f32::INFINITY, |(_, b)| b.t + near)
                }
                _ => f32::INFINITY,
            }
        });
        best
    }

    /// Signed distance of `p` from triangle `id`'s plane, positive on its front side.
    #[inline]
    fn side(&self, id: usize, p: Vec3A) -> f32 {
        let [a, b, c] = self.vertices(id);
        (b - a).cross(c - a).normalize_or_zero().dot(p - a)
    }

    /// True when triangle `id` lies behind or in the plane of patch `patch` (f32 unit normal,
    /// offset), to within the near band: a ray leaving the front of a plane never meets such a
    /// triangle, whatever rounding of its origin says. The band is the f32 rounding scale of
    /// the whole scene, and also, in f64, [`super::ORIGIN_BAND_REL`] of the patch's radius plus
    /// [`super::COPLANAR_SLOPE`] of the distance, so that a patch small against the scene does
    /// not take a surface clearly in front of it for one in its plane.
    #[inline]
    fn behind(&self, id: usize, ((n, off), patch): ((Vec3A, f32), usize)) -> bool {
        self.vertices(id).iter().all(|v| n.dot(*v) - off <= self.near) && {
            let pl = &self.patch_plane64[patch];
            self.tri64[id]
                .iter()
                .all(|v| pl.normal.dot(*v) - pl.offset <= pl.band + COPLANAR_SLOPE * v.distance(pl.centre))
        }
    }

    /// True when something other than patches `skip_i` and `skip_j` (and anything behind or in
    /// their planes) blocks the segment p–q; p and q are front-facing points of those patches.
    pub fn occluded(&self, p: DVec3, q: DVec3, skip_i: usize, skip_j: usize) -> bool {
        if self.is_empty() {
            return false;
        }
        let (pf, qf) = (self.to_frame(p), self.to_frame(q));
        let d = qf - pf;
        let len = d.length();
        if len.is_nan() || len <= 0.0 {
            return false;
        }
        self.occluded_frame(pf.as_vec3a(), (d / len).as_vec3a(), len as f32, skip_i as u32, skip_j as u32)
    }

    /// Occlusion in the normalised frame along unit `d` over length `len`.
    #[inline]
    pub(crate) fn occluded_frame(&self, o: Vec3A, d: Vec3A, len: f32, skip_i: u32, skip_j: u32) -> bool {
        let (near, far) = (self.near, self.far);
        let planes = [
            (self.patch_plane[skip_i as usize], skip_i as usize),
            (self.patch_plane[skip_j as usize], skip_j as usize),
        ];
        let sheared = ShearedRay::new(o, d);
        let q = o + d * len;
        let ray = Ray::new(o, d, -far, len + far);
        !self.bvh.ray_traverse_miss(ray, |_, id| {
            let who = self.owner[id];
            if who == skip_i || who == skip_j {
                return f32::INFINITY;
            }
            match sheared.intersect_rows(&self.tri_rows[id]) {
                // A blocker separates p from q, sides taken with the rounding band as front.
                Some(h)
                    if h.t > -far
                        && h.t < len + far
                        && !planes.iter().any(|&pl| self.behind(id, pl))
                        && (self.side(id, o) > -near) != (self.side(id, q) > -near) =>
                {
                    0.0
                }
                _ => f32::INFINITY,
            }
        })
    }

    /// Occluder ids (sorted, unique, without `i` and `j`) whose triangles overlap the box of
    /// patches `i` and `j` and lie partly in front of both planes: every segment from the
    /// front of one patch to the front of the other stays in that box and those half-spaces.
    pub fn candidates_between(&self, i: usize, j: usize, out: &mut Vec<u32>) {
        out.clear();
        if self.is_empty() {
            return;
        }
        let query = self.patch_box[i].union(&self.patch_box[j]);
        let planes = [(self.patch_plane[i], i), (self.patch_plane[j], j)];
        let (skip_i, skip_j) = (i as u32, j as u32);
        let bvh = &self.bvh;
        let mut state = bvh.new_traversal(Vec3A::ONE);
        let mut node;
        obvhs::traverse!(bvh, node, state, node.intersect_aabb(&query, state.oct_inv4), {
            let id = state.primitive_id as usize;
            let who = self.owner[id];
            let tri = &self.vertices(id);
            if who != skip_i
                && who != skip_j
                && tri_aabb(tri).intersect_aabb(&query)
                && planes.iter().all(|&pl| !self.behind(id, pl))
            {
                out.push(who);
            }
        });
        out.sort_unstable();
        out.dedup();
    }

    /// Mean triangle tests per closest-hit ray over `rays` (tree-quality diagnostic).
    pub fn tests_per_ray(&self, rays: &[(DVec3, DVec3)]) -> f64 {
        let mut tests = 0u64;
        for &(o, d) in rays {
            let mut hit = RayHit::none();
            let (o, d) = (self.to_frame(o).as_vec3a(), d.as_vec3a());
            let sheared = ShearedRay::new(o, d);
            self.bvh.ray_traverse(Ray::new(o, d, -self.near, f32::INFINITY), &mut hit, |r, id| {
                tests += 1;
                match sheared.intersect_rows(&self.tri_rows[id]) {
                    Some(h) if h.t > 0.0 && h.t < r.tmax => h.t,
                    _ => f32::INFINITY,
                }
            });
        }
        tests as f64 / rays.len().max(1) as f64
    }
}
