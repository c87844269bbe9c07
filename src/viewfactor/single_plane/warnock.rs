//! Warnock-style visibility on the single plane: a cell of pixels is resolved whole when
//! no projected edge crosses it and one polygon covers it in front of every other; otherwise
//! it is split in four. Cells of at most [`SCAN_BLOCK`]² pixels that edges still cross are
//! resolved pixel by pixel, point sampled at the pixel centres with the same even–odd,
//! half-open rule as the hemicube's item buffer (row spans, as the rasteriser does: the same
//! answer as recursing to single pixels, at a fraction of the classification cost).
use super::grid::PlaneGrid;
use crate::geometry::clip::watertight::{self as clip, HalfSpace};
use crate::viewfactor::projection::prepare::{Gathered, NO_RECEIVER};
use crate::viewfactor::projection::raster::crossing;
use crate::viewfactor::projection::RECEIVER_DEPTH_BIAS;
use glam::{DVec2, DVec3};
use std::ops::Range;

/// One polygon projected onto the plane z = 1.
#[derive(Debug, Clone, Copy)]
struct ProjPoly {
    first: u32,
    len: u32,
    id: u32,
    lo: DVec2,
    hi: DVec2,
    /// Inverse depth a·x + b·y + c at plane point (x, y); larger is nearer.
    a: f64,
    b: f64,
    c: f64,
}

impl ProjPoly {
    #[inline]
    fn depth(&self, p: DVec2) -> f64 {
        self.a * p.x + self.b * p.y + self.c
    }
}

/// How a polygon meets a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Relation {
    Disjoint,
    /// An edge touches the cell (or the polygon lies inside it).
    Crosses,
    /// The cell lies inside the polygon.
    Surrounds,
}

/// The projected scene of one eye plus the subdivision stack (a reusable buffer).
#[derive(Debug, Clone, Default)]
pub(crate) struct PlaneScene {
    polys: Vec<ProjPoly>,
    pts: Vec<DVec2>,
    /// Candidate polygons of the cells being visited, with "surrounds the cell" flags (a
    /// polygon that surrounds a cell surrounds its children: no retest).
    stack: Vec<(u32, bool)>,
    clipped: Vec<DVec3>,
    tmp: Vec<DVec3>,
    /// Scan scratch: row crossings and the (depth, id) of a block's pixels.
    xs: Vec<f64>,
    block: Vec<(f64, u32)>,
    /// Receivers of the last projection that reach past the plane's edge (partly or wholly
    /// unseen), in gather order.
    pub cut: Vec<u32>,
}

/// Largest cell side, in pixels, resolved by scanning pixel rows rather than subdividing:
/// below it the quadtree's per-cell classification costs more than sampling each pixel.
const SCAN_BLOCK: usize = 8;

