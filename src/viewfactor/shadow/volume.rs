//! Penumbra and umbra of a convex blocker lit by a convex emitter: exact, conservative
//! classification of a receiver into clear / fully blocked / partly shadowed.
//!
//! With E the emitter and B the blocker, a point y is *shadowed from somewhere* when a segment
//! from E to y crosses B (the penumbra V), and *shadowed from everywhere* when every segment
//! does (the umbra U).
//! - Every plane that separates E and B, touching both, bounds V: y = x + t(z − x), t ≥ 1,
//!   with π(x) ≤ 0 ≤ π(z), gives π(y) ≥ 0. So V lies in the intersection of the half-spaces
//!   of the separating planes through an edge of one polygon and a vertex of the other, and
//!   beyond B's plane. Using any subset of them stays conservative.
//! - U is the intersection of the cones from each point of E through B, beyond B. For each
//!   edge of B the wedge of planes through it is extremal at vertices of E, so U is bounded by
//!   B's plane and, per edge of B, the plane through it and the vertex of E that leaves every
//!   other vertex of E on B's side (the tightest of the wedge).
//!
//! A convex receiver outside one penumbra plane is clear; one inside every umbra plane is
//! blocked. Anything else is partial and goes to the shadow integrator.
use crate::geometry::clip::clip_ring_keep;
use crate::geometry::convex::{convex_disjoint, convex_hull, twice_area};
#[cfg(test)]
use crate::geometry::planes::centre_half;
pub(super) use crate::geometry::planes::plane_of;
use crate::geometry::planes::Plane;
pub use crate::visibility::boxes::Region;
use glam::{DVec2, DVec3};

/// How a receiver relates to one blocker's shadow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// No segment from the emitter to the receiver meets the blocker.
    Clear,
    /// Every segment meets it.
    Full,
    /// Some do, or the test cannot tell.
    Partial,
}

/// Bounding planes of the penumbra and umbra of one blocker for one emitter.
///
/// An emitter cut by the blocker's plane is split there: each part sees the blocker from one
/// side only, and a receiver is clear when it is clear of both parts' penumbrae (it can never be
/// wholly blocked, since segments within one side never cross the plane).
#[derive(Debug, Clone, Default)]
pub struct ShadowVolume {
    parts: [Part; 2],
    count: usize,
    split: [Vec<DVec3>; 2],
}

/// The volume for an emitter entirely on one side of the blocker's plane.
#[derive(Debug, Clone)]
struct Part {
    penumbra: Vec<Plane>,
    umbra: Vec<Plane>,
    umbra_valid: bool,
    /// True when E straddles B's plane: no bound is derived and everything is partial.
    unbounded: bool,
    snap: f64,
    /// B's plane, oriented away from E.
    pb: Plane,
    /// In-plane axes of B and B in them.
    axes: (DVec3, DVec3),
    b2: Vec<DVec2>,
    /// E's vertices.
    e: Vec<DVec3>,
    /// Buffers of [`Self::crossings_miss`]: the crossing points and their hull.
    pts: Vec<DVec2>,
    hull: Vec<DVec2>,
}

impl Default for Part {
    fn default() -> Self {
        Self {
            penumbra: Vec::new(),
            umbra: Vec::new(),
            umbra_valid: false,
            unbounded: true,
            snap: 0.0,
            pb: Plane { n: DVec3::Z, d: 0.0 },
            axes: (DVec3::X, DVec3::Y),
            b2: Vec::new(),
            e: Vec::new(),
            pts: Vec::new(),
            hull: Vec::new(),
        }
    }
}

/// How [`ShadowVolume::build_parts`] split the emitter.
enum Parts {
    /// B has no plane: one unbounded part.
    Unbounded,
    /// E lies in B's plane: nothing is ever shadowed.
    Never,
    /// E lies on one side: one part.
    One,
    /// E straddles B's plane: a part per side.
    Split,
}

/// Outcome of [`ShadowVolume::build`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Build {
    /// The blocker can shadow something.
    Casts,
    /// The emitter lies in the blocker's plane: nothing is ever shadowed.
    Never,
}

