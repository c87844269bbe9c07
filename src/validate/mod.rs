//! The textbook validation suite behind `lambert validate`.
//!
//! - `case`: a case folder (scene + `reference.toml`: citation, reference quantities with
//!   provenance, per-method overrides) and discovery under `cases/`;
//! - [`runner`]: every case × every method, view-factor and heat checks;
//! - `tolerance`: each method's error model and the suite's run budget;
//! - `heat`: enclosure heat-rate / temperature checks through the radiation solve;
//! - `check`: one report row and its status (pass, FAIL, n/a, skip);
//! - [`report`]: the markdown report and the console table;
//! - `oracle`: independent reference values for the generated studies;
//! - `studies`: speed–accuracy, stability and Monte Carlo convergence sweeps (charts).
//!
//! Sits beside the CLI at the top of the dependency chain: it uses scene, viewfactor, solve
//! and report, and nothing below uses it.
use crate::error::InputError;
use crate::{Error, Result};
use std::path::{Path, PathBuf};

pub(crate) mod case;
pub(crate) mod check;
pub(crate) mod heat;
pub(crate) mod oracle;
pub mod report;
pub mod runner;
pub(crate) mod studies;
pub(crate) mod tolerance;

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
/// into `options.out`: into a staging folder first ([`STAGING`]), moved into `out` only when
/// every file has been written. `progress` receives one line per finished case.
pub fn run(options: &Options, progress: &mut dyn FnMut(&str)) -> Result<Suite> {
    let staging = Staging::create(&options.out)?;
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
    suite.sections = studies::run_all(options.quick, &staging.dir, progress)?;
    write_outputs(&suite, &staging.dir)?;
    staging.commit()?;
    Ok(suite)
}

/// An I/O error on `path` while writing `what`.
fn io(path: &Path, what: &str, source: std::io::Error) -> Error {
    let source = std::io::Error::new(source.kind(), format!("cannot write the {what}: {source}"));
    Error::Io { path: path.to_path_buf(), source }
}

/// The name of the staging folder inside `--out`; a leftover from a killed run is removed by
/// the next run.
pub const STAGING: &str = "validate.partial";

/// The folder a suite run writes into, moved file by file into `--out` at the end; removed
/// when the run fails.
struct Staging {
    out: PathBuf,
    dir: PathBuf,
    done: bool,
}

impl Staging {
    /// Creates `out` (if needed) and an empty staging folder in it.
    fn create(out: &Path) -> Result<Self> {
        std::fs::create_dir_all(out).map_err(|e| {
            Error::Usage(format!(
                "{} {}: cannot create the folder: {e}",
                crate::error::opt("out"),
                out.display()
            ))
        })?;
        let dir = out.join(STAGING);
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| io(&dir, "staging folder (a leftover)", e))?;
        }
        std::fs::create_dir(&dir).map_err(|e| io(&dir, "staging folder", e))?;
        Ok(Self { out: out.to_path_buf(), dir, done: false })
    }

    /// Moves every staged file into `out` and removes the staging folder.
    fn commit(mut self) -> Result<()> {
        let entries = std::fs::read_dir(&self.dir).map_err(|e| io(&self.dir, "staging folder", e))?;
        let mut names: Vec<_> = entries.filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
        names.sort();
        for name in names {
            let target = self.out.join(&name);
            std::fs::rename(self.dir.join(&name), &target)
                .map_err(|e| io(&target, "validation output", e))?;
        }
        std::fs::remove_dir(&self.dir).map_err(|e| io(&self.dir, "staging folder", e))?;
        self.done = true;
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

/// Writes `report.md` into `out`.
pub fn write_outputs(suite: &Suite, out: &Path) -> Result<()> {
    let path = out.join("report.md");
    std::fs::write(&path, report::markdown(suite)).map_err(|e| io(&path, "validation report", e))
}

/// The line of a full-suite report that [`check_options`] looks for.
const FULL_MODE_MARK: &str = "Mode: **full**";

/// A missing cases folder is bad usage, not a failed check; so is a quick run that would
/// replace a full-suite report (and its charts) in `out`.
pub fn check_options(options: &Options) -> Result<()> {
    if !options.cases.is_dir() {
        return Err(InputError::file(&options.cases, "the cases folder does not exist").into());
    }
    let report = options.out.join("report.md");
    if options.quick && std::fs::read_to_string(&report).is_ok_and(|t| t.contains(FULL_MODE_MARK)) {
        return Err(Error::Usage(format!(
            "{q} {o} {}: that folder holds the full suite's report ({}); the quick subset would replace \
             it and its charts; give another {o}, or drop {o} (a scratch folder is used)",
            options.out.display(),
            report.display(),
            q = crate::error::opt("quick"),
            o = crate::error::opt("out"),
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_files_move_in_at_the_end_and_a_failed_run_leaves_the_folder_as_it_was() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("validation");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("report.md"), "earlier").unwrap();
        // A leftover of a killed run is removed.
        std::fs::create_dir(out.join(STAGING)).unwrap();
        std::fs::write(out.join(STAGING).join("stale.png"), "x").unwrap();
        {
            let s = Staging::create(&out).unwrap();
            assert!(!s.dir.join("stale.png").exists());
            std::fs::write(s.dir.join("report.md"), "half").unwrap();
            // Dropped without commit: the run failed.
        }
        assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), "earlier");
        assert!(!out.join(STAGING).exists());
        let s = Staging::create(&out).unwrap();
        std::fs::write(s.dir.join("report.md"), "new").unwrap();
        std::fs::write(s.dir.join("chart.svg"), "svg").unwrap();
        assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), "earlier");
        s.commit().unwrap();
        assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), "new");
        assert_eq!(std::fs::read_to_string(out.join("chart.svg")).unwrap(), "svg");
        assert!(!out.join(STAGING).exists());
    }

    #[test]
    fn quick_runs_never_replace_a_full_report() {
        let dir = tempfile::tempdir().unwrap();
        let cases = dir.path().join("cases");
        std::fs::create_dir(&cases).unwrap();
        let out = dir.path().to_path_buf();
        let options = |quick| Options { cases: cases.clone(), out: out.clone(), quick };
        // The mark is what the report of a full run says, and only of a full run.
        assert!(report::markdown(&Suite::default()).contains(FULL_MODE_MARK));
        assert!(!report::markdown(&Suite { quick: true, ..Suite::default() }).contains(FULL_MODE_MARK));
        // No report yet, or a quick one: both modes may write.
        check_options(&options(true)).unwrap();
        std::fs::write(out.join("report.md"), "Mode: **quick**.").unwrap();
        check_options(&options(true)).unwrap();
        std::fs::write(out.join("report.md"), format!("Generated. {FULL_MODE_MARK}. 39 cases")).unwrap();
        check_options(&options(false)).unwrap();
        let e = check_options(&options(true)).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("report.md"), "{e}");
    }
}
