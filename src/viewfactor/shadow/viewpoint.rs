//! Exact shadow clipping from one viewpoint (View3D's obstructed path, research/view3d.md §2):
//! the factor from an emitter element to the *shaded* part of a receiver.
//!
//! Setup, once per pair ([`ShadowGeometry::new`]):
//! - a frame with the receiver in z = 0 facing +z; the receiver, clipped to the emitter's front
//!   half-space, becomes a 2-D ring (convex pieces plus the half-planes of its convex hull);
//! - every candidate blocker is clipped to the slab that matters, in front of both the receiver
//!   (z ≥ 0) and the emitter's plane. Parts elsewhere meet no segment between the two.
//!
//! Per viewpoint p = (p_x, p_y, h), h > 0 ([`ShadowGeometry::shaded`]):
//! - central projection onto z = 0 is linear in homogeneous coordinates,
//!   (X, Y, W) = (h·x − z·p_x, h·y − z·p_y, h − z), so each blocker is clipped *before* the
//!   division by the planes through p and the receiver hull's edges (n·q + c ≥ 0 becomes
//!   n·(X, Y) + c·W ≥ 0). That keeps exactly the part between p and the receiver: no 0.9999·h
//!   cut as in View3D, no point at infinity (for a bounded convex hull the constraints force
//!   W > 0), and every shadow lands inside the hull;
//! - the shadows' union: with few shadows, as disjoint convex pieces (each new shadow minus
//!   the pieces so far, [`crate::geometry::convex::subtract_convex`]); with more (a meshed
//!   body's facets), by one polygon boolean ([`crate::geometry::union::Union`]). Faces of a
//!   solid turned away from p are skipped, so a closed body's shadow is the union of its front
//!   faces' shadows: the region bounded by its silhouette loops, whatever its shape; an open
//!   mesh (a sheet, a fin) contributes every facet;
//! - in the boolean, a closed body enters by its outline only: the edges its front faces share
//!   are dropped (both ways round), the rest chained into loops (`geometry::loops`),
//!   whose winding number counts the front faces over each point, so the non-zero region is the
//!   same; the boolean then splits crossings of silhouette edges only, not of every facet's
//!   edges over the layers behind (thousands per viewpoint on a meshed part). If the edges do
//!   not close, the whole faces are united instead;
//! - in fact the outline edges are found and chained on the mesh, before any projection
//!   (`super::silhouette`), and each loop is clipped by the hull's planes and projected as
//!   one ring: the same region, no front face clipped. Each front face is still tested
//!   against the hull's planes (its corners all inside, or all outside one) for the counted
//!   work and the seen mask, which are those of the face-by-face outline (kept for the
//!   loops that do not close, and for comparison: [`ShadowGeometry::set_silhouette`]);
//! - Lambert's formula over those pieces (or the union's oriented contours, holes clockwise)
//!   gives g(p) = F(dA_p → shaded part).
//!
//! The pair's exchange area is then A·F = (A·F)_unobstructed − ∫_E g dA, which never exceeds
//! the unobstructed value since g ≥ 0.
use super::silhouette::{Silhouette, Vertices};
use crate::geometry::clip::{clip_homogeneous, clip_homogeneous_labelled, clip_ring};
use crate::geometry::convex::{
    clip_convex, ear_indices, is_convex, subtract_convex, twice_area, HalfPlane, PieceSet,
    Scratch as OpsScratch,
};
use crate::geometry::frame::Frame;
use crate::geometry::loops::Loops;
use crate::geometry::tolerance::SHADOW_SNAP_REL;
use crate::geometry::union::Union;
use crate::viewfactor::exact::lambert::edge_term;
use glam::{DVec2, DVec3};
use std::f64::consts::TAU;

/// How much of the receiver one viewpoint found shaded.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Coverage {
    /// Shaded area, m².
    pub area: f64,
    /// Bit k set when active blocker k cast a non-empty shadow on the receiver hull.
    pub seen: u64,
    /// Bit k set when active blocker k, a closed body's face, was skipped as turned away from
    /// the viewpoint: nothing of that face is left unseen there, but it says nothing of the
    /// body's shadow (see `super::adaptive`'s check that every body was seen).
    pub away: u64,
    /// Counted work: [`VIEWPOINT_WORK`] for the viewpoint, 1 per active blocker projected, 1
    /// per shadow piece subtracted from one covered piece (or per shadow united).
    pub work: u64,
}

/// Work units of one viewpoint besides its blockers (the rule point, Lambert's sum over the
/// shaded pieces): its time over that of one blocker projection, about eight on the
/// calibration pairs of box_500_block and sphere_room (`examples/price_units.rs`).
pub const VIEWPOINT_WORK: u64 = 8;

/// Active blockers above which the faces of a convex body are merged by one convex hull
/// instead of one subtraction each (below it the subtractions are cheaper).
const HULL_MIN_ACTIVE: usize = 8;

/// Active blockers above which the shadows are united by one polygon boolean instead of one
/// subtraction each. The subtractions cost O(shadows × covered pieces) per viewpoint but skip
/// far pieces by their boxes; the boolean sweeps every edge once. Measured with Clipper2 and
/// closed bodies by their outline (validation/cad.md): 8, 24 and 64 within the noise on the
/// U-channel, fingers and boards; the six-fin heat sink (92 triangles) 1.4× slower with 8.
const UNION_MIN_ACTIVE: usize = 64;

/// Label of a projected face edge that runs along the receiver hull's boundary (no mesh edge).
const ALONG_HULL: u32 = u32::MAX;

/// Gap, in snap lengths, across which the outline's loose edge ends are joined: merging
/// vertices closer than the snap length moves an end by at most that much per merge.
const OUTLINE_JOIN: f64 = 16.0;

/// An obstructed pair in the receiver's frame.
#[derive(Debug, Clone)]
pub struct ShadowGeometry {
    frame: Frame,
    /// Emitter normal in the frame.
    n_e: DVec3,
    /// Emitter ring in the frame, clipped to the receiver's front half-space.
    emitter: Vec<DVec3>,
    /// Receiver, clipped to the emitter's front: convex pieces in z = 0.
    receiver: PieceSet,
    /// Vertices of the receiver pieces in the frame (z = 0), for classification.
    receiver_ring: Vec<DVec3>,
    /// Half-planes of the receiver's convex hull, and the hull itself.
    hull: Vec<HalfPlane>,
    hull_ring: Vec<DVec2>,
    /// True when the receiver is one convex piece (shadows need no further clipping).
    convex: bool,
    receiver_area: f64,
    /// Blockers in the frame, clipped to the slab in front of both planes.
    blockers: Vec<Vec<DVec3>>,
    /// Original index of each kept blocker.
    blocker_ids: Vec<u32>,
    /// Kept blockers whose ring is the one given (not cut by the slab).
    whole: Vec<bool>,
    /// Per kept blocker and edge, the kept blocker folding across it ([`Self::set_neighbours`]).
    neighbours: Vec<Vec<Option<u32>>>,
    /// Per kept blocker: for a face of a closed body with outward normals, its plane (the face
    /// is skipped from viewpoints behind it); else `None`.
    facing: Vec<Option<(DVec3, f64)>>,
    /// Per kept blocker: the convex body it is a face of, if any.
    body: Vec<Option<u32>>,
    /// Per kept blocker: a face of a solid with a neighbour across some edge, whose shadow
    /// enters the boolean by the outline it shares with its neighbours.
    outline: Vec<bool>,
    /// Per kept blocker: a face of an open (or not consistently closed) mesh with a neighbour
    /// across some edge; its shadow enters the boolean by the outline it shares with the
    /// neighbours turned the same way from the viewpoint (front faces with front faces, back
    /// faces with back faces).
    open_outline: Vec<bool>,
    /// Corner numbers of the outline faces.
    corners: Vertices,
    /// Active blockers above which the shadows are united by one boolean.
    union_min: usize,
    /// Closed bodies enter the union by their silhouette loops (else face by face).
    by_silhouette: bool,
    snap: f64,
}

