//! The union of many plane polygons in one boolean operation (the `i_overlay` crate).
//!
//! - [`Union`] collects rings ([`Union::push`]), then [`Union::run`] returns the region
//!   covered by at least one of them (non-zero winding, so the rings must all turn the same
//!   way), optionally intersected with a second set of rings (the clip).
//! - The result is a set of oriented contours: outer boundaries counter-clockwise, holes
//!   clockwise, so any contour integral (area, Lambert's formula) over the region is the sum
//!   of the signed integrals over its contours.
//! - Coordinates go through `i_overlay`'s 64-bit integer engine: the grid spacing is
//!   2⁻⁶⁰ of the given bounds, below the f64 round-off of the inputs, so the union is exact
//!   up to the rounding of its new crossing points.
use glam::DVec2;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay::ShapeType;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::{FloatOverlay, OverlayOptions};
use i_overlay::i_float::adapter::FloatPointAdapter;
use i_overlay::i_float::float::rect::FloatRect;
use i_overlay::i_shape::flat::float::FloatFlatContoursBuffer;
use std::ops::Range;

/// Margin added around the given bounds, as a fraction of their size: the rings' round-off
/// may put points a hair outside, and the integer engine needs every point inside.
const BOUNDS_MARGIN_REL: f64 = 1e-3;

/// Rings to unite, and the buffers of the last result (reused across calls).
#[derive(Debug, Clone, Default)]
pub struct Union {
    points: Vec<[f64; 2]>,
    rings: Vec<Range<usize>>,
    clip_points: Vec<[f64; 2]>,
    clip_rings: Vec<Range<usize>>,
    out: FloatFlatContoursBuffer<[f64; 2]>,
    contour_points: Vec<DVec2>,
}

impl Union {
    /// Forgets every ring.
    pub fn clear(&mut self) {
        self.points.clear();
        self.rings.clear();
        self.clip_points.clear();
        self.clip_rings.clear();
    }
    /// Adds a ring to unite (every ring turning the same way).
    pub fn push(&mut self, ring: &[DVec2]) {
        let start = self.points.len();
        self.points.extend(ring.iter().map(|q| q.to_array()));
        self.rings.push(start..self.points.len());
    }
    /// Adds a ring of the clip: the union is intersected with the clip rings' union.
    pub fn push_clip(&mut self, ring: &[DVec2]) {
        let start = self.clip_points.len();
        self.clip_points.extend(ring.iter().map(|q| q.to_array()));
        self.clip_rings.push(start..self.clip_points.len());
    }

    /// The union of the rings (∩ the clip's, when there are clip rings), every point of which
    /// lies in the box `[lo, hi]`; its contours are read with [`Self::contours`].
    pub fn run(&mut self, [lo, hi]: [DVec2; 2]) {
        self.contour_points.clear();
        self.out.points.clear();
        self.out.ranges.clear();
        if self.rings.is_empty() || !(lo.x <= hi.x && lo.y <= hi.y) {
            return;
        }
        let margin = BOUNDS_MARGIN_REL * (hi - lo).max_element().max(lo.abs().max(hi.abs()).max_element());
        let Ok(rect) = FloatRect::new(lo.x - margin, hi.x + margin, lo.y - margin, hi.y + margin) else {
            return;
        };
        let adapter = FloatPointAdapter::<[f64; 2], i64>::new_conservative(rect);
        let segments = self.points.len() + self.clip_points.len();
        let mut overlay =
            FloatOverlay::new_custom(adapter, OverlayOptions::default(), Solver::default(), segments);
        for r in &self.rings {
            overlay = overlay.unsafe_add_contour(&self.points[r.clone()], ShapeType::Subject);
        }
        for r in &self.clip_rings {
            overlay = overlay.unsafe_add_contour(&self.clip_points[r.clone()], ShapeType::Clip);
        }
        let rule = if self.clip_rings.is_empty() { OverlayRule::Subject } else { OverlayRule::Intersect };
        overlay.overlay_into(rule, FillRule::NonZero, &mut self.out);
        self.contour_points.extend(self.out.points.iter().map(|&p| DVec2::from_array(p)));
    }

