//! Scene geometry flattened once for the projection methods (hemicube, single plane), and the
//! per-eye gather that culls it and moves it into the eye's local frame.
//!
//! Visibility rules, shared by both methods (surfaces are one-sided, docs/SPEC.md):
//! - a patch polygon whose front faces the eye is a *receiver*: it occludes and is counted;
//! - a patch polygon seen from its back is a *blocker*: a ray that hits a receiver's back side
//!   is stopped there but counts for nobody (it would be inside a solid in a closed model);
//! - obstruction polygons are blockers from both sides (a lone shade plate must shade whichever
//!   way its vertices run);
//! - polygons whose plane holds the eye (coplanar neighbours, edge-on faces) project to zero
//!   area and are skipped, as is the eye's own patch.
use crate::geometry::frame::Frame;
use crate::geometry::tolerance::EYE_IN_PLANE_REL;
use crate::scene::Scene;
use glam::DVec3;

/// The in-plane and near-plane tolerances are relative to the scene's size, but never to more
/// than this many times the local size (the eye's patch, or its distance to the polygon): a
/// small patch 0.5 m from a polygon 1e9 m long must see it, not take itself for in its plane.
pub(crate) const LOCAL_SPAN: f64 = 1e3;

/// Item-buffer id of a blocker: occludes, receives nothing.
pub(crate) const NO_RECEIVER: u32 = u32::MAX;

/// One polygon of the flattened scene.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PolyRec {
    /// First vertex in [`Prepared::verts`].
    pub first: u32,
    /// Vertex count.
    pub len: u32,
    /// Area centroid.
    pub centroid: DVec3,
    /// Unit normal of the front side.
    pub normal: DVec3,
    /// Largest centroid–vertex distance.
    pub radius: f64,
    /// Patch index, or [`NO_RECEIVER`] for obstructions.
    pub patch: u32,
}

/// Every patch and obstruction polygon of a scene, flattened.
#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    /// Polygons: patches first (index = patch index), then obstructions.
    pub polys: Vec<PolyRec>,
    /// Their vertices, world coordinates.
    pub verts: Vec<DVec3>,
    /// Length scale of the scene (half its bounding-box diagonal), m.
    pub scale: f64,
    /// Scale of the near plane: `scale`, or [`LOCAL_SPAN`] times the smallest patch radius
    /// when that is smaller.
    pub near_scale: f64,
}

impl Prepared {
    /// Flattens `scene`.
    pub fn new(scene: &Scene) -> Self {
        let mut polys = Vec::with_capacity(scene.patches.len());
        let mut verts = Vec::new();
        let mut push = |poly: &crate::geometry::Polygon, patch: u32| {
            polys.push(PolyRec {
                first: verts.len() as u32,
                len: poly.vertices().len() as u32,
                centroid: poly.centroid(),
                normal: poly.normal(),
                radius: poly.bounding_radius(),
                patch,
            });
            verts.extend_from_slice(poly.vertices());
        };
        for (k, p) in scene.patches.iter().enumerate() {
            push(&p.polygon, k as u32);
        }
        for o in &scene.obstructions {
            for poly in &o.polygons {
                push(poly, NO_RECEIVER);
            }
        }
        let (lo, hi) =
            verts.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        let scale = if verts.is_empty() { 1.0 } else { (0.5 * (hi - lo).length()).max(f64::MIN_POSITIVE) };
        let smallest = polys.iter().map(|p| p.radius).fold(f64::INFINITY, f64::min);
        let near_scale = scale.min(LOCAL_SPAN * smallest).max(f64::MIN_POSITIVE);
        Self { polys, verts, scale, near_scale }
    }

    /// The in-plane tolerance between an eye (on a patch of radius `own`) and polygon `p`:
    /// `global` (relative to the scene), unless the local scale is much smaller.
    #[inline]
    fn local_tol(&self, global: f64, own: f64, eye: DVec3, p: &PolyRec) -> f64 {
        let local = own.max((p.centroid - eye).length() - p.radius);
        global.min(EYE_IN_PLANE_REL * LOCAL_SPAN * local)
    }

