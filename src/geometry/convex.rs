//! 2-D convex polygon operations (behind exact shadow clipping and blocker classification).
//!
//! - [`HalfPlane`]: a unit-normal line n·q + c ≥ 0 (kept side); [`clip_convex`] clips a
//!   ring to one with the shared clipper (`super::clip::clip_ring`);
//! - [`subtract_convex`]: piece \ shadow as disjoint convex pieces (View3D's `PolygonOverlap`
//!   idea, without its 12-vertex limit), so a union of shadows leaves a non-convex remainder
//!   held as a [`PieceSet`];
//! - [`convex_hull`], [`convex_disjoint`], [`convex_contains`], [`is_convex`] (and
//!   [`is_convex_local`]): the 2-D tests of the blocker classification;
//! - [`ear_indices`]: ear clipping of a simple 2-D ring (non-convex receivers and emitters).
//!
//! Every ring is counter-clockwise. Nothing here allocates once the buffers have grown.
use super::clip::clip_ring;
use super::tolerance::{AXIS_EDGE_MIN_REL, CONVEX_TURN_REL, HULL_MERGE_REL};
use glam::DVec2;

/// Kept side of a line: `n·q + c ≥ 0`, `n` a unit vector, so `eval` is a signed distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfPlane {
    /// Unit normal pointing into the kept side.
    pub n: DVec2,
    /// Offset.
    pub c: f64,
}

impl HalfPlane {
    /// The left side of the directed edge a → b: the inside of a counter-clockwise ring.
    /// `None` for a zero-length edge.
    pub fn left_of(a: DVec2, b: DVec2) -> Option<Self> {
        let d = b - a;
        let len = d.length();
        if !(len > 0.0) {
            return None;
        }
        let n = DVec2::new(-d.y, d.x) / len;
        Some(Self { n, c: -n.dot(a) })
    }
    /// Signed distance of `q` from the line, positive on the kept side.
    #[inline]
    pub fn eval(&self, q: DVec2) -> f64 {
        self.n.dot(q) + self.c
    }
    /// The other side.
    pub fn flipped(&self) -> Self {
        Self { n: -self.n, c: -self.c }
    }
}

/// Twice the signed area of a ring (shoelace), positive when counter-clockwise.
pub fn twice_area(ring: &[DVec2]) -> f64 {
    let m = ring.len();
    if m < 3 {
        return 0.0;
    }
    let mut s = 0.0;
    let mut a = ring[m - 1];
    for &b in ring {
        s += a.perp_dot(b);
        a = b;
    }
    s
}

/// Clips the convex ring `src` to `hp`, writing the kept ring to `out` (cleared first).
/// Vertices within `snap` of the line count as on it, so no sliver thinner than `snap` and no
/// near-duplicate vertex is created.
pub fn clip_convex(src: &[DVec2], hp: HalfPlane, snap: f64, out: &mut Vec<DVec2>) {
    clip_ring(src, |q| hp.eval(q), snap, out);
}

/// Convex rings stored back to back: the unshaded remainder of a receiver.
#[derive(Debug, Clone, Default)]
pub struct PieceSet {
    verts: Vec<DVec2>,
    ends: Vec<usize>,
}

impl PieceSet {
    /// Removes every piece (keeps capacity).
    pub fn clear(&mut self) {
        self.verts.clear();
        self.ends.clear();
    }
    /// Appends one convex ring.
    pub fn push(&mut self, ring: &[DVec2]) {
        self.verts.extend_from_slice(ring);
        self.ends.push(self.verts.len());
    }
    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.ends.len()
    }
    /// True when nothing is left.
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }
    /// Piece `k`.
    pub fn piece(&self, k: usize) -> &[DVec2] {
        let start = if k == 0 { 0 } else { self.ends[k - 1] };
        &self.verts[start..self.ends[k]]
    }
    /// The pieces in order.
    pub fn iter(&self) -> impl Iterator<Item = &[DVec2]> + '_ {
        (0..self.len()).map(move |k| self.piece(k))
    }
    /// Total area.
    pub fn area(&self) -> f64 {
        0.5 * self.iter().map(twice_area).sum::<f64>()
    }
}

/// Reusable buffers for [`subtract_convex`].
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    cur: Vec<DVec2>,
    tmp: Vec<DVec2>,
    out: Vec<DVec2>,
}

