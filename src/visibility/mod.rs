//! Visibility: one BVH (obvhs CWBVH) over every triangle of every patch and obstruction.
//!
//! - this file: [`Visibility`] (build, coordinate frame, occluder table) and the result types;
//! - `boxes`: a box hierarchy for region queries with a caller's predicate;
//! - `query`: closest hit, occlusion between two points, blocker candidates of a patch pair;
//! - `triangle`: the watertight ray–triangle test.
//!
//! Design (measured choices in research/crates.md §1 and validation/rays.md):
//! - Traversal geometry is f32, in a *normalised frame*: the scene is centred and scaled by a
//!   power of two (exact) so its half-diagonal lies in [512, 1024). obvhs clamps every node
//!   interval to t ≥ 1e-4 in absolute units; in this frame that is below f32 resolution of the
//!   scene and far below the box padding, so no node near a ray origin is ever culled, and the
//!   results do not depend on the scene's units.
//! - Every triangle box is padded by [`PAD_REL`] of the scene diagonal (the flat-box pathology).
//! - Triangles are stored in BVH leaf order with their occluder id, so the callback is direct.
//! - Self-hits are avoided by skipping the source patch's triangles, never by offsets.
//!
//! **Sidedness rule.** Every triangle is opaque from both sides: a ray that reaches the back of
//! a one-sided surface stops there (it is absorbed by the plate's unmodelled back, or it is
//! inside a closed solid) but, in the view-factor methods, contributes to no F, because only
//! front sides exchange. This is what the analytic methods compute for front-to-front pairs
//! with two-sided blockers, and it is View3D's rule (research/view3d.md §2: obstructions are
//! opaque; keeping only those facing the receiver is exact for closed solids and plates).
//! A ray leaving the front of a patch never meets anything behind or in that patch's plane, so
//! such triangles (coplanar neighbours, the far face of a two-sided thin plate, the other faces
//! of a convex solid) are skipped, whatever f32 rounding of the origin says; occlusion queries
//! do the same for both end planes. "In the plane" means within the f32 band of the scene and,
//! checked in f64, within [`ORIGIN_BAND_REL`] of the patch's own radius plus [`COPLANAR_SLOPE`] of
//! the distance: a small patch 1 m over a ground 2e6 m wide still sees the ground.
//! Sides are decided by the origin's distance to a triangle's plane, not by t: a point
//! within [`ORIGIN_BAND_REL`] of the scene size behind a plane (the f32 rounding scale) counts as in
//! front of it, because the true origin lies in front of every surface that meets its patch
//! at an edge. A ray then hits a front side only from a front origin (at t = 0 when rounding
//! put the crossing just behind: a wall at a concave corner, a box standing on the floor) and a
//! back side only from a truly-behind origin; grazing rays cannot slip through a neighbour's
//! plane in either direction. An occlusion blocker must separate the two end points by the
//! same rule.
//! Coincident surfaces facing the *same* way are ambiguous; model a covering as a solid.
use crate::geometry::DVec3;
use crate::scene::Scene;
use glam::Vec3A;
use obvhs::{aabb::Aabb, cwbvh::CwBvh, Boundable, BvhBuildParams};
use std::time::{Duration, Instant};

pub(crate) mod boxes;
pub(crate) mod query;
pub(crate) mod triangle;

/// Box padding, as a fraction of the scene diagonal: 1e-6–1e-5 cures obvhs's degenerate trees
/// for axis-aligned triangles (research/crates.md §1.3) at no measurable cost.
pub const PAD_REL: f64 = 1e-5;
/// Half-width of the "near the origin" band, as a fraction of the scene half-diagonal: about 32
/// f32 ulps of the largest normalised coordinate (vertex rounding plus the test's own error).
pub const ORIGIN_BAND_REL: f64 = 4e-6;
/// Farthest a crossing may lie behind an origin (or beyond a target) and still count as a
/// contact there, as a fraction of the half-diagonal: grazing rays from an origin that
/// rounding put just behind a neighbour's plane cross it this far back.
pub const FAR_REL: f64 = 1e-3;
/// Planes meant to coincide (a coplanar neighbour, a face sharing an edge) deviate from the
/// source patch's plane by at most this slope times their distance from its centre, on top of
/// [`ORIGIN_BAND_REL`] of its own radius: f32 input coordinates and Newell normals agree to ~1e-7.
/// A surface clearly off the plane at a distance counts as in front even where the f32 band
/// of the whole scene would swallow it (a unit square 1 m over a 2e6 m ground).
pub const COPLANAR_SLOPE: f64 = 1e-7;
/// The normalised scene's half-diagonal lies in [TARGET/2, TARGET).
const TARGET_HALF_EXTENT: f64 = 1024.0;
/// obvhs's own node-interval floor (cwbvh::node::EPSILON); the padding must dwarf it.
const OBVHS_NODE_EPSILON: f32 = 1e-4;