impl PlaneScene {
    /// Clips every gathered polygon to the pyramid |x|, |y| ≤ s·z, z ≥ near and projects it.
    pub fn project(&mut self, gathered: &Gathered, half_width: f64, near: f64) {
        let s = half_width;
        let planes: [HalfSpace; 5] = [
            HalfSpace::new(-1.0, 0.0, s, 0.0),
            HalfSpace::new(1.0, 0.0, s, 0.0),
            HalfSpace::new(0.0, -1.0, s, 0.0),
            HalfSpace::new(0.0, 1.0, s, 0.0),
            HalfSpace::new(0.0, 0.0, 1.0, -near),
        ];
        self.polys.clear();
        self.pts.clear();
        self.cut.clear();
        for p in &gathered.polys {
            // A receiver with a point in front of the eye beyond |x|, |y| = s·z is partly missed.
            if p.id != NO_RECEIVER
                && gathered
                    .vertices(p)
                    .iter()
                    .any(|q| q.z > near && (q.x.abs() > s * q.z || q.y.abs() > s * q.z))
            {
                self.cut.push(p.id);
            }
            if clip::sphere_outside(&planes, p.centre, p.radius) {
                continue;
            }
            clip::clip_polygon(gathered.vertices(p), &planes, &mut self.clipped, &mut self.tmp);
            if self.clipped.is_empty() {
                continue;
            }
            let first = self.pts.len() as u32;
            self.pts.extend(self.clipped.iter().map(|q| DVec2::new(q.x / q.z, q.y / q.z)));
            let ring = &self.pts[first as usize..];
            let (lo, hi) =
                ring.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(l, h), q| (l.min(*q), h.max(*q)));
            let k = (if p.id == NO_RECEIVER { 1.0 } else { 1.0 + RECEIVER_DEPTH_BIAS }) / p.c;
            let len = ring.len() as u32;
            self.polys.push(ProjPoly {
                first,
                len,
                id: p.id,
                lo,
                hi,
                a: p.m.x * k,
                b: p.m.y * k,
                c: p.m.z * k,
            });
        }
    }

    /// Resolves the plane and calls `add(id, factor)` for every cell or pixel a receiver wins.
    pub fn resolve(&mut self, grid: &PlaneGrid, add: &mut impl FnMut(u32, f64)) {
        self.stack.clear();
        self.stack.extend((0..self.polys.len() as u32).map(|k| (k, false)));
        let n = self.stack.len();
        self.visit(grid, [0, grid.r, 0, grid.r], 0..n, add);
    }

    fn ring(&self, p: &ProjPoly) -> &[DVec2] {
        &self.pts[p.first as usize..(p.first + p.len) as usize]
    }

    /// One Warnock cell [i0, i1) × [j0, j1) with the candidate polygons stack[parent].
    fn visit(
        &mut self,
        grid: &PlaneGrid,
        cell: [usize; 4],
        parent: Range<usize>,
        add: &mut impl FnMut(u32, f64),
    ) {
        let [i0, i1, j0, j1] = cell;
        let lo = DVec2::new(grid.nodes[i0], grid.nodes[j0]);
        let hi = DVec2::new(grid.nodes[i1], grid.nodes[j1]);
        let start = self.stack.len();
        let mut crossing = false;
        for k in parent {
            let (p, surrounds) = self.stack[k];
            let relation =
                if surrounds { Relation::Surrounds } else { self.relation(&self.polys[p as usize], lo, hi) };
            match relation {
                Relation::Disjoint => {}
                Relation::Crosses => {
                    crossing = true;
                    self.stack.push((p, false));
                }
                Relation::Surrounds => self.stack.push((p, true)),
            }
        }
        let list = start..self.stack.len();
        if list.is_empty() {
            return;
        }
        // Every candidate surrounds the cell: resolved if one is in front over all of it.
        if !crossing {
            if let Some(id) = self.front_most(list.clone(), lo, hi) {
                if id != NO_RECEIVER {
                    add(id, grid.cell_factor(i0, i1, j0, j1));
                }
                self.stack.truncate(start);
                return;
            }
        }
        if i1 - i0 <= SCAN_BLOCK && j1 - j0 <= SCAN_BLOCK {
            self.scan_block(grid, cell, list, add);
        } else {
            let im = if i1 - i0 > 1 { (i0 + i1) / 2 } else { i1 };
            let jm = if j1 - j0 > 1 { (j0 + j1) / 2 } else { j1 };
            for (a, b) in [(i0, im), (im, i1)] {
                for (c, d) in [(j0, jm), (jm, j1)] {
                    if a < b && c < d {
                        self.visit(grid, [a, b, c, d], list.clone(), add);
                    }
                }
            }
        }
        self.stack.truncate(start);
    }

    /// The polygon nearest over the whole cell (its farthest corner depth beats every other's
    /// nearest; depth is affine, so corners bound it), or `None` when depths interleave.
    fn front_most(&self, list: Range<usize>, lo: DVec2, hi: DVec2) -> Option<u32> {
        let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
        let range = |p: &ProjPoly| {
            corners.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
                (a.min(p.depth(*c)), b.max(p.depth(*c)))
            })
        };
        let best = list.clone().max_by(|&a, &b| {
            range(&self.polys[self.stack[a].0 as usize])
                .0
                .total_cmp(&range(&self.polys[self.stack[b].0 as usize]).0)
        })?;
        let near = range(&self.polys[self.stack[best].0 as usize]).0;
        list.filter(|&k| k != best)
            .all(|k| range(&self.polys[self.stack[k].0 as usize]).1 <= near)
            .then(|| self.polys[self.stack[best].0 as usize].id)
    }

    /// Resolves a small cell pixel by pixel: each candidate's crossings with every pixel-row
    /// centre line give spans, the nearest polygon whose span holds a pixel centre wins it
    /// (the even–odd, half-open rule of the rasteriser).
    fn scan_block(
        &mut self,
        grid: &PlaneGrid,
        cell: [usize; 4],
        list: Range<usize>,
        add: &mut impl FnMut(u32, f64),
    ) {
        let [i0, i1, j0, j1] = cell;
        let w = i1 - i0;
        self.block.clear();
        self.block.resize(w * (j1 - j0), (f64::NEG_INFINITY, NO_RECEIVER));
        for k in list {
            let p = self.polys[self.stack[k].0 as usize];
            let ring = &self.pts[p.first as usize..(p.first + p.len) as usize];
            for j in j0..j1 {
                let yc = grid.centres[j];
                if yc < p.lo.y || yc > p.hi.y {
                    continue;
                }
                self.xs.clear();
                for e in 0..ring.len() {
                    let (a, b) = (ring[e], ring[(e + 1) % ring.len()]);
                    if (a.y <= yc) != (b.y <= yc) {
                        self.xs.push(crossing(a, b, yc));
                    }
                }
                self.xs.sort_unstable_by(f64::total_cmp);
                for pair in self.xs.chunks_exact(2) {
                    for i in i0..i1 {
                        let xc = grid.centres[i];
                        if xc >= pair[0] && xc < pair[1] {
                            let q = p.depth(DVec2::new(xc, yc));
                            let slot = &mut self.block[(j - j0) * w + (i - i0)];
                            if q > slot.0 {
                                *slot = (q, p.id);
                            }
                        }
                    }
                }
            }
        }
        for (k, &(_, id)) in self.block.iter().enumerate() {
            if id != NO_RECEIVER {
                let (i, j) = (i0 + k % w, j0 + k / w);
                add(id, grid.cell_factor(i, i + 1, j, j + 1));
            }
        }
    }

    fn relation(&self, p: &ProjPoly, lo: DVec2, hi: DVec2) -> Relation {
        if p.hi.x < lo.x || p.lo.x > hi.x || p.hi.y < lo.y || p.lo.y > hi.y {
            return Relation::Disjoint;
        }
        let ring = self.ring(p);
        let n = ring.len();
        if (0..n).any(|k| segment_meets_box(ring[k], ring[(k + 1) % n], lo, hi)) {
            Relation::Crosses
        } else if contains(ring, 0.5 * (lo + hi)) {
            Relation::Surrounds
        } else {
            Relation::Disjoint
        }
    }
}

