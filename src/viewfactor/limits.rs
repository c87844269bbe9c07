//! The bounds on a view-factor run's knobs (samples, resolution, tolerance), one definition
//! for every caller: the CLI names its flags in the messages, the Python binding its keywords.
use crate::{Error, Result};
use std::ops::RangeInclusive;

/// Most rays (point pairs for `mc-area`) per patch: 1,000 times the default, where the
/// standard error of a factor is already below 5e-5·√F; tighter goals are the exact methods'
/// (`-m auto --tolerance`), at a small fraction of the cost.
pub const MAX_SAMPLES: usize = 100_000_000;
/// Smallest tolerance: the exact integrals' round-off in f64 (about 1e-14 relative on a
/// factor, summed over a row) sits just below it, so a tighter goal cannot be met and only
/// makes the adaptive rules and samplers run without end.
pub const MIN_TOLERANCE: f64 = 1e-13;
/// Hemicube / single-plane resolutions (cells per full face side) a run accepts.
pub const RESOLUTIONS: RangeInclusive<usize> = 2..=16384;

/// Checks a tolerance given as `what` (a flag, a keyword, or a scene file's View3D `eps`):
/// in (0, 1) and not below [`MIN_TOLERANCE`].
pub fn tolerance(t: f64, what: &str) -> Result<f64> {
    if !(t.is_finite() && t > 0.0 && t < 1.0) {
        return Err(Error::Usage(format!("{what} must be in (0, 1), got {t}")));
    }
    if t < MIN_TOLERANCE {
        return Err(Error::Usage(format!(
            "{what} {t:e} is below {MIN_TOLERANCE:e}, the round-off floor of the exact integrals in f64: it \
             cannot be met and the run would not end; give {MIN_TOLERANCE:e} or more"
        )));
    }
    Ok(t)
}
