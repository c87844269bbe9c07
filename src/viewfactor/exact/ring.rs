//! Vertex rings without heap allocation for small polygons, and half-space clipping on them.
//!
//! The kernels clip every polygon pair against each other's plane; a [`Ring`] keeps up to
//! [`INLINE`] vertices on the stack and spills to the heap only for larger polygons
//! (tessellated disks), so the common triangle/quad path never allocates.
use crate::geometry::clip::clip_ring_each;
use glam::DVec3;

/// Vertices kept on the stack; a quad clipped by a plane has at most 5.
pub const INLINE: usize = 12;

/// A closed vertex ring (last vertex connects to the first).
#[derive(Debug, Clone)]
pub struct Ring {
    inline: [DVec3; INLINE],
    len: usize,
    heap: Vec<DVec3>,
}

impl Default for Ring {
    fn default() -> Self {
        Self { inline: [DVec3::ZERO; INLINE], len: 0, heap: Vec::new() }
    }
}

impl Ring {
    /// An empty ring.
    pub fn new() -> Self {
        Self::default()
    }

    /// Removes every vertex (keeps any heap capacity).
    pub fn clear(&mut self) {
        self.len = 0;
        self.heap.clear();
    }

    /// Appends a vertex, spilling to the heap past [`INLINE`] vertices.
    pub fn push(&mut self, v: DVec3) {
        if self.len < INLINE {
            self.inline[self.len] = v;
        } else {
            if self.len == INLINE {
                self.heap.extend_from_slice(&self.inline);
            }
            self.heap.push(v);
        }
        self.len += 1;
    }

    /// Removes the last vertex, moving back to the stack when the ring shrinks to [`INLINE`].
    pub fn pop(&mut self) {
        if self.len == 0 {
            return;
        }
        self.len -= 1;
        if self.len >= INLINE {
            self.heap.pop();
            if self.len == INLINE {
                self.inline.copy_from_slice(&self.heap);
                self.heap.clear();
            }
        }
    }

    /// The vertices.
    pub fn as_slice(&self) -> &[DVec3] {
        if self.len <= INLINE {
            &self.inline[..self.len]
        } else {
            &self.heap
        }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the ring has no vertex.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Fills the ring with `(v − origin)·scale` for each vertex of `src`.
    pub fn fill_mapped(&mut self, src: &[DVec3], origin: DVec3, scale: f64) {
        self.clear();
        for &v in src {
            self.push((v - origin) * scale);
        }
    }
}

/// How a ring sits against a half-space.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Every vertex is on the kept side or on the plane.
    Inside,
    /// Every vertex is on the discarded side or on the plane.
    Outside,
    /// The plane cuts the ring.
    Cut,
}

/// Classifies `src` against `(x − point)·normal ≥ 0`, with distances below `snap` counted as 0.
pub fn classify(src: &[DVec3], point: DVec3, normal: DVec3, snap: f64) -> Side {
    let (mut pos, mut neg) = (false, false);
    for v in src {
        let d = (*v - point).dot(normal);
        pos |= d > snap;
        neg |= d < -snap;
    }
    match (pos, neg) {
        (_, false) => Side::Inside,
        (false, true) => Side::Outside,
        (true, true) => Side::Cut,
    }
}

/// Sutherland–Hodgman: writes into `out` the part of `src` with `(x − point)·normal ≥ 0`.
///
/// Vertices within `snap` of the plane count as on it (kept, never split), so a polygon that
/// touches the plane along an edge is not cut into slivers by round-off. A non-convex ring may
/// come back with zero-width bridges along the plane; their edges cancel in every contour sum.
pub fn clip_into(src: &[DVec3], point: DVec3, normal: DVec3, snap: f64, out: &mut Ring) {
    out.clear();
    clip_ring_each(src, |v| (v - point).dot(normal), snap, |x| push_distinct(out, x));
    // Close the ring: drop a last vertex equal to the first.
    while out.len() > 1 && out.as_slice()[0] == out.as_slice()[out.len() - 1] {
        out.pop();
    }
    if out.len() < 3 {
        out.clear();
    }
}

fn push_distinct(out: &mut Ring, v: DVec3) {
    if out.as_slice().last() != Some(&v) {
        out.push(v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spills_to_heap_and_keeps_order() {
        let mut r = Ring::new();
        for k in 0..INLINE + 5 {
            r.push(DVec3::splat(k as f64));
        }
        assert_eq!(r.len(), INLINE + 5);
        assert!(r.as_slice().iter().enumerate().all(|(k, v)| v.x == k as f64));
        // Popping back to the stack keeps the same vertices.
        for _ in 0..6 {
            r.pop();
        }
        assert_eq!(r.len(), INLINE - 1);
        assert!(r.as_slice().iter().enumerate().all(|(k, v)| v.x == k as f64));
        r.push(DVec3::splat(-1.0));
        r.push(DVec3::splat(-2.0));
        assert_eq!(r.as_slice()[INLINE].x, -2.0);
    }

    #[test]
    fn clips_square_and_snaps_touching_vertices() {
        let sq = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let mut out = Ring::new();
        clip_into(&sq, DVec3::new(0.25, 0.0, 0.0), DVec3::X, 0.0, &mut out);
        assert_eq!(out.len(), 4);
        let xs: Vec<f64> = out.as_slice().iter().map(|v| v.x).collect();
        assert!(xs.iter().all(|&x| x >= 0.25), "{xs:?}");
        // A vertex 1e-17 behind the plane counts as on it: nothing is split off.
        let mut touching = sq;
        touching[0].x = -1e-17;
        clip_into(&touching, DVec3::ZERO, DVec3::X, 1e-14, &mut out);
        assert_eq!(out.as_slice(), &touching);
        assert_eq!(classify(&touching, DVec3::ZERO, DVec3::X, 1e-14), Side::Inside);
        assert_eq!(classify(&touching, DVec3::new(2.0, 0.0, 0.0), DVec3::X, 1e-14), Side::Outside);
    }
}
