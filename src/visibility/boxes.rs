//! A box hierarchy for region queries: an obvhs `Bvh2` over padded boxes, walked with the
//! caller's box predicate ("may this box hold what I want?"). Nodes failing the predicate are
//! pruned, so a query costs the boxes it touches, never a linear scan. Boxes are grown by the
//! caller's margin and rounded outwards to f32, so a conservative predicate gives a
//! conservative query.
use glam::{DVec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::Bvh2, Boundable, BvhBuildParams};
use std::time::Duration;

/// Deepest hint path [`BoxTree::find_near`] follows (deeper hints start at the root).
const PATH_MAX: usize = 64;

struct PaddedBox(Aabb);
impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// Where a box lies relative to a query region.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// Wholly outside: prune.
    Out,
    /// Wholly inside: everything below is in.
    In,
    /// Possibly both.
    Cross,
}

/// A `Bvh2` over boxes, indexed 0..len in input order.
#[derive(Clone, Default)]
pub struct BoxTree {
    bvh: Bvh2,
    /// Each box as stored (padded, rounded to f32), so node boxes contain it exactly.
    boxes: Vec<(DVec3, DVec3)>,
    /// Per node: its parent (the root its own).
    parent: Vec<u32>,
    /// Per box: the leaf node that holds it.
    leaf: Vec<u32>,
}

impl std::fmt::Debug for BoxTree {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BoxTree")
            .field("len", &self.boxes.len())
            .field("nodes", &self.bvh.nodes.len())
            .finish()
    }
}

impl BoxTree {
    /// Builds over the boxes (lo, hi), each grown by `pad` on every side.
    pub fn new(boxes: impl IntoIterator<Item = (DVec3, DVec3)>, pad: f64) -> Self {
        let prims: Vec<PaddedBox> =
            boxes.into_iter().map(|(lo, hi)| PaddedBox(Aabb::new(down(lo - pad), up(hi + pad)))).collect();
        let boxes = prims.iter().map(|b| (to64(b.0.min), to64(b.0.max))).collect();
        if prims.is_empty() {
            return Self::default();
        }
        let bvh =
            obvhs::bvh2::builder::build_bvh2(&prims, BvhBuildParams::fast_build(), &mut Duration::default());
        let (mut parent, mut leaf) = (vec![0u32; bvh.nodes.len()], vec![0u32; prims.len()]);
        for (k, node) in bvh.nodes.iter().enumerate() {
            if node.is_leaf() {
                for slot in node.first_index..node.first_index + node.prim_count {
                    leaf[bvh.primitive_indices[slot as usize] as usize] = k as u32;
                }
            } else {
                parent[node.first_index as usize] = k as u32;
                parent[node.first_index as usize + 1] = k as u32;
            }
        }
        Self { bvh, boxes, parent, leaf }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.bvh.nodes.len()
    }

    /// Sets `marks[node] = stamp` on every node above the boxes `ks` (`marks` holds one entry
    /// per node): the subtrees a walk limited to those boxes enters.
    pub fn mark_paths(&self, ks: impl IntoIterator<Item = u32>, stamp: u32, marks: &mut [u32]) {
        for k in ks {
            let mut n = self.leaf[k as usize];
            while marks[n as usize] != stamp {
                marks[n as usize] = stamp;
                if n == 0 {
                    break;
                }
                n = self.parent[n as usize];
            }
        }
    }
    /// Feeds the tree (every node's box, count and index, the primitive order) and the
    /// stored boxes to `h`: equal hashes mean equal trees (the MPI and shard agreement check).
    pub fn hash_into(&self, h: &mut impl std::hash::Hasher) {
        h.write_u64(self.bvh.nodes.len() as u64);
        for n in &self.bvh.nodes {
            for v in [n.aabb.min, n.aabb.max] {
                v.to_array().iter().for_each(|x| h.write_u32(x.to_bits()));
            }
            h.write_u32(n.prim_count);
            h.write_u32(n.first_index);
        }
        self.bvh.primitive_indices.iter().for_each(|&k| h.write_u32(k));
        for (lo, hi) in &self.boxes {
            lo.to_array().iter().chain(hi.to_array().iter()).for_each(|x| h.write_u64(x.to_bits()));
        }
    }
    /// Swaps the first two primitive indices: a tree as another build could order it.
    #[cfg(test)]
    pub(crate) fn swap_primitives_for_test(&mut self) {
        self.bvh.primitive_indices.swap(0, 1);
    }
    /// Number of boxes.
    pub fn len(&self) -> usize {
        self.boxes.len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.boxes.is_empty()
    }
    /// Box `k` as stored: padded and rounded outwards to f32.
    pub fn get(&self, k: usize) -> (DVec3, DVec3) {
        self.boxes[k]
    }

