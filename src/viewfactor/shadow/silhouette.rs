//! A closed body's outline from one viewpoint, taken on the mesh before any projection: the
//! silhouette loops of its front faces (used by [`super::viewpoint`]).
//!
//! - Setup, once per pair ([`Vertices::new`]): the outline faces' corners are numbered, equal
//!   points (bit for bit, as the mesh's shared edges are found) getting one number.
//! - Per viewpoint ([`Silhouette::chain`]): an edge of a front face is on the outline unless
//!   the face across it is front too; the outline edges are chained by their corners' numbers
//!   into closed loops in 3-D. Projected, the loops' winding number counts the front faces
//!   over each point, as the faces' own shadows would.
//! - The viewpoint then clips each loop, as one ring, by the receiver hull's planes in
//!   homogeneous coordinates. Sutherland–Hodgman keeps a closed chain's winding number on the
//!   kept side of each plane (the replaced excursions and the plane's pieces that close them
//!   lie in the plane, which projects to a line), so the loops' clipped region is the union of
//!   the faces clipped one by one: no face is projected, only the outline. That holds where
//!   every loop point lies below the viewpoint's height (W = h − z > 0, where central
//!   projection is one-to-one); a face reaching that height is left out of the loops and
//!   projected on its own (a channel pair lost 0.87 of its unshaded value's shadow at some
//!   viewpoints before, validation/cad.md).
//! - Edges that do not close (corners equal only up to round-off, a mesh open at a slab cut)
//!   make `chain` say so; the viewpoint then takes the faces whole.
use glam::DVec3;
use std::collections::HashMap;
use std::ops::Range;

/// Corner numbers of the outline faces (one number per distinct point).
#[derive(Debug, Clone, Default)]
pub struct Vertices {
    /// Per kept blocker, its range in `ids` (empty for a face not on an outline).
    start: Vec<u32>,
    ids: Vec<u32>,
}

impl Vertices {
    /// Numbers the corners of every kept blocker `k` with `outline[k]`.
    pub fn new(blockers: &[Vec<DVec3>], outline: &[bool]) -> Self {
        let mut seen: HashMap<[u64; 3], u32> = HashMap::new();
        let mut out = Self { start: Vec::with_capacity(blockers.len() + 1), ids: Vec::new() };
        out.start.push(0);
        for (ring, &on) in blockers.iter().zip(outline) {
            if on {
                for x in ring {
                    let next = seen.len() as u32;
                    out.ids.push(*seen.entry([x.x.to_bits(), x.y.to_bits(), x.z.to_bits()]).or_insert(next));
                }
            }
            out.start.push(out.ids.len() as u32);
        }
        out
    }

    /// Corner numbers of kept blocker `k`, in ring order.
    pub fn of(&self, k: usize) -> &[u32] {
        &self.ids[self.start[k] as usize..self.start[k + 1] as usize]
    }
}

/// One viewpoint's front outline faces and the loops chained from their edges (buffers
/// reused across viewpoints).
#[derive(Debug, Clone, Default)]
pub struct Silhouette {
    /// Per kept blocker: front from this viewpoint (only the faces in `faces` are set).
    pub front: Vec<bool>,
    /// The front outline faces of this viewpoint.
    pub faces: Vec<u32>,
    /// Outline edges: (start corner, end corner, start point).
    edges: Vec<(u32, u32, DVec3)>,
    /// (start corner, edge index), sorted.
    starts: Vec<(u32, u32)>,
    used: Vec<bool>,
    points: Vec<DVec3>,
    rings: Vec<Range<usize>>,
    /// Viewpoints whose outline edges did not close.
    pub fallbacks: u64,
}

impl Silhouette {
    /// Marks kept blocker `k` as a front outline face.
    pub fn add(&mut self, k: u32) {
        self.front[k as usize] = true;
        self.faces.push(k);
    }

