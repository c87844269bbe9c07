//! Which pairs of a row are obstructed, and by what (exact and conservative).
//!
//! For row i:
//! 1. the blockers with a point strictly in front of patch i come from the blocker hierarchy;
//! 2. each is clipped to i's front half-space (the rest meets no segment leaving i) and its
//!    penumbra and umbra from i are built (`super::volume`);
//! 3. the patch hierarchy is walked once for all these volumes: a subtree is pruned when it is
//!    clear of every penumbra, blocked whole when it is inside some umbra, and the remaining
//!    receivers that face i are classified one by one against the volumes still in play:
//!    clear, fully blocked or partial.
//!
//! A receiver absent from the result is unobstructed. The cost follows the receivers near each
//! blocker's shadow boundary, not N × blockers.
use super::blockers::{bounds, Blockers};
use super::volume::{Build, Class, Region, ShadowVolume};
use crate::geometry::clip::clip_ring;
use crate::geometry::planes::centre_half;
use crate::geometry::shaft::Shaft;
use crate::geometry::Polygon;
use crate::scene::Scene;
use glam::DVec3;

/// The obstruction status of receiver j in a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status<'a> {
    /// No blocker reaches the pair.
    Clear,
    /// Some single blocker intercepts every segment between the two patches: F = 0.
    Blocked,
    /// These blockers (indices into `Blockers`) may cut some segments.
    Partial(&'a [u32]),
}

const CLEAR: u8 = 0;
const BLOCKED: u8 = 1;
const PARTIAL: u8 = 2;

/// The classification of one row; dense per receiver, reset in time proportional to the
/// receivers touched.
#[derive(Debug, Clone, Default)]
pub struct RowShadows {
    mark: Vec<u8>,
    /// Per partial receiver: start of its blockers in `blockers`, and their number.
    span: Vec<(u32, u32)>,
    touched: Vec<u32>,
    blockers: Vec<u32>,
    partial: Vec<(u32, u32)>,
    row_blockers: Vec<u32>,
    ring: Vec<DVec3>,
    volumes: Vec<ShadowVolume>,
    ids: Vec<u32>,
    /// Per patch-tree node, then per patch: `stamp` where a row limited to its receivers
    /// wants them.
    nodes: Vec<u32>,
    wanted: Vec<u32>,
    stamp: u32,
    /// Per blocker: `stamp` once a row limited to its receivers has taken it.
    seen: Vec<u32>,
}

impl RowShadows {
    /// Status of receiver `j` (any j ≥ the row's first receiver).
    #[inline]
    pub fn status(&self, j: usize) -> Status<'_> {
        match self.mark.get(j).copied().unwrap_or(CLEAR) {
            CLEAR => Status::Clear,
            BLOCKED => Status::Blocked,
            _ => {
                let (start, len) = self.span[j];
                Status::Partial(&self.blockers[start as usize..(start + len) as usize])
            }
        }
    }
    /// Receivers with a non-clear status, unordered.
    pub fn touched(&self) -> &[u32] {
        &self.touched
    }
    fn reset(&mut self, n: usize) {
        if self.mark.len() != n {
            self.mark = vec![CLEAR; n];
            self.span = vec![(0, 0); n];
        } else {
            for &j in &self.touched {
                self.mark[j as usize] = CLEAR;
            }
        }
        self.touched.clear();
        self.blockers.clear();
        self.partial.clear();
    }
}

/// Classifies the receivers j ≥ `first` (j ≠ i) of row `i` into `out`.
pub fn classify_row(scene: &Scene, blockers: &Blockers, i: usize, first: usize, out: &mut RowShadows) {
    classify_row_in(scene, blockers, i, first, None, out);
}

/// The blockers a row of emitter `pi` is classified against, into `out` (in the blocker
/// tree's order): those whose box reaches in front of the emitter's plane, less a solid's
/// faces turned away from all of the emitter (never crossed first).
pub fn row_blockers(blockers: &Blockers, pi: &Polygon, out: &mut Vec<u32>) {
    let snap = blockers.snap();
    let plane = (pi.normal(), pi.normal().dot(pi.centroid()));
    out.clear();
    blockers.blockers_where(|lo, hi| reaches_front(plane, lo, hi, snap), out);
    out.retain(|&b| !blockers.turned_from(b as usize, pi.vertices()));
}