    /// Depth-first walk: subtrees whose box fails `keep(lo, hi)` are pruned, and `visit(index)`
    /// is called for each box that passes `keep` itself; `visit` returns false to stop.
    pub fn walk(&self, mut keep: impl FnMut(DVec3, DVec3) -> bool, mut visit: impl FnMut(u32) -> bool) {
        if !self.bvh.nodes.is_empty() {
            self.first_in(0, None, &mut keep, &mut |k| !visit(k));
        }
    }

    /// Some box that a [`BoxTree::walk`] with `keep` visits and `accept` takes, `None` exactly
    /// when there is none. The search starts from `hints`: each hint's own box first (along
    /// its path, as [`BoxTree::reaches`]), then the deepest node above the first hint that the
    /// walk enters (the neighbourhood of a blocker that just failed), then the rest of the tree.
    pub fn find_near(
        &self,
        hints: &[u32],
        mut keep: impl FnMut(DVec3, DVec3) -> bool,
        mut accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        if self.bvh.nodes.is_empty() {
            return None;
        }
        let mut anchor = None;
        for &h in hints.iter().filter(|&&h| (h as usize) < self.boxes.len()) {
            // The hint's path, root first; the deepest node of it that the walk enters.
            let mut path = [0u32; PATH_MAX];
            let mut depth = 0;
            let mut n = self.leaf[h as usize];
            loop {
                if depth == PATH_MAX {
                    depth = 0;
                    break;
                }
                path[depth] = n;
                depth += 1;
                if n == 0 {
                    break;
                }
                n = self.parent[n as usize];
            }
            let mut entered = None;
            for &n in path[..depth].iter().rev() {
                let node = &self.bvh.nodes[n as usize];
                if !keep(to64(node.aabb.min), to64(node.aabb.max)) {
                    break;
                }
                entered = Some(n);
            }
            if depth > 0 && entered == Some(path[0]) {
                let (lo, hi) = self.boxes[h as usize];
                if keep(lo, hi) && accept(h) {
                    return Some(h);
                }
            }
            if anchor.is_none() {
                anchor = entered;
            }
        }
        match anchor {
            Some(a) if a != 0 => self
                .first_in(a, None, &mut keep, &mut accept)
                .or_else(|| self.first_in(0, Some(a), &mut keep, &mut accept)),
            _ => self.first_in(0, None, &mut keep, &mut accept),
        }
    }

    /// Depth first from node `start` (whose ancestors the caller has checked), leaving out the
    /// subtree of `skip`: the first box that passes `keep` (with every node above it) and
    /// `accept`.
    fn first_in(
        &self,
        start: u32,
        skip: Option<u32>,
        keep: &mut impl FnMut(DVec3, DVec3) -> bool,
        accept: &mut impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        let mut stack = Vec::with_capacity(PATH_MAX);
        stack.push(start);
        while let Some(k) = stack.pop() {
            if skip == Some(k) {
                continue;
            }
            let node = &self.bvh.nodes[k as usize];
            if !keep(to64(node.aabb.min), to64(node.aabb.max)) {
                continue;
            }
            if node.is_leaf() {
                for slot in node.first_index..node.first_index + node.prim_count {
                    let k = self.bvh.primitive_indices[slot as usize];
                    let (lo, hi) = self.boxes[k as usize];
                    if keep(lo, hi) && accept(k) {
                        return Some(k);
                    }
                }
            } else {
                stack.push(node.first_index + 1);
                stack.push(node.first_index);
            }
        }
        None
    }