/// What a triangle belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Occluder {
    /// An exchanging patch (index into `Scene::patches`).
    Patch(usize),
    /// Polygon `polygon` of obstruction `obstruction` (indices into `Scene::obstructions`).
    Obstruction {
        /// Obstruction index.
        obstruction: usize,
        /// Polygon index within it.
        polygon: usize,
    },
}

/// A closest hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// What was hit.
    pub occluder: Occluder,
    /// Distance along the (unit) direction, ≥ 0.
    pub t: f64,
    /// True when the ray met the front (emitting, receiving) side.
    pub front_facing: bool,
}

/// Build statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildStats {
    /// Triangles in the BVH.
    pub triangles: usize,
    /// CWBVH nodes.
    pub nodes: usize,
    /// Wall time of the build (triangulation included).
    pub time: Duration,
}

/// A padded triangle box for the builder.
struct PaddedBox(Aabb);
impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// The scene's triangles in one BVH; `Send + Sync`, shared by reference across threads.
#[derive(Debug, Clone)]
pub struct Visibility {
    pub(crate) bvh: CwBvh,
    /// Triangles in BVH leaf order, normalised frame, stored transposed (rows x, y, z of the
    /// three vertices; `triangle::transpose`): the layout of the ray–triangle test.
    pub(crate) tri_rows: Vec<[Vec3A; 3]>,
    /// Occluder id of each triangle (BVH order): patches are 0..n_patches.
    pub(crate) owner: Vec<u32>,
    /// Occluder id → owner.
    occluders: Vec<Occluder>,
    /// Per patch: padded box and plane (unit normal, offset n·x) in the normalised frame.
    pub(crate) patch_box: Vec<Aabb>,
    pub(crate) patch_plane: Vec<(Vec3A, f32)>,
    /// Per patch, f64 in the normalised frame: unit normal, offset, centroid and the band of
    /// the in-plane test ([`ORIGIN_BAND_REL`] of its radius).
    pub(crate) patch_plane64: Vec<PlaneBand>,
    /// Triangles in BVH leaf order, normalised frame, f64 (the in-plane test of rays that
    /// leave a patch small against the scene).
    pub(crate) tri64: Vec<[DVec3; 3]>,
    /// Ray length covering the whole scene, normalised units.
    pub(crate) ray_length: f32,
    center: DVec3,
    scale: f64,
    /// Rounding band in normalised units.
    pub(crate) near: f32,
    /// Contact reach behind an origin in normalised units.
    pub(crate) far: f32,
    stats: BuildStats,
}

/// A patch's plane for the f64 in-plane test.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PlaneBand {
    pub normal: DVec3,
    pub offset: f64,
    pub centre: DVec3,
    pub band: f64,
}

/// Occluder id meaning "skip nothing".
pub(crate) const NO_SKIP: u32 = u32::MAX;

impl Visibility {
    /// Builds the BVH of `scene` with the default quality (`medium_build`).
    pub fn new(scene: &Scene) -> Self {
        Self::with_params(scene, BvhBuildParams::medium_build())
    }

    /// Hash of the built tree: every CWBVH node as stored, the primitive order and each
    /// triangle's owner. Ranks or shards whose hashes differ would not trace the same rays.
    pub fn tree_hash(&self) -> u64 {
        use std::hash::Hasher;
        let mut h = fnv::FnvHasher::default();
        h.write_u64(self.bvh.nodes.len() as u64);
        for n in &self.bvh.nodes {
            n.p.to_array().iter().for_each(|x| h.write_u32(x.to_bits()));
            h.write(&n.e);
            h.write_u8(n.imask);
            h.write_u32(n.child_base_idx);
            h.write_u32(n.primitive_base_idx);
            for a in [n.child_meta, n.child_min_x, n.child_max_x, n.child_min_y, n.child_max_y] {
                h.write(&a);
            }
            h.write(&n.child_min_z);
            h.write(&n.child_max_z);
        }
        self.bvh.primitive_indices.iter().for_each(|&k| h.write_u32(k));
        self.owner.iter().for_each(|&k| h.write_u32(k));
        h.finish()
    }

    /// Builds with an explicit obvhs preset (benchmarks compare them).
    pub fn with_params(scene: &Scene, params: BvhBuildParams) -> Self {
        Self::build(scene, params, |_| true)
    }