/// Appends `piece` \ `shadow` to `out` as disjoint convex rings. `shadow` is given by the
/// half-planes of its edges (its inside is their intersection); rings whose doubled area is
/// below `min_area2` are dropped. Returns false when `shadow` missed `piece` (copied whole).
pub fn subtract_convex(
    piece: &[DVec2],
    shadow: &[HalfPlane],
    snap: f64,
    min_area2: f64,
    out: &mut PieceSet,
    s: &mut Scratch,
) -> bool {
    // Separating edge of the shadow: the piece is wholly outside it.
    if shadow.iter().any(|h| piece.iter().all(|&q| h.eval(q) <= snap)) {
        out.push(piece);
        return false;
    }
    s.cur.clear();
    s.cur.extend_from_slice(piece);
    for h in shadow {
        // The part beyond this edge is outside the shadow: keep it; go on with the rest.
        clip_convex(&s.cur, h.flipped(), snap, &mut s.out);
        if twice_area(&s.out) > min_area2 {
            out.push(&s.out);
        }
        clip_convex(&s.cur, *h, snap, &mut s.tmp);
        std::mem::swap(&mut s.cur, &mut s.tmp);
        if twice_area(&s.cur) <= min_area2 {
            return true;
        }
    }
    // What is left lies inside every edge: shaded.
    true
}

/// Convex hull of `pts` (Andrew's monotone chain), counter-clockwise, collinear points dropped
/// and points within `HULL_MERGE_REL` of each other taken once; `pts` is scratch (sorted and
/// compacted in place).
pub fn convex_hull(pts: &mut [DVec2], hull: &mut Vec<DVec2>) {
    hull.clear();
    pts.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    // Round-off twins of one point make a chain step of arbitrary direction, after which the
    // chain's local turn test keeps points inside the hull: take each point once.
    let m = compact_close(pts);
    let pts = &pts[..m];
    if pts.len() < 3 {
        hull.extend_from_slice(pts);
        return;
    }
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    for &p in pts.iter() {
        while hull.len() >= 2 && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    let lower = hull.len() + 1;
    for &p in pts.iter().rev().skip(1) {
        while hull.len() >= lower && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    hull.pop();
    merge_close(hull);
}

/// True when `a` and `b` lie within [`HULL_MERGE_REL`] of their coordinates' magnitude.
fn close(a: DVec2, b: DVec2) -> bool {
    (a - b).abs().max_element() <= HULL_MERGE_REL * a.abs().max(b.abs()).max_element()
}

/// Moves forward each point of `pts` not [`close`] to the last one kept; returns how many were
/// kept.
fn compact_close(pts: &mut [DVec2]) -> usize {
    let mut kept = 0;
    for k in 0..pts.len() {
        if kept == 0 || !close(pts[kept - 1], pts[k]) {
            pts[kept] = pts[k];
            kept += 1;
        }
    }
    kept
}

/// Drops each vertex of the ring `hull` within [`HULL_MERGE_REL`] of the last one kept (the
/// last also against the first): round-off twins of one point, as a projection through a
/// point on the plane makes, otherwise leave an edge of arbitrary direction.
fn merge_close(hull: &mut Vec<DVec2>) {
    let mut kept = compact_close(hull);
    while kept > 1 && close(hull[kept - 1], hull[0]) {
        kept -= 1;
    }
    hull.truncate(kept);
}

/// True when the convex counter-clockwise rings `a` and `b` are separated by a line through
/// an edge of either, allowing contact within `snap` (separating-axis test). A degenerate
/// ring (under three points) offers no edges, so the answer is then conservative: false
/// unless the other ring's edges separate.
pub fn convex_disjoint(a: &[DVec2], b: &[DVec2], snap: f64) -> bool {
    separated_by_edges(a, b, snap) || separated_by_edges(b, a, snap)
}

/// True when a line through an edge of `a` has every point of `b` on its outer side (within
/// `snap`). Edges shorter than [`AXIS_EDGE_MIN_REL`] of their coordinates are skipped: their
/// direction is round-off, and fewer axes only make the answer more conservative.
fn separated_by_edges(a: &[DVec2], b: &[DVec2], snap: f64) -> bool {
    let m = a.len();
    m >= 3
        && (0..m).any(|k| {
            let (p, q) = (a[k], a[(k + 1) % m]);
            if (q - p).length() <= AXIS_EDGE_MIN_REL * p.abs().max(q.abs()).max_element() {
                return false;
            }
            match HalfPlane::left_of(p, q) {
                Some(h) => b.iter().all(|&v| h.eval(v) <= snap),
                None => false,
            }
        })
}

/// True when two convex polygons overlap by more than `tol` along every separating-axis
/// candidate (the edge normals of both). Unlike [`convex_disjoint`] it takes either
/// orientation and compares projected intervals, with a thickness `tol` instead of a snap.
pub fn convex_overlap(a: &[DVec2], b: &[DVec2], tol: f64) -> bool {
    for poly in [a, b] {
        for k in 0..poly.len() {
            let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
            let axis = DVec2::new(q.y - p.y, p.x - q.x);
            let len = axis.length();
            if len == 0.0 {
                continue;
            }
            let proj = |s: &[DVec2]| {
                s.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    let d = v.dot(axis) / len;
                    (lo.min(d), hi.max(d))
                })
            };
            let ((alo, ahi), (blo, bhi)) = (proj(a), proj(b));
            if ahi <= blo + tol || bhi <= alo + tol {
                return false;
            }
        }
    }
    true
}