    /// Walk with a three-way region test on node boxes: subtrees `Out` are pruned, subtrees
    /// `In` are visited whole without further tests; `visit(index, region)` receives every box
    /// of a reached leaf with its node's region (`Cross` boxes are left to the caller to test,
    /// with [`BoxTree::get`] or finer geometry).
    pub fn walk_regions(
        &self,
        mut region: impl FnMut(DVec3, DVec3) -> Region,
        mut visit: impl FnMut(u32, Region),
    ) {
        if self.bvh.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0u32, false)];
        while let Some((k, inside)) = stack.pop() {
            let node = &self.bvh.nodes[k as usize];
            let r = if inside { Region::In } else { region(to64(node.aabb.min), to64(node.aabb.max)) };
            if r == Region::Out {
                continue;
            }
            if node.is_leaf() {
                for slot in node.first_index..node.first_index + node.prim_count {
                    visit(self.bvh.primitive_indices[slot as usize], r);
                }
            } else {
                let inside = r == Region::In;
                stack.push((node.first_index + 1, inside));
                stack.push((node.first_index, inside));
            }
        }
    }

    /// Walk carrying a state down the tree: `descend(lo, hi, parent_state)` returns the node's
    /// state, or `None` to prune it; `visit(index, state)` receives every box of a reached leaf
    /// with its leaf's state. Several region queries can share one walk this way.
    pub fn walk_with<S: Copy>(
        &self,
        root: S,
        descend: impl FnMut(DVec3, DVec3, S) -> Option<S>,
        visit: impl FnMut(u32, S),
    ) {
        self.walk_marked_with(None, root, descend, visit)
    }

    /// As [`BoxTree::walk_with`], entering only the nodes `marked` (marks, stamp) stamps (see
    /// [`BoxTree::mark_paths`]) when given.
    pub fn walk_marked_with<S: Copy>(
        &self,
        marked: Option<(&[u32], u32)>,
        root: S,
        mut descend: impl FnMut(DVec3, DVec3, S) -> Option<S>,
        mut visit: impl FnMut(u32, S),
    ) {
        if self.bvh.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0u32, root)];
        while let Some((k, parent)) = stack.pop() {
            if marked.is_some_and(|(marks, stamp)| marks[k as usize] != stamp) {
                continue;
            }
            let node = &self.bvh.nodes[k as usize];
            let Some(state) = descend(to64(node.aabb.min), to64(node.aabb.max), parent) else { continue };
            if node.is_leaf() {
                for slot in node.first_index..node.first_index + node.prim_count {
                    visit(self.bvh.primitive_indices[slot as usize], state);
                }
            } else {
                stack.push((node.first_index + 1, state));
                stack.push((node.first_index, state));
            }
        }
    }

    /// Indices of the boxes that pass `keep`, appended to `out` (tree order).
    pub fn collect(&self, keep: impl FnMut(DVec3, DVec3) -> bool, out: &mut Vec<u32>) {
        self.walk(keep, |k| {
            out.push(k);
            true
        });
    }
}

/// f32 vector not above `v`, component-wise.
fn down(v: DVec3) -> Vec3A {
    let f = |x: f64| {
        let y = x as f32;
        if (y as f64) > x {
            y.next_down()
        } else {
            y
        }
    };
    Vec3A::new(f(v.x), f(v.y), f(v.z))
}

/// f32 vector not below `v`, component-wise.
fn up(v: DVec3) -> Vec3A {
    let f = |x: f64| {
        let y = x as f32;
        if (y as f64) < x {
            y.next_up()
        } else {
            y
        }
    };
    Vec3A::new(f(v.x), f(v.y), f(v.z))
}