    /// For [`Self::occluded`] only: the BVH holds just the occluder polygons `cuts` keeps
    /// (patches and obstruction polygons); the frame, bands and patch planes are those of the
    /// whole scene, so an occlusion answer is the full tree's whenever the dropped occluders
    /// cannot separate two patch points (a convex room's walls: every patch on their front).
    /// Not for [`Self::first_hit`], whose closest hit may be a dropped one.
    pub fn occluding_only(scene: &Scene, cuts: impl FnMut(&crate::geometry::Polygon) -> bool) -> Self {
        Self::build(scene, BvhBuildParams::medium_build(), cuts)
    }

    fn build(
        scene: &Scene,
        params: BvhBuildParams,
        mut cuts: impl FnMut(&crate::geometry::Polygon) -> bool,
    ) -> Self {
        let start = Instant::now();
        // Occluder table: patches first (id = patch index), then obstruction polygons.
        let mut polys: Vec<(&crate::geometry::Polygon, Occluder)> =
            scene.patches.iter().enumerate().map(|(p, patch)| (&patch.polygon, Occluder::Patch(p))).collect();
        for (o, obs) in scene.obstructions.iter().enumerate() {
            for (k, poly) in obs.polygons.iter().enumerate() {
                polys.push((poly, Occluder::Obstruction { obstruction: o, polygon: k }));
            }
        }
        let (center, scale) = normalisation(polys.iter().flat_map(|(p, _)| p.vertices().iter().copied()));
        let to_f64 = |x: DVec3| (x - center) * scale;
        let to_f32 = |x: DVec3| to_f64(x).as_vec3a();
        let mut tris = Vec::new();
        let mut tris64 = Vec::new();
        let mut owner = Vec::new();
        // The bands come from every triangle's box; only those `cuts` keeps enter the tree.
        let mut whole = Aabb::empty();
        for (id, (poly, _)) in polys.iter().enumerate() {
            let keep = cuts(poly);
            for [a, b, c] in poly.triangulate() {
                let t = [to_f32(a), to_f32(b), to_f32(c)];
                whole = whole.union(&tri_aabb(&t));
                if keep {
                    tris.push(t);
                    tris64.push([to_f64(a), to_f64(b), to_f64(c)]);
                    owner.push(id as u32);
                }
            }
        }
        let half = scene_half_extent(whole);
        let pad = Vec3A::splat((PAD_REL * 2.0 * half) as f32);
        let near = (ORIGIN_BAND_REL * half) as f32;
        let far = (FAR_REL * half) as f32;
        debug_assert!(tris.is_empty() || pad.x > near + OBVHS_NODE_EPSILON);
        let boxes: Vec<PaddedBox> = tris
            .iter()
            .map(|t| {
                let b = tri_aabb(t);
                PaddedBox(Aabb::new(b.min - pad, b.max + pad))
            })
            .collect();
        let bvh = if boxes.is_empty() {
            CwBvh::default()
        } else {
            obvhs::cwbvh::builder::build_cwbvh(&boxes, params, &mut Duration::default())
        };
        // Reorder triangles into leaf order so the callback index is direct.
        let (tri_rows, owner): (Vec<_>, Vec<_>) = bvh
            .primitive_indices
            .iter()
            .map(|&k| (triangle::transpose(&tris[k as usize]), owner[k as usize]))
            .unzip();
        let tri64 = bvh.primitive_indices.iter().map(|&k| tris64[k as usize]).collect();
        let patch_plane64 = scene
            .patches
            .iter()
            .map(|p| {
                let (n, c) = (p.polygon.normal(), to_f64(p.polygon.centroid()));
                PlaneBand {
                    normal: n,
                    offset: n.dot(c),
                    centre: c,
                    band: ORIGIN_BAND_REL * p.polygon.bounding_radius() * scale,
                }
            })
            .collect();
        let (patch_box, patch_plane) = scene
            .patches
            .iter()
            .map(|p| {
                let v: Vec<Vec3A> = p.polygon.vertices().iter().map(|&x| to_f32(x)).collect();
                let b = Aabb::from_points(&v);
                let n = p.polygon.normal().as_vec3a();
                (Aabb::new(b.min - pad, b.max + pad), (n, n.dot(to_f32(p.polygon.centroid()))))
            })
            .unzip();
        let stats = BuildStats { triangles: tri_rows.len(), nodes: bvh.nodes.len(), time: start.elapsed() };
        Self {
            bvh,
            tri_rows,
            owner,
            occluders: polys.into_iter().map(|(_, o)| o).collect(),
            patch_box,
            patch_plane,
            patch_plane64,
            tri64,
            // The padded box's diagonal is below 2·half·(1 + 2·PAD_REL); twice that is ample.
            ray_length: (4.0 * half) as f32,
            center,
            scale,
            near,
            far,
            stats,
        }
    }