/// Buffers reused across viewpoints.
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    hom: Vec<(DVec3, u32)>,
    hom2: Vec<(DVec3, u32)>,
    shadow: Vec<DVec2>,
    /// Per point of `shadow`, the label of the edge leaving it (see [`Outline::points`]).
    labels: Vec<u32>,
    /// The last projection turned clockwise and was turned round.
    reversed: bool,
    piece: Vec<DVec2>,
    shadow_tmp: Vec<DVec2>,
    covered: PieceSet,
    /// Bounding box of each covered piece (same order as `covered`).
    cover_boxes: Vec<[DVec2; 2]>,
    /// Per covered piece: the convex body whose front face cast it, if any.
    cover_bodies: Vec<Option<u32>>,
    frags: PieceSet,
    frags2: PieceSet,
    edges: Vec<HalfPlane>,
    ops: OpsScratch,
    body_pts: Vec<(u32, DVec2)>,
    hull_pts: Vec<DVec2>,
    union: Union,
    outline: Outline,
    /// The back faces of open meshes, turned counter-clockwise, outlined apart from the front
    /// faces.
    outline_back: Outline,
    silhouette: Silhouette,
    /// A silhouette loop in homogeneous coordinates while it is clipped.
    loop_hom: Vec<DVec3>,
    loop_hom2: Vec<DVec3>,
}

/// Buffers of one viewpoint's closed-body outline (the shadows of front faces with their edge
/// labels) and the count of viewpoints that fell back to whole faces.
#[derive(Debug, Clone, Default)]
struct Outline {
    /// Shadow points, each with the label of the edge leaving it (its index in the face ring,
    /// or [`ALONG_HULL`]).
    points: Vec<(DVec2, u32)>,
    /// Per projected face: the kept blocker and its range in `points`.
    faces: Vec<(u32, std::ops::Range<usize>)>,
    /// Per kept blocker: its face is among `faces`.
    included: Vec<bool>,
    loops: Loops,
    fallbacks: u64,
    /// Viewpoints whose outline closed and entered the union.
    outlined: u64,
}

impl Scratch {
    /// Viewpoints whose closed-body outline did not close, so that whole faces were united.
    pub fn outline_fallbacks(&self) -> u64 {
        self.outline.fallbacks + self.outline_back.fallbacks + self.silhouette.fallbacks
    }
}

impl Outline {
    /// Adds the shadow of face `k` with its edge labels.
    fn push(&mut self, k: u32, shadow: &[DVec2], labels: &[u32]) {
        let start = self.points.len();
        self.points.extend(shadow.iter().copied().zip(labels.iter().copied()));
        self.included[k as usize] = true;
        self.faces.push((k, start..self.points.len()));
    }
}

impl ShadowGeometry {
    /// Prepares emitter ring `e` (normal `n_e`), receiver ring `r` (normal `n_r`) and the
    /// candidate blocker rings (convex, world coordinates). `None` when the two patches do not
    /// face each other.
    pub fn new(e: &[DVec3], n_e: DVec3, r: &[DVec3], n_r: DVec3, blockers: &[&[DVec3]]) -> Option<Self> {
        let centroid = r.iter().copied().sum::<DVec3>() / r.len() as f64;
        let frame = Frame::new(centroid, n_r);
        let scale = r.iter().map(|v| v.distance(centroid)).fold(0.0, f64::max);
        let snap = SHADOW_SNAP_REL * scale;
        let n_el = frame.vector(n_e);
        // Emitter in the frame, kept in front of the receiver (z ≥ 0).
        let e_loc: Vec<DVec3> = e.iter().map(|&x| frame.point(x)).collect();
        let e_point = e_loc.iter().copied().sum::<DVec3>() / e_loc.len() as f64;
        let emitter = clip3(&e_loc, DVec3::Z, 0.0, snap);
        // Receiver in 2-D as convex pieces, kept in front of the emitter:
        // n_e·(q − e_point) ≥ 0 at z = 0.
        let r2: Vec<DVec2> = r.iter().map(|&x| frame.point(x).truncate()).collect();
        let front = HalfPlane::from_normal(n_el.truncate(), -n_el.dot(e_point));
        if front.is_none() && -n_el.dot(e_point) <= snap {
            return None;
        }
        let mut receiver = PieceSet::default();
        let mut piece = Vec::new();
        let convex = is_convex(&r2);
        let parts: Vec<Vec<DVec2>> = if convex {
            vec![r2]
        } else {
            ear_indices(&r2).iter().map(|t| t.map(|k| r2[k]).to_vec()).collect()
        };
        for part in &parts {
            match front {
                Some(h) => clip_convex(part, h, snap, &mut piece),
                None => piece.clone_from(part),
            }
            if twice_area(&piece) > snap * snap {
                receiver.push(&piece);
            }
        }
        if emitter.len() < 3 || receiver.is_empty() {
            return None;
        }
        let mut hull_pts: Vec<DVec2> = receiver.iter().flatten().copied().collect();
        let receiver_ring = hull_pts.iter().map(|q| q.extend(0.0)).collect();
        let mut hull_ring = Vec::new();
        crate::geometry::convex::convex_hull(&mut hull_pts, &mut hull_ring);
        let hull = edges_of(&hull_ring);
        let convex = convex && receiver.len() == 1;
        // Blockers: in front of the receiver (z ≥ 0) and of the emitter's plane.
        let mut kept = Vec::new();
        let mut ids = Vec::new();
        let mut whole = Vec::new();
        for (k, b) in blockers.iter().enumerate() {
            let loc: Vec<DVec3> = b.iter().map(|&x| frame.point(x)).collect();
            let a = clip3(&loc, DVec3::Z, 0.0, snap);
            let a = clip3(&a, n_el, -n_el.dot(e_point), snap);
            if a.len() >= 3 {
                whole.push(a == loc);
                kept.push(a);
                ids.push(k as u32);
            }
        }
        let receiver_area = receiver.area();
        Some(Self {
            frame,
            n_e: n_el,
            emitter,
            receiver,
            receiver_ring,
            hull,
            hull_ring,
            convex,
            receiver_area,
            blockers: kept,
            blocker_ids: ids,
            whole,
            neighbours: Vec::new(),
            facing: Vec::new(),
            body: Vec::new(),
            outline: Vec::new(),
            open_outline: Vec::new(),
            corners: Vertices::default(),
            union_min: UNION_MIN_ACTIVE,
            by_silhouette: true,
            snap,
        })
    }

    /// Records, per blocker given to [`Self::new`] and per edge, the blocker (same indexing)
    /// sharing that edge; links survive only between blockers the slab left whole.
    /// `closed` holds, per given blocker, [`super::blockers::Blocker::closed`] and
    /// [`super::blockers::Blocker::body`].
    pub fn set_neighbours(&mut self, given: &[Vec<Option<u32>>], closed: &[(i8, Option<u32>)]) {
        self.body = (0..self.blockers.len())
            .map(|k| closed.get(self.blocker_ids[k] as usize).and_then(|c| c.1))
            .collect();
        self.facing = (0..self.blockers.len())
            .map(|k| {
                // Only bodies whose normals point out (solid parts): a viewpoint inside a body
                // (an enclosure meshed with inward normals) sees out only through faces turned
                // away from it, so there every face is kept.
                let sign = f64::from(closed.get(self.blocker_ids[k] as usize)?.0);
                let plane = super::volume::plane_of(&self.blockers[k])?;
                (sign > 0.0).then_some((plane.n, plane.d))
            })
            .collect();
        let mut kept_of = vec![None; given.len()];
        for (k, &id) in self.blocker_ids.iter().enumerate() {
            if self.whole[k] {
                kept_of[id as usize] = Some(k as u32);
            }
        }
        self.neighbours = (0..self.blockers.len())
            .map(|k| {
                let id = self.blocker_ids[k] as usize;
                match given.get(id) {
                    Some(edges) if self.whole[k] && edges.len() == self.blockers[k].len() => edges
                        .iter()
                        .map(|c| c.and_then(|c| kept_of.get(c as usize).copied().flatten()))
                        .collect(),
                    _ => Vec::new(),
                }
            })
            .collect();
        self.outline = (0..self.blockers.len())
            .map(|k| self.facing[k].is_some() && self.neighbours[k].iter().any(Option::is_some))
            .collect();
        self.open_outline = (0..self.blockers.len())
            .map(|k| {
                self.facing[k].is_none()
                    && self.body[k].is_none()
                    && self.neighbours[k].iter().any(Option::is_some)
            })
            .collect();
        self.corners = Vertices::new(&self.blockers, &self.outline);
    }

    /// Unites the shadows by one polygon boolean from more than `min` active blockers on
    /// (default `UNION_MIN_ACTIVE`).
    pub fn set_union_min(&mut self, min: usize) {
        self.union_min = min;
    }