    /// The oriented contours of the last [`Self::run`] (outer boundaries counter-clockwise,
    /// holes clockwise).
    pub fn contours(&self) -> impl Iterator<Item = &[DVec2]> + '_ {
        self.out.ranges.iter().map(|r| &self.contour_points[r.clone()])
    }

    /// Area of the last result: the sum of its contours' signed areas (each taken about its
    /// first point, so that far from the origin no digits cancel).
    pub fn area(&self) -> f64 {
        let twice = |c: &[DVec2]| {
            let o = c[0];
            c.windows(2).map(|w| (w[0] - o).perp_dot(w[1] - o)).sum::<f64>()
        };
        0.5 * self.contours().filter(|c| !c.is_empty()).map(twice).sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, y: f64, s: f64) -> Vec<DVec2> {
        vec![DVec2::new(x, y), DVec2::new(x + s, y), DVec2::new(x + s, y + s), DVec2::new(x, y + s)]
    }

    #[test]
    fn overlapping_squares_unite_and_a_ring_of_squares_keeps_its_hole() {
        let mut u = Union::default();
        u.push(&square(0.0, 0.0, 2.0));
        u.push(&square(1.0, 1.0, 2.0));
        u.run([DVec2::ZERO, DVec2::splat(3.0)]);
        assert!((u.area() - 7.0).abs() < 1e-14, "{}", u.area());
        // Eight unit squares around a missing middle one: area 8, one hole turning clockwise.
        u.clear();
        for k in 0..9 {
            if k != 4 {
                u.push(&square((k % 3) as f64, (k / 3) as f64, 1.0));
            }
        }
        u.run([DVec2::ZERO, DVec2::splat(3.0)]);
        assert!((u.area() - 8.0).abs() < 1e-14, "{}", u.area());
        let signs: Vec<bool> = u.contours().map(|c| super::super::convex::twice_area(c) > 0.0).collect();
        assert_eq!(signs.len(), 2, "an outer boundary and a hole");
        assert_eq!(signs.iter().filter(|&&s| s).count(), 1);
    }

    #[test]
    fn the_clip_cuts_the_union_and_an_empty_union_is_empty() {
        let mut u = Union::default();
        u.push(&square(0.0, 0.0, 2.0));
        u.push(&square(1.0, 1.0, 2.0));
        // Two clip pieces: [0, 1.5] × [0, 3] and [1.5, 3] × [2.5, 3].
        u.push_clip(&[
            DVec2::new(0.0, 0.0),
            DVec2::new(1.5, 0.0),
            DVec2::new(1.5, 3.0),
            DVec2::new(0.0, 3.0),
        ]);
        u.push_clip(&[
            DVec2::new(1.5, 2.5),
            DVec2::new(3.0, 2.5),
            DVec2::new(3.0, 3.0),
            DVec2::new(1.5, 3.0),
        ]);
        u.run([DVec2::ZERO, DVec2::splat(3.0)]);
        // Left part: 1.5 × 2 + 0.5 × 1 = 3.5; top strip: 1.5 × 0.5 = 0.75.
        assert!((u.area() - 4.25).abs() < 1e-14, "{}", u.area());
        u.clear();
        u.run([DVec2::ZERO, DVec2::ONE]);
        assert_eq!(u.contours().count(), 0);
        assert_eq!(u.area(), 0.0);
    }

    #[test]
    fn tiny_coordinates_keep_their_precision() {
        // Squares of side 2⁻²³ far from the origin, every coordinate exact in f64: the union's
        // area to 1e-12 relative.
        let (o, s) = (DVec2::new(3.0, -2.0), 2f64.powi(-23));
        let mut u = Union::default();
        u.push(&square(o.x, o.y, s));
        u.push(&square(o.x + 0.25 * s, o.y + 0.5 * s, s));
        u.run([o, o + DVec2::splat(1.5 * s)]);
        let want = 2.0 * s * s - 0.75 * s * 0.5 * s;
        assert!((u.area() - want).abs() < 1e-12 * want, "{} vs {want}", u.area());
    }
}
