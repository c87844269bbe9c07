//! Studies that sweep a knob or a degeneracy parameter, with charts (SVG + PNG) in the output
//! folder and markdown sections for the report.
//!
//! - [`scenes`]: programmatic study scenes and their independent references;
//! - [`sweep`]: one measured run (time, error) and chart series;
//! - [`speed`]: speed–accuracy on the cube, the blocked squares and the obstructed room;
//! - [`stability`]: touching, far-field, vanishing-receiver and grazing sweeps;
//! - [`convergence`]: Monte Carlo error against samples with the reference slopes.
use crate::Result;
use std::path::Path;

pub(crate) mod convergence;
pub(crate) mod scenes;
pub(crate) mod speed;
pub(crate) mod stability;
pub(crate) mod sweep;

/// Runs every study, writes its charts into `out` and returns markdown sections for the report.
pub fn run_all(quick: bool, out: &Path, progress: &mut dyn FnMut(&str)) -> Result<Vec<String>> {
    Ok(vec![
        speed::run(quick, out, progress)?,
        stability::run(quick, out, progress)?,
        convergence::run(quick, out, progress)?,
    ])
}