    /// Takes closed bodies into the union by their silhouette loops (the default), or by
    /// their front faces' projected outline (`false`).
    pub fn set_silhouette(&mut self, on: bool) {
        self.by_silhouette = on;
    }

    /// The kept blocker folding across edge `e` of kept blocker `k`, if any.
    pub fn neighbour(&self, k: usize, e: usize) -> Option<u32> {
        self.neighbours.get(k).and_then(|v| v.get(e).copied().flatten())
    }

    /// True when kept blocker `k` is a face of a solid (outward normals) and every point of
    /// the convex `cell` (frame coordinates) lies behind its plane: from there it is skipped.
    pub fn turned_away(&self, k: usize, cell: &[DVec3]) -> bool {
        match self.facing.get(k) {
            Some(Some((n, d))) => cell.iter().all(|x| n.dot(*x) + d <= 0.0),
            _ => false,
        }
    }

    /// The frame.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }
    /// Emitter ring in the frame (clipped to the receiver's front).
    pub fn emitter(&self) -> &[DVec3] {
        &self.emitter
    }
    /// Emitter normal in the frame.
    pub fn emitter_normal(&self) -> DVec3 {
        self.n_e
    }
    /// The receiver's convex hull in the frame (z = 0), counter-clockwise.
    pub fn receiver_hull(&self) -> &[DVec2] {
        &self.hull_ring
    }
    /// Receiver vertices in the frame (z = 0); their convex hull bounds the receiver.
    pub fn receiver_ring(&self) -> &[DVec3] {
        &self.receiver_ring
    }
    /// Edges of the receiver pieces' convex hull in the frame (z = 0), as point pairs.
    pub fn receiver_edges(&self) -> Vec<(DVec3, DVec3)> {
        self.hull_ring
            .iter()
            .zip(self.hull_ring.iter().cycle().skip(1))
            .map(|(a, b)| (a.extend(0.0), b.extend(0.0)))
            .collect()
    }
    /// Kept blockers in the frame.
    pub fn blockers(&self) -> &[Vec<DVec3>] {
        &self.blockers
    }
    /// Index, in the list given to [`Self::new`], of kept blocker `k`.
    pub fn blocker_id(&self, k: usize) -> u32 {
        self.blocker_ids[k]
    }
    /// Receiver area after clipping, m².
    pub fn receiver_area(&self) -> f64 {
        self.receiver_area
    }
    /// Length below which points coincide.
    pub fn snap(&self) -> f64 {
        self.snap
    }

    /// F(dA_p → receiver) for a viewpoint p in the frame: the unobstructed integrand.
    pub fn unshaded(&self, p: DVec3) -> f64 {
        self.receiver.iter().map(|ring| lambert(p, self.n_e, ring)).sum()
    }

    /// g(p) = F(dA_p → shaded part of the receiver) with the blockers `active` (indices into
    /// [`Self::blockers`]); p in the frame with p.z > 0.
    pub fn shaded(&self, p: DVec3, active: &[u32], s: &mut Scratch) -> (f64, Coverage) {
        self.shaded_by(p, active, s, active.len() > self.union_min)
    }

    /// [`Self::shaded`], the shadows united by one polygon boolean (`unite`) or subtracted one
    /// by one.
    pub fn shaded_by(&self, p: DVec3, active: &[u32], s: &mut Scratch, unite: bool) -> (f64, Coverage) {
        let mut cov = Coverage { work: VIEWPOINT_WORK + active.len() as u64, ..Coverage::default() };
        s.covered.clear();
        s.cover_boxes.clear();
        s.cover_bodies.clear();
        s.body_pts.clear();
        let h = p.z;
        if !(h > self.snap) {
            return (0.0, cov);
        }
        let hull_bodies = active.len() > HULL_MIN_ACTIVE;
        s.union.clear();
        if unite && s.outline.included.len() < self.blockers.len() {
            s.outline.included.resize(self.blockers.len(), false);
            s.outline_back.included.resize(self.blockers.len(), false);
        }
        let by_silhouette = unite && self.by_silhouette;
        if by_silhouette && s.silhouette.front.len() < self.blockers.len() {
            s.silhouette.front.resize(self.blockers.len(), false);
        }
        for (bit, &k) in active.iter().enumerate() {
            if let Some(Some((n, d))) = self.facing.get(k as usize) {
                // Turned away: no sight line enters the body through it.
                if n.dot(p) + d <= 0.0 {
                    if bit < 64 {
                        cov.away |= 1 << bit;
                    }
                    continue;
                }
            }
            let convex_body = hull_bodies && self.body.get(k as usize).is_some_and(Option::is_some);
            // A face reaching the viewpoint's height (z ≥ h) leaves the region where central
            // projection keeps a loop's winding number (W = h − z > 0): it is projected on its
            // own instead (clipped by the hull's planes like any face), and its neighbours' loops
            // close along its edges.
            if by_silhouette
                && !convex_body
                && self.outline.get(k as usize) == Some(&true)
                && self.blockers[k as usize].iter().all(|x| x.z < h)
            {
                // A front face: its edges shared with other front faces never reach the
                // outline, so it is not projected; the work and the mask are the face's own.
                if self.casts(&self.blockers[k as usize], p, s) {
                    if bit < 64 {
                        cov.seen |= 1 << bit;
                    }
                    cov.work += u64::from(!s.reversed);
                }
                s.silhouette.add(k);
                continue;
            }
            if !self.project(&self.blockers[k as usize], p, s) {
                continue;
            }
            if bit < 64 {
                cov.seen |= 1 << bit;
            }
            if unite && self.open_outline.get(k as usize) == Some(&true) {
                // An open mesh's face: its shadow joins the outline of the faces turned the
                // same way (a shared edge is walked both ways by two consistently oriented
                // neighbours, so dropping it keeps the count of faces over each point).
                let o = if s.reversed { &mut s.outline_back } else { &mut s.outline };
                o.push(k, &s.shadow, &s.labels);
                cov.work += 1;
                continue;
            }
            if unite && !convex_body && self.outline.get(k as usize) == Some(&true) {
                // A front face's shadow turns counter-clockwise; one turned round by round-off
                // is seen edge-on (no area): left out, its neighbours keep their edges with it.
                if !s.reversed {
                    s.outline.push(k, &s.shadow, &s.labels);
                    cov.work += 1;
                }
                continue;
            }
            if let (true, Some(Some(body))) = (hull_bodies, self.body.get(k as usize)) {
                s.body_pts.extend(s.shadow.iter().map(|&q| (*body, q)));
                continue;
            }
            self.add(s, &mut cov, unite, self.front_body(k as usize));
        }
        // A convex body's shadow is the hull of its faces' shadows (each already cut to the
        // receiver hull, whose intersection with the body's shadow is convex).
        if !s.body_pts.is_empty() {
            s.body_pts.sort_unstable_by_key(|b| b.0);
            let mut start = 0;
            while start < s.body_pts.len() {
                let body = s.body_pts[start].0;
                let end = start + s.body_pts[start..].iter().take_while(|b| b.0 == body).count();
                s.hull_pts.clear();
                s.hull_pts.extend(s.body_pts[start..end].iter().map(|b| b.1));
                crate::geometry::convex::convex_hull(&mut s.hull_pts, &mut s.shadow);
                if s.shadow.len() >= 3 && twice_area(&s.shadow) > self.snap * self.snap {
                    self.add(s, &mut cov, unite, None);
                }
                start = end;
            }
        }
        if unite {
            if !s.outline.faces.is_empty() {
                self.unite_outline(s, false);
            }
            if !s.outline_back.faces.is_empty() {
                self.unite_outline(s, true);
            }
            if !s.silhouette.faces.is_empty() {
                self.unite_silhouette(p, s);
            }
            if !self.convex {
                for piece in self.receiver.iter() {
                    s.union.push_clip(piece);
                }
            }
            s.union.run(bounds(self.hull_ring.iter()));
            cov.area = s.union.area();
            let g = s.union.contours().map(|ring| lambert(p, self.n_e, ring)).sum::<f64>();
            return (g.max(0.0), cov);
        }
        cov.area = s.covered.area();
        let g = s.covered.iter().map(|ring| lambert(p, self.n_e, ring)).sum::<f64>();
        (g.max(0.0), cov)
    }

    /// The convex body of kept blocker `k` when `k` is a face of it with outward normals (so
    /// [`Self::shaded_by`] only projects it from viewpoints in front of it).
    fn front_body(&self, k: usize) -> Option<u32> {
        match (self.facing.get(k), self.body.get(k)) {
            (Some(Some(_)), Some(Some(body))) => Some(*body),
            _ => None,
        }
    }

