//! The single plane's pixel grid and its exact cell factors.
//!
//! The plane z = 1 over the eye is cut into R × R pixels by node lines x_k (the same along y).
//! Instead of per-level tables of summed midpoint deltas, the node table G(x_i, y_j) of the
//! signed corner factor holds every level at once: the factor of any pixel-aligned cell
//! [x_i0, x_i1] × [y_j0, y_j1] is G(i1, j1) − G(i0, j1) − G(i1, j0) + G(i0, j0), exact, in four
//! look-ups. A Warnock cell that one polygon covers therefore adds its exact factor; only
//! cells cut by edges (down to one pixel) carry sampling error.
use crate::viewfactor::closed_form::element_to_rectangle_corner;

/// How the R pixels are laid out along each axis of the plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Spacing {
    /// Nodes x_k = tan φ_k with φ_k equally spaced over [−atan s, atan s]: pixels subtend
    /// about equal angles, so a wide plane costs no resolution at the zenith (the default).
    #[default]
    EqualAngle,
    /// Nodes equally spaced over [−s, s]: the classic layout; at s = 10 its pixels at the
    /// zenith are 10× coarser (in angle) than a hemicube's at the same R.
    Uniform,
}

/// Signed corner factor F(dA → [0, x] × [0, y] at unit height), catalogue B (V10); the
/// formula is odd in x and in y, so signed corners sum to any rectangle.
fn corner_factor(x: f64, y: f64) -> f64 {
    element_to_rectangle_corner(x, y, 1.0)
}

/// Node coordinates and the node table of [`corner_factor`].
#[derive(Debug, Clone)]
pub(crate) struct PlaneGrid {
    /// Pixels per axis.
    pub r: usize,
    /// R + 1 node coordinates from −s to s.
    pub nodes: Vec<f64>,
    /// R pixel centres (node midpoints), where pixels are point sampled.
    pub centres: Vec<f64>,
    /// G at node (i, j), index j·(R + 1) + i.
    g: Vec<f64>,
}

impl PlaneGrid {
    /// The grid of `r` pixels per axis over [−s, s]².
    pub fn new(r: usize, half_width: f64, spacing: Spacing) -> Self {
        let phi = half_width.atan();
        let mut nodes: Vec<f64> = (0..=r)
            .map(|k| {
                let t = 2.0 * k as f64 / r as f64 - 1.0;
                match spacing {
                    Spacing::EqualAngle => (t * phi).tan(),
                    Spacing::Uniform => t * half_width,
                }
            })
            .collect();
        // Exact ends (and centre) so the plane's total is exactly 4·F_corner(s, s).
        nodes[0] = -half_width;
        nodes[r] = half_width;
        if r.is_multiple_of(2) {
            nodes[r / 2] = 0.0;
        }
        let mut g = Vec::with_capacity((r + 1) * (r + 1));
        for &y in &nodes {
            g.extend(nodes.iter().map(|&x| corner_factor(x, y)));
        }
        let centres = nodes.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        Self { r, nodes, centres, g }
    }

    /// Exact factor of the cell of pixels [i0, i1) × [j0, j1).
    #[inline]
    pub fn cell_factor(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> f64 {
        let w = self.r + 1;
        self.g[j1 * w + i1] - self.g[j1 * w + i0] - self.g[j0 * w + i1] + self.g[j0 * w + i0]
    }

    /// Factor of the whole plane, 4·F_corner(s, s): what the plane captures of the hemisphere.
    pub fn captured(&self) -> f64 {
        self.cell_factor(0, self.r, 0, self.r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_captures_the_literature_fractions() {
        // docs/literature.md §4: 0.554, 0.917, 0.968, 0.9919 for s = 1, 3, 5, 10.
        for (s, want) in [(1.0, 0.554), (3.0, 0.917), (5.0, 0.968), (10.0, 0.9919)] {
            let got = PlaneGrid::new(8, s, Spacing::EqualAngle).captured();
            assert!((got - want).abs() < 6e-4, "s = {s}: {got}");
        }
    }

    #[test]
    fn cells_add_up_and_match_the_corner_formula() {
        let g = PlaneGrid::new(16, 10.0, Spacing::EqualAngle);
        let sum: f64 = (0..16)
            .flat_map(|i| (0..16).map(move |j| (i, j)))
            .map(|(i, j)| g.cell_factor(i, i + 1, j, j + 1))
            .sum();
        assert!((sum - 4.0 * corner_factor(10.0, 10.0)).abs() < 1e-14);
        // The quadrant [0, s]² is one corner factor.
        assert!((g.cell_factor(8, 16, 8, 16) - corner_factor(10.0, 10.0)).abs() < 1e-15);
    }
}
