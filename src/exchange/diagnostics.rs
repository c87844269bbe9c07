//! Residuals of an exchange matrix: closure (row sums), reciprocity and sign, with the worst
//! rows by name. Computed before and after enforcement and printed by the CLI.
use super::operator::Operator;
use std::fmt;

/// How many worst rows are named.
pub const WORST_ROWS: usize = 5;

/// Closure, reciprocity and sign residuals of one exchange matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostics {
    /// max_i |Σ_j F_ij − 1| (closed) or max_i max(Σ_j F_ij − 1, 0) (open: the ambient takes
    /// any shortfall, only an excess is an error).
    pub max_row_error: f64,
    /// RMS of the same per-row errors.
    pub rms_row_error: f64,
    /// max |A_iF_ij − A_jF_ji| / max |A_iF_ij|.
    pub reciprocity: f64,
    /// Number of stored negative S_ij (ambient included).
    pub negatives: usize,
    /// Rows with the largest row error: (name, Σ_j F_ij − 1), worst first.
    pub worst: Vec<(String, f64)>,
}

impl Diagnostics {
    /// Measures any exchange store as it now is; `open` selects the one-sided row error of
    /// open scenes.
    pub fn of(op: &dyn Operator, open: bool) -> Self {
        Self::with_sums(op, &op.row_sums(), op.asymmetry(), open)
    }

    /// As [`Diagnostics::of`] with the row sums `sums` (m²) and the reciprocity residual
    /// given (the raw ones before enforcement, or sums the caller has already formed).
    pub fn with_sums(op: &dyn Operator, sums: &[f64], reciprocity: f64, open: bool) -> Self {
        let amb_neg = op.ambient().map_or(0, |a| a.iter().filter(|&&x| x < 0.0).count());
        Self::from_rows(sums, op.areas(), op.names(), open, reciprocity, op.negatives() + amb_neg)
    }

    /// The row residuals of row sums `sums` (m²) over `areas`, with the other two measures
    /// given: shared by every exchange store.
    pub fn from_rows(
        sums: &[f64],
        areas: &[f64],
        names: &[String],
        open: bool,
        reciprocity: f64,
        negatives: usize,
    ) -> Self {
        let n = sums.len();
        let dev: Vec<f64> = (0..n).map(|i| sums[i] / areas[i] - 1.0).collect();
        let err: Vec<f64> = dev.iter().map(|&d| if open { d.max(0.0) } else { d.abs() }).collect();
        let max_row_error = err.iter().copied().fold(0.0, f64::max);
        let rms_row_error =
            if n == 0 { 0.0 } else { (err.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt() };
        let mut order: Vec<usize> = (0..n).filter(|&i| err[i] > 0.0).collect();
        order.sort_by(|&a, &b| err[b].total_cmp(&err[a]).then(a.cmp(&b)));
        let worst = order.into_iter().take(WORST_ROWS).map(|i| (names[i].clone(), dev[i])).collect();
        Self { max_row_error, rms_row_error, reciprocity, negatives, worst }
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "max |row sum - 1| = {:.3e}, rms = {:.3e}, reciprocity = {:.3e}, negatives = {}",
            self.max_row_error, self.rms_row_error, self.reciprocity, self.negatives
        )?;
        if !self.worst.is_empty() && self.max_row_error > 0.0 {
            let names: Vec<String> = self.worst.iter().map(|(n, d)| format!("{n} ({d:+.2e})")).collect();
            write!(f, "; worst: {}", names.join(", "))?;
        }
        Ok(())
    }
}
