//! A box tree over one pair's partial blockers for the Monte Carlo segment test
//! ([`super::mc_pair`]): a sample's segment is tested against the blockers whose boxes it
//! meets, not against every partial blocker.
//!
//! - A pair behind a meshed body has tens to hundreds of partial facets, and a visible segment
//!   had to be tested against all of them; the tree is built once per pair (b log b, median
//!   splits along the longest axis, at most [`LEAF`] blockers a leaf) and walked per sample.
//! - **Same answer as the scan.** [`SegmentBlocker::cuts`] still decides; the tree only skips
//!   blockers whose boxes the segment misses, and each box is padded
//!   ([`crate::geometry::tolerance::BLOCKER_BOX_PAD_REL`]) beyond the round-off of the cut point,
//!   so a pair's samples see exactly the visibility of the linear scan.
//! - **Counted work.** [`SegmentTree::blocked`] counts its box and blocker tests: the unit in
//!   which `auto` prices sampling ([`super::policy`]).
use super::blockers::bounds;
use glam::DVec3;

/// A convex blocker ready for segment tests.
#[derive(Debug, Clone, Default)]
pub struct SegmentBlocker {
    n: DVec3,
    off: f64,
    /// (point on edge, inward edge normal in the plane).
    edges: Vec<(DVec3, DVec3)>,
    /// Bounding box, padded.
    lo: DVec3,
    hi: DVec3,
}

impl SegmentBlocker {
    /// From a convex ring (counter-clockwise about its normal); its box grows by `pad`.
    pub fn new(ring: &[DVec3], pad: f64) -> Self {
        let m = ring.len();
        let mut n = DVec3::ZERO;
        for k in 0..m {
            n += ring[k].cross(ring[(k + 1) % m]);
        }
        let n = n.normalize_or_zero();
        let edges = (0..m).map(|k| (ring[k], n.cross(ring[(k + 1) % m] - ring[k]))).collect();
        let (lo, hi) = bounds(ring);
        Self { n, off: n.dot(ring[0]), edges, lo: lo - pad, hi: hi + pad }
    }
    /// The padded bounding box (lo, hi).
    #[inline]
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }
    /// True when the open segment x → y crosses the blocker's interior.
    #[inline]
    pub fn cuts(&self, x: DVec3, y: DVec3) -> bool {
        let (dx, dy) = (self.n.dot(x) - self.off, self.n.dot(y) - self.off);
        if dx * dy >= 0.0 {
            return false;
        }
        let z = x + (y - x) * (dx / (dx - dy));
        self.edges.iter().all(|&(a, m)| m.dot(z - a) > 0.0)
    }
}

/// Most blockers in a leaf: below this many, testing them beats another box.
pub const LEAF: usize = 4;

/// A node: a leaf holds `order[a..a + n]`; an inner node (n = 0) has children k + 1 and a.
#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    a: u32,
    n: u32,
}

/// The tree and its walk stack (reused across pairs).
#[derive(Debug, Clone, Default)]
pub struct SegmentTree {
    nodes: Vec<Node>,
    order: Vec<u32>,
    stack: Vec<u32>,
}

impl SegmentTree {
    /// Rebuilds the tree over the blockers `ids` (indices into `all`).
    pub fn build(&mut self, all: &[SegmentBlocker], ids: &[u32]) {
        self.nodes.clear();
        self.order.clear();
        self.order.extend_from_slice(ids);
        if !ids.is_empty() {
            self.node(all, 0, ids.len());
        }
    }

