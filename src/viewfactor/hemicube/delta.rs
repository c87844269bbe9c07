//! Delta form factors of the hemicube pixels (Cohen & Greenberg 1985), computed once per
//! resolution: ΔF = ΔA/[π(x² + y² + 1)²] on the top face (z = 1) and
//! ΔF = z·ΔA/[π(u² + z² + 1)²] on the four half side faces, at the pixel centres.
//!
//! They are the midpoint rule of the exact pixel factors, so their total is 1 + O(h²)
//! (1 + 8e-6 at R = 256, literature.md §4).
use std::f64::consts::PI;

/// Delta factors for one resolution, shared by every eye.
#[derive(Debug, Clone)]
pub(crate) struct DeltaTables {
    /// Pixels along the top face (even).
    pub resolution: usize,
    /// Top face (R × R, rows from y = −1) as row prefix sums, R + 1 per row starting at 0,
    /// so a run of pixels sums in one subtraction.
    pub top_prefix: Vec<f64>,
    /// One side face (R columns × R/2 rows from z = 0; all four sides share it), likewise.
    pub side_prefix: Vec<f64>,
    /// Σ of all five faces' delta factors.
    total: f64,
}

impl DeltaTables {
    /// Tables for an even resolution `r`.
    pub fn new(r: usize) -> Self {
        debug_assert!(r >= 2 && r.is_multiple_of(2));
        let h = 2.0 / r as f64;
        let centre = |k: usize| -1.0 + (k as f64 + 0.5) * h;
        let mut top = Vec::with_capacity(r * r);
        for row in 0..r {
            let y = centre(row);
            for col in 0..r {
                let x = centre(col);
                let d = x * x + y * y + 1.0;
                top.push(h * h / (PI * d * d));
            }
        }
        let mut side = Vec::with_capacity(r * r / 2);
        for row in 0..r / 2 {
            let z = (row as f64 + 0.5) * h;
            for col in 0..r {
                let u = centre(col);
                let d = u * u + z * z + 1.0;
                side.push(z * h * h / (PI * d * d));
            }
        }
        let total = top.iter().sum::<f64>() + 4.0 * side.iter().sum::<f64>();
        Self { resolution: r, top_prefix: row_prefix(&top, r), side_prefix: row_prefix(&side, r), total }
    }

    /// Σ of all five faces' delta factors (1 + O(h²)).
    pub fn total(&self) -> f64 {
        self.total
    }
}

/// Per-row prefix sums (R + 1 per row, starting at 0) of a row-major table of width `r`.
fn row_prefix(table: &[f64], r: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(table.len() / r * (r + 1));
    for row in table.chunks_exact(r) {
        let mut sum = 0.0;
        out.push(0.0);
        out.extend(row.iter().map(|d| {
            sum += d;
            sum
        }));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delta_factors_sum_to_one_with_midpoint_error() {
        // literature.md §4: 1 + 8e-6 at 256²; the midpoint error scales as h².
        let e256 = DeltaTables::new(256).total() - 1.0;
        let e128 = DeltaTables::new(128).total() - 1.0;
        assert!(e256 > 0.0 && e256 < 1e-5, "256: {e256:e}");
        let order = (e128 / e256).log2();
        assert!((order - 2.0).abs() < 0.05, "order {order}");
    }
}