fn extremes(pts: &[DVec3], p: &Plane) -> (f64, f64) {
    pts.iter()
        .map(|&x| p.distance(x))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

impl ShadowVolume {
    /// Builds the volume of blocker `b` (convex ring) lit by emitter `e` (convex ring).
    /// `snap` is the length below which points count as on a plane.
    pub fn build(&mut self, e: &[DVec3], b: &[DVec3], snap: f64) -> Build {
        match self.build_parts(e, b, snap, |part, half, pb| {
            part.build(half, b, pb, snap);
            false
        }) {
            Parts::Never => Build::Never,
            _ => Build::Casts,
        }
    }

    /// [`Self::build`] then the exact classification of the convex ring `r` (the planes, then
    /// the segments' crossing points), stopping at the first penumbra plane that clears `r`
    /// (most blockers, when an integration cell is re-classified); `None` where `build` gives
    /// [`Build::Never`]. The same answer; the volume is then built only as far as that answer
    /// needed, so build it again before classifying anything else.
    pub fn build_classify_exact(
        &mut self,
        e: &[DVec3],
        b: &[DVec3],
        snap: f64,
        r: &[DVec3],
    ) -> Option<Class> {
        let mut class = Class::Clear;
        match self.build_parts(e, b, snap, |part, half, pb| {
            class = part.build_classify(half, b, pb, snap, r);
            class != Class::Clear
        }) {
            Parts::Never => None,
            Parts::Unbounded => Some(Class::Partial),
            // A part of a split emitter lies on the plane's side only: never wholly blocked.
            Parts::Split if class != Class::Clear => Some(Class::Partial),
            Parts::Split | Parts::One => Some(class),
        }
    }

    /// The parts of the volume: E whole when it lies on one side of B's plane, else its halves
    /// on each side; `each(part, e_part, pb)` builds one (pb oriented away from it) and stops
    /// the rest by returning true.
    fn build_parts(
        &mut self,
        e: &[DVec3],
        b: &[DVec3],
        snap: f64,
        mut each: impl FnMut(&mut Part, &[DVec3], Plane) -> bool,
    ) -> Parts {
        self.count = 0;
        let Some(pb) = plane_of(b) else {
            self.parts[0].unbounded = true;
            self.count = 1;
            return Parts::Unbounded;
        };
        let (lo, hi) = extremes(e, &pb);
        if lo >= -snap && hi <= snap {
            return Parts::Never;
        }
        if lo < -snap && hi > snap {
            // E straddles B's plane: one part per side.
            let [neg, pos] = &mut self.split;
            clip_side(e, pb.flipped(), snap, neg);
            clip_side(e, pb, snap, pos);
            for half in [&*neg, &*pos] {
                if half.len() >= 3 {
                    let (_, hi) = extremes(half, &pb);
                    let part = &mut self.parts[self.count];
                    self.count += 1;
                    if each(part, half, if hi > snap { pb.flipped() } else { pb }) {
                        break;
                    }
                }
            }
            return Parts::Split;
        }
        self.count = 1;
        each(&mut self.parts[0], e, if hi > snap { pb.flipped() } else { pb });
        Parts::One
    }

    /// Classifies a convex receiver ring with the bounding planes (fast, conservative).
    pub fn classify(&self, r: &[DVec3]) -> Class {
        self.classify_with(r, false)
    }

    /// As [`Self::classify`], and a receiver the planes leave partial is checked once more
    /// with the segments' crossing points (exact for a single part; about twice the cost).
    #[cfg(test)]
    pub fn classify_exact(&self, r: &[DVec3]) -> Class {
        self.classify_with(r, true)
    }

    fn classify_with(&self, r: &[DVec3], exact: bool) -> Class {
        match self.count {
            0 => Class::Clear,
            1 => self.parts[0].classify(r, exact),
            _ => {
                if self.parts[..self.count].iter().all(|p| p.classify(r, exact) == Class::Clear) {
                    Class::Clear
                } else {
                    Class::Partial
                }
            }
        }
    }

    /// True when the box [lo, hi] lies wholly outside the penumbra.
    #[cfg(test)]
    pub fn box_clear(&self, lo: DVec3, hi: DVec3) -> bool {
        let (c, h) = centre_half(lo, hi);
        self.box_clear_ch(c, h)
    }

    /// True when the box of centre `c` and half-extents `h` lies wholly outside the penumbra.
    #[inline]
    fn box_clear_ch(&self, c: DVec3, h: DVec3) -> bool {
        self.parts[..self.count].iter().all(|p| p.box_clear(c, h))
    }

    /// The box of centre `c` and half-extents `h` ([`crate::geometry::planes::centre_half`]) against the volume: `Out`
    /// clear of the penumbra, `In` inside the umbra (everything in it is blocked), else
    /// `Cross`. One box tested against many volumes computes `c` and `h` once.
    #[inline]
    pub fn box_region_ch(&self, c: DVec3, h: DVec3) -> Region {
        match self.count {
            0 => Region::Out,
            1 => self.parts[0].box_region(c, h),
            _ if self.box_clear_ch(c, h) => Region::Out,
            _ => Region::Cross,
        }
    }
}

impl Part {
    /// Builds from E entirely behind `pb` (B's plane oriented away from E).
    fn build(&mut self, e: &[DVec3], b: &[DVec3], pb: Plane, snap: f64) {
        self.build_until(e, b, pb, snap, true, |_| false);
    }

    /// [`Self::build`] then [`Self::classify`] of the convex ring `r` (exact), stopping at
    /// the first penumbra plane that clears `r`; the part is then built only that far.
    fn build_classify(&mut self, e: &[DVec3], b: &[DVec3], pb: Plane, snap: f64, r: &[DVec3]) -> Class {
        // No penumbra plane kept: each is tested against `r` as it is found.
        if self.build_until(e, b, pb, snap, false, |p| r.iter().all(|&x| p.distance(x) <= snap)) {
            return Class::Clear;
        }
        if self.umbra_valid && self.umbra.iter().all(|p| r.iter().all(|&x| p.distance(x) >= snap)) {
            return Class::Full;
        }
        let (mut pts, mut hull) = (std::mem::take(&mut self.pts), std::mem::take(&mut self.hull));
        let miss = self.crossings_miss_in(r, &mut pts, &mut hull);
        (self.pts, self.hull) = (pts, hull);
        if miss {
            Class::Clear
        } else {
            Class::Partial
        }
    }

    /// [`Self::build`], stopping (true) at the first penumbra plane for which `stop` holds;
    /// the penumbra planes are kept only when `keep`.
    fn build_until(
        &mut self,
        e: &[DVec3],
        b: &[DVec3],
        pb: Plane,
        snap: f64,
        keep: bool,
        mut stop: impl FnMut(&Plane) -> bool,
    ) -> bool {
        self.penumbra.clear();
        self.umbra.clear();
        self.snap = snap;
        self.unbounded = false;
        self.umbra_valid = false;
        let min_len = 1e-300;
        self.penumbra.push(pb);
        self.umbra.push(pb);
        self.pb = pb;
        if stop(&pb) {
            return true;
        }
        // Separating planes: edge of one polygon, vertex of the other.
        for (edges, verts) in [(b, e), (e, b)] {
            let m = edges.len();
            for k in 0..m {
                let (a, c) = (edges[k], edges[(k + 1) % m]);
                for &v in verts {
                    let Some(p) = Plane::through(a, c, v, min_len * (c - a).length()) else { continue };
                    let (elo, ehi) = extremes(e, &p);
                    let (e_behind, e_ahead) = (ehi <= snap, elo >= -snap);
                    if !(e_behind || e_ahead) {
                        // E on both sides: not separating, whatever B does.
                        continue;
                    }
                    let (blo, bhi) = extremes(b, &p);
                    let p = if e_behind && blo >= -snap {
                        p
                    } else if e_ahead && bhi <= snap {
                        p.flipped()
                    } else {
                        continue;
                    };
                    if stop(&p) {
                        return true;
                    }
                    // The same plane often comes from several edge–vertex pairs.
                    if keep
                        && !self
                            .penumbra
                            .iter()
                            .any(|q| q.n.dot(p.n) > 1.0 - 1e-12 && (q.d - p.d).abs() <= snap)
                    {
                        self.penumbra.push(p);
                    }
                }
            }
        }
        let (a1, _) = pb.n.any_orthonormal_pair();
        let a2 = pb.n.cross(a1);
        self.axes = (a1, a2);
        self.b2.clear();
        self.b2.extend(b.iter().map(|&v| DVec2::new(v.dot(a1), v.dot(a2))));
        if twice_area(&self.b2) < 0.0 {
            self.b2.reverse();
        }
        self.e.clear();
        self.e.extend_from_slice(e);
        self.umbra_valid = e.iter().all(|&x| pb.distance(x) < -snap);
        // Umbra: per edge of B, the tightest plane through it and a vertex of E (B's interior
        // inside): the one with every other vertex of E on B's side.
        if self.umbra_valid {
            let cb = b.iter().copied().sum::<DVec3>() / b.len() as f64;
            let m = b.len();
            for k in 0..m {
                let (a, c) = (b[k], b[(k + 1) % m]);
                let tightest = e.iter().find_map(|&v| {
                    let p = Plane::through(a, c, v, min_len)?;
                    let p = if p.distance(cb) >= 0.0 { p } else { p.flipped() };
                    e.iter().all(|&w| p.distance(w) >= -snap).then_some(p)
                });
                match tightest {
                    Some(p) => self.umbra.push(p),
                    None => self.umbra_valid = false,
                }
            }
        }
        false
    }

    /// Classifies a convex receiver ring: the bounding planes first, then, for what they leave
    /// partial, the crossing points of the segments with B's plane (see [`Self::crossings_miss`]).
    fn classify(&self, r: &[DVec3], exact: bool) -> Class {
        if self.unbounded {
            return Class::Partial;
        }
        let snap = self.snap;
        if self.penumbra.iter().any(|p| r.iter().all(|&x| p.distance(x) <= snap)) {
            return Class::Clear;
        }
        if self.umbra_valid && self.umbra.iter().all(|p| r.iter().all(|&x| p.distance(x) >= snap)) {
            return Class::Full;
        }
        if exact && self.crossings_miss(r) {
            return Class::Clear;
        }
        Class::Partial
    }

    /// True when no segment from E to the convex ring R crosses B. With E behind B's plane,
    /// only R's part beyond it matters, and a segment from x to y meets the plane at
    /// z(x, y); for fixed y, x ↦ z is a central projection (convexity preserved), and likewise
    /// for fixed x, so every z(x, y) lies in the hull of the z(v, w) over vertex pairs. A line
    /// separating that hull from B (2-D separating axes) proves the pair clear. This is the
    /// edge–edge case the bounding planes cannot see.
    fn crossings_miss(&self, r: &[DVec3]) -> bool {
        self.crossings_miss_in(r, &mut Vec::new(), &mut Vec::new())
    }

    /// [`Self::crossings_miss`] in the buffers `pts` and `hull`.
    fn crossings_miss_in(&self, r: &[DVec3], pts: &mut Vec<DVec2>, hull: &mut Vec<DVec2>) -> bool {
        let snap = self.snap;
        let pb = self.pb;
        let (a1, a2) = self.axes;
        pts.clear();
        let m = r.len();
        let mut push_beyond = |w: DVec3, dw: f64| {
            for &v in &self.e {
                let dv = pb.distance(v);
                let z = if dw - dv > 0.0 { v + (w - v) * (-dv / (dw - dv)).clamp(0.0, 1.0) } else { v };
                pts.push(DVec2::new(z.dot(a1), z.dot(a2)));
            }
        };
        // R clipped to B's far side, vertex by vertex.
        let mut a = r[m - 1];
        let mut da = pb.distance(a);
        for &w in r {
            let dw = pb.distance(w);
            if (da > 0.0 && dw < 0.0) || (da < 0.0 && dw > 0.0) {
                let x = a + (w - a) * (da / (da - dw));
                push_beyond(x, 0.0);
            }
            if dw >= 0.0 {
                push_beyond(w, dw);
            }
            a = w;
            da = dw;
        }
        if pts.is_empty() {
            return true;
        }
        convex_hull(pts, hull);
        convex_disjoint(hull, &self.b2, snap)
    }

    /// The box of centre `c`, half-extents `h` is outside a penumbra plane.
    #[inline]
    fn box_clear(&self, c: DVec3, h: DVec3) -> bool {
        !self.unbounded && self.penumbra.iter().any(|p| p.box_max_ch(c, h) <= self.snap)
    }

    #[inline]
    fn box_region(&self, c: DVec3, h: DVec3) -> Region {
        if self.box_clear(c, h) {
            Region::Out
        } else if self.umbra_valid
            && !self.unbounded
            && self.umbra.iter().all(|p| p.box_min_ch(c, h) >= self.snap)
        {
            Region::In
        } else {
            Region::Cross
        }
    }
}

/// The part of a convex ring with p(x) ≥ 0, vertices within `snap` of the plane kept on it
/// (a remainder under three vertices is kept: the caller tests it).
fn clip_side(ring: &[DVec3], p: Plane, snap: f64, out: &mut Vec<DVec3>) {
    clip_ring_keep(ring, |x| p.distance(x), snap, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geometry::fixtures::square;

    #[test]
    fn centred_blocker_is_partial_small_receiver_behind_it_is_full() {
        // Emitter z = 0, blocker 0.5² centred at z = 0.5.
        let e = square(0.0, 0.0, 0.0, 1.0, true);
        let b = square(0.5, 0.25, 0.25, 0.5, true);
        let mut v = ShadowVolume::default();
        assert_eq!(v.build(&e, &b, 1e-12), Build::Casts);
        assert_eq!(v.classify(&square(1.0, 0.0, 0.0, 1.0, false)), Class::Partial);
        // Just behind the blocker, its centre is in the umbra.
        assert_eq!(v.classify(&square(0.51, 0.45, 0.45, 0.1, false)), Class::Full);
        // Far to the side: clear. Between emitter and blocker: clear.
        assert_eq!(v.classify(&square(1.0, 3.0, 0.0, 1.0, false)), Class::Clear);
        assert_eq!(v.classify(&square(0.25, 0.4, 0.4, 0.2, false)), Class::Clear);
        assert!(v.box_clear(DVec3::new(3.0, 0.0, 0.9), DVec3::new(4.0, 1.0, 1.1)));
        assert!(!v.box_clear(DVec3::new(0.0, 0.0, 0.9), DVec3::new(1.0, 1.0, 1.1)));
    }

    #[test]
    fn a_large_blocker_covers_a_whole_receiver() {
        let e = square(0.0, 0.0, 0.0, 1.0, true);
        let b = square(0.5, -2.0, -2.0, 5.0, false);
        let mut v = ShadowVolume::default();
        v.build(&e, &b, 1e-12);
        assert_eq!(v.classify(&square(1.0, 0.0, 0.0, 1.0, false)), Class::Full);
    }

    #[test]
    fn coplanar_blocker_never_casts_and_straddling_emitter_is_conservative() {
        let e = square(0.0, 0.0, 0.0, 1.0, true);
        let mut v = ShadowVolume::default();
        assert_eq!(v.build(&e, &square(0.0, 2.0, 0.0, 1.0, true), 1e-12), Build::Never);
        // A vertical blocker through the emitter's middle.
        let b = vec![
            DVec3::new(0.5, -1.0, -1.0),
            DVec3::new(0.5, 2.0, -1.0),
            DVec3::new(0.5, 2.0, 1.0),
            DVec3::new(0.5, -1.0, 1.0),
        ];
        assert_eq!(v.build(&e, &b, 1e-12), Build::Casts);
        assert_eq!(v.classify(&square(1.0, 5.0, 5.0, 1.0, false)), Class::Partial);
    }

    /// Does the segment x → y cross the convex ring b (interior)?
    fn hits(x: DVec3, y: DVec3, b: &[DVec3]) -> bool {
        let p = plane_of(b).unwrap();
        let (dx, dy) = (p.distance(x), p.distance(y));
        if dx * dy >= 0.0 {
            return false;
        }
        let z = x + (y - x) * (dx / (dx - dy));
        let m = b.len();
        (0..m).all(|k| (b[(k + 1) % m] - b[k]).cross(z - b[k]).dot(p.n) > 0.0)
    }

    #[test]
    fn classification_agrees_with_sampled_segments() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut v = ShadowVolume::default();
        let mut counts = [0usize; 3];
        for case in 0..480 {
            let mut rnd =
                |s: f64| DVec3::new(rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>()) * s;
            let tri = |c: DVec3, s: f64, r: &mut dyn FnMut(f64) -> DVec3| {
                let (a, b, d) = (c + r(s) - s / 2.0, c + r(s) - s / 2.0, c + r(s) - s / 2.0);
                vec![a, b, d]
            };
            let e = tri(DVec3::ZERO, 1.0, &mut rnd);
            let b = if case % 4 == 3 {
                // A tall blocker whose plane cuts the emitter: the split volumes.
                let x = rnd(0.6).x - 0.3;
                vec![DVec3::new(x - 0.2, -3.0, -1.0), DVec3::new(x + 0.1, 3.0, -1.0), DVec3::new(x, 0.0, 3.0)]
            } else {
                tri(DVec3::new(0.0, 0.0, 1.0), if case % 4 == 0 { 1.0 } else { 6.0 }, &mut rnd)
            };
            let r = tri(DVec3::new(0.0, 0.0, 2.0), 1.5, &mut rnd);
            if v.build(&e, &b, 1e-12) == Build::Never {
                continue;
            }
            let class = if case % 2 == 0 { v.classify(&r) } else { v.classify_exact(&r) };
            counts[class as usize] += 1;
            // The fused build that stops at the first clearing plane answers alike.
            let exact = v.classify_exact(&r);
            assert_eq!(
                ShadowVolume::default().build_classify_exact(&e, &b, 1e-12, &r),
                Some(exact),
                "case {case}"
            );
            // Sample segments between random points of e and r.
            let mut bary = |t: &[DVec3]| {
                let (mut u, mut w) = (rng.random::<f64>(), rng.random::<f64>());
                if u + w > 1.0 {
                    (u, w) = (1.0 - u, 1.0 - w);
                }
                t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * w
            };
            for _ in 0..400 {
                let (x, y) = (bary(&e), bary(&r));
                let h = hits(x, y, &b);
                match class {
                    Class::Clear => assert!(!h, "case {case}: clear but blocked: e {e:?} b {b:?} r {r:?}"),
                    Class::Full => assert!(h, "case {case}: full but visible: e {e:?} b {b:?} r {r:?}"),
                    Class::Partial => {}
                }
            }
        }
        assert!(counts.iter().all(|&c| c >= 5), "every class exercised: {counts:?}");
    }

    /// A cell of a hole's facet in the channel (validation/cad.md) whose corner lies on the
    /// edge the facet shares with the blocker, the next facet of the hole: the crossing points
    /// through that corner are round-off twins of it. Their hull's edge between the twins
    /// pointed anywhere and "separated" the blocker, so every cell along the edge lost its
    /// shadow (F to a floor patch 0.66 of the unshaded value instead of 0.51).
    #[test]
    fn a_cell_touching_the_blocker_s_plane_at_its_edge_keeps_the_blocker() {
        let d = DVec3::new;
        let cell = [
            d(0.22708045291900636, 0.7148565483093261, 0.9524030818939209),
            d(0.22556592750549315, 0.7148565483093261, 0.9541396141052245),
            d(0.2257488031387329, 0.7171065483093262, 0.9533976573944092),
        ];
        let b = [
            d(0.22582949829101562, 0.7126065483093261, 0.9486621284484863),
            d(0.2268975772857666, 0.7126065483093261, 0.9531450386047363),
            d(0.2272633285522461, 0.7171065483093262, 0.9516611251831054),
        ];
        let r = [d(-0.25, -0.25, 0.0), d(0.25, -0.25, 0.0), d(0.25, 0.25, 0.0), d(-0.25, 0.25, 0.0)];
        // The corner lies on the blocker's plane (to round-off); segments from near it cross the
        // blocker.
        let on = plane_of(&b).unwrap().distance(cell[0]);
        assert!(on.abs() < 1e-14, "{on:e}");
        let mut crossing = 0;
        for (a, c) in (0..=10).flat_map(|a| (0..=10 - a).map(move |c| (a, c))) {
            let p =
                cell[0] + (cell[1] - cell[0]) * (a as f64 / 10.0) + (cell[2] - cell[0]) * (c as f64 / 10.0);
            for (x, y) in (0..=10).flat_map(|x| (0..=10).map(move |y| (x, y))) {
                let q = d(-0.25 + 0.05 * x as f64, -0.25 + 0.05 * y as f64, 0.0);
                crossing += usize::from(hits(p, q, &b));
            }
        }
        assert!(crossing > 0);
        let mut v = ShadowVolume::default();
        assert_eq!(v.build(&cell, &b, 3.5355339059327e-13), Build::Casts);
        assert_eq!(v.classify_exact(&r), Class::Partial, "{crossing} sampled segments cross the blocker");
        assert_eq!(v.build_classify_exact(&cell, &b, 3.5355339059327e-13, &r), Some(Class::Partial));
    }
}