    /// Build statistics.
    pub fn stats(&self) -> BuildStats {
        self.stats
    }
    /// Owner of occluder id `id` (ids < patch count are patches).
    pub fn occluder(&self, id: u32) -> Occluder {
        self.occluders[id as usize]
    }
    /// Number of occluder polygons (patches plus obstruction polygons).
    pub fn occluder_count(&self) -> usize {
        self.occluders.len()
    }
    /// Vertices of triangle slot `id` (normalised frame).
    #[inline]
    pub(crate) fn vertices(&self, id: usize) -> [Vec3A; 3] {
        triangle::transpose(&self.tri_rows[id])
    }
    /// True when the BVH holds no triangle.
    pub(crate) fn is_empty(&self) -> bool {
        self.tri_rows.is_empty()
    }
    /// World point → normalised frame (f64).
    pub(crate) fn to_frame(&self, x: DVec3) -> DVec3 {
        (x - self.center) * self.scale
    }
    /// Length of a ray that crosses the whole scene from any point in it, normalised units.
    pub(crate) fn ray_length(&self) -> f32 {
        self.ray_length
    }
    /// World distance → normalised distance.
    pub(crate) fn scale(&self) -> f64 {
        self.scale
    }
}

/// Centre of the vertices' box and a power-of-two scale mapping its half-diagonal into
/// [TARGET/2, TARGET); powers of two scale exactly.
fn normalisation(points: impl Iterator<Item = DVec3>) -> (DVec3, f64) {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if lo.x.partial_cmp(&hi.x).is_none_or(|o| o.is_gt()) {
        return (DVec3::ZERO, 1.0);
    }
    let half = 0.5 * (hi - lo).length();
    let scale = if half > 0.0 { ((TARGET_HALF_EXTENT / half).log2().ceil() - 1.0).exp2() } else { 1.0 };
    (0.5 * (lo + hi), scale)
}

/// Half-diagonal of the normalised triangles' box `b` (≈ 512–1024; 1 when empty).
fn scene_half_extent(b: Aabb) -> f64 {
    if b.valid() {
        (0.5 * (b.max - b.min).length() as f64).max(1.0)
    } else {
        1.0
    }
}

pub(crate) fn tri_aabb(t: &[Vec3A; 3]) -> Aabb {
    Aabb::new(t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_send_sync<T: Send + Sync>() {}

    #[test]
    fn visibility_is_send_and_sync() {
        assert_send_sync::<Visibility>();
    }

    /// Two unit squares facing each other at `gap`, 3 × 3 patches each.
    fn squares(gap: f64) -> Scene {
        let grid = |o: DVec3, u: DVec3, v: DVec3| {
            crate::geometry::subdivide::parallelogram_grid(o, u, v, 3, 3).expect("a grid")
        };
        Scene::builder()
            .surface("low", grid(DVec3::ZERO, DVec3::X, DVec3::Y), 0.9, None)
            .surface("high", grid(DVec3::Z * gap, DVec3::Y, DVec3::X), 0.9, None)
            .build()
    }

    #[test]
    fn the_tree_hash_tells_equal_trees_from_different_ones() {
        let a = Visibility::new(&squares(1.0));
        assert_eq!(a.tree_hash(), Visibility::new(&squares(1.0)).tree_hash());
        assert_ne!(a.tree_hash(), Visibility::new(&squares(1.5)).tree_hash(), "another geometry");
        let mut node = a.clone();
        node.bvh.nodes[0].child_meta[0] ^= 1;
        assert_ne!(a.tree_hash(), node.tree_hash(), "one node byte differs");
        let mut order = a.clone();
        order.bvh.primitive_indices.swap(0, 1);
        assert_ne!(a.tree_hash(), order.tree_hash(), "the primitives in another order");
    }

    #[test]
    fn normalisation_is_a_power_of_two_into_the_target_band() {
        for half in [1e-6, 0.3, 1.0, 7.0, 1e5] {
            let pts = [DVec3::new(-half, 0.0, 0.0) + 3.0, DVec3::new(half, 0.0, 0.0) + 3.0];
            let (c, s) = normalisation(pts.into_iter());
            assert!((c - DVec3::splat(3.0)).length() < 1e-9);
            assert_eq!(s.log2().fract(), 0.0, "{s}");
            let h = half * s;
            assert!((TARGET_HALF_EXTENT / 2.0..TARGET_HALF_EXTENT).contains(&h), "half {half} -> {h}");
        }
    }
}