    /// Puts this viewpoint's outlined faces into the union (the closed bodies' and open meshes'
    /// front faces, or the open meshes' back faces turned round: `back`): their outline (the
    /// edges no two included faces share, chained into loops), or the whole faces when it does
    /// not close.
    fn unite_outline(&self, s: &mut Scratch, back: bool) {
        let o = if back { &mut s.outline_back } else { &mut s.outline };
        o.loops.clear();
        for (k, range) in &o.faces {
            let ring = &o.points[range.clone()];
            for (i, &(q, label)) in ring.iter().enumerate() {
                let shared = label != ALONG_HULL
                    && self.neighbour(*k as usize, label as usize).is_some_and(|j| o.included[j as usize]);
                if !shared {
                    o.loops.push(q, ring[(i + 1) % ring.len()].0);
                }
            }
        }
        if o.loops.chain(OUTLINE_JOIN * self.snap) {
            o.outlined += 1;
            for ring in o.loops.rings() {
                s.union.push(ring);
            }
        } else {
            o.fallbacks += 1;
            for (_, range) in &o.faces {
                s.shadow.clear();
                s.shadow.extend(o.points[range.clone()].iter().map(|v| v.0));
                s.union.push(&s.shadow);
            }
        }
        for (k, _) in &o.faces {
            o.included[*k as usize] = false;
        }
        o.faces.clear();
        o.points.clear();
    }

    /// Puts this viewpoint's front outline faces into the union by their silhouette loops,
    /// each clipped by the receiver hull and projected; or by the faces' projected outline
    /// ([`Self::unite_outline`]) when the loops do not close.
    fn unite_silhouette(&self, p: DVec3, s: &mut Scratch) {
        let closed = s.silhouette.chain(&self.blockers, &self.corners, |k, e| self.neighbour(k, e));
        if closed {
            let sil = std::mem::take(&mut s.silhouette);
            for ring in sil.rings() {
                if self.project_loop(ring, p, s) {
                    s.union.push(&s.shadow);
                }
            }
            s.silhouette = sil;
        } else {
            s.silhouette.fallbacks += 1;
            for f in 0..s.silhouette.faces.len() {
                let k = s.silhouette.faces[f];
                if self.project(&self.blockers[k as usize], p, s) && !s.reversed {
                    s.outline.push(k, &s.shadow, &s.labels);
                }
            }
            if !s.outline.faces.is_empty() {
                self.unite_outline(s, false);
            }
        }
        s.silhouette.clear();
    }

    /// Clips the closed loop `ring` (frame points, any shape) by the planes through p and the
    /// receiver hull's edges in homogeneous coordinates and projects it from p onto z = 0,
    /// into `s.shadow`. The winding number of what is left is the loop's inside the hull and
    /// 0 outside (see [`super::silhouette`]). False when fewer than three points remain.
    fn project_loop(&self, ring: &[DVec3], p: DVec3, s: &mut Scratch) -> bool {
        let h = p.z;
        s.loop_hom.clear();
        s.loop_hom.extend(ring.iter().map(|x| DVec3::new(h * x.x - x.z * p.x, h * x.y - x.z * p.y, h - x.z)));
        for e in &self.hull {
            clip_homogeneous(&s.loop_hom, DVec3::new(e.n.x, e.n.y, e.c), &mut s.loop_hom2);
            std::mem::swap(&mut s.loop_hom, &mut s.loop_hom2);
            if s.loop_hom.len() < 3 {
                return false;
            }
        }
        let w_min = 1e-12 * h;
        let snap2 = self.snap * self.snap;
        s.shadow.clear();
        for v in &s.loop_hom {
            let w = v.z.max(w_min);
            let q = DVec2::new(v.x / w, v.y / w);
            if s.shadow.last().is_none_or(|l| l.distance_squared(q) > snap2) {
                s.shadow.push(q);
            }
        }
        while s.shadow.len() > 1 && s.shadow[0].distance_squared(*s.shadow.last().unwrap()) <= snap2 {
            s.shadow.pop();
        }
        s.shadow.len() >= 3
    }

    /// The shadow in `s.shadow` (cast by a front face of convex body `body`, if any) joins the
    /// union to be taken (`unite`, one work unit), or is merged into the covered pieces at once.
    fn add(&self, s: &mut Scratch, cov: &mut Coverage, unite: bool, body: Option<u32>) {
        if unite {
            s.union.push(&s.shadow);
            cov.work += 1;
        } else {
            self.merge(s, cov, body);
        }
    }

    /// Adds the shadow in `s.shadow` (counter-clockwise, inside the receiver hull; cast by a
    /// front face of convex body `body`, if any) to the covered pieces `s.covered`, minus what
    /// they already cover.
    fn merge(&self, s: &mut Scratch, cov: &mut Coverage, body: Option<u32>) {
        let snap = self.snap;
        {
            // Shadow ∩ receiver pieces (already inside the hull when the receiver is convex).
            s.frags.clear();
            if self.convex {
                s.frags.push(&s.shadow);
            } else {
                edges_into(&s.shadow, &mut s.edges);
                for piece in self.receiver.iter() {
                    intersect(piece, &s.edges, snap, &mut s.piece, &mut s.shadow_tmp);
                    if twice_area(&s.piece) > snap * snap {
                        s.frags.push(&s.piece);
                    }
                }
            }
            // Minus what earlier shadows already cover. A covered piece whose box lies more
            // than `snap` away from the fragments' box cannot cut them (most pieces of a
            // meshed body's shadow lie elsewhere), so it is passed over unread.
            // A sight line from outside a convex body enters it through one front face, so the
            // shadows of one body's front faces do not overlap: no subtraction between them.
            let mut frag_box = bounds(s.frags.iter().flatten());
            for c in 0..s.covered.len() {
                if s.frags.is_empty() {
                    break;
                }
                if boxes_apart(&frag_box, &s.cover_boxes[c], snap)
                    || body.is_some() && s.cover_bodies[c] == body
                {
                    continue;
                }
                let cover = s.covered.piece(c);
                edges_into(cover, &mut s.edges);
                s.frags2.clear();
                cov.work += s.frags.len() as u64;
                for f in 0..s.frags.len() {
                    let piece = s.frags.piece(f);
                    if boxes_apart(&bounds(piece.iter()), &s.cover_boxes[c], snap) {
                        s.frags2.push(piece);
                        continue;
                    }
                    subtract_convex(piece, &s.edges, snap, snap * snap, &mut s.frags2, &mut s.ops);
                }
                std::mem::swap(&mut s.frags, &mut s.frags2);
                frag_box = bounds(s.frags.iter().flatten());
            }
            for f in 0..s.frags.len() {
                let piece = s.frags.piece(f);
                s.cover_boxes.push(bounds(piece.iter()));
                s.cover_bodies.push(body);
                s.covered.push(piece);
            }
        }
    }

    /// Projects blocker `b` from p onto z = 0 inside the receiver hull, into `s.shadow`
    /// (counter-clockwise; `s.reversed` when it had to be turned round), with the label of
    /// each point's leaving edge in `s.labels` (its index in `b`, or [`ALONG_HULL`]). False
    /// when nothing remains.
    fn project(&self, b: &[DVec3], p: DVec3, s: &mut Scratch) -> bool {
        Self::lift(b, p, s);
        self.clip_hull(s) && self.divide(p.z, s)
    }

    /// [`Self::project`]'s answer (and `s.reversed`), the face's corners tested first: all
    /// inside the hull's planes, the clip would keep them as they are and is skipped; all
    /// outside one plane, nothing is left.
    fn casts(&self, b: &[DVec3], p: DVec3, s: &mut Scratch) -> bool {
        Self::lift(b, p, s);
        let mut inside = true;
        for e in &self.hull {
            let l = DVec3::new(e.n.x, e.n.y, e.c);
            let kept = s.hom.iter().filter(|v| l.dot(v.0) >= 0.0).count();
            if kept == 0 {
                return false;
            }
            inside &= kept == s.hom.len();
        }
        (inside || self.clip_hull(s)) && self.divide(p.z, s)
    }

    /// Blocker `b` in homogeneous coordinates from p, each corner labelled by its index.
    fn lift(b: &[DVec3], p: DVec3, s: &mut Scratch) {
        let h = p.z;
        s.hom.clear();
        s.hom.extend(
            b.iter()
                .enumerate()
                .map(|(e, x)| (DVec3::new(h * x.x - x.z * p.x, h * x.y - x.z * p.y, h - x.z), e as u32)),
        );
    }

