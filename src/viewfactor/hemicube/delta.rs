//! Delta form factors of the hemicube pixels (Cohen & Greenberg 1985), computed once per
//! resolution: ΔF = ΔA/[π(x² + y² + 1)²] on the top face (z = 1) and
//! ΔF = z·ΔA/[π(u² + z² + 1)²] on the four half side faces, at the pixel centres.
//!
//! They are the midpoint rule of the exact pixel factors, so their raw total is 1 + O(h²)
//! (1 + 8e-6 at R = 256, 1.0154 at R = 6; docs/literature.md §4). They are divided by that total,
//! so the five faces sum to 1 up to round-off: a receiver that fills the whole hemisphere gets
//! F = 1, never more, and a closed row sums to 1.
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
    /// Σ of all five faces' delta factors after normalisation (1 up to round-off).
    total: f64,
    /// Σ of the raw midpoint delta factors (1 + O(h²)), by which they were divided.
    midpoint_total: f64,
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
        let midpoint_total = top.iter().sum::<f64>() + 4.0 * side.iter().sum::<f64>();
        top.iter_mut().chain(side.iter_mut()).for_each(|d| *d /= midpoint_total);
        let total = top.iter().sum::<f64>() + 4.0 * side.iter().sum::<f64>();
        Self {
            resolution: r,
            top_prefix: row_prefix(&top, r),
            side_prefix: row_prefix(&side, r),
            total,
            midpoint_total,
        }
    }

    /// Σ of all five faces' delta factors (1 up to round-off).
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Σ of the raw midpoint delta factors (1 + O(h²)), the normalisation divisor.
    pub fn midpoint_total(&self) -> f64 {
        self.midpoint_total
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
        // docs/literature.md §4: 1 + 8e-6 at 256²; the midpoint error scales as h².
        let e256 = DeltaTables::new(256).midpoint_total() - 1.0;
        let e128 = DeltaTables::new(128).midpoint_total() - 1.0;
        assert!(e256 > 0.0 && e256 < 1e-5, "256: {e256:e}");
        let order = (e128 / e256).log2();
        assert!((order - 2.0).abs() < 0.05, "order {order}");
    }

    #[test]
    fn normalised_delta_factors_sum_to_one_at_any_resolution() {
        // R = 6 (the evened --resolution 5) has a raw total of 1.0154.
        let coarse = DeltaTables::new(6);
        assert!((coarse.midpoint_total() - 1.0154).abs() < 1e-4, "{}", coarse.midpoint_total());
        for r in [2, 6, 64, 256, 4096] {
            let t = DeltaTables::new(r).total();
            assert!((t - 1.0).abs() < 1e-13, "R = {r}: {t}");
        }
    }
}
