//! The last check on written factors: every F must lie in [−[`RANGE_SLACK`], 1 + slack]
//! whatever the method, or the run fails (exit 1) naming the pair and the method. A factor
//! outside that range is impossible, so it is never clamped or written.
//!
//! Monte Carlo entries are estimates with a reported standard error σ (an unbiased estimate of
//! an F near 1 lies above 1 half the time): their slack adds [`RANGE_SIGMAS`]·σ.
use super::packed::PackedTriangular;
use super::{MethodSet, ViewFactors};
use crate::{Error, Result};

/// Slack on [0, 1] for round-off: a factor computed to 1e-15 relative and summed over a few
/// thousand patches stays well inside it.
pub const RANGE_SLACK: f64 = 1e-12;
/// Standard errors of slack for estimated entries: a false alarm needs a 6σ event.
pub const RANGE_SIGMAS: f64 = 6.0;

/// Checks every factor of `vf` (its own level's names).
pub fn check(vf: &ViewFactors) -> Result<()> {
    for (i, row) in vf.rows.iter().enumerate() {
        for e in row {
            if !in_range(e.factor, e.std_error) {
                return Err(out_of_range(
                    &vf.names[i],
                    &vf.names[e.to as usize],
                    e.factor,
                    e.std_error,
                    e.method,
                ));
            }
        }
    }
    Ok(())
}

/// Checks every factor F_ij = s̄_ij/A_i and F_ji = s̄_ij/A_j of the packed store, with
/// `names` its node names.
pub fn check_triangle(t: &PackedTriangular, names: &[String]) -> Result<()> {
    for i in 0..t.n {
        let row = t.row(i);
        let ai = t.areas[i];
        for (k, &s) in row.iter().enumerate() {
            let j = i + k;
            let aj = t.areas[j];
            // Cheap test first: no division unless a factor may be out of range.
            if s >= -RANGE_SLACK * ai.min(aj) && s <= ai.min(aj) {
                continue;
            }
            let (method, var) = t.meta(i, j);
            let (fi, fj) = (s / ai, s / aj);
            if !in_range(fi, var.sqrt() / ai) {
                return Err(out_of_range(&names[i], &names[j], fi, var.sqrt() / ai, method));
            }
            if !in_range(fj, var.sqrt() / aj) {
                return Err(out_of_range(&names[j], &names[i], fj, var.sqrt() / aj, method));
            }
        }
    }
    Ok(())
}

/// True when `f` (standard error `sigma`) is a possible view factor.
pub fn in_range(f: f64, sigma: f64) -> bool {
    let slack = RANGE_SLACK + RANGE_SIGMAS * sigma;
    f >= -slack && f <= 1.0 + slack
}

fn out_of_range(from: &str, to: &str, f: f64, sigma: f64, method: MethodSet) -> Error {
    let se = if sigma > 0.0 { format!(" (standard error {sigma:e})") } else { String::new() };
    Error::Compute(format!(
        "impossible view factor F({from} -> {to}) = {f}{se} from method {method}: outside [0, 1] beyond round-off; \
         nothing was written"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewfactor::{Entry, Level};
    use std::time::Duration;

    fn matrix(factor: f64, std_error: f64, method: MethodSet) -> ViewFactors {
        let e = |to, factor| Entry { to, factor, std_error, method };
        ViewFactors {
            level: Level::Surface,
            names: vec!["floor".into(), "sky".into()],
            areas: vec![1.0, 1.0],
            rows: vec![vec![e(1, factor)], vec![e(0, 0.5)]],
            patch_row_sums: vec![factor, 0.5],
            patch_samples: vec![0, 0],
            pairs: 1,
            wall: Duration::ZERO,
            flags: Vec::new(),
            warnings: Vec::new(),
        }
    }

    #[test]
    fn an_impossible_factor_fails_naming_the_pair_and_the_method() {
        for f in [1.0154, 1.0 + 2e-12, -1e-9, f64::NAN] {
            let err = check(&matrix(f, 0.0, MethodSet::HEMICUBE)).unwrap_err();
            assert_eq!(err.exit_code(), 1);
            let msg = err.to_string();
            assert!(msg.contains("F(floor -> sky)") && msg.contains("hemicube"), "{msg}");
        }
        for f in [0.0, 1.0, 1.0 + 5e-13, -5e-13] {
            assert!(check(&matrix(f, 0.0, MethodSet::ANALYTIC)).is_ok(), "{f}");
        }
    }

    #[test]
    fn estimates_get_their_standard_errors_of_slack() {
        // An unbiased estimate of F = 1 lies above 1 half the time: 4σ above passes, 7σ fails.
        assert!(check(&matrix(1.0 + 4e-3, 1e-3, MethodSet::MC_UNIFORM)).is_ok());
        let err = check(&matrix(1.0 + 7e-3, 1e-3, MethodSet::MC_UNIFORM)).unwrap_err();
        assert!(err.to_string().contains("standard error"), "{err}");
    }

    #[test]
    fn the_packed_store_is_checked_in_both_directions() {
        // s = 0.9 m² between a 1 m² and a 0.5 m² node: F = 0.9 one way, 1.8 the other.
        let mut t = PackedTriangular::zeros(2, vec![1.0, 0.5]).unwrap();
        t.rows_mut()[0][1] = 0.9;
        let names = ["big".to_string(), "small".to_string()];
        let err = check_triangle(&t, &names).unwrap_err();
        assert!(err.to_string().contains("F(small -> big) = 1.8"), "{err}");
        t.rows_mut()[0][1] = 0.4;
        assert!(check_triangle(&t, &names).is_ok());
    }
}