    /// Clips `s.hom` by the planes through p and the receiver hull's edges; false when fewer
    /// than three points remain.
    fn clip_hull(&self, s: &mut Scratch) -> bool {
        for e in &self.hull {
            clip_homogeneous_labelled(&s.hom, DVec3::new(e.n.x, e.n.y, e.c), ALONG_HULL, &mut s.hom2);
            std::mem::swap(&mut s.hom, &mut s.hom2);
            if s.hom.len() < 3 {
                return false;
            }
        }
        true
    }

    /// Divides the clipped `s.hom` (viewpoint height `h`) into `s.shadow` and `s.labels`,
    /// merging points within the snap length and turning the ring counter-clockwise; false
    /// when no area is left.
    fn divide(&self, h: f64, s: &mut Scratch) -> bool {
        let w_min = 1e-12 * h;
        let snap2 = self.snap * self.snap;
        s.shadow.clear();
        s.labels.clear();
        for &(v, label) in &s.hom {
            let w = v.z.max(w_min);
            let q = DVec2::new(v.x / w, v.y / w);
            match s.shadow.last() {
                // Merged into the last point: the edge leaving it is now about q's.
                Some(l) if l.distance_squared(q) <= snap2 => *s.labels.last_mut().unwrap() = label,
                _ => {
                    s.shadow.push(q);
                    s.labels.push(label);
                }
            }
        }
        while s.shadow.len() > 1 && s.shadow[0].distance_squared(*s.shadow.last().unwrap()) <= snap2 {
            s.shadow.pop();
            s.labels.pop();
        }
        let a2 = twice_area(&s.shadow);
        s.reversed = a2 < 0.0;
        if s.reversed {
            // Point k now leaves along the edge that arrived at it.
            s.shadow.reverse();
            s.labels.reverse();
            s.labels.rotate_left(1);
        }
        s.shadow.len() >= 3 && a2.abs() > snap2
    }
}

impl HalfPlane {
    /// n·q + c ≥ 0 with `n` normalised; `None` for a zero normal.
    pub fn from_normal(n: DVec2, c: f64) -> Option<Self> {
        let len = n.length();
        (len > 1e-14).then(|| Self { n: n / len, c: c / len })
    }
}

/// Lambert (docs/literature.md V12) for the ring `q` in z = 0 seen from p with unit normal n:
/// (1/2π) Σ_k β_k n·(R_{k+1} × R_k)/‖R_{k+1} × R_k‖, R_k = (q_k, 0) − p.
pub(super) fn lambert(p: DVec3, n: DVec3, ring: &[DVec2]) -> f64 {
    let m = ring.len();
    let mut sum = 0.0;
    let mut a = ring[m - 1].extend(0.0) - p;
    for q in ring {
        let b = q.extend(0.0) - p;
        sum += edge_term(n, a, b);
        a = b;
    }
    sum / TAU
}

/// Clips a planar 3-D ring to n·x + c ≥ 0 (snapping within `snap` of the plane).
fn clip3(src: &[DVec3], n: DVec3, c: f64, snap: f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(src.len() + 2);
    clip_ring(src, |x| n.dot(x) + c, snap, &mut out);
    out
}

/// Axis-aligned bounding box [min, max] of the points (inverted when there are none).
fn bounds<'a>(pts: impl Iterator<Item = &'a DVec2>) -> [DVec2; 2] {
    pts.fold([DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)], |[lo, hi], &q| {
        [lo.min(q), hi.max(q)]
    })
}

/// True when boxes `a` and `b` are more than `gap` apart along x or y.
#[inline]
fn boxes_apart(a: &[DVec2; 2], b: &[DVec2; 2], gap: f64) -> bool {
    a[0].x > b[1].x + gap || b[0].x > a[1].x + gap || a[0].y > b[1].y + gap || b[0].y > a[1].y + gap
}

fn edges_of(ring: &[DVec2]) -> Vec<HalfPlane> {
    let mut v = Vec::new();
    edges_into(ring, &mut v);
    v
}

fn edges_into(ring: &[DVec2], out: &mut Vec<HalfPlane>) {
    out.clear();
    let m = ring.len();
    out.extend((0..m).filter_map(|k| HalfPlane::left_of(ring[k], ring[(k + 1) % m])));
}

