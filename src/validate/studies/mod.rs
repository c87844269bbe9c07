//! Studies that sweep a knob or a degeneracy parameter and draw charts.
use crate::Result;
use std::path::Path;

/// Runs every study, writes its charts into `out` and returns markdown sections for the report.
pub fn run_all(_quick: bool, _out: &Path, _progress: &mut dyn FnMut(&str)) -> Result<Vec<String>> {
    Ok(Vec::new())
}