/// True when some point of the box [lo, hi] lies more than `snap` in front of the plane
/// (n, offset).
#[inline]
fn reaches_front((n, off): (DVec3, f64), lo: DVec3, hi: DVec3, snap: f64) -> bool {
    n.dot(0.5 * (lo + hi)) + n.abs().dot(0.5 * (hi - lo)) - off > snap
}

/// The blockers of row `i` limited to `receivers` into `out.row_blockers`: those of
/// [`row_blockers`] that also meet the shaft of patch i and some receiver (every sight line of
/// the pair lies in it), found by one blocker-tree walk per receiver. Uses the row's stamp
/// (`out.stamp`, set for these receivers) to take each blocker once.
fn shaft_blockers(scene: &Scene, blockers: &Blockers, i: usize, js: &[u32], out: &mut RowShadows) {
    let snap = blockers.snap();
    let pi = &scene.patches[i].polygon;
    let plane_i = (pi.normal(), pi.normal().dot(pi.centroid()));
    let bi = bounds(pi.vertices());
    let (stamp, seen, list) = (out.stamp, &mut out.seen, &mut out.row_blockers);
    list.clear();
    for &j in js {
        let pj = &scene.patches[j as usize].polygon;
        let plane_j = (pj.normal(), pj.normal().dot(pj.centroid()));
        let shaft = Shaft::new(bi, bounds(pj.vertices()), snap);
        blockers.walk_blockers(
            |lo, hi| {
                reaches_front(plane_i, lo, hi, snap)
                    && reaches_front(plane_j, lo, hi, snap)
                    && shaft.meets_box(lo, hi)
            },
            |k| {
                if seen[k as usize] != stamp && may_cut(&shaft, plane_j, &blockers.get(k as usize).ring, snap)
                {
                    seen[k as usize] = stamp;
                    if !blockers.turned_from(k as usize, pi.vertices()) {
                        list.push(k);
                    }
                }
            },
        );
    }
}

/// False when blocker `ring` cannot cut a sight line of a patch pair: it lies outside the
/// pair's box `shaft`, or on or behind the receiver's plane (n, offset) to `snap`, which
/// every sight line leaves from its front.
pub fn may_cut(shaft: &Shaft, (n, off): (DVec3, f64), ring: &[DVec3], snap: f64) -> bool {
    ring.iter().any(|&v| n.dot(v) - off > snap) && shaft.meets_points(ring)
}