/// `piece` ∩ (inside of every edge), into `out`.
fn intersect(piece: &[DVec2], edges: &[HalfPlane], snap: f64, out: &mut Vec<DVec2>, buf: &mut Vec<DVec2>) {
    out.clear();
    out.extend_from_slice(piece);
    for e in edges {
        clip_convex(out, *e, snap, buf);
        std::mem::swap(out, buf);
        if out.is_empty() {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Polygon;
    use crate::scene::Scene;
    use crate::viewfactor::shadow::adaptive::{AdaptScratch, Cell, Cuts, Integrator};
    use crate::viewfactor::shadow::blockers::Blockers;
    use crate::viewfactor::shadow::pair::OWN_FACES_CUTS;
    use crate::viewfactor::shadow::policy::{AUTO_ADAPT, AUTO_CUTS};

    /// Two ways of taking the same union agree this closely, relative to the unshaded value.
    const AGREE_REL: f64 = 1e-9;

    /// Heat-sink profile (a base and three fins, the middle one short), counter-clockwise.
    const FINS: &[[f64; 2]] = &[
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 0.8],
        [0.9, 0.8],
        [0.9, 0.2],
        [0.55, 0.2],
        [0.55, 0.4],
        [0.45, 0.4],
        [0.45, 0.2],
        [0.1, 0.2],
        [0.1, 0.8],
        [0.0, 0.8],
    ];

    /// The closed, outward triangle mesh of FINS extruded along y, standing between the
    /// planes z = 0 and z = 1.5.
    fn fins() -> Vec<Polygon> {
        super::super::prism::extrude(FINS, |q, w| {
            DVec3::new(0.2 + 0.6 * q.x, 0.8 - 0.6 * w, 0.45 + 0.6 * q.y)
        })
    }

    /// An emitter triangle below the fins (z = 0) and a receiver triangle above them (z = 1.5),
    /// facing each other across them.
    fn below_and_above() -> (Vec<DVec3>, Vec<DVec3>) {
        let d = DVec3::new;
        (
            vec![d(-0.2, -0.2, 0.0), d(1.4, -0.2, 0.0), d(-0.2, 1.4, 0.0)],
            vec![d(1.2, 1.2, 1.5), d(1.2, -0.2, 1.5), d(-0.2, 1.2, 1.5)],
        )
    }

    /// The shadow geometry of an emitter and a receiver around one meshed body (its faces'
    /// neighbours set, as a row sets them), and each face's (closed, body) labels.
    fn body_geometry(
        emitter: Vec<DVec3>,
        receiver: Vec<DVec3>,
        body: Vec<Polygon>,
    ) -> (ShadowGeometry, Vec<(i8, Option<u32>)>) {
        let (e, r) = (Polygon::new(emitter).unwrap(), Polygon::new(receiver).unwrap());
        let scene = Scene::builder()
            .surface("emitter", vec![e.clone()], 1.0, None)
            .surface("receiver", vec![r.clone()], 1.0, None)
            .obstruction("body", body)
            .ambient(0.0)
            .build();
        let blockers = Blockers::new(&scene);
        let rings: Vec<&[DVec3]> = (0..blockers.len()).map(|k| blockers.get(k).ring.as_slice()).collect();
        let mut geo =
            ShadowGeometry::new(e.vertices(), e.normal(), r.vertices(), r.normal(), &rings).unwrap();
        let across: Vec<Vec<Option<u32>>> =
            (0..blockers.len()).map(|k| blockers.get(k).across.clone()).collect();
        let closed: Vec<(i8, Option<u32>)> =
            (0..blockers.len()).map(|k| (blockers.get(k).closed, blockers.get(k).body)).collect();
        geo.set_neighbours(&across, &closed);
        (geo, closed)
    }

    /// Largest |united − subtracted| over a grid of viewpoints on the emitter, relative to the
    /// unshaded value, and the largest shaded fraction seen.
    fn compare(emitter: Vec<DVec3>, receiver: Vec<DVec3>, body: Vec<Polygon>) -> (f64, f64) {
        let (geo, closed) = body_geometry(emitter, receiver, body);
        let active: Vec<u32> = (0..geo.blockers().len() as u32).collect();
        assert!(active.len() > 20, "a meshed body: {} blockers", active.len());
        let solid = closed.iter().all(|c| c.0 == 1);
        assert_eq!(geo.outline.iter().any(|&o| o), solid, "closed solids enter the boolean by their outline");
        let mut s = Scratch::default();
        let agreement = union_against_subtraction(&geo, &active, &mut s, |_, _, _| {});
        assert_eq!(s.outline_fallbacks(), 0, "every closed-body outline closed");
        agreement
    }

    /// Over an 11 × 11 grid of viewpoints on the emitter (its ring's fan from the first
    /// vertex), `active`'s shadows united by one boolean and subtracted one by one: the same
    /// shaded area and mask at every viewpoint, and `check(p, subtracted coverage, scratch)`
    /// run after the subtraction. Returns the largest |united − subtracted| relative to the
    /// unshaded value, and the largest shaded fraction seen.
    fn union_against_subtraction(
        geo: &ShadowGeometry,
        active: &[u32],
        s: &mut Scratch,
        mut check: impl FnMut(DVec3, &Coverage, &Scratch),
    ) -> (f64, f64) {
        let (mut worst, mut most) = (0.0f64, 0.0f64);
        let ring = geo.emitter().to_vec();
        for a in 1..12 {
            for b in 1..12 {
                let (u, v) = (a as f64 / 12.0, b as f64 / 12.0);
                let p = ring[0] + u * (ring[1] - ring[0]) + v * (1.0 - u) * (ring[2] - ring[0]);
                let whole = geo.unshaded(p);
                let (g1, c1) = geo.shaded_by(p, active, s, true);
                let (g0, c0) = geo.shaded_by(p, active, s, false);
                worst = worst.max((g1 - g0).abs() / whole);
                assert!((c1.area - c0.area).abs() <= AGREE_REL * geo.receiver_area(), "{c1:?} vs {c0:?}");
                assert_eq!(c1.seen, c0.seen);
                most = most.max(g0 / whole);
                check(p, &c0, s);
            }
        }
        (worst, most)
    }

    /// A square frame (a closed body with a through hole along z), outward triangles.
    fn frame() -> Vec<Polygon> {
        let at = |q: DVec2, w: f64| DVec3::new(0.2 + 0.6 * q.x, 0.2 + 0.6 * q.y, 0.45 + 0.6 * w);
        let tri = |a, b, c| Polygon::new(vec![a, b, c]).unwrap();
        let square = |lo: f64, hi: f64| {
            [DVec2::new(lo, lo), DVec2::new(hi, lo), DVec2::new(hi, hi), DVec2::new(lo, hi)]
        };
        let (o, i) = (square(0.0, 1.0), square(0.3, 0.7));
        let mut out = Vec::new();
        // Walls: the outer ring counter-clockwise, the inner one clockwise (solid on the left).
        let walls =
            o.iter().zip(o.iter().cycle().skip(1)).chain(i.iter().rev().zip(i.iter().rev().cycle().skip(1)));
        for (&a, &b) in walls {
            out.push(tri(at(a, 0.0), at(b, 0.0), at(b, 1.0)));
            out.push(tri(at(a, 0.0), at(b, 1.0), at(a, 1.0)));
        }
        for k in 0..4 {
            let (o0, o1, i0, i1) = (o[k], o[(k + 1) % 4], i[k], i[(k + 1) % 4]);
            out.push(tri(at(o0, 1.0), at(o1, 1.0), at(i1, 1.0)));
            out.push(tri(at(o0, 1.0), at(i1, 1.0), at(i0, 1.0)));
            out.push(tri(at(i1, 0.0), at(o1, 0.0), at(o0, 0.0)));
            out.push(tri(at(i0, 0.0), at(i1, 0.0), at(o0, 0.0)));
        }
        out
    }

    /// Largest |silhouette − face-by-face| over a grid of viewpoints, relative to the unshaded
    /// value (both united by one boolean, the same work and mask), the largest shaded fraction,
    /// and how many distinct sets of front faces the grid saw.
    fn by_silhouette(emitter: Vec<DVec3>, receiver: Vec<DVec3>, body: Vec<Polygon>) -> (f64, f64, usize) {
        let (geo, _) = body_geometry(emitter, receiver, body);
        let a = silhouette_against_faces(&geo);
        (a.worst, a.most, a.fronts)
    }

    /// What [`silhouette_against_faces`] found over its grid of viewpoints.
    struct Agreement {
        /// Largest |silhouette − face-by-face| relative to the unshaded value.
        worst: f64,
        /// Largest shaded fraction.
        most: f64,
        /// Distinct sets of front faces.
        fronts: usize,
        /// Viewpoints with a blocker corner at or above their height.
        past: usize,
    }

    /// [`ShadowGeometry::shaded_by`] with silhouette loops against the face-by-face outline on
    /// a 15 × 15 grid of the emitter's viewpoints, every blocker active (the same work, mask
    /// and shaded area up to round-off, and no outline falling back).
    fn silhouette_against_faces(geo: &ShadowGeometry) -> Agreement {
        let mut faces = geo.clone();
        faces.set_silhouette(false);
        let active: Vec<u32> = (0..geo.blockers().len() as u32).collect();
        let mut out = Agreement { worst: 0.0, most: 0.0, fronts: 0, past: 0 };
        let mut fronts = std::collections::BTreeSet::new();
        let (mut s1, mut s0) = (Scratch::default(), Scratch::default());
        let ring = geo.emitter().to_vec();
        for a in 1..16 {
            for b in 1..16 {
                let (u, v) = (a as f64 / 16.0, b as f64 / 16.0);
                let p = ring[0] + u * (ring[1] - ring[0]) + v * (1.0 - u) * (ring[2] - ring[0]);
                let whole = geo.unshaded(p);
                let (g1, c1) = geo.shaded_by(p, &active, &mut s1, true);
                let (g0, c0) = faces.shaded_by(p, &active, &mut s0, true);
                out.worst = out.worst.max((g1 - g0).abs() / whole);
                out.most = out.most.max(g0 / whole);
                out.past += usize::from(geo.blockers().iter().any(|f| f.iter().any(|x| x.z >= p.z)));
                assert_eq!((c1.work, c1.seen), (c0.work, c0.seen), "the face-by-face work and mask");
                assert!((c1.area - c0.area).abs() <= AGREE_REL * geo.receiver_area(), "{c1:?} vs {c0:?}");
                let front: Vec<usize> = (0..geo.blockers().len())
                    .filter(|&k| geo.facing[k].is_some_and(|(n, d)| n.dot(p) + d > 0.0))
                    .collect();
                fronts.insert(front);
            }
        }
        assert_eq!(s1.outline_fallbacks(), 0, "every silhouette closed");
        out.fronts = fronts.len();
        out
    }

    #[test]
    fn a_concave_body_s_silhouette_loops_give_its_front_faces_region() {
        let d = DVec3::new;
        let (bottom, top) = below_and_above();
        // The fins' side planes cross the emitter: faces turn front and back across it.
        let (worst, most, fronts) = by_silhouette(bottom.clone(), top.clone(), fins());
        assert!(
            worst <= AGREE_REL && most > 0.3 && fronts > 3,
            "worst {worst}, shaded {most}, {fronts} fronts"
        );
        // A receiver smaller than the shadow: the loops are cut by its hull.
        let small = vec![d(0.7, 0.6, 1.5), d(0.7, 0.3, 1.5), d(0.4, 0.6, 1.5)];
        let (worst, most, _) = by_silhouette(bottom.clone(), small, fins());
        assert!(worst <= AGREE_REL && most > 0.5, "small receiver: worst {worst}, shaded {most}");
        // A wall beside the body looking at the floor: from its low viewpoints the body's top
        // lies above the viewpoint (W < 0 before the clip).
        let wall = vec![d(-0.3, -0.2, 0.1), d(-0.3, 1.4, 0.1), d(-0.3, 1.4, 2.0), d(-0.3, -0.2, 2.0)];
        let floor = vec![d(-0.2, -0.2, 0.0), d(1.4, -0.2, 0.0), d(1.4, 1.4, 0.0), d(-0.2, 1.4, 0.0)];
        let (worst, most, fronts) = by_silhouette(wall, floor, fins());
        assert!(
            worst <= AGREE_REL && most > 0.1 && fronts > 1,
            "wall: worst {worst}, shaded {most}, {fronts}"
        );
        // A body with a through hole: a loop turning clockwise.
        let (worst, most, _) = by_silhouette(bottom, top, frame());
        assert!(worst <= AGREE_REL && most > 0.2, "frame: worst {worst}, shaded {most}");
    }

    #[test]
    fn a_concave_body_reaching_past_the_viewpoint_s_height_keeps_its_silhouette_region() {
        let d = DVec3::new;
        // The floor under the fins emits towards the walls around them: from a viewpoint under
        // the body, the body's parts farther from the wall than the viewpoint lie past it
        // (W = h − z ≤ 0 in the wall's frame); those faces are projected on their own and the
        // loops of the others must still give the front faces' region.
        let floor = vec![d(-0.2, -0.2, 0.0), d(1.4, -0.2, 0.0), d(1.4, 1.4, 0.0), d(-0.2, 1.4, 0.0)];
        let walls = [
            vec![d(1.4, -0.2, 0.05), d(1.4, -0.2, 1.6), d(1.4, 1.4, 1.6), d(1.4, 1.4, 0.05)],
            vec![d(-0.4, 1.4, 0.05), d(-0.4, 1.4, 1.6), d(-0.4, -0.2, 1.6), d(-0.4, -0.2, 0.05)],
            vec![d(-0.2, -0.3, 0.05), d(-0.2, -0.3, 1.6), d(1.4, -0.3, 1.6), d(1.4, -0.3, 0.05)],
            vec![d(1.4, 0.3, 0.6), d(1.4, 0.3, 1.2), d(1.4, 0.7, 1.2), d(1.4, 0.7, 0.6)],
        ];
        for (k, wall) in walls.into_iter().enumerate() {
            let (worst, most, fronts) = by_silhouette(floor.clone(), wall, fins());
            assert!(
                worst <= AGREE_REL && most > 0.05 && fronts > 1,
                "wall {k}: worst {worst}, shaded {most}, {fronts} fronts"
            );
        }
    }

    /// A pair of the 7,582-triangle channel (`validation/cad.md`, 2026-11-28): triangle 337
    /// emitting to triangle 3383 past 159 of the part's faces, as `shadow::pair` handed them to
    /// the shadow geometry (read by [`dumped_pair`]).
    const CHANNEL_PAIR: &str = include_str!("testdata/channel_pair.txt");

    /// The shadow geometry of a pair dumped from `shadow::pair` (`e`/`r` rings, then per
    /// blocker: closed, body, the blocker across each edge, its ring; frame-free world
    /// coordinates, exact in their shortest decimals), and its blocker count.
    fn dumped_pair(text: &str) -> (ShadowGeometry, usize) {
        let points = |t: &str| -> Vec<DVec3> {
            let v: Vec<f64> = t.split_whitespace().map(|x| x.parse().unwrap()).collect();
            v.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect()
        };
        let (mut e, mut r, mut rings, mut across, mut closed) = (vec![], vec![], vec![], vec![], vec![]);
        for line in text.lines() {
            let (tag, rest) = line.split_once(' ').unwrap();
            match tag {
                "e" => e = points(rest),
                "r" => r = points(rest),
                _ => {
                    let (head, ring) = rest.split_once(" | ").unwrap();
                    let f: Vec<&str> = head.split(' ').collect();
                    closed.push((
                        f[0].parse::<i8>().unwrap(),
                        f[1].parse::<i64>().ok().and_then(|b| u32::try_from(b).ok()),
                    ));
                    across.push(if f[2] == "none" {
                        Vec::new()
                    } else {
                        f[2].split(',').map(|c| c.parse::<u32>().ok()).collect()
                    });
                    rings.push(points(ring));
                }
            }
        }
        let (pe, pr) = (Polygon::new(e).unwrap(), Polygon::new(r).unwrap());
        let refs: Vec<&[DVec3]> = rings.iter().map(Vec::as_slice).collect();
        let mut geo =
            ShadowGeometry::new(pe.vertices(), pe.normal(), pr.vertices(), pr.normal(), &refs).unwrap();
        geo.set_neighbours(&across, &closed);
        (geo, rings.len())
    }

    #[test]
    fn a_channel_pair_whose_faces_reach_past_the_viewpoint_keeps_its_silhouette_region() {
        let (geo, given) = dumped_pair(CHANNEL_PAIR);
        assert_eq!(given, 159);
        let Agreement { worst, most, past, .. } = silhouette_against_faces(&geo);
        // Faces reach past the viewpoints' height, and the shadow is large: before the loops
        // left those faces out, they gave up to 0.87 of the unshaded value too little shadow.
        assert!(past > 100 && most > 0.5, "{past} viewpoints with faces past them, shaded {most}");
        assert!(worst <= AGREE_REL, "silhouette against face by face: {worst}");
    }

    /// ∫_E g dA and the unshaded ∫_E over the emitter by the midpoint rule on 4^depth congruent
    /// triangles per fan triangle, every blocker active at every point (no per-cell
    /// classification): the reference of the dumped pairs.
    fn midpoint_reference(geo: &ShadowGeometry, depth: u32) -> (f64, f64) {
        let active: Vec<u32> = (0..geo.blockers().len() as u32).collect();
        let mut s = Scratch::default();
        let e = geo.emitter();
        let mut cells: Vec<Cell> = (1..e.len() - 1).map(|k| Cell::Tri([e[0], e[k], e[k + 1]])).collect();
        for _ in 0..depth {
            cells = cells.iter().flat_map(Cell::children).collect();
        }
        let (mut shaded, mut whole) = (0.0, 0.0);
        for c in &cells {
            let Cell::Tri([a, b, d]) = *c else { unreachable!() };
            let p = (a + b + d) / 3.0;
            shaded += c.area() * geo.shaded_by(p, &active, &mut s, true).0;
            whole += c.area() * geo.unshaded(p);
        }
        (shaded, whole)
    }

    /// `auto`'s integration (its rules and depths) of the pair `geo` with each of `cuts`, to a
    /// goal of 1e-4 of the unshaded value: within 1e-3 of it from the reference `shaded`.
    fn integrates_to_reference(geo: &ShadowGeometry, cuts: &[Cuts], (shaded, whole): (f64, f64)) {
        for &cuts in cuts {
            let info = Integrator::new(AUTO_ADAPT).with_cuts(cuts).shaded(
                geo,
                1e-4 * whole,
                &mut AdaptScratch::default(),
            );
            let off = (info.shaded - shaded).abs() / whole;
            assert!(
                off <= 1e-3,
                "{cuts:?}: shaded {} against {}, error estimate {:.1e}",
                info.shaded / whole,
                shaded / whole,
                info.error / whole
            );
        }
    }

    /// A pair of the channel (`validation/cad.md`): triangle 7449, a facet inside a bored hole,
    /// emitting (the smaller patch, with its own faces) to a floor patch past six facets of
    /// the hole, the nearest sharing an edge with it.
    const HOLE_PAIR: &str = include_str!("testdata/hole_pair.txt");

    #[test]
    fn a_facet_beside_its_blocker_keeps_the_shadow_in_every_cell() {
        let (geo, given) = dumped_pair(HOLE_PAIR);
        assert_eq!((given, geo.blockers().len()), (6, 6));
        let (shaded, whole) = midpoint_reference(&geo, 6);
        // About half the view is shaded; the cells along the shared edge once lost 0.15 of it.
        assert!((0.45..0.55).contains(&(shaded / whole)), "reference {}", shaded / whole);
        integrates_to_reference(&geo, &[OWN_FACES_CUTS, Cuts::ALL], (shaded, whole));
    }

    /// A pair of the channel (`validation/cad.md`): triangle 4056, a sliver of the flange's
    /// face, emitting to triangle 6415 past 162 of the part's faces, one of them the receiver's
    /// neighbour; about 1 % of the view is left.
    const FLANGE_PAIR: &str = include_str!("testdata/flange_pair.txt");

    #[test]
    fn a_receiver_beside_its_blocker_keeps_the_shadow_in_every_root_cell() {
        let (geo, given) = dumped_pair(FLANGE_PAIR);
        assert_eq!((given, geo.blockers().len()), (162, 162));
        let (shaded, whole) = midpoint_reference(&geo, 6);
        assert!((0.005..0.02).contains(&(1.0 - shaded / whole)), "reference left {}", 1.0 - shaded / whole);
        // `auto`'s cuts leave kinks to the adaptivity: a root cell's classification, its
        // crossing points through the receiver's corner on the blocker's plane, once cleared a
        // blocker and left 0.093 of the view instead of 0.012.
        integrates_to_reference(&geo, &[AUTO_CUTS, Cuts::ALL], (shaded, whole));
    }

    /// A pair of the enclosure with boards (`validation/cad.md`): floor patch 8 emitting to
    /// wall patch 14 of x = 0 past two faces of one board, its side and its underside.
    const BOARD_PAIR: &str = include_str!("testdata/board_pair.txt");

    #[test]
    fn a_body_whose_faces_turn_away_is_seen_only_where_its_shadow_falls() {
        let (geo, given) = dumped_pair(BOARD_PAIR);
        assert_eq!((given, geo.blockers().len()), (2, 2));
        let (shaded, _) = midpoint_reference(&geo, 7);
        // `auto`'s goal at a tolerance of 1e-4: 1e-4 × the smaller patch, the receiver.
        let goal = 1e-4 * geo.receiver_area();
        assert!((5.0..100.0).contains(&(shaded / goal)), "reference shadow {} goals", shaded / goal);
        // Cut along four pieces' worth of kink planes, most cells see no shadow from any rule
        // point while the underside still shades part of the receiver from part of the cell.
        // The side, turned away from those points, once counted as the board's shadow seen:
        // the cells were accepted with an error estimate of 0.00 goals, 1.57 goals off.
        for cuts in [Cuts::up_to(4, true), AUTO_CUTS] {
            let info =
                Integrator::new(AUTO_ADAPT).with_cuts(cuts).shaded(&geo, goal, &mut AdaptScratch::default());
            let off = (info.shaded - shaded).abs();
            assert!(
                off <= goal && info.error <= goal,
                "{cuts:?}: {:.2} goals off, error estimate {:.2} goals",
                off / goal,
                info.error / goal
            );
        }
    }

    #[test]
    fn a_convex_body_s_front_faces_are_merged_without_subtracting_each_other() {
        // A block of 12 outward triangles (a sheared box: flat faces), tilted so that two or three of its sides face the
        // emitter's points; the receiver catches part of its shadow.
        let block =
            super::super::prism::extrude(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], |q, w| {
                DVec3::new(
                    0.3 + 0.4 * q.x + 0.1 * w,
                    0.25 + 0.3 * q.y + 0.15 * q.x,
                    0.5 + 0.35 * w + 0.1 * q.y,
                )
            });
        let d = DVec3::new;
        let (geo, closed) = body_geometry(
            vec![d(-0.5, -0.4, 0.0), d(1.6, -0.3, 0.0), d(0.2, 1.5, 0.0)],
            vec![d(1.1, 1.2, 1.5), d(0.9, -0.2, 1.5), d(-0.1, 0.9, 1.5)],
            block,
        );
        assert!(closed.iter().all(|&c| c == (1, Some(0))), "one closed convex body: {closed:?}");
        // Six square faces (each face's two triangles are one blocker); at most
        // HULL_MIN_ACTIVE active faces take the subtraction path.
        assert_eq!(geo.blockers().len(), 6);
        let active: Vec<u32> = (0..geo.blockers().len() as u32).collect();
        assert!(active.len() <= HULL_MIN_ACTIVE);
        let mut several = 0usize;
        let (worst, most) = union_against_subtraction(&geo, &active, &mut Scratch::default(), |p, c0, s| {
            // Work: the viewpoint and one unit per active face, none for subtractions.
            assert_eq!(c0.work, VIEWPOINT_WORK + active.len() as u64, "at {p}");
            several += usize::from(s.covered.len() > 1);
        });
        assert!(worst <= AGREE_REL && most > 0.1 && several > 20, "worst {worst}, most {most}, {several}");
    }

    #[test]
    fn the_union_of_a_concave_body_s_shadows_matches_the_subtraction() {
        let d = DVec3::new;
        let (bottom, top) = below_and_above();
        let (worst, most) = compare(bottom.clone(), top.clone(), fins());
        assert!(worst <= AGREE_REL && most > 0.3, "worst {worst}, shaded up to {most}");
        // An open mesh: one side of the base gone (outlined front and back, as tested below).
        let mut open = fins();
        open.remove(0);
        let (worst, most) = compare(bottom.clone(), top.clone(), open);
        assert!(worst <= AGREE_REL && most > 0.3, "open: worst {worst}, shaded up to {most}");
        // A non-convex receiver (an L): the union is clipped by its pieces.
        let l = vec![
            d(1.2, 1.2, 1.5),
            d(1.2, -0.2, 1.5),
            d(0.5, -0.2, 1.5),
            d(0.5, 0.5, 1.5),
            d(-0.2, 0.5, 1.5),
            d(-0.2, 1.2, 1.5),
        ];
        let (worst, most) = compare(bottom.clone(), l, fins());
        assert!(worst <= AGREE_REL && most > 0.2, "L receiver: worst {worst}, shaded up to {most}");
        // A body with a through hole: its outline has a loop turning clockwise.
        let (worst, most) = compare(bottom, top, frame());
        assert!(worst <= AGREE_REL && most > 0.2, "frame: worst {worst}, shaded up to {most}");
    }

    #[test]
    fn an_open_mesh_enters_the_union_by_its_front_and_back_outlines() {
        let (bottom, top) = below_and_above();
        // One side of the base gone: through the opening the emitter sees faces from behind.
        let mut open = fins();
        open.remove(0);
        let united = |body: Vec<Polygon>| {
            let (geo, _) = body_geometry(bottom.clone(), top.clone(), body);
            let outlined = geo.open_outline.iter().filter(|&&o| o).count();
            let active: Vec<u32> = (0..geo.blockers().len() as u32).collect();
            let mut s = Scratch::default();
            let (worst, most) = union_against_subtraction(&geo, &active, &mut s, |_, _, _| {});
            assert_eq!(s.outline_fallbacks(), 0, "every outline closed");
            (worst, most, outlined, s.outline.outlined, s.outline_back.outlined)
        };
        let (worst, most, faces, front, back) = united(open.clone());
        assert!(faces > 20, "the open mesh's faces are outlined: {faces}");
        assert!(front > 0 && back > 0, "front and back outlines both used: {front}, {back}");
        assert!(worst <= AGREE_REL && most > 0.3, "worst {worst}, shaded up to {most}");
        // A face wound against its neighbours is linked to none of them: its shadow turns the
        // same way as theirs along the shared edge, which the outline keeps.
        let k = open.len() / 2;
        open[k] = Polygon::new(open[k].vertices().iter().rev().copied().collect()).unwrap();
        let (worst, most, _, front, back) = united(open);
        assert!(front > 0 && back > 0, "front and back outlines both used: {front}, {back}");
        assert!(worst <= AGREE_REL && most > 0.3, "wound against: worst {worst}, shaded up to {most}");
    }

    #[test]
    fn a_folded_open_sheet_s_outlines_give_the_union_of_its_facets() {
        // A 6 × 6 height field of steep, uneven slopes (triangulated, normals up): from the
        // emitter below, some facets face it and some turn away, and they fold over each other.
        let (bottom, top) = below_and_above();
        let n = 6;
        let height = |i: usize, j: usize| 0.75 + 0.3 * (((i * 7 + j * 13) * 37 % 11) as f64 / 10.0 - 0.5);
        let at = |i: usize, j: usize| {
            DVec3::new(0.1 + 0.8 * i as f64 / n as f64, 0.1 + 0.8 * j as f64 / n as f64, height(i, j))
        };
        let mut sheet = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                sheet.push(Polygon::new(vec![a, b, c]).unwrap());
                sheet.push(Polygon::new(vec![a, c, d]).unwrap());
            }
        }
        let (geo, closed) = body_geometry(bottom, top, sheet);
        assert!(closed.iter().all(|c| c.0 == 0), "an open sheet");
        let outlined = geo.open_outline.iter().filter(|&&o| o).count();
        assert_eq!(outlined, geo.blockers().len(), "every facet has a neighbour");
        let active: Vec<u32> = (0..geo.blockers().len() as u32).collect();
        let mut s = Scratch::default();
        let (worst, most) = union_against_subtraction(&geo, &active, &mut s, |_, _, _| {});
        assert_eq!(s.outline_fallbacks(), 0, "every outline closed");
        let (front, back) = (s.outline.outlined, s.outline_back.outlined);
        assert!(front > 0 && back > 0, "front and back outlines both used: {front}, {back}");
        assert!(worst <= AGREE_REL && most > 0.3, "worst {worst}, shaded up to {most}");
    }
}