fn to64(v: Vec3A) -> DVec3 {
    DVec3::new(v.x as f64, v.y as f64, v.z as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 20×20×20 lattice of unit boxes, 0.5 apart.
    fn lattice() -> Vec<(DVec3, DVec3)> {
        (0..8000)
            .map(|k| {
                let c = DVec3::new((k % 20) as f64, ((k / 20) % 20) as f64, (k / 400) as f64) * 1.5;
                (c, c + 1.0)
            })
            .collect()
    }

    #[test]
    fn a_marked_walk_reaches_exactly_the_marked_boxes_the_full_walk_reaches() {
        // A 20×20×20 lattice; a walk pruned by a slab, limited to every 7th box (then to one).
        let tree = BoxTree::new(lattice(), 1e-6);
        let slab = |lo: DVec3, hi: DVec3, ()| (lo.x <= 14.0 && hi.x >= 5.0).then_some(());
        let mut full = Vec::new();
        tree.walk_with((), slab, |k, ()| full.push(k));
        let mut marks = vec![0; tree.node_count()];
        for (stamp, step) in [(1, 7), (2, 7919)] {
            let wanted: Vec<u32> = (0..8000).step_by(step).collect();
            tree.mark_paths(wanted.iter().copied(), stamp, &mut marks);
            let mut got = Vec::new();
            tree.walk_marked_with(Some((&marks, stamp)), (), slab, |k, ()| got.push(k));
            // Leaves are entered whole: every wanted box the full walk reaches is reached, and
            // only boxes of leaves that hold a wanted one.
            let want: Vec<u32> = full.iter().copied().filter(|k| k % step as u32 == 0).collect();
            assert!(want.iter().all(|k| got.contains(k)), "step {step}");
            assert!(got.iter().all(|&k| marks[tree.leaf[k as usize] as usize] == stamp), "step {step}");
            assert!(got.len() < full.len() / 2, "step {step}: {} of {}", got.len(), full.len());
        }
    }

    #[test]
    fn a_search_from_hints_finds_a_box_exactly_when_the_walk_does() {
        // A predicate that is not monotone under containment (small boxes pass, wide ones
        // only near x = 0): a walk prunes nodes whose boxes pass on their own.
        let tree = BoxTree::new(lattice(), 1e-6);
        let keep = |lo: DVec3, hi: DVec3| (hi - lo).max_element() < 8.0 || lo.x < 3.0;
        let mut visited = vec![false; tree.len()];
        tree.walk(keep, |k| {
            visited[k as usize] = true;
            true
        });
        let alone = (0..tree.len()).filter(|&k| {
            let (lo, hi) = tree.get(k);
            keep(lo, hi)
        });
        assert!(alone.count() > visited.iter().filter(|&&v| v).count(), "the ball test prunes a passing box");
        assert!(visited.iter().filter(|&&v| v).count() > 100);
        // Accepted sets from none to many, hints on reached, pruned and accepted boxes.
        for (m, hints) in
            [(1, vec![]), (97, vec![5]), (997, vec![3, 4000]), (8001, vec![17, 7999]), (13, vec![8])]
        {
            let accepted = |k: u32| k.is_multiple_of(m) || k == 4242;
            let want = (0..tree.len() as u32).any(|k| visited[k as usize] && accepted(k));
            let got = tree.find_near(&hints, keep, accepted);
            assert_eq!(got.is_some(), want, "every {m}, hints {hints:?}");
            if let Some(k) = got {
                assert!(visited[k as usize] && accepted(k), "box {k}");
            }
        }
        // Each visited box alone accepted, hinted at itself or from a neighbour: found.
        for k in (0..tree.len() as u32).filter(|&k| visited[k as usize]).step_by(7) {
            assert_eq!(tree.find_near(&[k], keep, |j| j == k), Some(k));
            assert_eq!(tree.find_near(&[k ^ 1], keep, |j| j == k), Some(k));
        }
        // A pruned box is never returned, whatever the hints.
        for k in (0..tree.len() as u32).filter(|&k| !visited[k as usize]).step_by(11) {
            assert_eq!(tree.find_near(&[k], keep, |j| j == k), None);
        }
    }

    #[test]
    fn region_queries_match_a_brute_force_scan() {
        // A 20×20×20 lattice of unit boxes; query a slab and a plane-bounded region.
        let tree = BoxTree::new(lattice(), 1e-6);
        assert_eq!(tree.len(), 8000);
        let n = DVec3::new(1.0, 2.0, -0.5).normalize();
        let beyond = |lo: DVec3, hi: DVec3| n.dot(0.5 * (lo + hi)) + n.abs().dot(0.5 * (hi - lo)) > 20.0;
        let mut got = Vec::new();
        tree.collect(beyond, &mut got);
        got.sort_unstable();
        let want: Vec<u32> = (0..8000u32)
            .filter(|&k| {
                let (lo, hi) = tree.get(k as usize);
                beyond(lo, hi)
            })
            .collect();
        assert!(want.len() > 100 && want.len() < 7900, "{}", want.len());
        assert_eq!(got, want);
        // Three-way walk: inside the slab 10 ≤ x ≤ 20 counts as In.
        let mut regions = Vec::new();
        let slab = |lo: DVec3, hi: DVec3| {
            if hi.x < 10.0 || lo.x > 20.0 {
                Region::Out
            } else if lo.x >= 10.0 && hi.x <= 20.0 {
                Region::In
            } else {
                Region::Cross
            }
        };
        tree.walk_regions(slab, |k, r| {
            let r = if r == Region::Cross {
                let (lo, hi) = tree.get(k as usize);
                slab(lo, hi)
            } else {
                r
            };
            if r != Region::Out {
                regions.push((k, r));
            }
        });
        regions.sort_unstable_by_key(|p| p.0);
        let want: Vec<(u32, Region)> = (0..8000u32)
            .filter_map(|k| {
                let (lo, hi) = tree.get(k as usize);
                let r = slab(lo, hi);
                (r != Region::Out).then_some((k, r))
            })
            .collect();
        assert_eq!(regions, want);
        // Early stop.
        let mut visits = 0;
        tree.walk(
            |_, _| true,
            |_| {
                visits += 1;
                visits < 5
            },
        );
        assert_eq!(visits, 5);
    }
}