    /// Vertices of polygon `k`.
    pub fn vertices(&self, k: usize) -> &[DVec3] {
        let p = &self.polys[k];
        &self.verts[p.first as usize..(p.first + p.len) as usize]
    }

    /// Lower bound on the distance from `eye` to the nearest polygon in front of the plane
    /// (`eye`, `n`) other than `skip`; infinity when there is none.
    pub fn nearest_in_front(&self, eye: DVec3, n: DVec3, skip: usize) -> f64 {
        let tol = EYE_IN_PLANE_REL * self.scale;
        let own = self.polys.get(skip).map_or(0.0, |p| p.radius);
        let mut best = f64::INFINITY;
        for (k, p) in self.polys.iter().enumerate() {
            if k == skip {
                continue;
            }
            let ahead = (p.centroid - eye).dot(n);
            let facing = p.normal.dot(eye - p.centroid).abs();
            if (ahead + p.radius <= tol || facing <= tol) && {
                let tol = self.local_tol(tol, own, eye, p);
                ahead + p.radius <= tol || facing <= tol
            } {
                continue;
            }
            // Sphere and plane bounds: both are below the true point–polygon distance.
            let sphere = (p.centroid - eye).length() - p.radius;
            let plane = p.normal.dot(eye - p.centroid).abs();
            best = best.min(sphere.max(plane).max(0.0));
        }
        best
    }
}

/// One gathered polygon in the eye's local frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalPoly {
    /// First vertex in [`Gathered::verts`].
    pub first: u32,
    /// Vertex count.
    pub len: u32,
    /// Receiving patch, or [`NO_RECEIVER`].
    pub id: u32,
    /// Bounding-sphere centre, local.
    pub centre: DVec3,
    /// Bounding-sphere radius.
    pub radius: f64,
    /// Plane of the polygon, local: m·p = c with c ≠ 0 (the eye is off the plane).
    pub m: DVec3,
    /// Plane offset.
    pub c: f64,
}

/// The polygons an eye may see, in its local frame (a reusable buffer).
#[derive(Debug, Clone, Default)]
pub(crate) struct Gathered {
    /// Polygons.
    pub polys: Vec<LocalPoly>,
    /// Their vertices, local.
    pub verts: Vec<DVec3>,
}

impl Gathered {
    /// Vertices of gathered polygon `p`.
    pub fn vertices(&self, p: &LocalPoly) -> &[DVec3] {
        &self.verts[p.first as usize..(p.first + p.len) as usize]
    }

    /// Collects the polygons of `prep` that reach the eye's front half-space, skipping patch
    /// `own` and classifying receivers and blockers (module rules).
    pub fn gather(&mut self, prep: &Prepared, eye: &Frame, own: usize) {
        self.polys.clear();
        self.verts.clear();
        let tol = EYE_IN_PLANE_REL * prep.scale;
        let own_radius = prep.polys[own].radius;
        for (k, p) in prep.polys.iter().enumerate() {
            if k == own {
                continue;
            }
            // The scene-relative tests first; the local tolerance only when they would skip.
            let ahead = (p.centroid - eye.origin).dot(eye.n);
            if ahead + p.radius <= tol && ahead + p.radius <= prep.local_tol(tol, own_radius, eye.origin, p) {
                continue; // entirely behind (or in) the eye's plane
            }
            let facing = p.normal.dot(eye.origin - p.centroid);
            if facing.abs() <= tol && facing.abs() <= prep.local_tol(tol, own_radius, eye.origin, p) {
                continue; // the eye lies in this polygon's plane: zero projected area
            }
            let id = if facing > 0.0 { p.patch } else { NO_RECEIVER };
            let first = self.verts.len() as u32;
            self.verts.extend(prep.vertices(k).iter().map(|v| eye.point(*v)));
            self.polys.push(LocalPoly {
                first,
                len: p.len,
                id,
                centre: eye.point(p.centroid),
                radius: p.radius,
                m: eye.vector(p.normal),
                c: -facing,
            });
        }
    }
}
