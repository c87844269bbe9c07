//! Closed rings from loose directed edges that form a cycle: the boundary of a sum of
//! polygons once the edges two of them share (traversed both ways) are dropped.
//!
//! - [`Loops::push`] takes the edges in any order; [`Loops::chain`] follows each edge to one
//!   starting where it ends (the same point bit for bit, else the nearest within a tolerance)
//!   and closes a ring when it comes back to its first point.
//! - At a point where several edges start, any choice gives rings whose winding numbers add
//!   up to the cycle's: the region a non-zero fill rule sees is the same.
//! - An edge end that meets no start within the tolerance means the edges were no cycle (a
//!   shared edge dropped on one side only): `chain` says so, and the caller falls back to the
//!   whole polygons. So do more than [`MAX_NEAR`] inexact joins, which bounds the linear
//!   searches they need.
use glam::DVec2;
use std::ops::Range;

/// Inexact joins (end and start apart by round-off, below the tolerance) allowed in one
/// [`Loops::chain`]; each costs a linear search over the edges.
pub const MAX_NEAR: usize = 64;

/// Directed edges to chain, and the rings of the last [`Loops::chain`].
#[derive(Debug, Clone, Default)]
pub struct Loops {
    edges: Vec<[DVec2; 2]>,
    /// (start point bits, edge index), sorted: the exact lookup.
    starts: Vec<([u64; 2], u32)>,
    used: Vec<bool>,
    points: Vec<DVec2>,
    rings: Vec<Range<usize>>,
}

fn key(q: DVec2) -> [u64; 2] {
    [q.x.to_bits(), q.y.to_bits()]
}

impl Loops {
    /// Forgets every edge and ring.
    pub fn clear(&mut self) {
        self.edges.clear();
        self.points.clear();
        self.rings.clear();
    }
    /// Adds the directed edge a → b.
    pub fn push(&mut self, a: DVec2, b: DVec2) {
        self.edges.push([a, b]);
    }

    /// Chains the edges into closed rings (read with [`Self::rings`]); false when some edge
    /// end finds no unused start within `tol`, or more than [`MAX_NEAR`] joins are inexact.
    pub fn chain(&mut self, tol: f64) -> bool {
        self.points.clear();
        self.rings.clear();
        self.starts.clear();
        self.starts.extend(self.edges.iter().enumerate().map(|(i, e)| (key(e[0]), i as u32)));
        self.starts.sort_unstable();
        self.used.clear();
        self.used.resize(self.edges.len(), false);
        let mut near = 0;
        for first in 0..self.edges.len() {
            if self.used[first] {
                continue;
            }
            let begin = self.points.len();
            let start = self.edges[first][0];
            self.used[first] = true;
            self.points.push(start);
            let mut end = self.edges[first][1];
            loop {
                if key(end) == key(start) {
                    break;
                }
                if let Some(next) = self.exact(end) {
                    self.used[next] = true;
                    self.points.push(self.edges[next][0]);
                    end = self.edges[next][1];
                    continue;
                }
                near += 1;
                if near > MAX_NEAR {
                    return false;
                }
                if end.distance_squared(start) <= tol * tol {
                    break;
                }
                let Some(next) = self.nearest(end, tol) else { return false };
                self.used[next] = true;
                self.points.push(self.edges[next][0]);
                end = self.edges[next][1];
            }
            if self.points.len() - begin >= 3 {
                self.rings.push(begin..self.points.len());
            } else {
                self.points.truncate(begin);
            }
        }
        true
    }

    /// An unused edge starting at `q` bit for bit.
    fn exact(&self, q: DVec2) -> Option<usize> {
        let k = key(q);
        let from = self.starts.partition_point(|s| s.0 < k);
        self.starts[from..].iter().take_while(|s| s.0 == k).map(|s| s.1 as usize).find(|&i| !self.used[i])
    }