/// True when every point of `pts` lies in the convex counter-clockwise ring `ring`, at least
/// `margin` inside every edge.
pub fn convex_contains(ring: &[DVec2], pts: &[DVec2], margin: f64) -> bool {
    let m = ring.len();
    m >= 3
        && (0..m).all(|k| match HalfPlane::left_of(ring[k], ring[(k + 1) % m]) {
            Some(h) => pts.iter().all(|&q| h.eval(q) >= margin),
            None => true,
        })
}

/// True when every turn of the counter-clockwise ring is left or straight, a right turn down
/// to `CONVEX_TURN_REL` × (largest |q|²) counting as straight.
pub fn is_convex(ring: &[DVec2]) -> bool {
    let m = ring.len();
    let scale = ring.iter().map(|q| q.length_squared()).fold(0.0, f64::max);
    (0..m).all(|k| {
        let (a, b, c) = (ring[k], ring[(k + 1) % m], ring[(k + 2) % m]);
        (b - a).perp_dot(c - b) >= -CONVEX_TURN_REL * scale
    })
}

/// As [`is_convex`], a right turn down to `CONVEX_TURN_REL` × the product of the two edge
/// lengths at the corner counting as straight (the scale of [`Polygon::is_convex`](super::Polygon::is_convex)).
pub fn is_convex_local(ring: &[DVec2]) -> bool {
    let m = ring.len();
    (0..m).all(|k| {
        let (a, b, c) = (ring[k], ring[(k + 1) % m], ring[(k + 2) % m]);
        (b - a).perp_dot(c - b) >= -CONVEX_TURN_REL * (b - a).length() * (c - b).length()
    })
}