/// Even–odd point-in-ring test with half-open edges (the rasteriser's rule).
fn contains(ring: &[DVec2], p: DVec2) -> bool {
    let n = ring.len();
    let mut inside = false;
    for k in 0..n {
        let (a, b) = (ring[k], ring[(k + 1) % n]);
        if (a.y <= p.y) != (b.y <= p.y) && p.x >= crossing(a, b, p.y) {
            inside = !inside;
        }
    }
    inside
}

/// True when the segment a–b meets the closed box [lo, hi] (Liang–Barsky).
fn segment_meets_box(a: DVec2, b: DVec2, lo: DVec2, hi: DVec2) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, dp, l, h) in [(a.x, d.x, lo.x, hi.x), (a.y, d.y, lo.y, hi.y)] {
        if dp == 0.0 {
            if p < l || p > h {
                return false;
            }
        } else {
            let (ta, tb) = ((l - p) / dp, (h - p) / dp);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_box_and_point_tests() {
        let (lo, hi) = (DVec2::ZERO, DVec2::ONE);
        assert!(segment_meets_box(DVec2::new(-1.0, 0.5), DVec2::new(2.0, 0.5), lo, hi));
        assert!(segment_meets_box(DVec2::new(0.2, 0.2), DVec2::new(0.3, 0.3), lo, hi));
        assert!(!segment_meets_box(DVec2::new(-1.0, 1.5), DVec2::new(2.0, 1.2), lo, hi));
        assert!(!segment_meets_box(DVec2::new(1.5, -1.0), DVec2::new(3.0, 0.5), lo, hi));
        let tri = [DVec2::ZERO, DVec2::new(2.0, 0.0), DVec2::new(0.0, 2.0)];
        assert!(contains(&tri, DVec2::new(0.5, 0.5)));
        assert!(!contains(&tri, DVec2::new(1.5, 1.5)));
    }
}