    /// The unused edge whose start is nearest `q`, if within `tol`.
    fn nearest(&self, q: DVec2, tol: f64) -> Option<usize> {
        (0..self.edges.len())
            .filter(|&i| !self.used[i])
            .map(|i| (self.edges[i][0].distance_squared(q), i))
            .filter(|&(d, _)| d <= tol * tol)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, i)| i)
    }

    /// The closed rings of the last [`Self::chain`] (each at least three points; the closing
    /// edge from the last point back to the first is implied).
    pub fn rings(&self) -> impl Iterator<Item = &[DVec2]> + '_ {
        self.rings.iter().map(|r| &self.points[r.clone()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::convex::twice_area;

    fn push_ring(l: &mut Loops, ring: &[DVec2], skip: &[usize]) {
        for k in 0..ring.len() {
            if !skip.contains(&k) {
                l.push(ring[k], ring[(k + 1) % ring.len()]);
            }
        }
    }

    #[test]
    fn two_squares_sharing_an_edge_chain_into_their_outline() {
        let d = DVec2::new;
        // [0,1]² and [1,2]×[0,1], both counter-clockwise; the shared edge x = 1 dropped both ways.
        let a = [d(0.0, 0.0), d(1.0, 0.0), d(1.0, 1.0), d(0.0, 1.0)];
        let b = [d(1.0, 0.0), d(2.0, 0.0), d(2.0, 1.0), d(1.0, 1.0)];
        let mut l = Loops::default();
        push_ring(&mut l, &b, &[3]);
        push_ring(&mut l, &a, &[1]);
        assert!(l.chain(1e-12));
        let rings: Vec<&[DVec2]> = l.rings().collect();
        assert_eq!(rings.len(), 1);
        assert_eq!(rings[0].len(), 6);
        assert!((0.5 * twice_area(rings[0]) - 2.0).abs() < 1e-15);
    }

    #[test]
    fn a_frame_gives_an_outer_ring_and_a_hole_and_round_off_is_joined() {
        let d = DVec2::new;
        // Four quads around the hole [1,2]²; one shared corner moved by 1e-15 on one side.
        let quads = [
            [d(0.0, 0.0), d(3.0, 0.0), d(2.0, 1.0), d(1.0, 1.0)],
            [d(3.0, 0.0), d(3.0, 3.0), d(2.0, 2.0), d(2.0, 1.0 + 1e-15)],
            [d(3.0, 3.0), d(0.0, 3.0), d(1.0, 2.0), d(2.0, 2.0)],
            [d(0.0, 3.0), d(0.0, 0.0), d(1.0, 1.0), d(1.0, 2.0)],
        ];
        let mut l = Loops::default();
        // Each quad shares its second and fourth edges (the diagonals) with its neighbours.
        for q in &quads {
            push_ring(&mut l, q, &[1, 3]);
        }
        assert!(l.chain(1e-12));
        let areas: Vec<f64> = l.rings().map(|r| 0.5 * twice_area(r)).collect();
        assert_eq!(areas.len(), 2, "{areas:?}");
        assert!((areas.iter().sum::<f64>() - 8.0).abs() < 1e-12, "{areas:?}");
        assert!(areas.iter().any(|&a| (a + 1.0).abs() < 1e-12), "the hole turns clockwise: {areas:?}");
    }

    #[test]
    fn edges_that_are_no_cycle_are_refused() {
        let d = DVec2::new;
        let a = [d(0.0, 0.0), d(1.0, 0.0), d(1.0, 1.0), d(0.0, 1.0)];
        let mut l = Loops::default();
        // The top edge dropped without a partner: the chain cannot close.
        push_ring(&mut l, &a, &[2]);
        assert!(!l.chain(1e-12));
        // A gap above the tolerance is refused too.
        l.clear();
        l.push(d(0.0, 0.0), d(1.0, 0.0));
        l.push(d(1.0, 1e-9), d(0.0, 0.0));
        assert!(!l.chain(1e-12));
        assert!(l.chain(1e-8));
    }
}