/// Ear clipping of a simple counter-clockwise 2-D ring: triangles as vertex indices.
pub fn ear_indices(ring: &[DVec2]) -> Vec<[usize; 3]> {
    let mut idx: Vec<usize> = (0..ring.len()).collect();
    let mut tris = Vec::new();
    let orient = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let mut guard = 0;
    while idx.len() > 3 && guard < ring.len() * ring.len() {
        guard += 1;
        let m = idx.len();
        let ear = (0..m).find(|&k| {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (ring[ia], ring[ib], ring[ic]);
            orient(a, b, c) > 0.0
                && !idx.iter().any(|&q| {
                    let p = ring[q];
                    q != ia
                        && q != ib
                        && q != ic
                        && orient(a, b, p) >= 0.0
                        && orient(b, c, p) >= 0.0
                        && orient(c, a, p) >= 0.0
                })
        });
        let Some(k) = ear else { break };
        tris.push([idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]]);
        idx.remove(k);
    }
    if idx.len() == 3 {
        tris.push([idx[0], idx[1], idx[2]]);
    }
    tris
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sq(x0: f64, y0: f64, s: f64) -> Vec<DVec2> {
        vec![DVec2::new(x0, y0), DVec2::new(x0 + s, y0), DVec2::new(x0 + s, y0 + s), DVec2::new(x0, y0 + s)]
    }

    fn edges(ring: &[DVec2]) -> Vec<HalfPlane> {
        (0..ring.len()).filter_map(|k| HalfPlane::left_of(ring[k], ring[(k + 1) % ring.len()])).collect()
    }

    #[test]
    fn clip_keeps_the_left_half() {
        let mut out = Vec::new();
        let h = HalfPlane::left_of(DVec2::new(0.25, 1.0), DVec2::new(0.25, 0.0)).unwrap();
        clip_convex(&sq(0.0, 0.0, 1.0), h, 0.0, &mut out);
        assert!((0.5 * twice_area(&out) - 0.75).abs() < 1e-15, "{out:?}");
        // Clipping along an edge keeps the square whole, without duplicate vertices.
        let h = HalfPlane::left_of(DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0)).unwrap();
        clip_convex(&sq(0.0, 0.0, 1.0), h, 1e-12, &mut out);
        assert_eq!(out.len(), 4);
    }

    #[test]
    fn subtracting_a_centred_hole_leaves_a_frame() {
        let mut set = PieceSet::default();
        let mut s = Scratch::default();
        let hole = sq(0.25, 0.25, 0.5);
        assert!(subtract_convex(&sq(0.0, 0.0, 1.0), &edges(&hole), 1e-14, 0.0, &mut set, &mut s));
        assert_eq!(set.len(), 4);
        assert!((set.area() - 0.75).abs() < 1e-15);
        for p in set.iter() {
            assert!(twice_area(p) > 0.0, "pieces stay counter-clockwise");
            assert!(convex_disjoint(p, &hole, 1e-12), "pieces never overlap the hole");
        }
    }

    #[test]
    fn union_of_overlapping_shadows_is_removed_once() {
        // Two overlapping shadows: remaining area = 1 − |A ∪ B| with |A ∪ B| = 0.25 + 0.25 − 0.0625.
        let mut a = PieceSet::default();
        let mut b = PieceSet::default();
        let mut s = Scratch::default();
        a.push(&sq(0.0, 0.0, 1.0));
        for shadow in [sq(0.1, 0.1, 0.5), sq(0.35, 0.35, 0.5)] {
            b.clear();
            for k in 0..a.len() {
                subtract_convex(a.piece(k), &edges(&shadow), 1e-14, 0.0, &mut b, &mut s);
            }
            std::mem::swap(&mut a, &mut b);
        }
        assert!((a.area() - (1.0 - 0.4375)).abs() < 1e-14, "{}", a.area());
        // A shadow covering everything leaves nothing.
        b.clear();
        for k in 0..a.len() {
            subtract_convex(a.piece(k), &edges(&sq(-1.0, -1.0, 3.0)), 1e-14, 0.0, &mut b, &mut s);
        }
        assert!(b.is_empty());
    }

    #[test]
    fn disjoint_shadow_is_a_cheap_copy() {
        let mut set = PieceSet::default();
        let mut s = Scratch::default();
        assert!(!subtract_convex(
            &sq(0.0, 0.0, 1.0),
            &edges(&sq(1.0, 0.0, 1.0)),
            1e-14,
            0.0,
            &mut set,
            &mut s
        ));
        assert_eq!(set.len(), 1);
        assert_eq!(set.piece(0), &sq(0.0, 0.0, 1.0)[..]);
    }

    #[test]
    fn hull_and_containment() {
        let mut pts = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.5, 0.5),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(0.5, 0.0),
        ];
        let mut hull = Vec::new();
        convex_hull(&mut pts, &mut hull);
        assert_eq!(hull.len(), 4, "{hull:?}");
        assert!((0.5 * twice_area(&hull) - 1.0).abs() < 1e-15);
        assert!(convex_contains(&sq(-0.1, -0.1, 1.2), &hull, 0.0));
        assert!(!convex_contains(&sq(0.0, 0.0, 0.9), &hull, 0.0));
        assert!(!convex_disjoint(&hull, &sq(0.9, 0.9, 1.0), 0.0));
        assert!(convex_disjoint(&hull, &sq(1.5, 0.0, 1.0), 0.0));
        // Diagonal separation needs the other ring's edge.
        let tri = [DVec2::new(1.2, 1.0), DVec2::new(2.0, 0.2), DVec2::new(2.0, 1.0)];
        assert!(convex_disjoint(&hull, &tri, 0.0));
        let touching = sq(1.0 - 1e-13, 0.0, 1.0);
        assert!(convex_disjoint(&hull, &touching, 1e-12), "contact within snap counts as apart");
        assert!(!convex_disjoint(&hull, &touching, 0.0));
    }

    #[test]
    fn overlap_needs_more_than_contact_in_either_orientation() {
        let v = |p: &[[f64; 2]]| p.iter().map(|&[x, y]| DVec2::new(x, y)).collect::<Vec<_>>();
        let sq = |x: f64| v(&[[x, 0.0], [x + 1.0, 0.0], [x + 1.0, 1.0], [x, 1.0]]);
        assert!(convex_overlap(&sq(0.0), &sq(0.5), 1e-9));
        assert!(!convex_overlap(&sq(0.0), &sq(1.0), 1e-9), "touching along an edge is not overlap");
        assert!(!convex_overlap(&sq(0.0), &sq(1.5), 1e-9));
        let tri = v(&[[1.2, -1.0], [2.0, 0.5], [1.2, 2.0]]);
        assert!(!convex_overlap(&sq(0.0), &tri, 1e-9));
        let cw: Vec<DVec2> = sq(0.5).into_iter().rev().collect();
        assert!(convex_overlap(&sq(0.0), &cw, 1e-9));
    }

    /// The crossing points of a blocker classification (`shadow::volume`) whose emitter cell
    /// touches the blocker's plane at the blocker's edge: two pairs of round-off twins, one of
    /// them on that edge. The hull once kept both twins, and the line through the twins'
    /// edge, pointing anywhere, "separated" the blocker that the hull overlaps.
    #[test]
    fn round_off_twins_neither_stay_in_a_hull_nor_separate_it() {
        let d = DVec2::new;
        let twins = vec![
            d(-0.06828393510377129, 0.2637112590673876),
            d(0.011638523756946004, -0.23628874093261243),
            d(1.0529186377995177, -0.5821482582551125),
            d(1.0577385925309113, -0.5820800663284191),
            d(1.057738592530912, -0.5820800663284176),
            d(1.0541539916580063, -0.5778468944628082),
            d(-0.06828393510377127, 0.26371125906738757),
        ];
        let blocker = [
            d(1.0573411797867398, -0.5844228224763632),
            d(1.0581360052750919, -0.5797373101804779),
            d(1.053561817874342, -0.5802977437901572),
        ];
        let snap = 3.5355339059327e-13;
        // The ring with its twins: their edge offers no axis.
        assert!(!convex_disjoint(&twins, &blocker, snap));
        // The hull of the same points keeps one of each pair.
        let (mut pts, mut hull) = (twins.clone(), Vec::new());
        convex_hull(&mut pts, &mut hull);
        assert_eq!(hull.len(), 5, "{hull:?}");
        assert!(!convex_disjoint(&hull, &blocker, snap));
        // A blocker corner inside the hull: they do overlap.
        assert!(blocker.iter().any(|&q| convex_contains(&hull, &[q], 1e-6)), "{hull:?}");
    }

    /// The crossing points of a blocker classification whose receiver has a corner on the
    /// blocker's plane: every emitter corner projects through it onto one point, six round-off
    /// twins of it. Chained one after the other, the twins turned the chain's test at random,
    /// and the "hull" kept two interior points and a line that "separated" the blocker.
    #[test]
    fn a_hull_through_six_twins_of_one_point_stays_convex_and_holds_every_point() {
        let d = DVec2::new;
        let twin = [
            d(-9.004677748541628e-5, -0.0013381168709545156),
            d(-9.004677748541626e-5, -0.0013381168709545156),
            d(-9.004677748541623e-5, -0.001338116870954519),
            d(-9.004677748541623e-5, -0.001338116870954519),
            d(-9.00467774854162e-5, -0.001338116870954519),
            d(-9.00467774854162e-5, -0.001338116870954519),
        ];
        let mut pts = vec![
            d(-0.00040648341809646914, 0.018602666366652143),
            d(-0.0003895525764349174, 0.01753574111124779),
        ];
        pts.extend(twin);
        pts.extend([
            d(0.04991775705321141, -0.03535721777342271),
            d(0.04994395118901568, -0.03700788497542802),
            d(0.07041069228283796, -0.05148571631969664),
            d(0.07042181822617334, -0.052186836215093464),
        ]);
        let all = pts.clone();
        let mut hull = Vec::new();
        convex_hull(&mut pts, &mut hull);
        // The twins once (with a corner collinear within 1e-10 kept or not), every turn left
        // or straight, every point inside.
        assert_eq!(hull.iter().filter(|q| (**q - twin[0]).length() < 1e-12).count(), 1, "{hull:?}");
        let m = hull.len();
        let turns =
            (0..m).map(|k| (hull[(k + 1) % m] - hull[k]).perp_dot(hull[(k + 2) % m] - hull[(k + 1) % m]));
        assert!(turns.clone().all(|t| t > -1e-15), "{:?}", turns.collect::<Vec<_>>());
        assert!(convex_contains(&hull, &all, -1e-15), "{hull:?}");
        let blocker = [
            d(0.016089431047620527, 0.001611578084757287),
            d(0.004049495637397961, 0.012195666336118663),
            d(0.0058387215550749294, 0.0029799560443099196),
        ];
        assert!(!convex_disjoint(&hull, &blocker, 3.286125287654079e-15));
    }
}