    /// Forgets the faces (keeps `front` cleared for the next viewpoint).
    pub fn clear(&mut self) {
        for &k in &self.faces {
            self.front[k as usize] = false;
        }
        self.faces.clear();
    }

    /// Chains the outline edges of the front faces into closed loops (read with
    /// [`Self::rings`]): edge e of face k runs from corner e to corner e + 1 of `rings[k]`,
    /// `across(k, e)` is the face sharing it. False when the edges do not close.
    pub fn chain(
        &mut self,
        rings: &[Vec<DVec3>],
        corners: &Vertices,
        across: impl Fn(usize, usize) -> Option<u32>,
    ) -> bool {
        self.edges.clear();
        for &k in &self.faces {
            let (ring, ids) = (&rings[k as usize], corners.of(k as usize));
            let m = ring.len();
            for e in 0..m {
                if across(k as usize, e).is_some_and(|j| self.front[j as usize]) {
                    continue;
                }
                self.edges.push((ids[e], ids[(e + 1) % m], ring[e]));
            }
        }
        self.starts.clear();
        self.starts.extend(self.edges.iter().enumerate().map(|(i, e)| (e.0, i as u32)));
        self.starts.sort_unstable();
        self.used.clear();
        self.used.resize(self.edges.len(), false);
        self.points.clear();
        self.rings.clear();
        for first in 0..self.edges.len() {
            if self.used[first] {
                continue;
            }
            let begin = self.points.len();
            let (start, mut end, q) = self.edges[first];
            self.used[first] = true;
            self.points.push(q);
            while end != start {
                let from = self.starts.partition_point(|s| s.0 < end);
                let next = self.starts[from..]
                    .iter()
                    .take_while(|s| s.0 == end)
                    .map(|s| s.1 as usize)
                    .find(|&i| !self.used[i]);
                let Some(next) = next else { return false };
                self.used[next] = true;
                self.points.push(self.edges[next].2);
                end = self.edges[next].1;
            }
            if self.points.len() - begin >= 3 {
                self.rings.push(begin..self.points.len());
            } else {
                self.points.truncate(begin);
            }
        }
        true
    }

    /// The loops of the last [`Self::chain`] (frame points; the closing edge is implied).
    pub fn rings(&self) -> impl Iterator<Item = &[DVec3]> + '_ {
        self.rings.iter().map(|r| &self.points[r.clone()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_front_triangles_chain_into_their_square_and_a_lone_edge_is_refused() {
        let d = DVec3::new;
        // The square [0,1]² split along its diagonal; triangle 1 shares edge 2 of triangle 0.
        let rings = vec![
            vec![d(0.0, 0.0, 0.0), d(1.0, 0.0, 0.0), d(1.0, 1.0, 0.0)],
            vec![d(0.0, 0.0, 0.0), d(1.0, 1.0, 0.0), d(0.0, 1.0, 0.0)],
        ];
        let corners = Vertices::new(&rings, &[true, true]);
        assert_eq!(corners.of(1), &[0, 2, 3]);
        let across = |k: usize, e: usize| match (k, e) {
            (0, 2) => Some(1),
            (1, 0) => Some(0),
            _ => None,
        };
        let mut s = Silhouette { front: vec![false; 2], ..Silhouette::default() };
        s.add(0);
        s.add(1);
        assert!(s.chain(&rings, &corners, across));
        let loops: Vec<&[DVec3]> = s.rings().collect();
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), 4, "{loops:?}");
        // Triangle 1 alone: its edge 0 now bounds it, a triangle again.
        s.clear();
        s.add(1);
        assert!(s.chain(&rings, &corners, across));
        assert_eq!(s.rings().map(<[DVec3]>::len).collect::<Vec<_>>(), vec![3]);
        // A face claiming a front neighbour that does not claim it back leaves an open chain.
        s.clear();
        s.add(0);
        s.add(1);
        let one_sided = |k: usize, e: usize| (k == 0 && e == 2).then_some(1);
        assert!(!s.chain(&rings, &corners, one_sided));
    }
}