/// As [`classify_row`] for the `receivers` only (any order) when given: only blockers that may
/// cut a sight line of some pair (i, j) ([`may_cut`]) are considered, and the walk enters only
/// the patch tree's nodes above the receivers. Any receiver's status is what the whole row
/// gives it, once each pair keeps the partial blockers that may cut its own sight lines.
pub fn classify_row_in(
    scene: &Scene,
    blockers: &Blockers,
    i: usize,
    first: usize,
    receivers: Option<&[u32]>,
    out: &mut RowShadows,
) {
    out.reset(scene.patches.len());
    if blockers.is_empty() {
        return;
    }
    let region = receivers.map(|js| {
        js.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), &j| {
            let (l, h) = bounds(scene.patches[j as usize].polygon.vertices());
            (lo.min(l), hi.max(h))
        })
    });
    let tree = blockers.patch_tree();
    let marked = receivers.map(|js| {
        if out.nodes.len() != tree.node_count()
            || out.wanted.len() != scene.patches.len()
            || out.seen.len() != blockers.len()
        {
            out.nodes = vec![0; tree.node_count()];
            out.wanted = vec![0; scene.patches.len()];
            out.seen = vec![0; blockers.len()];
            out.stamp = 0;
        }
        out.stamp = out.stamp.wrapping_add(1);
        if out.stamp == 0 {
            out.nodes.fill(0);
            out.wanted.fill(0);
            out.seen.fill(0);
            out.stamp = 1;
        }
        tree.mark_paths(js.iter().copied(), out.stamp, &mut out.nodes);
        for &j in js {
            out.wanted[j as usize] = out.stamp;
        }
        out.stamp
    });
    let snap = blockers.snap();
    let pi = &scene.patches[i].polygon;
    let (ni, off) = (pi.normal(), pi.normal().dot(pi.centroid()));
    let meets = |(rl, rh): (DVec3, DVec3), lo: DVec3, hi: DVec3| lo.cmple(rh).all() && hi.cmpge(rl).all();
    let in_front = |lo: DVec3, hi: DVec3| {
        reaches_front((ni, off), lo, hi, snap) && region.is_none_or(|r| meets(r, lo, hi))
    };
    match receivers {
        Some(js) => shaft_blockers(scene, blockers, i, js, out),
        None => row_blockers(blockers, pi, &mut out.row_blockers),
    }
    out.row_blockers.sort_unstable();
    // One shadow volume per blocker (at most 64 per walk), then one walk for all of them.
    let RowShadows { mark, touched, partial, row_blockers, ring, volumes, ids, nodes, wanted, .. } = out;
    let marked = marked.map(|stamp| (&nodes[..], stamp));
    for chunk in row_blockers.chunks(64) {
        ids.clear();
        for &b in chunk {
            clip_front(&blockers.get(b as usize).ring, ni, off, snap, ring);
            if ring.len() < 3 {
                continue;
            }
            if volumes.len() <= ids.len() {
                volumes.push(ShadowVolume::default());
            }
            if volumes[ids.len()].build(pi.vertices(), ring, snap) == Build::Casts {
                ids.push(b);
            }
        }
        if ids.is_empty() {
            continue;
        }
        let vols = &volumes[..ids.len()];
        let all = if ids.len() == 64 { u64::MAX } else { (1u64 << ids.len()) - 1 };
        // State: (volumes whose penumbra may reach the box, the box is in some umbra).
        let descend = |lo: DVec3, hi: DVec3, (mask, blocked): (u64, bool)| {
            if blocked {
                return Some((mask, true));
            }
            if !in_front(lo, hi) {
                return None;
            }
            let mut keep = 0u64;
            let mut m = mask;
            let (c, h) = centre_half(lo, hi);
            while m != 0 {
                let k = m.trailing_zeros() as usize;
                m &= m - 1;
                match vols[k].box_region_ch(c, h) {
                    Region::Out => {}
                    Region::In => return Some((0, true)),
                    Region::Cross => keep |= 1 << k,
                }
            }
            (keep != 0).then_some((keep, false))
        };
        tree.walk_marked_with(marked, (all, false), descend, |j, (mask, blocked)| {
            let ju = j as usize;
            if ju < first || ju == i || mark[ju] == BLOCKED || marked.is_some_and(|(_, s)| wanted[ju] != s) {
                return;
            }
            let pj = &scene.patches[ju].polygon;
            if !blocked {
                // Only receivers that face i and that i faces can exchange with it.
                let (nj, offj) = (pj.normal(), pj.normal().dot(pj.centroid()));
                if !pj.vertices().iter().any(|&v| ni.dot(v) - off > snap)
                    || !pi.vertices().iter().any(|&v| nj.dot(v) - offj > snap)
                {
                    return;
                }
            }
            let mut m = mask;
            let mut full = blocked;
            let mut any = false;
            while m != 0 && !full {
                let k = m.trailing_zeros() as usize;
                m &= m - 1;
                match vols[k].classify(pj.vertices()) {
                    Class::Clear => {}
                    Class::Full => full = true,
                    Class::Partial => {
                        partial.push((j, ids[k]));
                        any = true;
                    }
                }
            }
            if full {
                if mark[ju] == CLEAR {
                    touched.push(j);
                }
                mark[ju] = BLOCKED;
            } else if any && mark[ju] == CLEAR {
                touched.push(j);
                mark[ju] = PARTIAL;
            }
        });
    }
    // Group the partial blockers of receivers not blocked outright: counted per receiver,
    // then placed in the order they came, which is ascending per receiver (one walk per chunk
    // of ascending blockers, each receiver visited once per walk).
    let RowShadows { mark, span, touched, blockers, partial, .. } = out;
    let mut end = 0u32;
    for &j in touched.iter() {
        span[j as usize] = (0, 0);
    }
    for &(j, _) in partial.iter() {
        if mark[j as usize] == PARTIAL {
            span[j as usize].1 += 1;
        }
    }
    for &j in touched.iter() {
        if mark[j as usize] == PARTIAL {
            let len = span[j as usize].1;
            span[j as usize] = (end, 0);
            end += len;
        }
    }
    blockers.resize(end as usize, 0);
    for &(j, b) in partial.iter() {
        if mark[j as usize] == PARTIAL {
            let (start, len) = &mut span[j as usize];
            debug_assert!(*len == 0 || blockers[(*start + *len - 1) as usize] < b, "ascending per receiver");
            blockers[(*start + *len) as usize] = b;
            *len += 1;
        }
    }
}

