//! The textbook validation suite behind `lambert validate`.
//!
//! - [`case`]: a case folder (scene + `reference.toml`: citation, reference quantities with
//!   provenance, per-method overrides) and discovery under `cases/`;
//! - [`runner`]: every case × every method, view-factor and heat checks;
//! - [`tolerance`]: each method's error model and the suite's run budget;
//! - [`heat`]: enclosure heat-rate / temperature checks through the radiation solve;
//! - [`check`]: one report row and its status (pass, FAIL, n/a, skip);
//! - [`report`]: the markdown report and the console table;
//! - [`oracle`]: independent reference values for the generated studies;
//! - [`studies`]: speed–accuracy, stability and Monte Carlo convergence sweeps (charts).
//!
//! Sits beside the CLI at the top of the dependency chain: it uses scene, viewfactor, solve
//! and report, and nothing below uses it.
use crate::error::InputError;
use crate::{Error, Result};
use std::path::{Path, PathBuf};

pub mod case;
pub mod check;
pub mod heat;
pub mod oracle;
pub mod report;
pub mod runner;
pub mod studies;
pub mod tolerance;

pub use case::Case;
pub use check::{Check, Status};
pub use tolerance::Budget;

/// What `lambert validate` was asked to do.
#[derive(Debug, Clone)]
pub struct Options {
    /// Folder of cases.
    pub cases: PathBuf,
    /// Folder for the report and charts.
    pub out: PathBuf,
    /// The CI subset: small budgets, small studies.
    pub quick: bool,
}

/// The results of a suite run.
#[derive(Debug, Clone, Default)]
pub struct Suite {
    /// Quick mode.
    pub quick: bool,
    /// The budget, in words.
    pub budget_note: String,
    /// 1-, 5- and 15-minute load averages at the start (Linux), to qualify the timings.
    pub load: Option<String>,
    /// Loaded cases in run order.
    pub cases: Vec<Case>,
    /// Case folders without a reference file.
    pub without_reference: Vec<String>,
    /// Every check.
    pub checks: Vec<Check>,
    /// Further markdown sections (study tables, chart links).
    pub sections: Vec<String>,
}

impl Suite {
    /// Number of failed checks.
    pub fn failures(&self) -> usize {
        self.checks.iter().filter(|c| matches!(c.status, Status::Fail(_))).count()
    }
}

/// Runs every case under `options.cases`, then the studies, and writes the report and charts
/// into `options.out`. `progress` receives one line per finished case.
pub fn run(options: &Options, progress: &mut dyn FnMut(&str)) -> Result<Suite> {
    let budget = if options.quick { Budget::quick() } else { Budget::full() };
    let (dirs, bare) = case::discover(&options.cases)?;
    let mut suite = Suite {
        quick: options.quick,
        budget_note: format!(
            "Monte Carlo {} rays per case (at least {} per patch), hemicube/single-plane R = {}, auto goal {:e}, seed {}",
            budget.rays_per_case, budget.min_samples, budget.resolution, budget.auto_tolerance, budget.seed
        ),
        load: std::fs::read_to_string("/proc/loadavg")
            .ok()
            .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(", ")),
        without_reference: bare.iter().filter_map(|d| d.file_name()).map(|n| n.to_string_lossy().into_owned()).collect(),
        ..Suite::default()
    };
    for dir in &dirs {
        match Case::load(dir) {
            Ok(case) => {
                let checks = runner::run_case(&case, &budget);
                let failed = checks.iter().filter(|c| matches!(c.status, Status::Fail(_))).count();
                progress(&format!("{:<32} {} checks, {} failed", case.name, checks.len(), failed));
                suite.checks.extend(checks);
                suite.cases.push(case);
            }
            Err(e) => {
                let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                progress(&format!("{name:<32} reference error: {e}"));
                suite.checks.push(Check::without_value(
                    &name,
                    "reference.toml",
                    "-",
                    Status::Fail(e.to_string()),
                ));
            }
        }
    }
    std::fs::create_dir_all(&options.out).map_err(|e| io(&options.out, e))?;
    suite.sections = studies::run_all(options.quick, &options.out, progress)?;
    write_outputs(&suite, &options.out)?;
    Ok(suite)
}

fn io(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.to_path_buf(), source }
}

/// Writes `report.md` into `out`.
pub fn write_outputs(suite: &Suite, out: &Path) -> Result<()> {
    let path = out.join("report.md");
    std::fs::write(&path, report::markdown(suite)).map_err(|e| io(&path, e))
}

/// A missing cases folder is bad usage, not a failed check.
pub fn check_options(options: &Options) -> Result<()> {
    if !options.cases.is_dir() {
        return Err(InputError::file(&options.cases, "the cases folder does not exist").into());
    }
    Ok(())
}