    fn node(&mut self, all: &[SegmentBlocker], start: usize, end: usize) -> u32 {
        let k = self.nodes.len() as u32;
        let ids = &mut self.order[start..end];
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let (mut clo, mut chi) = (lo, hi);
        for &b in ids.iter() {
            let (l, h) = all[b as usize].bounds();
            (lo, hi) = (lo.min(l), hi.max(h));
            (clo, chi) = (clo.min(l + h), chi.max(l + h));
        }
        self.nodes.push(Node { lo, hi, a: start as u32, n: ids.len() as u32 });
        if ids.len() <= LEAF {
            return k;
        }
        // Median split of the box centres along their longest extent.
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let centre = |b: u32| {
            let (l, h) = all[b as usize].bounds();
            (l + h)[axis]
        };
        let mid = ids.len() / 2;
        ids.select_nth_unstable_by(mid, |&p, &q| centre(p).total_cmp(&centre(q)).then(p.cmp(&q)));
        self.node(all, start, start + mid);
        let right = self.node(all, start + mid, end);
        self.nodes[k as usize].a = right;
        self.nodes[k as usize].n = 0;
        k
    }

    /// True when a blocker of the tree cuts the open segment x → y; adds the box and blocker
    /// tests made to `tests`.
    #[inline]
    pub fn blocked(&mut self, all: &[SegmentBlocker], x: DVec3, y: DVec3, tests: &mut u64) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let d = y - x;
        let inv = d.recip();
        self.stack.clear();
        self.stack.push(0);
        while let Some(k) = self.stack.pop() {
            let node = self.nodes[k as usize];
            *tests += 1;
            if !meets(node.lo, node.hi, x, d, inv) {
                continue;
            }
            if node.n > 0 {
                for &b in &self.order[node.a as usize..(node.a + node.n) as usize] {
                    *tests += 1;
                    if all[b as usize].cuts(x, y) {
                        return true;
                    }
                }
            } else {
                self.stack.push(node.a);
                self.stack.push(k + 1);
            }
        }
        false
    }
}

/// True when the segment x + t·d, t ∈ [0, 1], meets the box [lo, hi] (slab test; `inv` = 1/d).
#[inline]
fn meets(lo: DVec3, hi: DVec3, x: DVec3, d: DVec3, inv: DVec3) -> bool {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for a in 0..3 {
        if d[a] == 0.0 {
            if x[a] < lo[a] || x[a] > hi[a] {
                return false;
            }
            continue;
        }
        let (u, v) = ((lo[a] - x[a]) * inv[a], (hi[a] - x[a]) * inv[a]);
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
        if t0 > t1 {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small triangles scattered over [0, 1]³ in a fixed pattern.
    fn triangles(n: usize) -> Vec<SegmentBlocker> {
        (0..n)
            .map(|k| {
                let f = |m: usize| ((k * m + 7) % 97) as f64 / 97.0;
                let o = DVec3::new(f(13), f(29), f(41));
                let ring = [o, o + DVec3::new(0.08, 0.01, 0.02), o + DVec3::new(0.02, 0.07, -0.03)];
                SegmentBlocker::new(&ring, 1e-9)
            })
            .collect()
    }

    #[test]
    fn the_tree_answers_as_the_linear_scan() {
        let all = triangles(200);
        let ids: Vec<u32> = (0..200).filter(|k| k % 3 != 1).collect();
        let mut tree = SegmentTree::default();
        tree.build(&all, &ids);
        let (mut tests, mut hits) = (0u64, 0);
        for k in 0..2000u32 {
            let g = |m: u32| ((k.wrapping_mul(m) ^ (k >> 3)) % 1009) as f64 / 1009.0;
            let x = DVec3::new(g(7), g(11), -0.1);
            let y = DVec3::new(g(13), g(17), 1.1);
            let scan = ids.iter().any(|&b| all[b as usize].cuts(x, y));
            assert_eq!(tree.blocked(&all, x, y, &mut tests), scan, "segment {x} → {y}");
            hits += usize::from(scan);
        }
        assert!(hits > 100 && hits < 1900, "both outcomes exercised: {hits}");
        // And it tests fewer than the scan would.
        assert!(tests < 2000 * ids.len() as u64 / 4, "{tests} tests");
    }
}