/// The part of a convex ring with n·x − off ≥ 0 (snapping within `snap`), into `out`; empty
/// when no vertex is strictly in front.
pub fn clip_front(ring: &[DVec3], n: DVec3, off: f64, snap: f64, out: &mut Vec<DVec3>) {
    let dist = |x: DVec3| n.dot(x) - off;
    clip_ring(ring, dist, snap, out);
    if !out.iter().any(|&x| dist(x) > snap) {
        out.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::super::blockers::BlockerSource;
    use super::*;
    use crate::geometry::subdivide::parallelogram_grid;
    use crate::geometry::DVec3 as V;

    /// A square `side` wide at `o` spanned by u, v (normal u × v).
    fn plate(o: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Vec<Polygon> {
        parallelogram_grid(V::from(o), V::from(u), V::from(v), 1, 1).unwrap()
    }

    #[test]
    fn a_row_limited_to_its_receivers_takes_only_blockers_that_may_cut_one_of_its_pairs() {
        // Emitter e (z = 0, facing up), receivers a above it and b beside it (z = 2, facing
        // down); a plate between e and a, and a plate low under b: inside the box of the row
        // but outside both pairs' shafts.
        let scene = Scene::builder()
            .surface("e", plate([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), 0.9, None)
            .surface("a", plate([0.0, 0.0, 2.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 0.9, None)
            .surface("b", plate([4.0, 0.0, 2.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 0.9, None)
            .surface("mid", plate([0.2, 0.2, 1.0], [0.0, 0.6, 0.0], [0.6, 0.0, 0.0]), 0.9, None)
            .surface("low", plate([3.5, 0.2, 0.3], [0.0, 0.6, 0.0], [0.5, 0.0, 0.0]), 0.9, None)
            .build();
        let blockers = Blockers::new(&scene);
        let name = |b: u32| match blockers.get(b as usize).source {
            BlockerSource::Surface(s) => scene.surfaces[s].name.clone(),
            BlockerSource::Patch(p) => scene.surfaces[scene.patches[p].surface].name.clone(),
            BlockerSource::Obstruction { .. } => String::from("obstruction"),
        };
        let mut row = RowShadows::default();
        let pi = &scene.patches[0].polygon;
        let mut hull = Vec::new();
        let (rl, rh) = (V::ZERO, V::new(5.0, 1.0, 2.0));
        blockers.blockers_where(|lo, hi| lo.cmple(rh).all() && hi.cmpge(rl).all(), &mut hull);
        let mut named: Vec<String> = hull.iter().map(|&b| name(b)).collect();
        named.sort();
        assert!(named.contains(&"low".to_string()) && named.contains(&"mid".to_string()), "{named:?}");
        classify_row_in(&scene, &blockers, 0, 0, Some(&[1, 2]), &mut row);
        let taken: Vec<String> = row.row_blockers.iter().map(|&b| name(b)).collect();
        assert_eq!(taken, ["mid"]);
        // The statuses are the whole row's, once each pair keeps the blockers that may cut it.
        let mut full = RowShadows::default();
        classify_row(&scene, &blockers, 0, 0, &mut full);
        let own = |j: usize, list: &[u32]| -> Vec<u32> {
            let pj = &scene.patches[j].polygon;
            let shaft = Shaft::new(bounds(pi.vertices()), bounds(pj.vertices()), blockers.snap());
            let plane = (pj.normal(), pj.normal().dot(pj.centroid()));
            list.iter()
                .copied()
                .filter(|&b| may_cut(&shaft, plane, &blockers.get(b as usize).ring, blockers.snap()))
                .collect()
        };
        match (row.status(1), full.status(1)) {
            (Status::Partial(got), Status::Partial(want)) => {
                assert_eq!(own(1, got), own(1, want));
                assert_eq!(got.iter().map(|&b| name(b)).collect::<Vec<_>>(), ["mid"]);
            }
            other => panic!("receiver a: {other:?}"),
        }
        assert!(matches!(row.status(2), Status::Clear), "receiver b: {:?}", row.status(2));
        match full.status(2) {
            Status::Clear => {}
            Status::Partial(want) => assert!(own(2, want).is_empty(), "{want:?}"),
            Status::Blocked => panic!("receiver b blocked"),
        }
    }
}
