//! One row of the validation report: a quantity of a case computed by a method, compared with
//! its reference under that method's tolerance.
use std::time::Duration;

/// Outcome of one check.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Within tolerance.
    Pass,
    /// Out of tolerance, or the run failed.
    Fail(String),
    /// The method refused the case (`Unsupported`): reported, never counted as a pass.
    NotApplicable(String),
    /// Deliberately not run (`[skip]` in reference.toml, or not in `--quick`), with the reason.
    Skipped(String),
    /// Out of tolerance with a known, reported defect (`[known_issue]`): listed, not counted.
    Known(String),
}

impl Status {
    /// Short label for tables.
    pub fn label(&self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Fail(_) => "FAIL",
            Status::NotApplicable(_) => "n/a",
            Status::Skipped(_) => "skip",
            Status::Known(_) => "known",
        }
    }
    /// The reason attached to a non-pass status.
    pub fn reason(&self) -> Option<&str> {
        match self {
            Status::Pass => None,
            Status::Fail(r) | Status::NotApplicable(r) | Status::Skipped(r) | Status::Known(r) => Some(r),
        }
    }
}

/// A compared quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Case (folder) name.
    pub case: String,
    /// What is compared, e.g. `F(floor→ceiling)` or `q(heater) [W]`.
    pub quantity: String,
    /// Method name (SPEC names), or `vf-file` for a supplied exact view-factor file.
    pub method: String,
    /// Computed value.
    pub value: Option<f64>,
    /// Reference value.
    pub reference: Option<f64>,
    /// Absolute tolerance from the method's error model.
    pub tolerance: Option<f64>,
    /// Wall time of the method on the whole case.
    pub time: Option<Duration>,
    /// Outcome.
    pub status: Status,
}

impl Check {
    /// |value − reference|.
    pub fn error(&self) -> Option<f64> {
        Some((self.value? - self.reference?).abs())
    }
    /// |value − reference| / |reference| (absolute when the reference is 0).
    pub fn relative_error(&self) -> Option<f64> {
        let r = self.reference?;
        let e = self.error()?;
        Some(if r != 0.0 { e / r.abs() } else { e })
    }
    /// A check compared against `tolerance`: passes when the error is within it.
    pub fn compared(
        case: &str,
        quantity: String,
        method: &str,
        value: f64,
        reference: f64,
        tolerance: f64,
        time: Duration,
    ) -> Check {
        let err = (value - reference).abs();
        let status = if err <= tolerance {
            Status::Pass
        } else {
            Status::Fail(format!("error {err:.3e} exceeds tolerance {tolerance:.3e}"))
        };
        Check {
            case: case.to_string(),
            quantity,
            method: method.to_string(),
            value: Some(value),
            reference: Some(reference),
            tolerance: Some(tolerance),
            time: Some(time),
            status,
        }
    }
    /// Marks a failure as a known issue.
    pub fn with_known_issue(mut self, why: &str) -> Check {
        if let Status::Fail(r) = self.status {
            self.status = Status::Known(format!("{r}; known issue: {why}"));
        }
        self
    }
    /// A row without a value (failure, n/a or skip).
    pub fn without_value(case: &str, quantity: &str, method: &str, status: Status) -> Check {
        Check {
            case: case.to_string(),
            quantity: quantity.to_string(),
            method: method.to_string(),
            value: None,
            reference: None,
            tolerance: None,
            time: None,
            status,
        }
    }
}
